/* toml.c -- see toml.h for the supported subset and the guarantees. */
#include "scene/toml.h"

#include <errno.h>
#include <limits.h>
#include <math.h>
#include <stdarg.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* ------------------------------------------------------------------------ tree */

enum {
    F_DEFINED = 1,  /* table defined by a header, an inline table, or the root */
    F_IMPLICIT = 2, /* table created as an intermediate step of a [a.b] header */
    F_DOTTED = 4,   /* table created by a dotted key a.b = .. */
    F_INLINE = 8,   /* inline table {..}: frozen once closed */
    F_AOT = 16      /* array created by [[a]] */
};

typedef struct {
    char *key;
    int line;
    toml_value *val;
} toml_entry;

struct toml_value {
    toml_kind kind;
    int line;
    int depth;
    unsigned flags;
    /* string */
    char *str;
    size_t slen;
    /* scalars */
    long long i;
    double f;
    int b;
    /* table: entries in file order, plus an open-addressing index (slot = entry + 1) */
    toml_entry *ent;
    size_t *hash;
    size_t hcap;
    /* array */
    toml_value **items;
    /* table entries / array items */
    size_t n, cap;
};

static toml_value *node_new(toml_kind kind, int line, int depth)
{
    toml_value *v = calloc(1, sizeof *v);
    if (v) {
        v->kind = kind;
        v->line = line;
        v->depth = depth;
    }
    return v;
}

/* Depth is bounded by TOML_MAX_DEPTH + 1, so this recursion is bounded. */
static void node_free(toml_value *v)
{
    if (!v)
        return;
    if (v->kind == TOML_TABLE) {
        for (size_t i = 0; i < v->n; i++) {
            free(v->ent[i].key);
            node_free(v->ent[i].val);
        }
        free(v->ent);
        free(v->hash);
    } else if (v->kind == TOML_ARRAY) {
        for (size_t i = 0; i < v->n; i++)
            node_free(v->items[i]);
        free(v->items);
    } else if (v->kind == TOML_STRING) {
        free(v->str);
    }
    free(v);
}

void toml_free(toml_value *root) { node_free(root); }

static uint64_t hash_str(const char *s)
{
    uint64_t h = 1469598103934665603ull;
    for (; *s; s++) {
        h ^= (unsigned char)*s;
        h *= 1099511628211ull;
    }
    return h;
}

#define HASH_MIN 16 /* tables smaller than this are searched linearly */
#define NOT_FOUND ((size_t)-1)

static size_t tab_find(const toml_value *t, const char *key)
{
    if (t->hash) {
        size_t mask = t->hcap - 1, i = (size_t)hash_str(key) & mask, s;
        while ((s = t->hash[i]) != 0) {
            if (strcmp(t->ent[s - 1].key, key) == 0)
                return s - 1;
            i = (i + 1) & mask;
        }
        return NOT_FOUND;
    }
    for (size_t i = 0; i < t->n; i++)
        if (strcmp(t->ent[i].key, key) == 0)
            return i;
    return NOT_FOUND;
}

static void hash_insert(size_t *h, size_t hcap, const char *key, size_t slot)
{
    size_t mask = hcap - 1, i = (size_t)hash_str(key) & mask;
    while (h[i])
        i = (i + 1) & mask;
    h[i] = slot;
}

/* Append key -> val (key is taken over on success only). Returns 0, or -1 when out of memory
 * (nothing changed). */
static int tab_add(toml_value *t, char *key, int line, toml_value *val)
{
    if (t->n == t->cap) {
        size_t nc = t->cap ? t->cap * 2 : 8;
        if (nc > SIZE_MAX / sizeof(toml_entry))
            return -1;
        toml_entry *ne = realloc(t->ent, nc * sizeof *ne);
        if (!ne)
            return -1;
        t->ent = ne;
        t->cap = nc;
    }
    size_t n1 = t->n + 1;
    if (n1 >= HASH_MIN && (!t->hash || n1 * 2 > t->hcap)) {
        size_t hc = 64;
        while (hc < n1 * 4) {
            if (hc > SIZE_MAX / 2 / sizeof(size_t))
                return -1;
            hc *= 2;
        }
        size_t *h = calloc(hc, sizeof *h);
        if (!h)
            return -1;
        for (size_t i = 0; i < t->n; i++)
            hash_insert(h, hc, t->ent[i].key, i + 1);
        free(t->hash);
        t->hash = h;
        t->hcap = hc;
    }
    if (t->hash)
        hash_insert(t->hash, t->hcap, key, n1);
    t->ent[t->n].key = key;
    t->ent[t->n].line = line;
    t->ent[t->n].val = val;
    t->n = n1;
    return 0;
}

static int arr_push(toml_value *a, toml_value *v)
{
    if (a->n == a->cap) {
        size_t nc = a->cap ? a->cap * 2 : 4;
        if (nc > SIZE_MAX / sizeof(toml_value *))
            return -1;
        toml_value **ni = realloc(a->items, nc * sizeof *ni);
        if (!ni)
            return -1;
        a->items = ni;
        a->cap = nc;
    }
    a->items[a->n++] = v;
    return 0;
}

/* ---------------------------------------------------------------------- parser */

typedef struct {
    const unsigned char *s;
    size_t n, pos;
    int line;
    char *err;
    size_t errlen;
    int failed;
} parser;

#if defined(__GNUC__)
__attribute__((format(printf, 3, 4)))
#endif
static void fail(parser *p, int line, const char *fmt, ...)
{
    if (p->failed)
        return;
    p->failed = 1;
    if (!p->err || p->errlen == 0)
        return;
    int k = snprintf(p->err, p->errlen, "line %d: ", line);
    if (k < 0) {
        p->err[0] = '\0';
        return;
    }
    if ((size_t)k >= p->errlen)
        return;
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(p->err + k, p->errlen - (size_t)k, fmt, ap);
    va_end(ap);
}

static void oom(parser *p) { fail(p, p->line, "out of memory"); }

