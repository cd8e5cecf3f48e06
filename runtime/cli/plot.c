/* swim plot DIR: the figures of a run (runtime/plot/plot_run.py, matplotlib), or of a sweep when
 * DIR holds sweep.json (runtime/plot/plot_family.py, which calls this program's `inspect`). */
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
    char script[1024], probe[1100];
    snprintf(probe, sizeof probe, "%s/sweep.json", argv[2]);
    const int sweep = access(probe, R_OK) == 0;
    snprintf(script, sizeof script, "%s/runtime/plot/%s", SWIM_ROOT, sweep ? "plot_family.py" : "plot_run.py");
    char self[1024];
    ssize_t len = readlink("/proc/self/exe", self, sizeof self - 1);
    /* the scripts call back `swim flow` / `swim inspect`: tell them which binary this is */
    if (len > 0 && !getenv("SWIM_BIN")) {
        self[len] = '\0';
        setenv("SWIM_BIN", self, 1);
    }
    fflush(stdout);
    execl(SWIM_PYTHON, SWIM_PYTHON, script, argv[2], (char *)NULL);
    perror("swim plot: cannot start " SWIM_PYTHON);
    return 1;
}
