/* Tests for the TOML reader (runtime/scene/toml.c): every supported construct, line numbers,
 * a table of malformed inputs with their messages, truncated and mutated documents. And the
 * scene's law interpreter (runtime/scene/expr.c): when a law is defined (every part finite). */
#include <limits.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "scene/expr.h"
#include "scene/toml.h"

static char err[256];

/* Parse from an exact-size heap copy (no NUL terminator), so sanitizers see over-reads. */
static toml_value *parse_n(const char *text, size_t len)
{
    char *buf = malloc(len ? len : 1);
    if (!buf)
        return NULL;
    memcpy(buf, text, len);
    toml_value *r = toml_parse(buf, len, err, sizeof err);
    free(buf);
    return r;
}

static toml_value *parse(const char *text)
{
    toml_value *r = parse_n(text, strlen(text));
    CHECK(r != NULL, "parse failed: %s\n--- input:\n%s", err, text);
    return r;
}

/* Walks a path like "a.b.2.c" (numbers index arrays). */
static const toml_value *at(const toml_value *v, const char *path)
{
    char buf[256];
    snprintf(buf, sizeof buf, "%s", path);
    for (char *tok = strtok(buf, "."); tok && v; tok = strtok(NULL, ".")) {
        if (toml_kind_of(v) == TOML_ARRAY)
            v = toml_array_at(v, (size_t)atoi(tok));
        else
            v = toml_get(v, tok);
    }
    return v;
}

static void check_str(const toml_value *root, const char *path, const char *want, int line)
{
    const toml_value *v = at(root, path);
    CHECK(v && toml_kind_of(v) == TOML_STRING, "%s: not a string", path);
    if (!v || toml_kind_of(v) != TOML_STRING)
        return;
    CHECK(strcmp(toml_string(v), want) == 0, "%s: '%s' vs '%s'", path, toml_string(v), want);
    CHECK(toml_string_len(v) == strlen(want), "%s: length", path);
    if (line)
        CHECK(toml_line(v) == line, "%s: line %d vs %d", path, toml_line(v), line);
}

static void check_int(const toml_value *root, const char *path, long long want, int line)
{
    const toml_value *v = at(root, path);
    CHECK(v && toml_kind_of(v) == TOML_INT, "%s: not an integer", path);
    if (!v || toml_kind_of(v) != TOML_INT)
        return;
    CHECK(toml_int(v) == want, "%s: %lld vs %lld", path, toml_int(v), want);
    CHECK(toml_number(v) == (double)want, "%s: toml_number", path);
    if (line)
        CHECK(toml_line(v) == line, "%s: line %d vs %d", path, toml_line(v), line);
}

static void check_float(const toml_value *root, const char *path, double want, int line)
{
    const toml_value *v = at(root, path);
    CHECK(v && toml_kind_of(v) == TOML_FLOAT, "%s: not a float", path);
    if (!v || toml_kind_of(v) != TOML_FLOAT)
        return;
    double got = toml_number(v);
    if (isnan(want))
        CHECK(isnan(got), "%s: expected nan, got %g", path, got);
    else if (isinf(want))
        CHECK(got == want, "%s: %g vs %g", path, got, want);
    else
        CHECK_CLOSE(got, want, 1e-15, path);
    if (line)
        CHECK(toml_line(v) == line, "%s: line %d vs %d", path, toml_line(v), line);
}

static void check_bool(const toml_value *root, const char *path, int want, int line)
{
    const toml_value *v = at(root, path);
    CHECK(v && toml_kind_of(v) == TOML_BOOL, "%s: not a boolean", path);
    if (!v || toml_kind_of(v) != TOML_BOOL)
        return;
    CHECK(toml_bool(v) == want, "%s: %d vs %d", path, toml_bool(v), want);
    if (line)
        CHECK(toml_line(v) == line, "%s: line %d vs %d", path, toml_line(v), line);
}

static void check_kind(const toml_value *root, const char *path, toml_kind k, size_t size, int line)
{
    const toml_value *v = at(root, path);
    CHECK(v && toml_kind_of(v) == k, "%s: not a %s", path, toml_kind_name(k));
    if (!v || toml_kind_of(v) != k)
        return;
    size_t n = k == TOML_TABLE ? toml_table_size(v) : toml_array_size(v);
    CHECK(n == size, "%s: size %zu vs %zu", path, n, size);
    if (line)
        CHECK(toml_line(v) == line, "%s: line %d vs %d", path, toml_line(v), line);
}

/* ------------------------------------------------------------------ valid input */