static int peek(const parser *p) { return p->pos < p->n ? p->s[p->pos] : -1; }
static int peek_at(const parser *p, size_t k)
{
    return (p->n - p->pos > k) ? p->s[p->pos + k] : -1;
}

static void next_line(parser *p)
{
    if (p->line < INT_MAX)
        p->line++;
}

/* Text of a key/token for messages: printable, single line, at most ~60 bytes. */
#define SHOW_MAX 60
typedef struct {
    char b[SHOW_MAX + 8];
} showbuf;

static const char *show(showbuf *sb, const char *s, size_t len)
{
    size_t o = 0;
    size_t lim = len;
    int cut = 0;
    if (lim > SHOW_MAX) {
        lim = SHOW_MAX;
        /* do not cut a UTF-8 sequence in half */
        while (lim > 0 && ((unsigned char)s[lim] & 0xC0) == 0x80)
            lim--;
        cut = 1;
    }
    for (size_t i = 0; i < lim; i++) {
        unsigned char c = (unsigned char)s[i];
        sb->b[o++] = (c < 0x20 || c == 0x7f) ? '?' : (char)c;
    }
    if (cut) {
        memcpy(sb->b + o, "...", 3);
        o += 3;
    }
    sb->b[o] = '\0';
    return sb->b;
}

/* Description of the next input character for "found ..." messages. */
typedef struct {
    char b[24];
} foundbuf;

static const char *found(const parser *p, foundbuf *fb)
{
    int c = peek(p);
    if (c < 0)
        return "end of input";
    if (c == '\n' || c == '\r')
        return "end of line";
    if (c >= 0x20 && c < 0x7f)
        snprintf(fb->b, sizeof fb->b, "'%c'", c);
    else
        snprintf(fb->b, sizeof fb->b, "byte 0x%02X", (unsigned)c);
    return fb->b;
}

/* Reject NUL bytes and invalid UTF-8 anywhere in the input. */
static int prescan(parser *p)
{
    const unsigned char *s = p->s;
    size_t n = p->n, i = 0;
    int line = 1;
    while (i < n) {
        unsigned c = s[i];
        if (c == '\n') {
            if (line < INT_MAX)
                line++;
            i++;
            continue;
        }
        if (c == 0) {
            fail(p, line, "NUL byte in input");
            return -1;
        }
        if (c < 0x80) {
            i++;
            continue;
        }
        size_t need;
        unsigned lo = 0x80, hi = 0xBF;
        if (c >= 0xC2 && c <= 0xDF)
            need = 1;
        else if (c >= 0xE0 && c <= 0xEF) {
            need = 2;
            if (c == 0xE0)
                lo = 0xA0;
            else if (c == 0xED)
                hi = 0x9F;
        } else if (c >= 0xF0 && c <= 0xF4) {
            need = 3;
            if (c == 0xF0)
                lo = 0x90;
            else if (c == 0xF4)
                hi = 0x8F;
        } else {
            fail(p, line, "invalid UTF-8 byte 0x%02X", c);
            return -1;
        }
        if (n - i - 1 < need) {
            fail(p, line, "truncated UTF-8 sequence");
            return -1;
        }
        for (size_t k = 1; k <= need; k++) {
            unsigned d = s[i + k];
            unsigned l = (k == 1) ? lo : 0x80, h = (k == 1) ? hi : 0xBF;
            if (d < l || d > h) {
                fail(p, line, "invalid UTF-8 sequence");
                return -1;
            }
        }
        i += need + 1;
    }
    return 0;
}

static void skip_ws(parser *p)
{
    while (p->pos < p->n && (p->s[p->pos] == ' ' || p->s[p->pos] == '\t'))
        p->pos++;
}

/* At '#': skip to (not past) the end of line. */
static int skip_comment(parser *p)
{
    if (peek(p) != '#')
        return 0;
    p->pos++;
    while (p->pos < p->n) {
        unsigned c = p->s[p->pos];
        if (c == '\n' || (c == '\r' && peek_at(p, 1) == '\n'))
            break;
        if ((c < 0x20 && c != '\t') || c == 0x7f) {
            fail(p, p->line, "control character 0x%02X in comment", c);
            return -1;
        }
        p->pos++;
    }
    return 0;
}

/* Consume one line end: 1 if consumed, 0 if none here, -1 on a lone CR. */
static int newline(parser *p)
{
    int c = peek(p);
    if (c == '\n') {
        p->pos++;
        next_line(p);
        return 1;
    }
    if (c == '\r') {
        if (peek_at(p, 1) == '\n') {
            p->pos += 2;
            next_line(p);
            return 1;
        }
        fail(p, p->line, "carriage return not followed by a newline");
        return -1;
    }
    return 0;
}

/* Skip blanks, comments and line ends (inside arrays). */
static int skip_space_nl(parser *p)
{
    for (;;) {
        skip_ws(p);
        if (skip_comment(p) < 0)
            return -1;
        int r = newline(p);
        if (r < 0)
            return -1;
        if (r == 0)
            return 0;
    }
}

/* ------------------------------------------------------------------- strings */

typedef struct {
    char *b;
    size_t n, cap;
} sbuf;

static int sb_put(sbuf *sb, const char *s, size_t k)
{
    if (sb->cap - sb->n <= k) { /* keep room for the NUL */
        size_t nc = sb->cap ? sb->cap : 16;
        while (nc - sb->n <= k) {
            if (nc > SIZE_MAX / 2)
                return -1;
            nc *= 2;
        }
        char *nb = realloc(sb->b, nc);
        if (!nb)
            return -1;
        sb->b = nb;
        sb->cap = nc;
    }
    memcpy(sb->b + sb->n, s, k);
    sb->n += k;
    sb->b[sb->n] = '\0';
    return 0;
}

static int hexval(int c)
{
    if (c >= '0' && c <= '9')
        return c - '0';
    if (c >= 'a' && c <= 'f')
        return c - 'a' + 10;
    if (c >= 'A' && c <= 'F')
        return c - 'A' + 10;
    return -1;
}

