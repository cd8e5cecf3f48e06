/* swim plot DIR: the figures of a run (runtime/plot/plot_run.py, matplotlib). */
#include <stdio.h>
#include <string.h>
#include <unistd.h>

#include "cli/commands.h"
#include "io/files.h"
#include "io/message.h"


int swim_cmd_plot(int argc, char **argv)
{
    if (argc != 3 || strncmp(argv[2], "--", 2) == 0) {
        swim_message(stderr, "swim plot: expected one run directory, e.g. swim plot out/example3");
        return 2;
    }
    if (access(argv[2], R_OK) != 0) {
        swim_message(stderr, "swim plot: cannot read run directory '%s'", argv[2]);
        return 2;
    }
    const char *script = SWIM_ROOT "/runtime/plot/plot_run.py";
    fflush(stdout);
    execl(SWIM_PYTHON, SWIM_PYTHON, script, argv[2], (char *)NULL);
    perror("swim plot: cannot start " SWIM_PYTHON);
    return 1;
}