static void test_scalars(void)
{
    const char *doc = "s1 = \"plain\"\n"                                  /* 1 */
                      "s2 = \"q\\\" b\\\\ n\\n t\\t b\\b f\\f r\\r\"\n"   /* 2 */
                      "s3 = \"\\u00e9\\u20AC\\U0001F600\"\n"              /* 3 */
                      "s4 = 'C:\\path\\no \"escapes\"'\n"                 /* 4 */
                      "s5 = \"\"\n"                                       /* 5 */
                      "s6 = ''\n"                                         /* 6 */
                      "s7 = \"tab\there # not a comment\"\n"              /* 7 */
                      "s8 = \"h\xc3\xa9llo\"\n"                           /* 8 */
                      "i1 = 0\n"                                          /* 9 */
                      "i2 = -0\n"                                         /* 10 */
                      "i3 = +42\n"                                        /* 11 */
                      "i4 = -17\n"                                        /* 12 */
                      "i5 = 1_000_000\n"                                  /* 13 */
                      "i6 = 9223372036854775807\n"                        /* 14 */
                      "i7 = -9223372036854775808\n"                       /* 15 */
                      "i8 = 0xDEAD_beef\n"                                /* 16 */
                      "i9 = 0o755\n"                                      /* 17 */
                      "i10 = 0b1101\n"                                    /* 18 */
                      "i11 = 0x7FFFFFFFFFFFFFFF\n"                        /* 19 */
                      "i12 = 0x00ff\n"                                    /* 20 */
                      "f1 = 1.0\n"                                        /* 21 */
                      "f2 = -2.5e-3\n"                                    /* 22 */
                      "f3 = 1e6\n"                                        /* 23 */
                      "f4 = 6.626E-34\n"                                  /* 24 */
                      "f5 = 1_000.000_1\n"                                /* 25 */
                      "f6 = inf\n"                                        /* 26 */
                      "f7 = +inf\n"                                       /* 27 */
                      "f8 = -inf\n"                                       /* 28 */
                      "f9 = nan\n"                                        /* 29 */
                      "f10 = -nan\n"                                      /* 30 */
                      "f11 = +1.5e+2\n"                                   /* 31 */
                      "f12 = 0.0\n"                                       /* 32 */
                      "f13 = -0.0\n"                                      /* 33 */
                      "f14 = 0e0\n"                                       /* 34 */
                      "f15 = 3.141_592\n"                                 /* 35 */
                      "f16 = 1e-320\n"                                    /* 36 subnormal ok */
                      "b1 = true\n"                                       /* 37 */
                      "b2 = false\n";                                     /* 38 */
    toml_value *r = parse(doc);
    if (!r)
        return;
    check_str(r, "s1", "plain", 1);
    check_str(r, "s2", "q\" b\\ n\n t\t b\b f\f r\r", 2);
    check_str(r, "s3", "\xc3\xa9\xe2\x82\xac\xf0\x9f\x98\x80", 3);
    check_str(r, "s4", "C:\\path\\no \"escapes\"", 4);
    check_str(r, "s5", "", 5);
    check_str(r, "s6", "", 6);
    check_str(r, "s7", "tab\there # not a comment", 7);
    check_str(r, "s8", "h\xc3\xa9llo", 8);
    check_int(r, "i1", 0, 9);
    check_int(r, "i2", 0, 10);
    check_int(r, "i3", 42, 11);
    check_int(r, "i4", -17, 12);
    check_int(r, "i5", 1000000, 13);
    check_int(r, "i6", LLONG_MAX, 14);
    check_int(r, "i7", LLONG_MIN, 15);
    check_int(r, "i8", 0xDEADBEEF, 16);
    check_int(r, "i9", 0755, 17);
    check_int(r, "i10", 13, 18);
    check_int(r, "i11", LLONG_MAX, 19);
    check_int(r, "i12", 255, 20);
    check_float(r, "f1", 1.0, 21);
    check_float(r, "f2", -2.5e-3, 22);
    check_float(r, "f3", 1e6, 23);
    check_float(r, "f4", 6.626e-34, 24);
    check_float(r, "f5", 1000.0001, 25);
    check_float(r, "f6", INFINITY, 26);
    check_float(r, "f7", INFINITY, 27);
    check_float(r, "f8", -INFINITY, 28);
    check_float(r, "f9", NAN, 29);
    check_float(r, "f10", NAN, 30);
    check_float(r, "f11", 150.0, 31);
    check_float(r, "f12", 0.0, 32);
    check_float(r, "f13", -0.0, 33);
    CHECK(signbit(toml_number(toml_get(r, "f13"))), "-0.0 keeps its sign");
    check_float(r, "f14", 0.0, 34);
    check_float(r, "f15", 3.141592, 35);
    CHECK(toml_number(toml_get(r, "f16")) > 0 && toml_number(toml_get(r, "f16")) < 1e-300, "subnormal");
    check_bool(r, "b1", 1, 37);
    check_bool(r, "b2", 0, 38);
    CHECK(toml_table_size(r) == 38, "root has %zu keys", toml_table_size(r));
    toml_free(r);
}