static size_t utf8_encode(unsigned long cp, char out[4])
{
    if (cp < 0x80) {
        out[0] = (char)cp;
        return 1;
    }
    if (cp < 0x800) {
        out[0] = (char)(0xC0 | (cp >> 6));
        out[1] = (char)(0x80 | (cp & 0x3F));
        return 2;
    }
    if (cp < 0x10000) {
        out[0] = (char)(0xE0 | (cp >> 12));
        out[1] = (char)(0x80 | ((cp >> 6) & 0x3F));
        out[2] = (char)(0x80 | (cp & 0x3F));
        return 3;
    }
    out[0] = (char)(0xF0 | (cp >> 18));
    out[1] = (char)(0x80 | ((cp >> 12) & 0x3F));
    out[2] = (char)(0x80 | ((cp >> 6) & 0x3F));
    out[3] = (char)(0x80 | (cp & 0x3F));
    return 4;
}

/* Parse a "..." or '...' string at the current position into a fresh buffer. */
static int parse_string(parser *p, char **out, size_t *olen)
{
    int q = peek(p);
    int line = p->line;
    if (peek_at(p, 1) == q && peek_at(p, 2) == q) {
        fail(p, line, "multi-line strings (%c%c%c) are not supported", q, q, q);
        return -1;
    }
    p->pos++;
    sbuf sb = {0};
    if (sb_put(&sb, "", 0) < 0)
        goto nomem;
    for (;;) {
        int c = peek(p);
        if (c < 0 || c == '\n' || (c == '\r' && peek_at(p, 1) == '\n')) {
            fail(p, line, "unterminated string");
            goto bad;
        }
        if (c == q) {
            p->pos++;
            break;
        }
        if ((c < 0x20 && c != '\t') || c == 0x7f) {
            fail(p, line, "control character 0x%02X in string (use an escape)", (unsigned)c);
            goto bad;
        }
        if (c != '\\' || q == '\'') {
            /* copy a run of ordinary bytes */
            size_t start = p->pos;
            while (p->pos < p->n) {
                int d = p->s[p->pos];
                if (d == q || (d == '\\' && q == '"') || (d < 0x20 && d != '\t') || d == 0x7f)
                    break;
                p->pos++;
            }
            if (sb_put(&sb, (const char *)p->s + start, p->pos - start) < 0)
                goto nomem;
            continue;
        }
        /* escape */
        p->pos++;
        int e = peek(p);
        char tmp[4];
        if (e < 0 || e == '\n' || e == '\r') {
            fail(p, line, "unterminated string");
            goto bad;
        }
        const char *rep = NULL;
        switch (e) {
        case '"': rep = "\""; break;
        case '\\': rep = "\\"; break;
        case 'b': rep = "\b"; break;
        case 't': rep = "\t"; break;
        case 'n': rep = "\n"; break;
        case 'f': rep = "\f"; break;
        case 'r': rep = "\r"; break;
        case 'u':
        case 'U': {
            int nd = (e == 'u') ? 4 : 8;
            unsigned long cp = 0;
            p->pos++;
            for (int k = 0; k < nd; k++) {
                int h = hexval(peek(p));
                if (h < 0) {
                    fail(p, line, "escape \\%c needs %d hex digits", e, nd);
                    goto bad;
                }
                cp = cp * 16 + (unsigned long)h;
                p->pos++;
            }
            if (cp == 0) {
                fail(p, line, "\\%c escape of NUL is not allowed", e);
                goto bad;
            }
            if ((cp >= 0xD800 && cp <= 0xDFFF) || cp > 0x10FFFF) {
                fail(p, line, "escape \\%c is not a valid Unicode scalar value", e);
                goto bad;
            }
            size_t k = utf8_encode(cp, tmp);
            if (sb_put(&sb, tmp, k) < 0)
                goto nomem;
            continue;
        }
        default: {
            if (e >= 0x21 && e < 0x7f)
                fail(p, line, "invalid escape '\\%c' in string", e);
            else
                fail(p, line, "invalid escape in string");
            goto bad;
        }
        }
        p->pos++;
        if (sb_put(&sb, rep, 1) < 0)
            goto nomem;
    }
    *out = sb.b;
    *olen = sb.n;
    return 0;
nomem:
    oom(p);
bad:
    free(sb.b);
    return -1;
}

/* ---------------------------------------------------------------------- keys */

static int is_bare(int c)
{
    return (c >= 'A' && c <= 'Z') || (c >= 'a' && c <= 'z') || (c >= '0' && c <= '9') || c == '_' ||
           c == '-';
}

typedef struct {
    char *s[TOML_MAX_DEPTH];
    size_t len[TOML_MAX_DEPTH];
    int line[TOML_MAX_DEPTH];
    int n;
} keypath;

static void keypath_free(keypath *kp)
{
    for (int i = 0; i < kp->n; i++)
        free(kp->s[i]);
    kp->n = 0;
}

/* "a.b.c" (components 0..upto) for messages. */
typedef struct {
    char b[SHOW_MAX * 2 + 16];
} pathbuf;

static const char *keypath_str(pathbuf *pb, const keypath *kp, int upto)
{
    size_t o = 0;
    pb->b[0] = '\0';
    for (int i = 0; i <= upto && i < kp->n; i++) {
        showbuf sb;
        const char *part = show(&sb, kp->s[i] ? kp->s[i] : "?", kp->s[i] ? kp->len[i] : 1);
        size_t pl = strlen(part);
        size_t need = pl + (i ? 1 : 0);
        if (o + need + 4 >= sizeof pb->b) {
            memcpy(pb->b + o, "...", 4);
            return pb->b;
        }
        if (i)
            pb->b[o++] = '.';
        memcpy(pb->b + o, part, pl);
        o += pl;
        pb->b[o] = '\0';
    }
    return pb->b;
}

