/* status.h -- what went wrong, filled where it went wrong, shown by whoever owns the terminal.
 *
 * Library code (everything below runtime/cli/ and runtime/mpi/) never prints: a function that
 * refuses its input or fails fills the caller's swim_status and returns its usual code. The
 * status keeps the cause as fields (file, line, key) and as the exact line a command shows
 * ("swim: FILE:LINE: KEY: message"); a command prints it with swim_status_print, which writes
 * what swim_message wrote before (quoted, cut at SWIM_MESSAGE_MAX); libswim copies the fields
 * into its swim_error. A failure that a caller explains further (no kernel for this scene, after
 * the compiler's failure) adds lines after the cause, up to SWIM_STATUS_LINES; a failed kernel
 * build also keeps the last lines of its build.log (detail), which a command does not print.
 *
 * Notices that are not failures (a shape projected onto the constraints) go to the note
 * callback the caller installed in the status, nowhere without one. */
#ifndef SWIM_STATUS_H
#define SWIM_STATUS_H

#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>

#include "io/message.h"

#define SWIM_STATUS_LINES 3

typedef struct {
    char text[SWIM_MESSAGE_MAX + 8];   /* the line's first bytes (a UTF-8 sequence at the cut whole) */
    size_t len;                        /* its whole length: the rest is counted when it is shown */
} swim_status_line;

typedef struct {
    /* set by the caller (optional): where notices go */
    void (*note)(void *ctx, const char *line);
    void *note_ctx;
    /* filled by the failure */
    int failed;               /* 0: nothing went wrong (yet) */
    char file[1024];          /* the scene file (or name) the cause is in, "" when none */
    int line;                 /* its line, 0 when none */
    char key[128];            /* TABLE.KEY of the value refused, "" when none */
    size_t who_len;           /* the cause's line is "swim[ CMD]: message": the length of "swim[ CMD]: " */
    int nlines;
    swim_status_line lines[SWIM_STATUS_LINES];
    char detail[2048];        /* more for a reader than a terminal: the end of a build log */
} swim_status;

/* An empty status (keeping the note callback of *st). */
void swim_status_clear(swim_status *st);

/* A failure line "WHO: message" (who: "swim", "swim run", ...; NULL: the message alone). The first one is the cause and
 * records file, line and key (NULL or "" and 0 when the cause has none); later ones are added
 * after it. st may be NULL (nothing kept). */
void swim_status_fail(swim_status *st, const char *who, const char *file, int line, const char *key,
                      const char *fmt, ...) __attribute__((format(printf, 6, 7)));
void swim_status_vfail(swim_status *st, const char *who, const char *file, int line, const char *key,
                       const char *fmt, va_list ap);

/* swim_status_fail with WHO "swim CMD" (the line a command CMD shows): "swim CMD: message". */
void swim_status_fail_cmd(swim_status *st, const char *cmd, const char *file, const char *key, const char *fmt, ...)
    __attribute__((format(printf, 5, 6)));

/* A notice: to st's note callback, if any (the text as swim_message would show it, unquoted). */
void swim_status_note(const swim_status *st, const char *fmt, ...) __attribute__((format(printf, 2, 3)));

/* Each line of from as a notice of to (st's note callback): a failure the caller goes on past. */
void swim_status_notes_from(const swim_status *to, const swim_status *from);

/* The cause without "WHO: ", at most n - 1 bytes ("" when nothing failed). */
const char *swim_status_message(const swim_status *st, char *buf, size_t n);

/* Every line of st on f as swim_message shows it; nothing when nothing failed. 0 or -1. */
int swim_status_print(const swim_status *st, FILE *f);

/* A program shows a status with cli/report.h (swim_status_shown, SWIM_STATUS_STDERR). */

#endif