static void test_keys(void)
{
    const char *doc = "bare_Key-1 = 1\n"           /* 1 */
                      "\"quoted key\" = 2\n"       /* 2 */
                      "'literal key' = 3\n"        /* 3 */
                      "\"a.b\" = 4\n"              /* 4: one key containing a dot */
                      "\"\" = 5\n"                 /* 5: empty key */
                      "x . y . \"z w\" = 6\n"      /* 6: dotted with spaces */
                      "x.y.v = 7\n"                /* 7: extends the dotted table */
                      "x.u = 8\n"                  /* 8 */
                      "1234 = 9\n"                 /* 9: digits are a bare key */
                      "true = 10\n"                /* 10 */
                      "\"\\u00e9t\\u00e9\" = 11\n" /* 11 */
                      "  indented   =   12   # trailing comment\n";
    toml_value *r = parse(doc);
    if (!r)
        return;
    const char *keys[] = {"bare_Key-1", "quoted key", "literal key", "a.b", "", "x", "1234", "true",
                          "\xc3\xa9t\xc3\xa9", "indented"};
    int klines[] = {1, 2, 3, 4, 5, 6, 9, 10, 11, 12};
    size_t nk = sizeof keys / sizeof keys[0];
    CHECK(toml_table_size(r) == nk, "root has %zu keys", toml_table_size(r));
    for (size_t i = 0; i < nk && i < toml_table_size(r); i++) {
        CHECK(strcmp(toml_table_key(r, i), keys[i]) == 0, "key %zu: '%s' vs '%s'", i, toml_table_key(r, i),
              keys[i]);
        CHECK(toml_table_key_line(r, i) == klines[i], "key %zu line %d", i, toml_table_key_line(r, i));
    }
    check_int(r, "1234", 9, 9);
    check_int(r, "true", 10, 10);
    CHECK(toml_int(toml_get(r, "a.b")) == 4, "quoted key with a dot");
    CHECK(toml_int(toml_get(r, "")) == 5, "empty key");
    CHECK(toml_int(toml_get(r, "\xc3\xa9t\xc3\xa9")) == 11, "escaped key");
    check_kind(r, "x", TOML_TABLE, 2, 6);
    check_kind(r, "x.y", TOML_TABLE, 2, 6);
    const toml_value *y = at(r, "x.y");
    CHECK(toml_int(toml_get(y, "z w")) == 6, "x.y.'z w'");
    CHECK(toml_get_key_line(y, "v") == 7, "x.y.v key line");
    check_int(r, "x.u", 8, 8);
    check_int(r, "indented", 12, 12);
    CHECK(toml_get(r, "missing") == NULL, "absent key");
    CHECK(toml_get_key_line(r, "missing") == 0, "absent key line");
    toml_free(r);
}

static void test_tables(void)
{
    const char *doc = "# scene\n"                /* 1 */
                      "top = 1\n"                /* 2 */
                      "\n"                       /* 3 */
                      "[fluid]\n"                /* 4 */
                      "rho0 = 1.0\n"             /* 5 */
                      "  [fluid.far]  # sub\n"   /* 6 */
                      "u = [1.0, 0.0]\n"         /* 7 */
                      "[body.shape]\n"           /* 8: body implicit */
                      "L = 2\n"                  /* 9 */
                      "[body]\n"                 /* 10: now defined */
                      "mass = 3\n"               /* 11 */
                      "[ \"quoted\" . 'lit' ]\n" /* 12 */
                      "k = true\n"               /* 13 */
                      "[[probe]]\n"              /* 14 */
                      "name = \"tip\"\n"         /* 15 */
                      "[probe.where]\n"          /* 16: into the last probe */
                      "s = 1.0\n"                /* 17 */
                      "[[probe]]\n"              /* 18 */
                      "name = \"mid\"\n"         /* 19 */
                      "[[probe.hits]]\n"         /* 20 */
                      "t = 1\n"                  /* 21 */
                      "[[probe.hits]]\n"         /* 22 */
                      "t = 2\n"                  /* 23 */
                      "[[probe]]\n"              /* 24: empty element */
                      "[fruit]\n"                /* 25 */
                      "apple.color = \"red\"\n"  /* 26 */
                      "apple.taste.sweet = true\n" /* 27 */
                      "[fruit.apple.texture]\n"  /* 28: allowed by TOML */
                      "smooth = true\n";         /* 29 */
    toml_value *r = parse(doc);
    if (!r)
        return;
    CHECK(toml_table_size(r) == 6, "root keys: %zu", toml_table_size(r));
    check_int(r, "top", 1, 2);
    check_kind(r, "fluid", TOML_TABLE, 2, 4);
    check_float(r, "fluid.rho0", 1.0, 5);
    check_kind(r, "fluid.far", TOML_TABLE, 1, 6);
    check_kind(r, "fluid.far.u", TOML_ARRAY, 2, 7);
    check_kind(r, "body", TOML_TABLE, 2, 10);
    CHECK(toml_get_key_line(r, "body") == 10, "body key line after definition");
    CHECK(strcmp(toml_table_key(at(r, "body"), 0), "shape") == 0, "body keys in file order");
    check_kind(r, "body.shape", TOML_TABLE, 1, 8);
    check_int(r, "body.shape.L", 2, 9);
    check_int(r, "body.mass", 3, 11);
    check_bool(r, "quoted.lit.k", 1, 13);
    check_kind(r, "probe", TOML_ARRAY, 3, 14);
    check_kind(r, "probe.0", TOML_TABLE, 2, 14);
    check_str(r, "probe.0.name", "tip", 15);
    check_kind(r, "probe.0.where", TOML_TABLE, 1, 16);
    check_float(r, "probe.0.where.s", 1.0, 17);
    check_kind(r, "probe.1", TOML_TABLE, 2, 18);
    check_str(r, "probe.1.name", "mid", 19);
    check_kind(r, "probe.1.hits", TOML_ARRAY, 2, 20);
    check_int(r, "probe.1.hits.0.t", 1, 21);
    check_int(r, "probe.1.hits.1.t", 2, 23);
    check_kind(r, "probe.2", TOML_TABLE, 0, 24);
    check_str(r, "fruit.apple.color", "red", 26);
    check_bool(r, "fruit.apple.taste.sweet", 1, 27);
    check_bool(r, "fruit.apple.texture.smooth", 1, 29);
    check_kind(r, "fruit.apple", TOML_TABLE, 3, 26);
    toml_free(r);
}