static int parse_key(parser *p, keypath *kp)
{
    kp->n = 0;
    for (;;) {
        skip_ws(p);
        if (kp->n == TOML_MAX_DEPTH) {
            fail(p, p->line, "key has too many dotted parts (limit %d)", TOML_MAX_DEPTH);
            return -1;
        }
        int c = peek(p), line = p->line;
        char *s = NULL;
        size_t len = 0;
        if (c == '"' || c == '\'') {
            if (parse_string(p, &s, &len) < 0)
                return -1;
        } else if (c >= 0 && is_bare(c)) {
            size_t start = p->pos;
            while (p->pos < p->n && is_bare(p->s[p->pos]))
                p->pos++;
            len = p->pos - start;
            s = malloc(len + 1);
            if (!s) {
                oom(p);
                return -1;
            }
            memcpy(s, p->s + start, len);
            s[len] = '\0';
        } else {
            foundbuf fb;
            if (kp->n > 0) {
                pathbuf pb;
                fail(p, p->line, "expected a key after '%s.', found %s", keypath_str(&pb, kp, kp->n - 1),
                     found(p, &fb));
            } else {
                fail(p, p->line, "expected a key, found %s", found(p, &fb));
            }
            return -1;
        }
        kp->s[kp->n] = s;
        kp->len[kp->n] = len;
        kp->line[kp->n] = line;
        kp->n++;
        skip_ws(p);
        if (peek(p) != '.')
            return 0;
        p->pos++;
    }
}

/* ---------------------------------------------------------------- numbers etc. */

static int is_tokc(int c)
{
    return (c >= 'A' && c <= 'Z') || (c >= 'a' && c <= 'z') || (c >= '0' && c <= '9') || c == '_' ||
           c == '+' || c == '-' || c == '.' || c == ':';
}
static int is_digit(int c) { return c >= '0' && c <= '9'; }

/* Digits of base `base` with single '_' between digits, starting at t[*i]. Returns the
 * number of digits (0 if none or badly placed underscores). */
static size_t scan_digits(const char *t, size_t len, size_t *i, int base)
{
    size_t nd = 0;
    for (;;) {
        if (*i >= len)
            break;
        int c = (unsigned char)t[*i];
        int v = hexval(c);
        if (v >= 0 && v < base) {
            nd++;
            (*i)++;
            continue;
        }
        if (c == '_') {
            if (nd == 0 || *i + 1 >= len)
                return 0;
            int d = hexval((unsigned char)t[*i + 1]);
            if (d < 0 || d >= base)
                return 0;
            (*i)++;
            continue;
        }
        break;
    }
    return nd;
}

static toml_value *parse_token(parser *p, int depth)
{
    int line = p->line;
    size_t start = p->pos;
    while (p->pos < p->n && is_tokc(p->s[p->pos]))
        p->pos++;
    const char *t = (const char *)p->s + start;
    size_t len = p->pos - start;
    showbuf sb;
    toml_value *v = NULL;

    if ((len == 4 && memcmp(t, "true", 4) == 0) || (len == 5 && memcmp(t, "false", 5) == 0)) {
        v = node_new(TOML_BOOL, line, depth);
        if (!v)
            goto nomem;
        v->b = (len == 4);
        return v;
    }
    /* dates / times: 1979-05-27, 07:32:00, 1979-05-27T07:32:00Z */
    if (memchr(t, ':', len) ||
        (len >= 5 && is_digit(t[0]) && is_digit(t[1]) && is_digit(t[2]) && is_digit(t[3]) && t[4] == '-')) {
        fail(p, line, "dates and times are not supported ('%s')", show(&sb, t, len));
        return NULL;
    }
    size_t i = 0;
    int neg = 0, sign = 0;
    if (i < len && (t[i] == '+' || t[i] == '-')) {
        neg = t[i] == '-';
        sign = 1;
        i++;
    }
    const char *r = t + i;
    size_t rl = len - i;
    if ((rl == 3 && memcmp(r, "inf", 3) == 0) || (rl == 3 && memcmp(r, "nan", 3) == 0)) {
        v = node_new(TOML_FLOAT, line, depth);
        if (!v)
            goto nomem;
        if (r[0] == 'i')
            v->f = neg ? -(double)INFINITY : (double)INFINITY;
        else
            v->f = neg ? -(double)NAN : (double)NAN;
        return v;
    }
    if (rl == 0 || !is_digit(r[0])) {
        if (len > 0 && ((t[0] >= 'A' && t[0] <= 'Z') || (t[0] >= 'a' && t[0] <= 'z')))
            fail(p, line, "invalid value '%s' (strings must be quoted)", show(&sb, t, len));
        else if (len == 0) {
            foundbuf fb;
            fail(p, line, "expected a value, found %s", found(p, &fb));
        } else
            fail(p, line, "invalid number '%s'", show(&sb, t, len));
        return NULL;
    }
    /* prefixed integers */
    if (rl >= 2 && r[0] == '0' && (r[1] == 'x' || r[1] == 'o' || r[1] == 'b')) {
        int base = r[1] == 'x' ? 16 : r[1] == 'o' ? 8 : 2;
        if (sign) {
            fail(p, line, "sign not allowed on hex/octal/binary integer '%s'", show(&sb, t, len));
            return NULL;
        }
        size_t j = 2;
        size_t nd = scan_digits(r, rl, &j, base);
        if (nd == 0 || j != rl) {
            fail(p, line, "invalid number '%s'", show(&sb, t, len));
            return NULL;
        }
        unsigned long long m = 0;
        for (size_t k = 2; k < rl; k++) {
            if (r[k] == '_')
                continue;
            unsigned d = (unsigned)hexval((unsigned char)r[k]);
            if (m > ((unsigned long long)LLONG_MAX - d) / (unsigned)base) {
                fail(p, line, "integer '%s' is out of range", show(&sb, t, len));
                return NULL;
            }
            m = m * (unsigned)base + d;
        }
        v = node_new(TOML_INT, line, depth);
        if (!v)
            goto nomem;
        v->i = (long long)m;
        return v;
    }
    /* decimal integer or float */
    size_t j = 0;
    size_t nint = scan_digits(r, rl, &j, 10);
    int is_float = 0;
    if (nint == 0) {
        fail(p, line, "invalid number '%s'", show(&sb, t, len));
        return NULL;
    }
    if (r[0] == '0' && nint > 1) {
        fail(p, line, "leading zeros are not allowed in '%s'", show(&sb, t, len));
        return NULL;
    }
    if (j < rl && r[j] == '.') {
        j++;
        is_float = 1;
        if (scan_digits(r, rl, &j, 10) == 0) {
            fail(p, line, "invalid number '%s' (digits needed after '.')", show(&sb, t, len));
            return NULL;
        }
    }
    if (j < rl && (r[j] == 'e' || r[j] == 'E')) {
        j++;
        is_float = 1;
        if (j < rl && (r[j] == '+' || r[j] == '-'))
            j++;
        if (scan_digits(r, rl, &j, 10) == 0) {
            fail(p, line, "invalid number '%s' (bad exponent)", show(&sb, t, len));
            return NULL;
        }
    }
    if (j != rl) {
        fail(p, line, "invalid number '%s'", show(&sb, t, len));
        return NULL;
    }
    if (!is_float) {
        unsigned long long lim = neg ? (unsigned long long)LLONG_MAX + 1ull : (unsigned long long)LLONG_MAX;
        unsigned long long m = 0;
        for (size_t k = 0; k < rl; k++) {
            if (r[k] == '_')
                continue;
            unsigned d = (unsigned)(r[k] - '0');
            if (m > (lim - d) / 10) {
                fail(p, line, "integer '%s' is out of range", show(&sb, t, len));
                return NULL;
            }
            m = m * 10 + d;
        }
        v = node_new(TOML_INT, line, depth);
        if (!v)
            goto nomem;
        if (neg)
            v->i = (m == (unsigned long long)LLONG_MAX + 1ull) ? LLONG_MIN : -(long long)m;
        else
            v->i = (long long)m;
        return v;
    }
    /* float: strip underscores and convert */
    char *buf = malloc(len + 1);
    if (!buf)
        goto nomem;
    size_t o = 0;
    for (size_t k = 0; k < len; k++)
        if (t[k] != '_')
            buf[o++] = t[k];
    buf[o] = '\0';
    errno = 0;
    char *end = NULL;
    double d = strtod(buf, &end);
    int bad = (end != buf + o);
    int range = (errno == ERANGE && isinf(d));
    free(buf);
    if (bad) {
        fail(p, line, "invalid number '%s'", show(&sb, t, len));
        return NULL;
    }
    if (range) {
        fail(p, line, "float '%s' is out of range", show(&sb, t, len));
        return NULL;
    }
    v = node_new(TOML_FLOAT, line, depth);
    if (!v)
        goto nomem;
    v->f = d;
    return v;
nomem:
    oom(p);
    return NULL;
}

