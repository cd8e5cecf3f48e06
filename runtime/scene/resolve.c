/* resolve.c -- the scene as run: overrides written into the scene file's text (resolve.h).
 *
 * The text is first parsed with the TOML reader (so it is known to be well-formed TOML and the
 * tree says which keys and tables exist), then scanned once by the small lexer below, which
 * records where each key's value lies (byte offsets) and where each [table]'s keys end. The
 * overrides become edits (replace bytes [at, end) by a text, or insert at `at`) applied to a copy
 * in one pass; a table the file lacks is appended. */
#include "scene/resolve.h"

#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "scene/toml.h"

#define PART_MAX 64    /* longer key parts never match an override (its names are < 32 bytes) */

/* ---- output buffer ------------------------------------------------------------------------ */

typedef struct {
    char *p;
    size_t n, cap;
    int oom;
} buf_t;

static void put(buf_t *b, const char *s, size_t n)
{
    if (b->oom) return;
    if (b->n + n + 1 > b->cap) {
        size_t cap = b->cap ? b->cap : 256;
        while (cap < b->n + n + 1) cap *= 2;
        char *p = realloc(b->p, cap);
        if (!p) {
            b->oom = 1;
            return;
        }
        b->p = p;
        b->cap = cap;
    }
    memcpy(b->p + b->n, s, n);
    b->n += n;
    b->p[b->n] = '\0';
}

static void puts_(buf_t *b, const char *s) { put(b, s, strlen(s)); }

/* Text for a comment or a one-line message: control characters (tab aside) and bytes that are
 * not valid UTF-8 become '?', so the line stays one TOML comment line. */
static void put_clean(buf_t *b, const char *s, size_t n)
{
    for (size_t i = 0; i < n;) {
        const unsigned char c = (unsigned char)s[i];
        size_t len = 0;
        unsigned cp = 0;
        if (c < 0x80) len = 1, cp = c;
        else if (c >= 0xC2 && c <= 0xDF) len = 2, cp = c & 0x1F;
        else if (c >= 0xE0 && c <= 0xEF) len = 3, cp = c & 0x0F;
        else if (c >= 0xF0 && c <= 0xF4) len = 4, cp = c & 0x07;
        int ok = len > 0 && i + len <= n;
        for (size_t k = 1; ok && k < len; k++) {
            const unsigned char d = (unsigned char)s[i + k];
            if ((d & 0xC0) != 0x80) ok = 0;
            else cp = (cp << 6) | (d & 0x3F);
        }
        if (ok && len == 3 && (cp < 0x800 || (cp >= 0xD800 && cp <= 0xDFFF))) ok = 0;
        if (ok && len == 4 && (cp < 0x10000 || cp > 0x10FFFF)) ok = 0;
        if (ok && len == 1 && ((c < 0x20 && c != '\t') || c == 0x7F)) ok = 0;
        if (!ok) {
            put(b, "?", 1);
            i++;
        } else {
            put(b, s + i, len);
            i += len;
        }
    }
}

static int fail(char *err, size_t errlen, const char *fmt, ...)
{
    if (!err || errlen == 0) return -1;
    char tmp[512];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(tmp, sizeof tmp, fmt, ap);
    va_end(ap);
    buf_t b = {0};
    put_clean(&b, tmp, strlen(tmp));
    snprintf(err, errlen, "%s", b.oom || !b.p ? "out of memory" : b.p);
    free(b.p);
    return -1;
}

/* ---- lexer --------------------------------------------------------------------------------- */

/* A key path (a.b."c") as far as overrides need it: its first two parts. */
typedef struct {
    int nparts;
    int bad;                          /* a part no override can name (escapes, too long) */
    char part[2][PART_MAX];
} path_t;

typedef struct {
    const char *s;
    size_t n, pos;
    int bad;                          /* the lexer met something it does not follow */
    size_t bad_at;
} lex_t;

static void lex_fail(lex_t *L)
{
    if (!L->bad) L->bad_at = L->pos;
    L->bad = 1;
}

static int at(const lex_t *L, char c) { return L->pos < L->n && L->s[L->pos] == c; }

static void skip_ws(lex_t *L)
{
    while (L->pos < L->n && (L->s[L->pos] == ' ' || L->s[L->pos] == '\t')) L->pos++;
}

static void skip_comment(lex_t *L)
{
    if (at(L, '#'))
        while (L->pos < L->n && L->s[L->pos] != '\n') L->pos++;
}

/* Blanks, line ends and comments (inside arrays). */
static void skip_ws_nl(lex_t *L)
{
    for (;;) {
        skip_ws(L);
        if (at(L, '\r') || at(L, '\n')) L->pos++;
        else if (at(L, '#')) skip_comment(L);
        else return;
    }
}