static void test_arrays_inline(void)
{
    const char *doc = "a = []\n"                                   /* 1 */
                      "b = [1, 2.5, \"x\", true]\n"                /* 2: mixed */
                      "c = [\n"                                    /* 3 */
                      "  1,  # one\n"                              /* 4 */
                      "  # comment line\n"                         /* 5 */
                      "\n"                                         /* 6 */
                      "  [2, [3, []]],\n"                          /* 7 */
                      "  { k = 'v' },\n"                           /* 8 */
                      "]\n"                                        /* 9 */
                      "d = [ 1 , 2 , ]\n"                          /* 10 */
                      "e = {}\n"                                   /* 11 */
                      "f = { a = 1, b = \"x\", c.d = [1, {e = 2}], \"q k\" = -inf }\n" /* 12 */
                      "g = [[1,2],[3,4]]\n"                        /* 13 */
                      "h = [\"a\"\n"                               /* 14 */
                      "  , \"b\"\n"                                /* 15 */
                      "  ]\n";                                     /* 16 */
    toml_value *r = parse(doc);
    if (!r)
        return;
    check_kind(r, "a", TOML_ARRAY, 0, 1);
    check_kind(r, "b", TOML_ARRAY, 4, 2);
    check_int(r, "b.0", 1, 2);
    check_float(r, "b.1", 2.5, 2);
    check_str(r, "b.2", "x", 2);
    check_bool(r, "b.3", 1, 2);
    check_kind(r, "c", TOML_ARRAY, 3, 3);
    check_int(r, "c.0", 1, 4);
    check_kind(r, "c.1", TOML_ARRAY, 2, 7);
    check_int(r, "c.1.0", 2, 7);
    check_kind(r, "c.1.1", TOML_ARRAY, 2, 7);
    check_kind(r, "c.1.1.1", TOML_ARRAY, 0, 7);
    check_kind(r, "c.2", TOML_TABLE, 1, 8);
    check_str(r, "c.2.k", "v", 8);
    check_kind(r, "d", TOML_ARRAY, 2, 10);
    check_kind(r, "e", TOML_TABLE, 0, 11);
    check_kind(r, "f", TOML_TABLE, 4, 12);
    check_int(r, "f.a", 1, 12);
    check_str(r, "f.b", "x", 12);
    check_kind(r, "f.c.d", TOML_ARRAY, 2, 12);
    check_int(r, "f.c.d.1.e", 2, 12);
    CHECK(isinf(toml_number(toml_get(at(r, "f"), "q k"))), "f.'q k'");
    check_int(r, "g.1.0", 3, 13);
    check_kind(r, "h", TOML_ARRAY, 2, 14);
    check_str(r, "h.1", "b", 15);
    toml_free(r);
}

static void test_misc(void)
{
    /* empty and comment-only documents */
    toml_value *r = parse("");
    CHECK(r && toml_table_size(r) == 0, "empty document");
    toml_free(r);
    r = toml_parse(NULL, 0, err, sizeof err);
    CHECK(r && toml_table_size(r) == 0, "NULL, 0");
    toml_free(r);
    r = parse("# only a comment");
    CHECK(r && toml_table_size(r) == 0, "comment only");
    toml_free(r);
    r = parse("\n\n  \t\n# x\n\n");
    CHECK(r && toml_table_size(r) == 0, "blank lines");
    toml_free(r);

    /* CRLF line ends */
    r = parse("a = 1\r\n# c\r\n[t]\r\nb = [\r\n 2,\r\n]\r\n");
    if (r) {
        check_int(r, "a", 1, 1);
        check_kind(r, "t", TOML_TABLE, 1, 3);
        check_int(r, "t.b.0", 2, 5);
        toml_free(r);
    }

    /* only len bytes are read: no terminator needed, bytes beyond len ignored */
    r = toml_parse("a = 12345", 5, err, sizeof err);
    CHECK(r && toml_int(toml_get(r, "a")) == 1, "length-limited input");
    toml_free(r);
    r = toml_parse("s = \"abc\"", 8, err, sizeof err);
    CHECK(!r && strstr(err, "unterminated string"), "length cuts a string: %s", err);

    /* accessors on wrong kinds / NULL are total */
    r = parse("s = \"x\"\ni = 3\na = [1]\n");
    if (r) {
        const toml_value *s = toml_get(r, "s"), *i = toml_get(r, "i"), *a = toml_get(r, "a");
        CHECK(toml_int(s) == 0 && toml_bool(s) == 0 && isnan(toml_number(s)), "string as number");
        CHECK(toml_string(i) == NULL && toml_string_len(i) == 0, "int as string");
        CHECK(toml_table_size(a) == 0 && toml_get(a, "x") == NULL && toml_table_key(a, 0) == NULL, "array as table");
        CHECK(toml_array_size(r) == 0 && toml_array_at(r, 0) == NULL, "table as array");
        CHECK(toml_array_at(a, 1) == NULL && toml_table_value(r, 99) == NULL, "out of range");
        CHECK(toml_line(NULL) == 0 && toml_get(NULL, "a") == NULL && toml_string(NULL) == NULL, "NULL node");
        CHECK(toml_is_number(i) && !toml_is_number(s), "toml_is_number");
        toml_free(r);
    }
    toml_free(NULL);

    const char *names[] = {"table", "array", "string", "integer", "float", "boolean"};
    for (int k = TOML_TABLE; k <= TOML_BOOL; k++)
        CHECK(strcmp(toml_kind_name((toml_kind)k), names[k]) == 0, "kind name %d", k);

    /* error buffer: NULL, tiny */
    r = toml_parse("a = ", 4, NULL, 0);
    CHECK(r == NULL, "error with NULL buffer");
    char tiny[6];
    r = toml_parse("a = ", 4, tiny, sizeof tiny);
    CHECK(r == NULL && strcmp(tiny, "line ") == 0, "error truncated to tiny buffer: '%s'", tiny);
}