/* -------------------------------------------------------------------- values */

static toml_value *parse_value(parser *p, int depth);
static int parse_keyval(parser *p, toml_value *tbl, int toplevel);

static toml_value *parse_array(parser *p, int depth)
{
    int open = p->line;
    p->pos++; /* '[' */
    toml_value *a = node_new(TOML_ARRAY, open, depth);
    foundbuf fb;
    if (!a) {
        oom(p);
        return NULL;
    }
    for (;;) {
        if (skip_space_nl(p) < 0)
            goto bad;
        int c = peek(p);
        if (c == ']') {
            p->pos++;
            return a;
        }
        if (c < 0) {
            fail(p, p->line, "unterminated array (opened on line %d)", open);
            goto bad;
        }
        toml_value *v = parse_value(p, depth + 1);
        if (!v)
            goto bad;
        if (arr_push(a, v) < 0) {
            node_free(v);
            oom(p);
            goto bad;
        }
        if (skip_space_nl(p) < 0)
            goto bad;
        c = peek(p);
        if (c == ',') {
            p->pos++;
            continue;
        }
        if (c == ']') {
            p->pos++;
            return a;
        }
        if (c < 0)
            fail(p, p->line, "unterminated array (opened on line %d)", open);
        else
            fail(p, p->line, "expected ',' or ']' in array, found %s", found(p, &fb));
        goto bad;
    }
bad:
    node_free(a);
    return NULL;
}

static toml_value *parse_inline_table(parser *p, int depth)
{
    int open = p->line;
    p->pos++; /* '{' */
    toml_value *t = node_new(TOML_TABLE, open, depth);
    foundbuf fb;
    if (!t) {
        oom(p);
        return NULL;
    }
    t->flags = F_DEFINED | F_INLINE;
    skip_ws(p);
    if (peek(p) == '}') {
        p->pos++;
        return t;
    }
    for (;;) {
        if (parse_keyval(p, t, 0) < 0)
            goto bad;
        skip_ws(p);
        int c = peek(p);
        if (c == ',') {
            p->pos++;
            skip_ws(p);
            if (peek(p) == '}') {
                fail(p, p->line, "trailing comma not allowed in inline table");
                goto bad;
            }
            continue;
        }
        if (c == '}') {
            p->pos++;
            return t;
        }
        if (c < 0)
            fail(p, p->line, "unterminated inline table (opened on line %d)", open);
        else if (c == '\n' || c == '\r' || c == '#')
            fail(p, p->line, "inline table must be on one line (missing '}'?)");
        else
            fail(p, p->line, "expected ',' or '}' in inline table, found %s", found(p, &fb));
        goto bad;
    }
bad:
    node_free(t);
    return NULL;
}

static toml_value *parse_value(parser *p, int depth)
{
    if (depth > TOML_MAX_DEPTH) {
        fail(p, p->line, "nesting too deep (limit %d)", TOML_MAX_DEPTH);
        return NULL;
    }
    int c = peek(p);
    if (c == '"' || c == '\'') {
        int line = p->line;
        char *s;
        size_t len;
        if (parse_string(p, &s, &len) < 0)
            return NULL;
        toml_value *v = node_new(TOML_STRING, line, depth);
        if (!v) {
            free(s);
            oom(p);
            return NULL;
        }
        v->str = s;
        v->slen = len;
        return v;
    }
    if (c == '[')
        return parse_array(p, depth);
    if (c == '{')
        return parse_inline_table(p, depth);
    if (c >= 0 && is_tokc(c))
        return parse_token(p, depth);
    foundbuf fb;
    fail(p, p->line, "expected a value, found %s", found(p, &fb));
    return NULL;
}

