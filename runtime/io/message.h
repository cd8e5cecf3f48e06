/* message.h -- the one way user text reaches a terminal.
 *
 * Scene files and command lines carry arbitrary bytes: a newline would split a one-line error,
 * an ESC [ 2 J in a title would clear the screen. swim_quote writes text with every control
 * character, terminal escape and invalid UTF-8 byte shown as a visible escape (\n, \t, \x1b,
 * \u009b, \\), so what it writes is always one line of printable UTF-8. swim_message formats a
 * whole message like printf and sends it through swim_quote, then ends the line: every error
 * and report line of bin/swim goes through it. */
#ifndef SWIM_MESSAGE_H
#define SWIM_MESSAGE_H

#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>

/* At most this many bytes of one message are shown; the rest is replaced by
 * "... (N more bytes)" so that a 16 MB value cannot flood a terminal. */
#define SWIM_MESSAGE_MAX 2000

/* Writes len bytes of text, escaped as above (at most `max` input bytes, then the elision
 * note; max = 0 means no limit). Returns 0, or -1 on a write error. */
int swim_quote(FILE *f, const char *text, size_t len, size_t max);

/* The same for a text of len bytes of which only the first `have` are at hand (have <= len,
 * have >= max + 3 so that a UTF-8 sequence at the cut is whole): what swim_quote writes for
 * the whole text (swim_status keeps no more of a line than this). */
int swim_quote_part(FILE *f, const char *text, size_t have, size_t len, size_t max);

/* printf-like; the result is quoted, cut at SWIM_MESSAGE_MAX, and followed by '\n'.
 * No fixed-size buffer: the text is formatted at its full length first. */
void swim_message(FILE *f, const char *fmt, ...) __attribute__((format(printf, 2, 3)));
void swim_vmessage(FILE *f, const char *fmt, va_list ap);

/* Length of the valid UTF-8 sequence at s (n >= 1 bytes available), or 0 if it is not one
 * (overlong forms, surrogates and code points above U+10FFFF are invalid); *cp gets the code
 * point. */
size_t swim_utf8_sequence(const unsigned char *s, size_t n, unsigned long *cp);

/* The formatted text in a new malloc'd string (NULL when out of memory). */
char *swim_strprintf(const char *fmt, ...) __attribute__((format(printf, 1, 2)));
char *swim_vstrprintf(const char *fmt, va_list ap);

/* argv[0..argc) as one line a shell reads back as the same words (a word with characters other
 * than [A-Za-z0-9_./:=,+-@%] in single quotes): the command line a summary records. NULL when
 * out of memory; the caller frees it. */
char *swim_shell_words(int argc, const char *const *argv);

#endif