static void test_limits(void)
{
    char *buf = malloc(4 << 20);
    if (!buf)
        return;
    /* nesting: 64 levels of arrays are fine, 65 are not */
    for (int depth = 63; depth <= 65; depth++) {
        size_t o = (size_t)sprintf(buf, "a = ");
        for (int i = 0; i < depth; i++)
            buf[o++] = '[';
        for (int i = 0; i < depth; i++)
            buf[o++] = ']';
        toml_value *r = parse_n(buf, o);
        if (depth <= TOML_MAX_DEPTH)
            CHECK(r != NULL, "depth %d: %s", depth, err);
        else
            CHECK(!r && strstr(err, "nesting too deep") && strncmp(err, "line 1:", 7) == 0, "depth %d: %s", depth,
                  err);
        toml_free(r);
    }
    /* deeply nested inline tables and arrays mixed, far too deep: error, not a crash */
    {
        size_t o = (size_t)sprintf(buf, "\n\nx = ");
        for (int i = 0; i < 100000; i++)
            o += (size_t)sprintf(buf + o, i % 2 ? "[" : "{a=");
        toml_value *r = parse_n(buf, o);
        CHECK(!r && strstr(err, "nesting too deep") && strncmp(err, "line 3:", 7) == 0, "deep mix: %s", err);
    }
    /* headers and dotted keys count towards the same limit */
    {
        size_t o = 0;
        buf[o++] = '[';
        for (int i = 0; i < 64; i++)
            o += (size_t)sprintf(buf + o, i ? ".k" : "k");
        o += (size_t)sprintf(buf + o, "]\nv = 1\n");
        toml_value *r = parse_n(buf, o);
        CHECK(!r && strstr(err, "nesting too deep") && strncmp(err, "line 2:", 7) == 0, "deep header: %s", err);
        o = 0;
        for (int i = 0; i < 70; i++)
            o += (size_t)sprintf(buf + o, i ? ".k" : "k");
        o += (size_t)sprintf(buf + o, " = 1\n");
        r = parse_n(buf, o);
        CHECK(!r && strstr(err, "too many dotted parts"), "long dotted key: %s", err);
        o = 0;
        for (int i = 0; i < 63; i++)
            o += (size_t)sprintf(buf + o, i ? ".k" : "k");
        o += (size_t)sprintf(buf + o, " = 1\n");
        r = parse_n(buf, o);
        CHECK(r != NULL, "63-part dotted key: %s", err);
        toml_free(r);
    }
    /* large tables (hash index) and arrays */
    {
        size_t o = 0;
        for (int i = 0; i < 20000; i++)
            o += (size_t)sprintf(buf + o, "key%d = %d\n", i, i);
        toml_value *r = parse_n(buf, o);
        CHECK(r && toml_table_size(r) == 20000, "20000 keys");
        int ok = 1;
        char k[32];
        for (int i = 0; r && i < 20000; i++) {
            snprintf(k, sizeof k, "key%d", i);
            ok &= toml_int(toml_get(r, k)) == i && toml_get_key_line(r, k) == i + 1;
            ok &= strcmp(toml_table_key(r, (size_t)i), k) == 0;
        }
        CHECK(ok, "lookups in a large table");
        CHECK(toml_get(r, "key20000") == NULL, "absent key in large table");
        toml_free(r);
        o += (size_t)sprintf(buf + o, "key12345 = 0\n");
        r = parse_n(buf, o);
        CHECK(!r && strstr(err, "duplicate key 'key12345' (first defined on line 12346)") &&
                  strncmp(err, "line 20001:", 11) == 0,
              "duplicate in large table: %s", err);
    }
    {
        size_t o = (size_t)sprintf(buf, "a = [");
        for (int i = 0; i < 200000; i++)
            o += (size_t)sprintf(buf + o, "%d,", i);
        o += (size_t)sprintf(buf + o, "]\ns = \"");
        for (int i = 0; i < 1000000; i++)
            buf[o++] = (char)('a' + i % 26);
        buf[o++] = '"';
        toml_value *r = parse_n(buf, o);
        CHECK(r && toml_array_size(toml_get(r, "a")) == 200000 &&
                  toml_int(toml_array_at(toml_get(r, "a"), 199999)) == 199999,
              "long array");
        CHECK(r && toml_string_len(toml_get(r, "s")) == 1000000, "long string");
        toml_free(r);
    }
    free(buf);
}