/* Expect optional blanks and comment, then a line end or the end of input. */
static int expect_eol(parser *p, const char *after)
{
    skip_ws(p);
    if (skip_comment(p) < 0)
        return -1;
    if (peek(p) < 0)
        return 0;
    int r = newline(p);
    if (r < 0)
        return -1;
    if (r == 0) {
        foundbuf fb;
        fail(p, p->line, "expected end of line after %s, found %s", after, found(p, &fb));
        return -1;
    }
    return 0;
}

/* key = value, added to tbl (dotted keys create sub-tables). */
static int parse_keyval(parser *p, toml_value *tbl, int toplevel)
{
    keypath kp;
    pathbuf pb;
    foundbuf fb;
    if (parse_key(p, &kp) < 0) {
        keypath_free(&kp);
        return -1;
    }
    int last = kp.n - 1;
    skip_ws(p);
    if (peek(p) != '=') {
        fail(p, p->line, "expected '=' after key '%s', found %s", keypath_str(&pb, &kp, last), found(p, &fb));
        goto bad;
    }
    p->pos++;
    skip_ws(p);
    {
        int c = peek(p);
        if (c < 0 || c == '\n' || c == '\r' || c == '#') {
            fail(p, p->line, "missing value for key '%s'", keypath_str(&pb, &kp, last));
            goto bad;
        }
    }
    toml_value *t = tbl;
    for (int i = 0; i < last; i++) {
        size_t k = tab_find(t, kp.s[i]);
        if (k == NOT_FOUND) {
            if (t->depth + 1 > TOML_MAX_DEPTH) {
                fail(p, kp.line[i], "nesting too deep (limit %d)", TOML_MAX_DEPTH);
                goto bad;
            }
            toml_value *nt = node_new(TOML_TABLE, kp.line[i], t->depth + 1);
            if (!nt || tab_add(t, kp.s[i], kp.line[i], nt) < 0) {
                free(nt);
                oom(p);
                goto bad;
            }
            nt->flags = F_DOTTED;
            kp.s[i] = NULL;
            t = nt;
            continue;
        }
        toml_value *v = t->ent[k].val;
        if (v->kind == TOML_TABLE && (v->flags & F_DOTTED) && !(v->flags & F_INLINE)) {
            t = v;
            continue;
        }
        if (v->kind == TOML_TABLE)
            fail(p, kp.line[i], "cannot add keys to table '%s' (defined on line %d) with a dotted key",
                 keypath_str(&pb, &kp, i), v->line);
        else
            fail(p, kp.line[i], "key '%s' is already a%s %s (line %d), not a table", keypath_str(&pb, &kp, i),
                 v->kind == TOML_ARRAY || v->kind == TOML_INT ? "n" : "", toml_kind_name(v->kind),
                 t->ent[k].line);
        goto bad;
    }
    {
        size_t k = tab_find(t, kp.s[last]);
        if (k != NOT_FOUND) {
            fail(p, kp.line[last], "duplicate key '%s' (first defined on line %d)", keypath_str(&pb, &kp, last),
                 t->ent[k].line);
            goto bad;
        }
    }
    toml_value *v = parse_value(p, t->depth + 1);
    if (!v)
        goto bad;
    char what[sizeof pb.b + 32];
    if (toplevel)
        snprintf(what, sizeof what, "value of key '%s'", keypath_str(&pb, &kp, last));
    if (tab_add(t, kp.s[last], kp.line[last], v) < 0) {
        node_free(v);
        oom(p);
        goto bad;
    }
    kp.s[last] = NULL;
    if (toplevel && expect_eol(p, what) < 0)
        goto bad;
    keypath_free(&kp);
    return 0;
bad:
    keypath_free(&kp);
    return -1;
}

