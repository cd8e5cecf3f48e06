#include "io/message.h"

#include <stdlib.h>
#include <string.h>

size_t swim_utf8_sequence(const unsigned char *s, size_t n, unsigned long *cp)
{
    size_t len;
    unsigned long c;
    if (s[0] < 0x80) { *cp = s[0]; return 1; }
    if (s[0] >= 0xC2 && s[0] <= 0xDF) { len = 2; c = s[0] & 0x1F; }
    else if (s[0] >= 0xE0 && s[0] <= 0xEF) { len = 3; c = s[0] & 0x0F; }
    else if (s[0] >= 0xF0 && s[0] <= 0xF4) { len = 4; c = s[0] & 0x07; }
    else return 0;
    if (n < len) return 0;
    for (size_t i = 1; i < len; i++) {
        if ((s[i] & 0xC0) != 0x80) return 0;
        c = (c << 6) | (s[i] & 0x3F);
    }
    if ((len == 3 && c < 0x800) || (len == 4 && (c < 0x10000 || c > 0x10FFFF))) return 0;
    if (c >= 0xD800 && c <= 0xDFFF) return 0;
    *cp = c;
    return len;
}

/* Code points a terminal acts on or that reorder the line: C0, DEL, C1 (0x9B is CSI), the
 * line/paragraph separators and the bidirectional overrides and isolates. */
static int invisible(unsigned long cp)
{
    return cp < 0x20 || (cp >= 0x7F && cp <= 0x9F) || cp == 0x2028 || cp == 0x2029 ||
           (cp >= 0x202A && cp <= 0x202E) || (cp >= 0x2066 && cp <= 0x2069) || cp == 0xFEFF;
}

int swim_quote(FILE *f, const char *text, size_t len, size_t max)
{
    return swim_quote_part(f, text, len, len, max);
}

int swim_quote_part(FILE *f, const char *text, size_t have, size_t len, size_t max)
{
    const unsigned char *s = (const unsigned char *)text;
    size_t i = 0, stop = max && len > max ? max : len;
    if (have > len) have = len;
    if (stop > have) stop = have;
    while (i < stop) {
        unsigned long cp;
        size_t k = swim_utf8_sequence(s + i, have - i, &cp);
        if (k == 0) {
            fprintf(f, "\\x%02x", s[i]);
            i++;
            continue;
        }
        if (cp == '\\') fputs("\\\\", f);
        else if (cp == '\n') fputs("\\n", f);
        else if (cp == '\r') fputs("\\r", f);
        else if (cp == '\t') fputs("\\t", f);
        else if (cp < 0x80 && invisible(cp)) fprintf(f, "\\x%02lx", cp);
        else if (invisible(cp)) fprintf(f, "\\u%04lx", cp);
        else fwrite(s + i, 1, k, f);
        i += k;
    }
    if (stop < len) fprintf(f, "... (%zu more bytes)", len - stop);
    return ferror(f) ? -1 : 0;
}

static char *vformat(const char *fmt, va_list ap, int *len)
{
    va_list again;
    va_copy(again, ap);
    int n = vsnprintf(NULL, 0, fmt, ap);
    char *buf = n >= 0 ? malloc((size_t)n + 1) : NULL;
    if (buf) vsnprintf(buf, (size_t)n + 1, fmt, again);
    va_end(again);
    *len = n;
    return buf;
}

void swim_vmessage(FILE *f, const char *fmt, va_list ap)
{
    int n;
    char *buf = vformat(fmt, ap, &n);
    if (buf) {
        swim_quote(f, buf, (size_t)n, SWIM_MESSAGE_MAX);
        free(buf);
    } else {
        fputs(fmt, f);   /* out of memory: the bare format still says what went wrong */
    }
    fputc('\n', f);
}

void swim_message(FILE *f, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    swim_vmessage(f, fmt, ap);
    va_end(ap);
}

char *swim_vstrprintf(const char *fmt, va_list ap)
{
    int n;
    return vformat(fmt, ap, &n);
}

char *swim_strprintf(const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    char *buf = swim_vstrprintf(fmt, ap);
    va_end(ap);
    return buf;
}

char *swim_shell_words(int argc, const char *const *argv)
{
    size_t len = 1;
    for (int i = 0; i < argc; i++) len += 4 * strlen(argv[i]) + 3;
    char *s = malloc(len), *p = s;
    if (!s) return NULL;
    for (int i = 0; i < argc; i++) {
        const char *a = argv[i];
        const int plain = a[0] && strspn(a, "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789_./:=,+-@%") == strlen(a);
        if (i) *p++ = ' ';
        if (!plain) *p++ = '\'';
        for (; *a; a++) {
            if (!plain && *a == '\'') { memcpy(p, "'\\''", 4); p += 4; }
            else *p++ = *a;
        }
        if (!plain) *p++ = '\'';
    }
    *p = '\0';
    return s;
}