/* Valid TOML that a too-strict table logic would wrongly reject. */
static void test_table_rules(void)
{
    const char *ok[] = {
        "[a.b.c]\n[a]\nx = 1\n",             /* implicit table defined later */
        "[a]\n[a.b]\n[a.c]\n",
        "[[a]]\n[[a.b]]\n[a.b.c]\nd = 1\n", /* header through two arrays of tables */
        "a.b = 1\n[a.c]\n",                 /* header below a dotted table */
        "[x]\na.b = 1\na.c = 2\n[x.a.d]\n",
        "t = {a.b = 1, a.c = 2}\n",          /* dotted keys inside an inline table */
        "a = [{b = 1}, {b = 2}]\n",
        "[[a]]\nb.c = 1\n[[a]]\nb.c = 2\n",
    };
    for (size_t i = 0; i < sizeof ok / sizeof ok[0]; i++) {
        toml_value *r = parse(ok[i]);
        toml_free(r);
    }
    toml_value *r = parse("[[a]]\n[[a.b]]\n[a.b.c]\nd = 1\n[[a.b]]\n[[a]]\n");
    if (r) {
        check_kind(r, "a", TOML_ARRAY, 2, 1);
        check_kind(r, "a.0.b", TOML_ARRAY, 2, 2);
        check_int(r, "a.0.b.0.c.d", 1, 4);
        check_kind(r, "a.0.b.1", TOML_TABLE, 0, 5);
        check_kind(r, "a.1", TOML_TABLE, 0, 6);
        toml_free(r);
    }
}

/* ---------------------------------------------------------------- error input */

typedef struct {
    const char *text;
    size_t len; /* 0: strlen */
    int line;
    const char *msg;
} bad_case;

