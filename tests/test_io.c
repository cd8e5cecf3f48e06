/* Tests for runtime/io: the quoting of user text in messages (swim_quote, swim_message), the
 * JSON strings (always UTF-8), the atomic file replacement, canonical paths, and the CSV writer's whole-row guarantee on a
 * file that cannot grow (RLIMIT_FSIZE). */
#include <errno.h>
#include <math.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <unistd.h>

#include "check.h"
#include "io/csv.h"
#include "io/files.h"
#include "io/json.h"
#include "io/message.h"
#include "io/status.h"

/* swim_quote of len bytes into a new string. */
static char *quoted(const char *text, size_t len, size_t max)
{
    char *buf = NULL;
    size_t n = 0;
    FILE *m = open_memstream(&buf, &n);
    swim_quote(m, text, len, max);
    fclose(m);
    return buf;
}

static void test_quote(void)
{
    static const struct { const char *in; size_t len; const char *out; } cases[] = {
        {"plain text", 10, "plain text"},
        {"two\nlines", 9, "two\\nlines"},
        {"cr\r tab\t", 8, "cr\\r tab\\t"},
        {"\x1b[2J clear", 10, "\\x1b[2J clear"},
        {"back\\slash", 10, "back\\\\slash"},
        {"caf\xc3\xa9", 5, "caf\xc3\xa9"},                 /* valid UTF-8 passes */
        {"csi \xc2\x9b" "2J", 8, "csi \\u009b2J"},          /* C1 CSI */
        {"bad \xff\xfe", 6, "bad \\xff\\xfe"},              /* invalid bytes */
        {"over \xc0\xaf", 7, "over \\xc0\\xaf"},            /* overlong '/' */
        {"nul\0x", 5, "nul\\x00x"},
        {"del\x7f", 4, "del\\x7f"},
        {"rtl \xe2\x80\xae", 7, "rtl \\u202e"},             /* bidi override */
        {"cut \xe2\x82", 6, "cut \\xe2\\x82"},              /* truncated sequence */
    };
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
        char *q = quoted(cases[i].in, cases[i].len, 0);
        CHECK(q && strcmp(q, cases[i].out) == 0, "quote case %zu: got '%s', want '%s'", i, q, cases[i].out);
        free(q);
    }
    char *q = quoted("abcdefghij", 10, 4);
    CHECK(q && strcmp(q, "abcd... (6 more bytes)") == 0, "quote with a limit: '%s'", q);
    free(q);
}

static void note_to(void *ctx, const char *line) { fprintf(ctx, "%s|", line); }

static void test_message(void)
{
    char *buf = NULL;
    size_t n = 0;
    FILE *m = open_memstream(&buf, &n);
    swim_message(m, "swim: %s: %d", "a\nb\x1b", 7);
    fclose(m);
    CHECK(buf && strcmp(buf, "swim: a\\nb\\x1b: 7\n") == 0, "message: '%s'", buf);
    free(buf);
    /* a message longer than SWIM_MESSAGE_MAX is cut, and still one line */
    char *big = malloc(100000);
    memset(big, 'x', 99999);
    big[99999] = '\0';
    buf = NULL;
    m = open_memstream(&buf, &n);
    swim_message(m, "%s", big);
    fclose(m);
    CHECK(n < SWIM_MESSAGE_MAX + 100 && strchr(buf, '\n') == buf + n - 1 && strstr(buf, "more bytes"),
          "long message: %zu bytes", n);
    free(buf);
    free(big);
    char *s = swim_strprintf("%s-%d", "p", 42);
    CHECK(s && strcmp(s, "p-42") == 0, "strprintf: '%s'", s);
    free(s);
}

/* What a status shows is what swim_message shows for the same line, also for a line longer than
 * the status keeps (a multibyte character across the cut); the cause's fields and message, later
 * lines, notices. */