/* After a value or a header: blanks, a comment and the line end; returns the offset just past
 * the line end (or the end of the text). */
static size_t end_of_line(lex_t *L)
{
    skip_ws(L);
    skip_comment(L);
    if (at(L, '\r')) L->pos++;
    if (at(L, '\n')) L->pos++;
    else if (L->pos < L->n) lex_fail(L);
    return L->pos;
}

static int bare_char(char c)
{
    return (c >= 'A' && c <= 'Z') || (c >= 'a' && c <= 'z') || (c >= '0' && c <= '9') || c == '_' || c == '-';
}

/* A basic "..." or literal '...' string at L->pos (single line); its content span. */
static void lex_string(lex_t *L, size_t *cs, size_t *ce, int *escaped)
{
    const char q = L->s[L->pos++];
    *cs = L->pos;
    *escaped = 0;
    while (L->pos < L->n && L->s[L->pos] != q && L->s[L->pos] != '\n') {
        if (q == '"' && L->s[L->pos] == '\\') {
            *escaped = 1;
            L->pos++;
        }
        L->pos++;
    }
    *ce = L->pos;
    if (!at(L, q)) {
        lex_fail(L);
        return;
    }
    L->pos++;
}

static void lex_key(lex_t *L, path_t *p)
{
    memset(p, 0, sizeof *p);
    for (;;) {
        skip_ws(L);
        size_t cs, ce;
        int escaped = 0;
        if (at(L, '"') || at(L, '\'')) {
            lex_string(L, &cs, &ce, &escaped);
        } else {
            cs = L->pos;
            while (L->pos < L->n && bare_char(L->s[L->pos])) L->pos++;
            ce = L->pos;
            if (ce == cs) {
                lex_fail(L);
                return;
            }
        }
        if (p->nparts < 2) {
            if (escaped || ce - cs >= PART_MAX) p->bad = 1;
            else memcpy(p->part[p->nparts], L->s + cs, ce - cs);
        }
        p->nparts++;
        skip_ws(L);
        if (!at(L, '.')) return;
        L->pos++;
    }
}

/* A value at L->pos: its end. Nesting is bounded by the reader (TOML_MAX_DEPTH). */
static void lex_value(lex_t *L, int depth)
{
    if (L->bad) return;
    if (depth > TOML_MAX_DEPTH + 1 || L->pos >= L->n) {
        lex_fail(L);
        return;
    }
    const char c = L->s[L->pos];
    if (c == '"' || c == '\'') {
        size_t cs, ce;
        int escaped;
        lex_string(L, &cs, &ce, &escaped);
    } else if (c == '[') {
        L->pos++;
        for (;;) {
            skip_ws_nl(L);
            if (at(L, ']')) break;
            lex_value(L, depth + 1);
            skip_ws_nl(L);
            if (L->bad) return;
            if (at(L, ',')) L->pos++;
            else if (!at(L, ']')) {
                lex_fail(L);
                return;
            }
        }
        L->pos++;
    } else if (c == '{') {
        L->pos++;
        skip_ws(L);
        while (!at(L, '}')) {
            path_t k;
            lex_key(L, &k);
            skip_ws(L);
            if (L->bad || !at(L, '=')) {
                lex_fail(L);
                return;
            }
            L->pos++;
            skip_ws(L);
            lex_value(L, depth + 1);
            skip_ws(L);
            if (L->bad) return;
            if (at(L, ',')) {
                L->pos++;
                skip_ws(L);
            } else if (!at(L, '}')) {
                lex_fail(L);
                return;
            }
        }
        L->pos++;
    } else {
        const size_t start = L->pos;
        while (L->pos < L->n && !strchr(" \t\r\n,]}#", L->s[L->pos])) L->pos++;
        if (L->pos == start) lex_fail(L);
    }
}

/* Item `index` of the array whose '[' is at `start`: its span. 0, or -1 (no such item). */
static int array_item(const char *s, size_t n, size_t start, long index, size_t *is, size_t *ie)
{
    lex_t L = {s, n, start + 1, 0, 0};
    for (long i = 0;; i++) {
        skip_ws_nl(&L);
        if (L.pos >= n || at(&L, ']')) return -1;
        *is = L.pos;
        lex_value(&L, 1);
        *ie = L.pos;
        if (L.bad) return -1;
        if (i == index) return 0;
        skip_ws_nl(&L);
        if (at(&L, ',')) L.pos++;
        else return -1;
    }
}

