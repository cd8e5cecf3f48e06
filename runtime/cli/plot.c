/* swim plot DIR: the figures of a run (runtime/plot/plot_run.py, matplotlib), or of a sweep when
 * DIR holds sweep.json (runtime/plot/plot_family.py, which calls this program's `inspect`). */
#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "cli/commands.h"
#include "io/files.h"


int swim_cmd_plot(int argc, char **argv)
{
    if (argc != 3 || strncmp(argv[2], "--", 2) == 0) {
        fprintf(stderr, "swim plot: expected one run directory, e.g. swim plot out/example3\n");
        return 2;
    }
    if (access(argv[2], R_OK) != 0) {
        fprintf(stderr, "swim plot: cannot read run directory '%s'\n", argv[2]);
        return 2;
    }
    const char *share = swim_share_dir(), *python = swim_python();
    if (!share) return 1;
    char script[4200], probe[4200];
    snprintf(probe, sizeof probe, "%s/sweep.json", argv[2]);
    const int sweep = access(probe, R_OK) == 0;
    snprintf(script, sizeof script, "%s/runtime/plot/%s", share, sweep ? "plot_family.py" : "plot_run.py");
    char self[4096];
    ssize_t len = readlink("/proc/self/exe", self, sizeof self - 1);
    /* the scripts call back `swim flow` / `swim inspect`: tell them which binary this is */
    if (len > 0 && !getenv("SWIM_BIN")) {
        self[len] = '\0';
        setenv("SWIM_BIN", self, 1);
    }
    fflush(stdout);
    execlp(python, python, script, argv[2], (char *)NULL);
    fprintf(stderr, "swim plot: cannot start %s: %s\n", python, strerror(errno));
    return 1;
}