static const bad_case bad[] = {
    {"a = 1\nrho0 1.0\n", 0, 2, "expected '=' after key 'rho0', found '1'"},
    {"N = 1\nx = 2\nN = 3\n", 0, 3, "duplicate key 'N' (first defined on line 1)"},
    {"a = 1\ns = \"abc\nb = 2\n", 0, 2, "unterminated string"},
    {"s = 'abc", 0, 1, "unterminated string"},
    {"s = \"abc\\", 0, 1, "unterminated string"},
    {"[a]\nx = 1\n[b]\n[a]\n", 0, 4, "table 'a' is already defined (line 1)"},
    {"x = \"\"\"multi\"\"\"\n", 0, 1, "multi-line strings (\"\"\") are not supported"},
    {"x = '''multi'''\n", 0, 1, "multi-line strings (''') are not supported"},
    {"d = 1979-05-27\n", 0, 1, "dates and times are not supported"},
    {"\nt = 07:32:00\n", 0, 2, "dates and times are not supported"},
    {"n = 9223372036854775808\n", 0, 1, "integer '9223372036854775808' is out of range"},
    {"n = -9223372036854775809\n", 0, 1, "is out of range"},
    {"n = 0x8000000000000000\n", 0, 1, "is out of range"},
    {"n = 99999999999999999999999999\n", 0, 1, "is out of range"},
    {"n = 007\n", 0, 1, "leading zeros are not allowed in '007'"},
    {"n = 1__0\n", 0, 1, "invalid number '1__0'"},
    {"n = 1_\n", 0, 1, "invalid number '1_'"},
    {"n = _1\n", 0, 1, "invalid number '_1'"},
    {"n = 1.\n", 0, 1, "digits needed after '.'"},
    {"n = .5\n", 0, 1, "invalid number '.5'"},
    {"n = 1e\n", 0, 1, "bad exponent"},
    {"n = 1.0.0\n", 0, 1, "invalid number '1.0.0'"},
    {"n = +0x10\n", 0, 1, "sign not allowed"},
    {"n = 0x\n", 0, 1, "invalid number '0x'"},
    {"n = 0b102\n", 0, 1, "invalid number '0b102'"},
    {"n = -\n", 0, 1, "invalid number '-'"},
    {"f = 1e999\n", 0, 1, "float '1e999' is out of range"},
    {"s = \"\\q\"\n", 0, 1, "invalid escape '\\q'"},
    {"s = \"\\u12\"\n", 0, 1, "escape \\u needs 4 hex digits"},
    {"s = \"\\U0011FFFF\"\n", 0, 1, "not a valid Unicode scalar value"},
    {"s = \"\\uD800\"\n", 0, 1, "not a valid Unicode scalar value"},
    {"s = \"\\u0000\"\n", 0, 1, "escape of NUL is not allowed"},
    {"a = [1, 2\n\n", 0, 3, "unterminated array (opened on line 1)"},
    {"a = [1 2]\n", 0, 1, "expected ',' or ']' in array, found '2'"},
    {"a = [1,,2]\n", 0, 1, "expected a value, found ','"},
    {"a = [,]\n", 0, 1, "expected a value, found ','"},
    {"a = {x = 1,}\n", 0, 1, "trailing comma not allowed in inline table"},
    {"a = {x = 1\n}\n", 0, 1, "inline table must be on one line"},
    {"a = {x = 1", 0, 1, "unterminated inline table (opened on line 1)"},
    {"a = {x = 1 y = 2}\n", 0, 1, "expected ',' or '}' in inline table, found 'y'"},
    {"a = {x = 1, x = 2}\n", 0, 1, "duplicate key 'x'"},
    {"a = {b = 1}\n[a.c]\n", 0, 2, "cannot extend inline table 'a'"},
    {"a = {b = 1}\na.c = 2\n", 0, 2, "cannot add keys to table 'a' (defined on line 1) with a dotted key"},
    {"a = {b = 1}\n[a]\n", 0, 2, "table 'a' is already defined"},
    {"a = 1 2\n", 0, 1, "expected end of line after value of key 'a', found '2'"},
    {"a = \"x\" \"y\"\n", 0, 1, "expected end of line after value of key 'a', found '\"'"},
    {"[a\nb = 1\n", 0, 1, "expected ']' to close table header, found end of line"},
    {"[[a]\n", 0, 1, "expected ']]' to close array-of-tables header"},
    {"[a]]\n", 0, 1, "expected end of line after table header, found ']'"},
    {"[a] x = 1\n", 0, 1, "expected end of line after table header, found 'x'"},
    {"\n[]\n", 0, 2, "expected a key, found ']'"},
    {"[a.]\n", 0, 1, "expected a key after 'a.', found ']'"},
    {"= 1\n", 0, 1, "expected a key, found '='"},
    {"a = \n", 0, 1, "missing value for key 'a'"},
    {"a.b = # c\n", 0, 1, "missing value for key 'a.b'"},
    {"a =", 0, 1, "missing value for key 'a'"},
    {"a = abc\n", 0, 1, "invalid value 'abc' (strings must be quoted)"},
    {"a = True\n", 0, 1, "invalid value 'True'"},
    {"a = infinity\n", 0, 1, "invalid value 'infinity'"},
    {"a = @\n", 0, 1, "expected a value, found '@'"},
    {"a = 1\na.b = 2\n", 0, 2, "key 'a' is already an integer (line 1), not a table"},
    {"a = 's'\n[a.b]\n", 0, 2, "key 'a' is already a string (line 1), not a table"},
    {"[a]\nb.c = 1\n[a.b]\n", 0, 3, "table 'a.b' is already defined (line 2)"},
    {"a.b.c = 1\n[a]\n", 0, 2, "table 'a' is already defined"},
    {"[a.b]\n[a]\nb.c = 1\n", 0, 3, "cannot add keys to table 'b' (defined on line 1) with a dotted key"},
    {"a = [1]\n[[a]]\n", 0, 2, "cannot define array of tables 'a': key is already an array (line 1)"},
    {"[[a]]\n[a]\n", 0, 2, "cannot define table 'a': key is already an array (line 1)"},
    {"[a]\n[[a]]\n", 0, 2, "cannot define array of tables 'a': key is already a table"},
    {"a = [{b = 1}]\n[a.c]\n", 0, 2, "key 'a' is already an array (line 1), not a table"},
    {"a = 1\0b = 2\n", 11, 1, "NUL byte in input"},
    {"a = 1\n# \0\n", 10, 2, "NUL byte in input"},
    {"a = \"\xff\"\n", 0, 1, "invalid UTF-8 byte 0xFF"},
    {"\n\na = \"\xc3\"\n", 0, 3, "invalid UTF-8 sequence"},
    {"a = \"\xed\xa0\x80\"\n", 0, 1, "invalid UTF-8 sequence"},  /* encoded surrogate */
    {"a = \"\xc0\xaf\"\n", 0, 1, "invalid UTF-8 byte 0xC0"},       /* overlong */
    {"a = \"\xe2\x82", 0, 1, "truncated UTF-8 sequence"},
    {"a = 1\rb = 2\n", 0, 1, "carriage return not followed by a newline"},
    {"# c\x01\n", 0, 1, "control character 0x01 in comment"},
    {"a = \"x\x01\"\n", 0, 1, "control character 0x01 in string"},
    {"a = 'x\x7f'\n", 0, 1, "control character 0x7F in string"},
    {"a = \"x\" # ok\nb = 'unterminated\n", 0, 2, "unterminated string"},
    {"a = 1\nb = [\n  1,\n  2\n  3\n]\n", 0, 5, "expected ',' or ']' in array, found '3'"},
    {"[x]\n[[y]]\n[y.z]\n[y.z]\n", 0, 4, "table 'y.z' is already defined (line 3)"},
    {"ke y = 1\n", 0, 1, "expected '=' after key 'ke', found 'y'"},
    {"\"a\nb\" = 1\n", 0, 1, "unterminated string"},
    {"a = \"\"\"\n", 0, 1, "multi-line strings"},
};

static void test_errors(void)
{
    size_t n = sizeof bad / sizeof bad[0];
    CHECK(n >= 25, "at least 25 malformed inputs");
    for (size_t i = 0; i < n; i++) {
        size_t len = bad[i].len ? bad[i].len : strlen(bad[i].text);
        toml_value *r = parse_n(bad[i].text, len);
        CHECK(r == NULL, "case %zu should fail: %s", i, bad[i].text);
        toml_free(r);
        if (r)
            continue;
        char prefix[32];
        snprintf(prefix, sizeof prefix, "line %d: ", bad[i].line);
        CHECK(strncmp(err, prefix, strlen(prefix)) == 0, "case %zu: wrong line: '%s' (want %s)", i, err, prefix);
        CHECK(strstr(err, bad[i].msg) != NULL, "case %zu: '%s' lacks '%s'", i, err, bad[i].msg);
        CHECK(strchr(err, '\n') == NULL, "case %zu: message is one line", i);
    }
}

/* -------------------------------------------------- truncated / mutated inputs */

