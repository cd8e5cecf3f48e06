/* libFuzzer target: the quoting of user text in messages (runtime/io/message.c). Whatever the
 * bytes, a message must come out as exactly one line of valid UTF-8 with no control
 * character (C0, DEL, C1) and no bidirectional override, and at most SWIM_MESSAGE_MAX input
 * bytes shown. */
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "io/message.h"

/* Valid UTF-8 without control characters, bidi controls, BOM or line separators, ending in
 * one '\n'. */
static int clean_line(const unsigned char *s, size_t n)
{
    if (n == 0 || s[n - 1] != '\n') return 0;
    for (size_t i = 0; i + 1 < n;) {
        unsigned long cp;
        size_t k;
        if (s[i] < 0x80) { cp = s[i]; k = 1; }
        else if ((s[i] & 0xE0) == 0xC0) { cp = s[i] & 0x1F; k = 2; }
        else if ((s[i] & 0xF0) == 0xE0) { cp = s[i] & 0x0F; k = 3; }
        else if ((s[i] & 0xF8) == 0xF0) { cp = s[i] & 0x07; k = 4; }
        else return 0;
        if (i + k > n - 1) return 0;
        for (size_t j = 1; j < k; j++) {
            if ((s[i + j] & 0xC0) != 0x80) return 0;
            cp = (cp << 6) | (s[i + j] & 0x3F);
        }
        if (cp < 0x20 || (cp >= 0x7F && cp <= 0x9F) || cp == 0x2028 || cp == 0x2029 ||
            (cp >= 0x202A && cp <= 0x202E) || (cp >= 0x2066 && cp <= 0x2069) || cp == 0xFEFF)
            return 0;
        i += k;
    }
    return 1;
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    char *text = malloc(size + 1), *out = NULL;
    if (!text) return 0;
    memcpy(text, data, size);
    text[size] = '\0';   /* swim_message sees the bytes up to the first NUL, swim_quote all */
    size_t len = 0;
    FILE *m = open_memstream(&out, &len);
    if (!m) { free(text); return 0; }
    swim_message(m, "swim: %s: x", text);
    fclose(m);
    if (!clean_line((const unsigned char *)out, len)) abort();
    /* every input byte becomes at most 6 output bytes (\u00XX), plus the elision note */
    if (len > 6 * (size_t)SWIM_MESSAGE_MAX + 64) abort();
    free(out);
    out = NULL;
    m = open_memstream(&out, &len);
    if (!m) { free(text); return 0; }
    swim_quote(m, text, size, 0);
    fputc('\n', m);
    fclose(m);
    if (!clean_line((const unsigned char *)out, len)) abort();
    free(out);
    free(text);
    return 0;
}