/* [a.b] or [[a.b]]; on success *cur is the table that following keys go into. */
static int parse_header(parser *p, toml_value *root, toml_value **cur)
{
    int line = p->line;
    int aot = peek_at(p, 1) == '[';
    keypath kp;
    pathbuf pb;
    foundbuf fb;
    p->pos += aot ? 2 : 1;
    if (parse_key(p, &kp) < 0) {
        keypath_free(&kp);
        return -1;
    }
    skip_ws(p);
    if (aot) {
        if (peek(p) != ']' || peek_at(p, 1) != ']') {
            fail(p, p->line, "expected ']]' to close array-of-tables header, found %s", found(p, &fb));
            goto bad;
        }
        p->pos += 2;
    } else {
        if (peek(p) != ']') {
            fail(p, p->line, "expected ']' to close table header, found %s", found(p, &fb));
            goto bad;
        }
        p->pos++;
    }
    int last = kp.n - 1;
    toml_value *t = root;
    for (int i = 0; i < last; i++) {
        size_t k = tab_find(t, kp.s[i]);
        if (k == NOT_FOUND) {
            if (t->depth + 1 > TOML_MAX_DEPTH) {
                fail(p, line, "nesting too deep (limit %d)", TOML_MAX_DEPTH);
                goto bad;
            }
            toml_value *nt = node_new(TOML_TABLE, line, t->depth + 1);
            if (!nt || tab_add(t, kp.s[i], line, nt) < 0) {
                free(nt);
                oom(p);
                goto bad;
            }
            nt->flags = F_IMPLICIT;
            kp.s[i] = NULL;
            t = nt;
            continue;
        }
        toml_value *v = t->ent[k].val;
        if (v->kind == TOML_TABLE && !(v->flags & F_INLINE)) {
            t = v;
        } else if (v->kind == TOML_ARRAY && (v->flags & F_AOT)) {
            t = v->items[v->n - 1];
        } else if (v->kind == TOML_TABLE) {
            fail(p, line, "cannot extend inline table '%s' (line %d)", keypath_str(&pb, &kp, i), v->line);
            goto bad;
        } else {
            fail(p, line, "key '%s' is already a%s %s (line %d), not a table", keypath_str(&pb, &kp, i),
                 v->kind == TOML_ARRAY || v->kind == TOML_INT ? "n" : "", toml_kind_name(v->kind),
                 t->ent[k].line);
            goto bad;
        }
    }
    size_t k = tab_find(t, kp.s[last]);
    toml_value *v = k == NOT_FOUND ? NULL : t->ent[k].val;
    if (!aot) {
        if (!v) {
            if (t->depth + 1 > TOML_MAX_DEPTH) {
                fail(p, line, "nesting too deep (limit %d)", TOML_MAX_DEPTH);
                goto bad;
            }
            toml_value *nt = node_new(TOML_TABLE, line, t->depth + 1);
            if (!nt || tab_add(t, kp.s[last], line, nt) < 0) {
                free(nt);
                oom(p);
                goto bad;
            }
            nt->flags = F_DEFINED;
            kp.s[last] = NULL;
            *cur = nt;
        } else if (v->kind == TOML_TABLE && (v->flags & F_IMPLICIT)) {
            v->flags = F_DEFINED;
            v->line = line;
            t->ent[k].line = line;
            *cur = v;
        } else if (v->kind == TOML_TABLE) {
            fail(p, line, "table '%s' is already defined (line %d)", keypath_str(&pb, &kp, last), v->line);
            goto bad;
        } else {
            fail(p, line, "cannot define table '%s': key is already a%s %s (line %d)",
                 keypath_str(&pb, &kp, last), v->kind == TOML_ARRAY || v->kind == TOML_INT ? "n" : "",
                 toml_kind_name(v->kind), t->ent[k].line);
            goto bad;
        }
    } else {
        toml_value *arr = v;
        if (!arr) {
            if (t->depth + 2 > TOML_MAX_DEPTH) {
                fail(p, line, "nesting too deep (limit %d)", TOML_MAX_DEPTH);
                goto bad;
            }
            arr = node_new(TOML_ARRAY, line, t->depth + 1);
            if (!arr || tab_add(t, kp.s[last], line, arr) < 0) {
                free(arr);
                oom(p);
                goto bad;
            }
            arr->flags = F_AOT;
            kp.s[last] = NULL;
        } else if (!(arr->kind == TOML_ARRAY && (arr->flags & F_AOT))) {
            fail(p, line, "cannot define array of tables '%s': key is already a%s %s (line %d)",
                 keypath_str(&pb, &kp, last),
                 arr->kind == TOML_ARRAY || arr->kind == TOML_INT ? "n" : "", toml_kind_name(arr->kind),
                 t->ent[k].line);
            goto bad;
        }
        toml_value *nt = node_new(TOML_TABLE, line, arr->depth + 1);
        if (!nt || arr_push(arr, nt) < 0) {
            free(nt);
            oom(p);
            goto bad;
        }
        nt->flags = F_DEFINED;
        *cur = nt;
    }
    keypath_free(&kp);
    return expect_eol(p, aot ? "array-of-tables header" : "table header");
bad:
    keypath_free(&kp);
    return -1;
}

toml_value *toml_parse(const char *text, size_t len, char *err, size_t errlen)
{
    parser p;
    memset(&p, 0, sizeof p);
    p.s = (const unsigned char *)text;
    p.n = len;
    p.line = 1;
    p.err = err;
    p.errlen = errlen;
    if (err && errlen)
        err[0] = '\0';
    if (!text && len) {
        fail(&p, 1, "no input text");
        return NULL;
    }
    if (prescan(&p) < 0)
        return NULL;
    toml_value *root = node_new(TOML_TABLE, 1, 0);
    if (!root) {
        oom(&p);
        return NULL;
    }
    root->flags = F_DEFINED;
    toml_value *cur = root;
    while (!p.failed) {
        skip_ws(&p);
        int c = peek(&p);
        if (c < 0)
            break;
        if (c == '#') {
            skip_comment(&p);
            continue;
        }
        int r = newline(&p);
        if (r < 0)
            break;
        if (r > 0)
            continue;
        if (c == '[')
            parse_header(&p, root, &cur);
        else
            parse_keyval(&p, cur, 1);
    }
    if (p.failed) {
        toml_free(root);
        return NULL;
    }
    return root;
}

/* ----------------------------------------------------------------- accessors */

toml_kind toml_kind_of(const toml_value *v) { return v->kind; }

const char *toml_kind_name(toml_kind k)
{
    switch (k) {
    case TOML_TABLE: return "table";
    case TOML_ARRAY: return "array";
    case TOML_STRING: return "string";
    case TOML_INT: return "integer";
    case TOML_FLOAT: return "float";
    case TOML_BOOL: return "boolean";
    }
    return "unknown";
}

int toml_line(const toml_value *v) { return v ? v->line : 0; }

size_t toml_table_size(const toml_value *t) { return t && t->kind == TOML_TABLE ? t->n : 0; }

const char *toml_table_key(const toml_value *t, size_t i)
{
    return t && t->kind == TOML_TABLE && i < t->n ? t->ent[i].key : NULL;
}

const toml_value *toml_table_value(const toml_value *t, size_t i)
{
    return t && t->kind == TOML_TABLE && i < t->n ? t->ent[i].val : NULL;
}

int toml_table_key_line(const toml_value *t, size_t i)
{
    return t && t->kind == TOML_TABLE && i < t->n ? t->ent[i].line : 0;
}

const toml_value *toml_get(const toml_value *t, const char *key)
{
    if (!t || t->kind != TOML_TABLE || !key)
        return NULL;
    size_t k = tab_find(t, key);
    return k == NOT_FOUND ? NULL : t->ent[k].val;
}

int toml_get_key_line(const toml_value *t, const char *key)
{
    if (!t || t->kind != TOML_TABLE || !key)
        return 0;
    size_t k = tab_find(t, key);
    return k == NOT_FOUND ? 0 : t->ent[k].line;
}

size_t toml_array_size(const toml_value *a) { return a && a->kind == TOML_ARRAY ? a->n : 0; }

const toml_value *toml_array_at(const toml_value *a, size_t i)
{
    return a && a->kind == TOML_ARRAY && i < a->n ? a->items[i] : NULL;
}

