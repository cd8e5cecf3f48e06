/* swim plot DIR: the figures of a run (runtime/plot/plot_run.py, matplotlib). */
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
    /* The script calls back `swim flow` for the body pictures: tell it which binary this is. */
    char self[1024];
    ssize_t len = readlink("/proc/self/exe", self, sizeof self - 1);
    if (len > 0) {
        self[len] = '\0';
        setenv("SWIM_BIN", self, 1);
    }
    char script[1024];
    snprintf(script, sizeof script, "%s/runtime/plot/plot_run.py", SWIM_ROOT);
    fflush(stdout);
    execl(SWIM_PYTHON, SWIM_PYTHON, script, argv[2], (char *)NULL);
    perror("swim plot: cannot start " SWIM_PYTHON);
    return 1;
}