/* ---- the scan: where values are and where tables end ------------------------------------- */

typedef struct {
    path_t path;                      /* the header's parts + the key's parts, first two */
    int depth;                        /* parts in all */
    size_t vs, ve;                    /* the value's bytes */
} kv_t;

typedef struct {
    path_t path;
    int array;                        /* [[...]] */
    size_t insert_at;                 /* after the line end of its last key (or of the header) */
} header_t;

typedef struct {
    kv_t *kv;
    size_t nkv;
    header_t *hd;
    size_t nhd;
    int oom;
} scan_t;

static int path_is(const path_t *p, int nparts, const char *a, const char *b)
{
    if (p->bad || p->nparts != nparts) return 0;
    return strcmp(p->part[0], a) == 0 && (nparts < 2 || strcmp(p->part[1], b) == 0);
}

static void scan_free(scan_t *sc)
{
    free(sc->kv);
    free(sc->hd);
}

static size_t line_of(const char *s, size_t pos)
{
    size_t line = 1;
    for (size_t i = 0; i < pos; i++) line += s[i] == '\n';
    return line;
}

/* 0, or -1 with a reason (a layout the lexer does not follow, out of memory). */
static int scan(const char *s, size_t n, scan_t *sc, char *err, size_t errlen)
{
    lex_t L = {s, n, 0, 0, 0};
    size_t cap_kv = 0, cap_hd = 0;
    long cur = -1;                    /* the header in force (index into sc->hd), -1: the root */
    while (L.pos < n && !L.bad) {
        skip_ws(&L);
        if (L.pos >= n) break;
        const char c = s[L.pos];
        if (c == '\r' || c == '\n') {
            L.pos++;
            continue;
        }
        if (c == '#') {
            skip_comment(&L);
            continue;
        }
        if (c == '[') {
            header_t h = {{0}, 0, 0};
            L.pos++;
            h.array = at(&L, '[');
            if (h.array) L.pos++;
            lex_key(&L, &h.path);
            skip_ws(&L);
            if (!at(&L, ']')) lex_fail(&L);
            else L.pos++;
            if (h.array) {
                if (!at(&L, ']')) lex_fail(&L);
                else L.pos++;
            }
            h.insert_at = end_of_line(&L);
            if (L.bad) break;
            if (sc->nhd == cap_hd) {
                cap_hd = cap_hd ? 2 * cap_hd : 16;
                header_t *p = realloc(sc->hd, cap_hd * sizeof *p);
                if (!p) return fail(err, errlen, "out of memory");
                sc->hd = p;
            }
            sc->hd[sc->nhd] = h;
            cur = (long)sc->nhd++;
            continue;
        }
        kv_t kv;
        memset(&kv, 0, sizeof kv);
        path_t key;
        lex_key(&L, &key);
        skip_ws(&L);
        if (L.bad || !at(&L, '=')) {
            lex_fail(&L);
            break;
        }
        L.pos++;
        skip_ws(&L);
        kv.vs = L.pos;
        lex_value(&L, 0);
        kv.ve = L.pos;
        const size_t line_end = end_of_line(&L);
        if (L.bad) break;
        /* the full path: the header's parts, then the key's */
        const path_t *hp = cur >= 0 ? &sc->hd[cur].path : NULL;
        const int hparts = hp ? hp->nparts : 0;
        kv.depth = hparts + key.nparts;
        kv.path.bad = (hp && hp->bad) || key.bad;
        for (int i = 0; i < 2 && i < kv.depth; i++)
            memcpy(kv.path.part[i], i < hparts ? hp->part[i] : key.part[i - hparts], PART_MAX);
        kv.path.nparts = kv.depth;
        if (cur >= 0) sc->hd[cur].insert_at = line_end;
        if (sc->nkv == cap_kv) {
            cap_kv = cap_kv ? 2 * cap_kv : 32;
            kv_t *p = realloc(sc->kv, cap_kv * sizeof *p);
            if (!p) return fail(err, errlen, "out of memory");
            sc->kv = p;
        }
        sc->kv[sc->nkv++] = kv;
    }
    if (L.bad)
        return fail(err, errlen, "line %zu: cannot follow the layout of the scene text here",
                    line_of(s, L.bad_at));
    return 0;
}

/* ---- values ---------------------------------------------------------------------------------- */

/* The override's value as TOML: `kind` is the kind of the node it replaces (TOML_FLOAT for a
 * new key), so that the result reads back as swim_scene_parse_with's tree (toml.c set_scalar). */