static void test_status(void)
{
    char *big = malloc(SWIM_MESSAGE_MAX + 5000);
    memset(big, 'v', SWIM_MESSAGE_MAX + 4999);
    /* a euro sign across the cut: its first byte the line's last shown ("swim: f.toml:3: model.rho0: " is 28) */
    memcpy(big + SWIM_MESSAGE_MAX - 1 - 28, "\xe2\x82\xac", 3);
    big[SWIM_MESSAGE_MAX + 4999] = '\0';
    char *want = NULL, *got = NULL;
    size_t nw = 0, ng = 0;
    FILE *m = open_memstream(&want, &nw);
    swim_message(m, "swim: f.toml:3: model.rho0: %s", big);
    swim_message(m, "swim run: f.toml: no kernel\x1b");
    fclose(m);
    swim_status st = {0};
    swim_status_fail(&st, "swim", "f.toml", 3, "model.rho0", "f.toml:3: model.rho0: %s", big);
    swim_status_fail(&st, "swim run", "other.toml", 9, "x", "f.toml: no kernel\x1b");
    m = open_memstream(&got, &ng);
    swim_status_print(&st, m);
    fclose(m);
    CHECK(want && got && strcmp(want, got) == 0, "a status shows what swim_message shows (%zu and %zu bytes)", nw, ng);
    CHECK(st.failed && strcmp(st.file, "f.toml") == 0 && st.line == 3 && strcmp(st.key, "model.rho0") == 0 &&
          st.nlines == 2, "the cause's fields, two lines: '%s' %d '%s' %d", st.file, st.line, st.key, st.nlines);
    char msg[64];
    swim_status_message(&st, msg, sizeof msg);
    CHECK(strncmp(msg, "f.toml:3: model.rho0: vvv", 25) == 0, "the message is the cause without 'swim: ': '%s'", msg);
    for (int i = 0; i < 5; i++) swim_status_fail(&st, NULL, NULL, 0, NULL, "more %d", i);
    CHECK(st.nlines == SWIM_STATUS_LINES, "at most %d lines kept: %d", SWIM_STATUS_LINES, st.nlines);
    swim_status_clear(&st);
    CHECK(!st.failed && st.nlines == 0 && swim_status_print(&st, stdout) == 0, "a clear status shows nothing");
    free(want);
    free(got);
    free(big);
    /* notices go to the callback, nowhere without one; clearing keeps it */
    char *notes = NULL;
    size_t nn = 0;
    FILE *nf = open_memstream(&notes, &nn);
    swim_status quiet = {0}, loud = {.note = note_to, .note_ctx = nf};
    swim_status_note(&quiet, "lost %d", 1);
    swim_status_note(&loud, "kept %d", 2);
    swim_status_clear(&loud);
    swim_status_note(&loud, "kept %d", 3);
    swim_status_note(NULL, "lost %d", 4);
    fclose(nf);
    CHECK(notes && strcmp(notes, "kept 2|kept 3|") == 0, "notices: '%s'", notes);
    free(notes);
}

static void test_json_string(void)
{
    char *buf = NULL;
    size_t n = 0;
    FILE *m = open_memstream(&buf, &n);
    swim_json_string(m, "a\"b\\c\nd\x1b\xff\xc3\xa9");
    fclose(m);
    CHECK(buf && strcmp(buf, "\"a\\\"b\\\\c\\nd\\u001b\\ufffd\xc3\xa9\"") == 0, "json string: %s", buf);
    free(buf);
}

/* A document built with jansson and written by swim_json_write: summary.json's layout, numbers as
 * the shortest text that reads back to the same double (NaN and infinities as null), integers
 * exactly, a number given to a few digits as printf shows it, any bytes in strings made UTF-8, and
 * the text read back by jansson to the same values. */
