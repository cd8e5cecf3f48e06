/* report.h -- what a program of the project (bin/swim, swim-mpi, an exported simulate) prints
 * itself: a status on stderr, notices as they come, and the end of its report on stdout. Library
 * code below the commands never prints; it fills a status (io/status.h) that these show.
 *
 * A report printed to a full disk, a closed pipe or /dev/full is lost without any error at the
 * printf: stdio buffers it, and the failure only shows at the flush or the close. A command that
 * prints a report therefore ends with swim_stdout_finish, which flushes and closes stdout and
 * turns a failure into one line on stderr naming stdout and exit status 1. */
#ifndef SWIM_CLI_REPORT_H
#define SWIM_CLI_REPORT_H

#include "io/status.h"

/* rc, after showing st on stderr when rc is nonzero: a command's `if (swim_status_shown(&st,
 * f(..., &st))) return 2;`. */
int swim_status_shown(const swim_status *st, int rc);

/* A note callback that shows each notice on stderr as one line (swim_message): what a command
 * installs, `swim_status st = SWIM_STATUS_STDERR;`. */
void swim_status_note_stderr(void *ctx, const char *line);
#define SWIM_STATUS_STDERR {.note = swim_status_note_stderr}

/* Flushes stdout and checks its error flag: 0, or -1 after one line
 * "swim CMD: cannot write the report to stdout: REASON" on stderr. The line is printed once per
 * process, however often this is called, so a command may check early and main check again. */
int swim_stdout_check(const char *cmd);

/* swim_stdout_check, then fclose(stdout) (a close can report a deferred write error); nothing
 * may be printed to stdout afterwards. Returns the exit status: `status` when stdout is fine,
 * else `status` if it already says failure (nonzero), 1 otherwise. */
int swim_stdout_finish(const char *cmd, int status);

#endif
