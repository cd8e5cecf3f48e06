/* swim animate DIR: DIR/animation.mp4 of a run (runtime/plot/animate_run.py: matplotlib frames
 * piped to ffmpeg; the flow frames come from `swim flow DIR --frames K`). */
#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "cli/args.h"
#include "cli/commands.h"
#include "io/files.h"
#include "io/message.h"
#include "cli/report.h"

/* The options of runtime/plot/animate_run.py (which parses them), for --help. */
static const swim_opt animate_options[] = {
    {"fps", 1, NULL, "F", "frames per second, 1..120 (default 25)"},
    {"duration", 1, NULL, "S", "length of the video in seconds, 0.1..3600 (default: the simulated time, clamped to [4, 20])"},
    {"out", 1, NULL, "FILE", "the video (default DIR/animation.mp4; a still DIR/animation.png beside it)"}};

int swim_cmd_animate(int argc, char **argv)
{
    for (int i = 2; i < argc; i++)
        if (strcmp(argv[i], "--help") == 0 || strcmp(argv[i], "-h") == 0) {
            swim_args_help(stdout, animate_options, (int)(sizeof animate_options / sizeof animate_options[0]));
            return SWIM_ARGS_HELP;
        }
    if (argc < 3 || strncmp(argv[2], "--", 2) == 0) {
        swim_message(stderr, "swim animate: expected a run directory first, e.g. swim animate out/example3 --fps 25");
        return 2;
    }
    if (access(argv[2], R_OK) != 0) {
        swim_message(stderr, "swim animate: cannot read run directory '%s'", argv[2]);
        return 2;
    }
    swim_status missing = {0};
    const char *share = swim_share_dir(&missing), *python = swim_python();
    if (swim_status_shown(&missing, !share)) return 1;
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
