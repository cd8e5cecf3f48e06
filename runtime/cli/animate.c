/* swim animate DIR: DIR/animation.mp4 of a run (runtime/plot/animate_run.py: matplotlib frames
 * piped to ffmpeg; the flow frames come from `swim flow DIR --frames K`). */
#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "cli/commands.h"
#include "io/files.h"
#include "io/message.h"

int swim_cmd_animate(int argc, char **argv)
{
    if (argc < 3 || strncmp(argv[2], "--", 2) == 0) {
        swim_message(stderr, "swim animate: expected a run directory first, e.g. swim animate out/example3 --fps 25");
        return 2;
    }
    if (access(argv[2], R_OK) != 0) {
        swim_message(stderr, "swim animate: cannot read run directory '%s'", argv[2]);
        return 2;
    }
    const char *share = swim_share_dir(), *python = swim_python();
    if (!share) return 1;
    /* The script calls back `swim flow`: tell it which binary this is. */
    char self[4096];
    ssize_t len = readlink("/proc/self/exe", self, sizeof self - 1);
    if (len > 0) {
        self[len] = '\0';
        setenv("SWIM_BIN", self, 1);
    }
    char script[4200];
    snprintf(script, sizeof script, "%s/runtime/plot/animate_run.py", share);
    char **args = calloc((size_t)argc + 2, sizeof(char *));
    if (!args) return 1;
    args[0] = (char *)python;
    args[1] = script;
    for (int i = 2; i < argc; i++) args[i] = argv[i];
    fflush(stdout);
    execvp(python, args);
    swim_message(stderr, "swim animate: cannot start %s: %s", python, strerror(errno));
    free(args);
    return 1;
}
