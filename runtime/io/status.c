#include "io/status.h"

#include <stdarg.h>
#include <stdlib.h>
#include <string.h>

void swim_status_clear(swim_status *st)
{
    if (!st) return;
    void (*note)(void *, const char *) = st->note;
    void *ctx = st->note_ctx;
    memset(st, 0, sizeof *st);
    st->note = note;
    st->note_ctx = ctx;
}

static void keep_line(swim_status_line *l, const char *text, size_t len)
{
    const size_t have = len < sizeof l->text - 1 ? len : sizeof l->text - 1;
    memcpy(l->text, text, have);
    l->text[have] = '\0';
    l->len = len;
}

void swim_status_vfail(swim_status *st, const char *who, const char *file, int line, const char *key,
                       const char *fmt, va_list ap)
{
    if (!st || st->nlines == SWIM_STATUS_LINES) return;
    char *msg = swim_vstrprintf(fmt, ap);
    /* out of memory: the bare format still says what went wrong (as swim_message) */
    char *text = swim_strprintf("%s%s%s", who ? who : "", who ? ": " : "", msg ? msg : fmt);
    free(msg);
    if (!text) return;
    swim_status_line *l = &st->lines[st->nlines++];
    keep_line(l, text, strlen(text));
    free(text);
    if (st->nlines > 1) return;
    st->failed = 1;
    st->who_len = who ? strlen(who) + 2 : 0;
    snprintf(st->file, sizeof st->file, "%s", file ? file : "");
    st->line = line;
    snprintf(st->key, sizeof st->key, "%s", key ? key : "");
}

void swim_status_fail(swim_status *st, const char *who, const char *file, int line, const char *key,
                      const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    swim_status_vfail(st, who, file, line, key, fmt, ap);
    va_end(ap);
}

void swim_status_fail_cmd(swim_status *st, const char *cmd, const char *file, const char *key, const char *fmt, ...)
{
    char who[64];
    snprintf(who, sizeof who, "swim %s", cmd);
    va_list ap;
    va_start(ap, fmt);
    swim_status_vfail(st, who, file, 0, key, fmt, ap);
    va_end(ap);
}

void swim_status_note(const swim_status *st, const char *fmt, ...)
{
    if (!st || !st->note) return;
    va_list ap;
    va_start(ap, fmt);
    char *text = swim_vstrprintf(fmt, ap);
    va_end(ap);
    st->note(st->note_ctx, text ? text : fmt);
    free(text);
}

void swim_status_notes_from(const swim_status *to, const swim_status *from)
{
    for (int i = 0; to && to->note && from && i < from->nlines; i++) to->note(to->note_ctx, from->lines[i].text);
}

const char *swim_status_message(const swim_status *st, char *buf, size_t n)
{
    const char *m = st && st->nlines ? st->lines[0].text + st->who_len : "";
    snprintf(buf, n, "%s", m);
    return buf;
}

int swim_status_print(const swim_status *st, FILE *f)
{
    for (int i = 0; st && i < st->nlines; i++) {
        const swim_status_line *l = &st->lines[i];
        swim_quote_part(f, l->text, strlen(l->text), l->len, SWIM_MESSAGE_MAX);
        fputc('\n', f);
    }
    return ferror(f) ? -1 : 0;
}