static void format_value(const swim_override *o, toml_kind kind, char *out, size_t len)
{
    if (o->word[0]) {
        if (!strcmp(o->word, "true") || !strcmp(o->word, "false")) snprintf(out, len, "%s", o->word);
        else snprintf(out, len, "\"%s\"", o->word);   /* letters, digits, '-', '_': nothing to escape */
        return;
    }
    const double v = o->value;
    if (kind == TOML_INT && v == floor(v) && fabs(v) < 9.0e15) {
        snprintf(out, len, "%lld", (long long)v);
        return;
    }
    for (int prec = 15; prec <= 17; prec++) {
        snprintf(out, len, "%.*g", prec, v);
        if (strtod(out, NULL) == v && (v != 0.0 || signbit(strtod(out, NULL)) == signbit(v))) break;
    }
    if (!strpbrk(out, ".eEni")) {   /* integral: keep it a float ("2.0", "-0.0") */
        const size_t l = strlen(out);
        if (l + 2 < len) memcpy(out + l, ".0", 3);
    }
}

/* ---- edits ----------------------------------------------------------------------------------- */

typedef struct {
    size_t at, end;                   /* replace [at, end); at == end: insert */
    int order;                        /* override index, so inserts at one place keep their order */
    char text[128];                   /* a value (< 64 bytes), or "KEY = VALUE" and line ends */
} edit_t;

static int edit_cmp(const void *a, const void *b)
{
    const edit_t *x = a, *y = b;
    if (x->at != y->at) return x->at < y->at ? -1 : 1;
    if ((x->end > x->at) != (y->end > y->at)) return x->end > x->at ? 1 : -1;   /* inserts first */
    return (x->order > y->order) - (x->order < y->order);
}

/* A table the file lacks, with the keys the overrides give it (in their order). */
typedef struct {
    const char *table;
    int first;                        /* the first override naming it */
} newtab_t;