static void test_json_write(void)
{
    json_t *o = json_object(), *ev = json_object();
    int bad = 0;
    bad |= swim_json_set(o, "s", swim_json_str("a\xff"));
    bad |= swim_json_set(o, "none", swim_json_str(NULL));
    bad |= swim_json_set(o, "x", swim_json_num(0.1));
    bad |= swim_json_set(o, "t", swim_json_num(12.0));
    bad |= swim_json_set(o, "nan", swim_json_num(NAN));
    bad |= swim_json_set(o, "inf", swim_json_num(-INFINITY));
    bad |= swim_json_set(o, "rtol", swim_json_fmt("%.3g", 1.23456e-8));
    bad |= swim_json_set(o, "n", json_integer(9007199254740993LL));
    const double v[2] = {1.5, NAN};
    bad |= swim_json_set(o, "vec", swim_json_vec(v, 2));
    bad |= swim_json_set(ev, "t", swim_json_num(2.0));
    bad |= swim_json_set(ev, "on", json_true());
    json_t *list = json_array();
    json_array_append_new(list, ev);
    bad |= swim_json_set(o, "events", list);
    bad |= swim_json_set(o, "empty", json_array());
    CHECK(!bad, "the document is built");
    CHECK(swim_json_set(o, "lost", NULL) == -1, "a value that could not be made (NULL) is refused");
    char *buf = NULL;
    size_t n = 0;
    FILE *m = open_memstream(&buf, &n);
    swim_json_write(m, o);
    fclose(m);
    const char *want = "{\n  \"s\": \"a\\ufffd\",\n  \"none\": null,\n  \"x\": 0.1,\n  \"t\": 12,\n  \"nan\": null,\n"
                       "  \"inf\": null,\n  \"rtol\": 1.23e-08,\n  \"n\": 9007199254740993,\n  \"vec\": [1.5, null],\n"
                       "  \"events\": [\n    {\"t\": 2, \"on\": true}\n  ],\n  \"empty\": []\n}\n";
    CHECK(buf && strcmp(buf, want) == 0, "the text:\n%s", buf);
    json_error_t e;
    json_t *back = buf ? json_loads(buf, JSON_REJECT_DUPLICATES, &e) : NULL;
    CHECK(back && json_real_value(json_object_get(back, "x")) == 0.1 &&
              json_integer_value(json_object_get(back, "n")) == 9007199254740993LL &&
              json_number_value(json_object_get(back, "rtol")) == 1.23e-8 && json_is_null(json_object_get(back, "nan")),
          "read back by jansson: the same values");
    json_decref(back);
    json_decref(o);
    free(buf);
}

/* The one number format of CSV and JSON: the shortest text that reads back to the same double. */
static void test_number_text(void)
{
    static const struct { double v; const char *text; } cases[] = {
        {30, "30"}, {0.05, "0.05"}, {0.1 + 0.2, "0.30000000000000004"}, {-1.5e-300, "-1.5e-300"},
        {1e21, "1e+21"}, {0, "0"}, {2.0 / 3.0, "0.6666666666666666"}};
    char buf[32];
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
        swim_number_text(buf, sizeof buf, cases[i].v);
        CHECK(strcmp(buf, cases[i].text) == 0, "number text %zu: '%s', want '%s'", i, buf, cases[i].text);
    }
    /* random bit patterns: each reads back exactly, and one digit fewer would not */
    unsigned long long x = 88172645463325252ULL;
    int bad = 0, longer = 0;
    for (int i = 0; i < 100000; i++) {
        x ^= x << 13;
        x ^= x >> 7;
        x ^= x << 17;
        double v;
        memcpy(&v, &x, sizeof v);
        if (!isfinite(v)) continue;
        swim_number_text(buf, sizeof buf, v);
        if (strtod(buf, NULL) != v) bad++;
        const char *e = strchr(buf, 'e');
        int digits = 0;   /* significant: from the first nonzero one */
        for (const char *c = buf; *c && c != e; c++) digits += (digits || (*c >= '1' && *c <= '9')) && *c >= '0' && *c <= '9';
        char shorter[400];
        if (digits > 15) {
            snprintf(shorter, sizeof shorter, "%.*g", digits - 1, v);
            if (strtod(shorter, NULL) == v) longer++;
        }
    }
    CHECK(bad == 0 && longer == 0, "number text of random doubles: %d do not read back, %d not shortest", bad, longer);
}

static char *slurp(const char *path)
{
    FILE *f = fopen(path, "rb");
    if (!f) return NULL;
    char *buf = calloc(1, 4096);
    size_t n = fread(buf, 1, 4095, f);
    buf[n] = '\0';
    fclose(f);
    return buf;
}