static const char *doc_full =
    "# swim scene\n"
    "title = \"example \\u00e9\"\n"
    "N = 7\n"
    "dt = 1.0e-3\n"
    "[fluid]\n"
    "rho0 = 1.0\n"
    "far = { u = [1.0, -0.5], name = 'far field' }\n"
    "[body]\n"
    "mass.density = 2.5e-1\n"
    "stiffness = [\n"
    "  1e3,   # soft\n"
    "  2_000.5,\n"
    "  [0x10, 0o7, 0b1],\n"
    "]\n"
    "[body.actuation]\n"
    "enabled = true\n"
    "[[probe]]\n"
    "name = \"tip\"\n"
    "[[probe]]\n"
    "name = \"mid\"\n"
    "[probe.at]\n"
    "s = -inf\n";

static int parse_outcome_ok(const char *text, size_t len)
{
    toml_value *r = parse_n(text, len);
    if (r) {
        int ok = toml_kind_of(r) == TOML_TABLE;
        toml_free(r);
        return ok;
    }
    int line = 0;
    return sscanf(err, "line %d: ", &line) == 1 && line >= 1 && strchr(err, '\n') == NULL && strlen(err) > 9;
}

static void test_truncated(void)
{
    size_t n = strlen(doc_full);
    toml_value *r = parse(doc_full);
    if (r) {
        check_str(r, "title", "example \xc3\xa9", 2);
        check_float(r, "fluid.far.u.1", -0.5, 7);
        check_int(r, "body.stiffness.2.0", 16, 13);
        check_kind(r, "probe", TOML_ARRAY, 2, 17);
        check_float(r, "probe.1.at.s", -INFINITY, 22);
        toml_free(r);
    }
    int ok = 1, parsed = 0, failed = 0;
    for (size_t len = 0; len <= n; len++) {
        toml_value *t = parse_n(doc_full, len);
        if (t) {
            parsed++;
            toml_free(t);
        } else {
            failed++;
            int line = 0;
            if (sscanf(err, "line %d: ", &line) != 1 || line < 1 || line > 23) {
                ok = 0;
                fprintf(stderr, "prefix %zu: bad message '%s'\n", len, err);
            }
        }
    }
    CHECK(ok, "every prefix parses or gives a proper error");
    CHECK(parsed > 10 && failed > 10, "prefixes: %d parsed, %d failed", parsed, failed);

    /* every byte replaced by a few troublesome ones, and every byte deleted */
    const char subs[] = {'\0', '\n', '\r', '"', '\'', '[', ']', '{', '}', '=', '.', ',', '#', '\\', 'x', '\xff'};
    char *m = malloc(n + 1);
    ok = 1;
    for (size_t i = 0; m && i < n; i++) {
        for (size_t k = 0; k < sizeof subs; k++) {
            memcpy(m, doc_full, n);
            m[i] = subs[k];
            ok &= parse_outcome_ok(m, n);
        }
        memcpy(m, doc_full, i);
        memcpy(m + i, doc_full + i + 1, n - i - 1);
        ok &= parse_outcome_ok(m, n - 1);
    }
    free(m);
    CHECK(ok, "mutated documents parse or give a proper error");
}

/* A law is defined at t when every operation in it is finite there, whatever its value: step
 * and pow can hide a NaN (step(NaN) = 0, NaN^0 = 1) that the generator, which folds constant
 * parts, refuses. The first failing operation is named. */
static void test_law_defined(void)
{
    static const struct { const char *law; double t; int defined; const char *why; } cases[] = {
        {"sin(t)*10^20/(1e20+t)", 0.0, 1, ""},
        {"step(t - 1)*abs(t)", 0.5, 1, ""},
        {"step(sqrt(-1))*t", 0.0, 0, "sqrt(-1) is not a finite real number"},
        {"sqrt(-1)^0 + t", 2.0, 0, "sqrt(-1)"},
        {"t + 0*log(0)", 0.0, 0, "log(0) is not"},
        {"step(1/t)", 0.0, 0, "1 / 0 is not"},
        {"step(1/t)", 1.0, 1, ""},
        {"(-8)^(1/3) + t", 1.0, 0, "-8 ^ 0.333333 is not"},
        {"10^400*0", 0.0, 0, "10 ^ 400 is not"},
        {"step(sqrt(1 - t))", 0.5, 1, ""},
        {"step(sqrt(1 - t))", 1.5, 0, "sqrt(-0.5)"},
        {"A*t", 1.0, 1, ""},
        {"sqrt(A - 1)*t", 1.0, 0, "sqrt(-0.25)"},
    };
    static const char *const names[] = {"A"};
    const double values[] = {0.75};
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
        char e_err[160], why[160] = "";
        swim_expr *e = swim_expr_compile_params(cases[i].law, names, 1, values, e_err, sizeof e_err);
        CHECK(e != NULL, "%s: %s", cases[i].law, e_err);
        if (!e) continue;
        int d = swim_expr_defined(e, cases[i].t, why, sizeof why);
        CHECK(d == cases[i].defined && strstr(why, cases[i].why),
              "%s at t = %g: defined %d (%s), want %d (%s)", cases[i].law, cases[i].t, d, why, cases[i].defined,
              cases[i].why);
        swim_expr_free(e);
    }
}

int main(void)
{
    test_law_defined();
    test_scalars();
    test_keys();
    test_tables();
    test_arrays_inline();
    test_table_rules();
    test_misc();
    test_limits();
    test_errors();
    test_truncated();
    return check_report("test_toml");
}