int swim_scene_resolve(const char *text, size_t len, const char *path, const swim_override *ov, int nov,
                       char **out, size_t *outlen, char *err, size_t errlen)
{
    *out = NULL;
    if (outlen) *outlen = 0;
    if (nov < 0 || (nov > 0 && !ov)) return fail(err, errlen, "bad override list");
    size_t bom = len >= 3 && memcmp(text, "\xEF\xBB\xBF", 3) == 0 ? 3 : 0;
    const char *s = text + bom;
    const size_t n = len - bom;
    char perr[256];
    toml_value *root = toml_parse(s, n, perr, sizeof perr);
    if (!root) return fail(err, errlen, "the scene is not TOML the reader takes: %s", perr);
    int earlier, j = swim_override_conflict(ov, nov, &earlier);
    if (j >= 0) {
        toml_free(root);
        return fail(err, errlen, "--set %s: conflicts with --set %s", ov[j].text, ov[earlier].text);
    }
    scan_t sc = {0};
    edit_t *ed = calloc((size_t)nov + 1, sizeof *ed);
    newtab_t *nt = calloc((size_t)nov + 1, sizeof *nt);
    int ned = 0, nnt = 0, rc = -1;
    buf_t b = {0};
    if (!ed || !nt) {
        fail(err, errlen, "out of memory");
        goto done;
    }
    if (scan(s, n, &sc, err, errlen) != 0) goto done;
    const char *nl = "\n";
    {
        const char *lf = memchr(s, '\n', n);
        if (lf && lf > s && lf[-1] == '\r') nl = "\r\n";
    }
    for (int i = 0; i < nov; i++) {
        const swim_override *o = &ov[i];
        const toml_value *t = toml_get(root, o->table);
        if (o->word[0] && o->index >= 0) {
            fail(err, errlen, "--set %s: an item takes a number", o->text);
            goto done;
        }
        if (t && toml_kind_of(t) != TOML_TABLE) {
            fail(err, errlen, "--set %s: %s is a %s, not a table", o->text, o->table, toml_kind_name(toml_kind_of(t)));
            goto done;
        }
        if (!t) {   /* a new table at the end */
            if (o->index >= 0) {
                fail(err, errlen, "--set %s: the scene has no array %s.%s", o->text, o->table, o->key);
                goto done;
            }
            int k = 0;
            while (k < nnt && strcmp(nt[k].table, o->table) != 0) k++;
            if (k == nnt) nt[nnt++] = (newtab_t){o->table, i};
            continue;
        }
        const toml_value *v = toml_get(t, o->key);
        if (!v) {   /* a new key at the end of the table */
            if (o->index >= 0) {
                fail(err, errlen, "--set %s: the scene has no array %s.%s", o->text, o->table, o->key);
                goto done;
            }
            int dup = 0;
            for (int k = 0; k < i; k++) dup |= swim_override_same_target(&ov[k], o);
            if (dup) continue;   /* the same value again (no conflict): added once */
            const header_t *h = NULL;
            for (size_t k = 0; k < sc.nhd; k++)
                if (!sc.hd[k].array && path_is(&sc.hd[k].path, 1, o->table, NULL)) h = &sc.hd[k];
            if (!h) {
                fail(err, errlen, "--set %s: table %s has no [%s] header to add %s under", o->text,
                     o->table, o->table, o->key);
                goto done;
            }
            edit_t *e = &ed[ned++];
            e->at = e->end = h->insert_at;
            e->order = i;
            char val[64];
            format_value(o, TOML_FLOAT, val, sizeof val);
            snprintf(e->text, sizeof e->text, "%s%s = %s%s",
                     h->insert_at == n && n > 0 && s[n - 1] != '\n' ? nl : "", o->key, val, nl);
            continue;
        }
        const kv_t *kv = NULL;
        for (size_t k = 0; k < sc.nkv; k++)
            if (path_is(&sc.kv[k].path, 2, o->table, o->key)) kv = &sc.kv[k];
        if (!kv) {
            fail(err, errlen, "--set %s: %s.%s is not written as `%s = ...` in [%s] or `%s.%s = ...` "
                 "(an inline table?): cannot place the override", o->text, o->table, o->key, o->key,
                 o->table, o->table, o->key);
            goto done;
        }
        size_t vs = kv->vs, ve = kv->ve;
        if (o->index >= 0) {
            const toml_value *item = toml_array_at(v, (size_t)o->index);
            if (toml_kind_of(v) != TOML_ARRAY || !item || s[vs] != '[' ||
                array_item(s, n, vs, o->index, &vs, &ve) != 0) {
                fail(err, errlen, "--set %s: %s.%s has no item %ld", o->text, o->table, o->key, o->index);
                goto done;
            }
            v = item;
        }
        edit_t *e = &ed[ned];
        e->at = vs;
        e->end = ve;
        e->order = i;
        format_value(o, toml_kind_of(v), e->text, sizeof e->text);
        int dup = 0;
        for (int k = 0; k < ned; k++) dup |= ed[k].at == vs && ed[k].end == ve;
        if (!dup) ned++;   /* the same item twice (no conflict): the same text */
    }
    qsort(ed, (size_t)ned, sizeof *ed, edit_cmp);
    for (int k = 1; k < ned; k++)
        if (ed[k].at < ed[k - 1].end) {
            fail(err, errlen, "overrides overlap in the text (line %zu)", line_of(s, ed[k].at));
            goto done;
        }
    /* the header line, then the text with the edits, then the new tables */
    put(&b, text, bom);
    puts_(&b, "# resolved by swim: ");
    if (nov == 0) puts_(&b, "no --set");
    for (int i = 0; i < nov; i++) {
        puts_(&b, i ? ", --set " : "--set ");
        put_clean(&b, ov[i].text, strlen(ov[i].text));
    }
    puts_(&b, " applied to ");
    put_clean(&b, path ? path : "", path ? strlen(path) : 0);
    puts_(&b, nl);
    size_t pos = 0;
    for (int k = 0; k < ned; k++) {
        put(&b, s + pos, ed[k].at - pos);
        puts_(&b, ed[k].text);
        pos = ed[k].end;
    }
    put(&b, s + pos, n - pos);
    for (int k = 0; k < nnt; k++) {
        if (b.n > 0 && b.p[b.n - 1] != '\n') puts_(&b, nl);
        puts_(&b, nl);
        puts_(&b, "[");
        puts_(&b, nt[k].table);
        puts_(&b, "]");
        puts_(&b, nl);
        for (int i = nt[k].first; i < nov; i++) {
            if (strcmp(ov[i].table, nt[k].table) != 0) continue;
            int dup = 0;
            for (int q = nt[k].first; q < i; q++) dup |= swim_override_same_target(&ov[q], &ov[i]);
            if (dup) continue;
            char val[64];
            format_value(&ov[i], TOML_FLOAT, val, sizeof val);
            puts_(&b, ov[i].key);
            puts_(&b, " = ");
            puts_(&b, val);
            puts_(&b, nl);
        }
    }
    if (b.oom || !b.p) {
        fail(err, errlen, "out of memory");
        goto done;
    }
    *out = b.p;
    if (outlen) *outlen = b.n;
    b.p = NULL;
    rc = 0;
done:
    free(b.p);
    free(ed);
    free(nt);
    scan_free(&sc);
    toml_free(root);
    return rc;
}
