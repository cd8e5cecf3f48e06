#include "cli/report.h"

#include <errno.h>
#include <stdio.h>
#include <string.h>

#include "io/message.h"

static int reported;   /* the line went out already: one failure, one line */

static int fail(const char *cmd, int err)
{
    if (!reported)
        swim_message(stderr, "swim %s: cannot write the report to stdout: %s", cmd, strerror(err ? err : EIO));
    reported = 1;
    return -1;
}

int swim_stdout_check(const char *cmd)
{
    errno = 0;
    if (fflush(stdout) != 0 || ferror(stdout) || reported) return fail(cmd, errno);
    return 0;
}

int swim_stdout_finish(const char *cmd, int status)
{
    int bad = swim_stdout_check(cmd) != 0;
    errno = 0;
    if (fclose(stdout) != 0 && !bad) bad = fail(cmd, errno) != 0;
    return bad && status == 0 ? 1 : status;
}

int swim_status_shown(const swim_status *st, int rc)
{
    if (rc) swim_status_print(st, stderr);
    return rc;
}

void swim_status_note_stderr(void *ctx, const char *line)
{
    (void)ctx;
    swim_message(stderr, "%s", line);
}