const char *toml_string(const toml_value *v) { return v && v->kind == TOML_STRING ? v->str : NULL; }
size_t toml_string_len(const toml_value *v) { return v && v->kind == TOML_STRING ? v->slen : 0; }
long long toml_int(const toml_value *v) { return v && v->kind == TOML_INT ? v->i : 0; }

double toml_number(const toml_value *v)
{
    if (v && v->kind == TOML_INT)
        return (double)v->i;
    if (v && v->kind == TOML_FLOAT)
        return v->f;
    return (double)NAN;
}

int toml_bool(const toml_value *v) { return v && v->kind == TOML_BOOL ? v->b : 0; }
int toml_is_number(const toml_value *v) { return v && (v->kind == TOML_INT || v->kind == TOML_FLOAT); }

/* ------------------------------------------------------------------ overrides */

static void set_scalar(toml_value *v, double value)
{
    /* An integral value keeps an integer an integer, so `model.modes` stays one. */
    if (v->kind == TOML_INT && value == floor(value) && fabs(value) < 9.0e15) {
        v->i = (long long)value;
    } else {
        v->kind = TOML_FLOAT;
        v->f = value;
    }
}

int toml_set_number(toml_value *root, const char *table, const char *key, long index, double value,
                    char *err, size_t errlen)
{
    char dummy[1];
    if (!err || errlen == 0) { err = dummy; errlen = sizeof dummy; }
    size_t k = root && root->kind == TOML_TABLE ? tab_find(root, table) : NOT_FOUND;
    toml_value *t = k == NOT_FOUND ? NULL : root->ent[k].val;
    if (!t || t->kind != TOML_TABLE) {
        snprintf(err, errlen, "the scene has no table [%s]", table);
        return -1;
    }
    k = tab_find(t, key);
    if (k == NOT_FOUND) {
        if (index >= 0) {
            snprintf(err, errlen, "the scene has no array %s.%s", table, key);
            return -1;
        }
        char *kc = malloc(strlen(key) + 1);
        toml_value *v = node_new(TOML_FLOAT, 0, t->depth + 1);
        if (!kc || !v || tab_add(t, strcpy(kc, key), 0, v) != 0) {
            free(kc);
            free(v);
            snprintf(err, errlen, "out of memory");
            return -1;
        }
        v->f = value;
        return 0;
    }
    toml_value *v = t->ent[k].val;
    if (index >= 0) {
        if (v->kind != TOML_ARRAY) {
            snprintf(err, errlen, "%s.%s is a %s, not an array", table, key, toml_kind_name(v->kind));
            return -1;
        }
        if ((size_t)index >= v->n) {
            snprintf(err, errlen, "index %ld is out of range: %s.%s has %zu items (0..%zu)", index, table,
                     key, v->n, v->n ? v->n - 1 : 0);
            return -1;
        }
        v = v->items[index];
    }
    if (v->kind != TOML_INT && v->kind != TOML_FLOAT) {
        snprintf(err, errlen, "%s.%s%s is a %s, not a number", table, key, index >= 0 ? "[i]" : "",
                 toml_kind_name(v->kind));
        return -1;
    }
    set_scalar(v, value);
    return 0;
}

/* The node at root[table][key] for an override of the given kind: the existing one when it has
 * that kind, else a new one added to an existing table. NULL with a reason in err. */
static toml_value *override_slot(toml_value *root, const char *table, const char *key, toml_kind kind,
                                 char *err, size_t errlen)
{
    size_t k = root && root->kind == TOML_TABLE ? tab_find(root, table) : NOT_FOUND;
    toml_value *t = k == NOT_FOUND ? NULL : root->ent[k].val;
    if (!t || t->kind != TOML_TABLE) {
        snprintf(err, errlen, "the scene has no table [%s]", table);
        return NULL;
    }
    k = tab_find(t, key);
    if (k == NOT_FOUND) {
        char *kc = strdup(key);
        toml_value *v = node_new(kind, 0, t->depth + 1);
        if (!kc || !v || tab_add(t, kc, 0, v) != 0) {
            free(kc);
            free(v);
            snprintf(err, errlen, "out of memory");
            return NULL;
        }
        return v;
    }
    toml_value *v = t->ent[k].val;
    if (v->kind != kind) {
        snprintf(err, errlen, "%s.%s is a %s, not a %s", table, key, toml_kind_name(v->kind), toml_kind_name(kind));
        return NULL;
    }
    return v;
}

int toml_set_string(toml_value *root, const char *table, const char *key, const char *text,
                    char *err, size_t errlen)
{
    char dummy[1];
    if (!err || errlen == 0) { err = dummy; errlen = sizeof dummy; }
    char *copy = strdup(text);
    if (!copy) {
        snprintf(err, errlen, "out of memory");
        return -1;
    }
    toml_value *v = override_slot(root, table, key, TOML_STRING, err, errlen);
    if (!v) {
        free(copy);
        return -1;
    }
    free(v->str);
    v->str = copy;
    v->slen = strlen(copy);
    return 0;
}

int toml_set_bool(toml_value *root, const char *table, const char *key, int value, char *err, size_t errlen)
{
    char dummy[1];
    if (!err || errlen == 0) { err = dummy; errlen = sizeof dummy; }
    toml_value *v = override_slot(root, table, key, TOML_BOOL, err, errlen);
    if (!v) return -1;
    v->b = value != 0;
    return 0;
}

int toml_set_origin(toml_value *root, const char *table, const char *key, long index, int line)
{
    size_t k = root && root->kind == TOML_TABLE ? tab_find(root, table) : NOT_FOUND;
    toml_value *t = k == NOT_FOUND ? NULL : root->ent[k].val;
    if (!t || t->kind != TOML_TABLE || (k = tab_find(t, key)) == NOT_FOUND) return -1;
    toml_value *v = t->ent[k].val;
    t->ent[k].line = line;   /* messages about the key name the key's line */
    if (index >= 0) {
        if (v->kind != TOML_ARRAY || (size_t)index >= v->n) return -1;
        v = v->items[index];
    }
    v->line = line;
    return 0;
}