static void test_replace_and_paths(const char *dir)
{
    char *path = swim_path_join(dir, "summary.json");
    CHECK(swim_replace_file(path, "old\n", 4) == 0, "replace: first write");
    CHECK(swim_replace_file(path, "new text\n", 9) == 0, "replace: second write");
    char *got = slurp(path);
    CHECK(got && strcmp(got, "new text\n") == 0, "replace: content '%s'", got);
    free(got);
    struct stat st;
    CHECK(stat(path, &st) == 0 && (st.st_mode & 0777) == (0666 & ~(unsigned)umask(022)), "replace: mode %o", st.st_mode & 0777);
    /* a folder that does not exist: -1 with errno, nothing left behind */
    char *missing = swim_path_join(dir, "nowhere/summary.json");
    errno = 0;
    CHECK(swim_replace_file(missing, "x", 1) == -1 && errno == ENOENT, "replace into a missing folder: errno %d", errno);
    free(missing);

    /* canonical paths: spellings of one file, existing or not */
    char *a = swim_canonical_path(path);
    char *twisted = malloc(strlen(dir) * 2 + 64);
    sprintf(twisted, "%s/./../%s/summary.json", dir, strrchr(dir, '/') + 1);
    char *b = swim_canonical_path(twisted);
    CHECK(a && b && strcmp(a, b) == 0, "canonical: '%s' vs '%s'", a, b);
    free(a);
    free(b);
    char *fresh = swim_path_join(dir, "not_yet.csv");
    sprintf(twisted, "%s/./not_yet.csv", dir);
    a = swim_canonical_path(fresh);
    b = swim_canonical_path(twisted);
    CHECK(a && b && strcmp(a, b) == 0 && a[0] == '/', "canonical of a new file: '%s' vs '%s'", a, b);
    free(a);
    free(b);
    free(fresh);
    free(twisted);
    free(path);

    /* mkdir -p with a path longer than any fixed buffer had room for */
    char *deep = strdup(dir);
    for (int i = 0; i < 12; i++) {
        char *next = swim_path_join(deep, "dddddddddddddddddddddddddddddddddddddddddddddddddddddddddddddddddddddddddddddddddddddddddddddddd");
        free(deep);
        deep = next;
    }
    CHECK(swim_mkdirs(deep) == 0 && stat(deep, &st) == 0 && S_ISDIR(st.st_mode), "mkdirs of %zu characters", strlen(deep));
    free(deep);
}

/* The CSV writer on a file that cannot grow past 300 bytes: the row that does not fit fails
 * with EFBIG and is cut off again, so the file holds whole rows only. */
static void test_csv_limit(const char *dir)
{
    char *path = swim_path_join(dir, "limited.csv");
    const char *names[] = {"t", "x", "y"};
    struct rlimit old, lim = {300, 300};
    getrlimit(RLIMIT_FSIZE, &old);
    lim.rlim_max = old.rlim_max;
    signal(SIGXFSZ, SIG_IGN);
    swim_csv w;
    CHECK(swim_csv_open(&w, path, names, 3) == 0, "csv open");
    setrlimit(RLIMIT_FSIZE, &lim);
    int rows = 0, rc = 0, err = 0;
    for (int k = 0; k < 100 && rc == 0; k++) {
        double v[3] = {k * 0.1, 1.0 / 3.0, -2.0 / 7.0};
        rc = swim_csv_row(&w, v);
        if (rc == 0) rows++;
        else err = errno;
    }
    setrlimit(RLIMIT_FSIZE, &old);
    CHECK(rc == -1 && err == EFBIG, "csv: the limit is reported (rc %d, errno %d)", rc, err);
    CHECK(swim_csv_close(&w) == 0, "csv close");
    CHECK(swim_csv_close(&w) == 0, "csv close twice is harmless");
    char *got = slurp(path);
    int lines = 0;
    for (char *p = got; p && *p; p++) lines += *p == '\n';
    CHECK(got && got[strlen(got) - 1] == '\n' && lines == rows + 1, "csv: %d whole rows + header, %d lines", rows, lines);
    free(got);
    free(path);
}

int main(void)
{
    char dir[] = "/tmp/swim-test-io-XXXXXX";
    if (!mkdtemp(dir)) return 1;
    test_quote();
    test_message();
    test_status();
    test_json_string();
    test_json_write();
    test_number_text();
    test_replace_and_paths(dir);
    test_csv_limit(dir);
    char cmd[64];
    snprintf(cmd, sizeof cmd, "rm -rf %s", dir);
    if (system(cmd) != 0) fprintf(stderr, "could not remove %s\n", dir);
    return check_report("test_io");
}
