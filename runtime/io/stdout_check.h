/* stdout_check.h -- the end of a report on the standard output.
 *
 * A report printed to a full disk, a closed pipe or /dev/full is lost without any error at the
 * printf: stdio buffers it, and the failure only shows at the flush or the close. A command that
 * prints a report therefore ends with swim_stdout_finish, which flushes and closes stdout and
 * turns a failure into one line on stderr naming stdout and exit status 1. */
#ifndef SWIM_IO_STDOUT_CHECK_H
#define SWIM_IO_STDOUT_CHECK_H

/* Flushes stdout and checks its error flag: 0, or -1 after one line
 * "swim CMD: cannot write the report to stdout: REASON" on stderr. The line is printed once per
 * process, however often this is called, so a command may check early and main check again. */
int swim_stdout_check(const char *cmd);

/* swim_stdout_check, then fclose(stdout) (a close can report a deferred write error); nothing
 * may be printed to stdout afterwards. Returns the exit status: `status` when stdout is fine,
 * else `status` if it already says failure (nonzero), 1 otherwise. */
int swim_stdout_finish(const char *cmd, int status);

#endif
