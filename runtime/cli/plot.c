/* swim plot DIR: the figures of a run (runtime/plot/plot_run.py, matplotlib), of a sweep when
 * DIR holds sweep.json (runtime/plot/plot_family.py, which calls this program's `inspect`), or of
 * a branch of periodic orbits when it holds branch.json (runtime/plot/plot_branch.py). */
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


/* The options of runtime/plot/plot_run.py (which parses them), for --help. */
static const swim_opt plot_options[] = {
    {"only", 1, NULL, "NAME ...", "only these figures: trajectory, energy, impulse, phase, snapshots, instants, "
                                  "phase3d, modes, path, stroke (default: every one the run has data for)"},
    {"mark", 2, NULL, "T1,T2,...", "mark these times on the time plots and draw the body at them (instants.png)"},
    {"events", 1, NULL, "all|COLUMN:KIND,...", "mark the events of DIR/events.csv: all of them, or the pairs "
                                               "named (KIND max, min, zero or *); without --mark and --events: the "
                                               "first 12 event times, the rest counted in a note"}};

int swim_cmd_plot(int argc, char **argv)
{
    for (int i = 2; i < argc; i++)
        if (strcmp(argv[i], "--help") == 0 || strcmp(argv[i], "-h") == 0) {
            swim_args_help(stdout, plot_options, (int)(sizeof plot_options / sizeof plot_options[0]));
            printf("a sweep folder (DIR/sweep.json) gets the family's figures, a swim continue folder "
                   "(DIR/branch.json) the bifurcation diagram and the multipliers; neither takes options\n");
            return SWIM_ARGS_HELP;
        }
    if (argc < 3 || strncmp(argv[2], "--", 2) == 0) {
        swim_message(stderr, "swim plot: expected a run directory first, e.g. swim plot out/example3 --mark 3.17,3.95");
        return 2;
    }
    if (access(argv[2], R_OK) != 0) {
        swim_message(stderr, "swim plot: cannot read run directory '%s'", argv[2]);
        return 2;
    }
    swim_status missing = {0};
    const char *share = swim_share_dir(&missing), *python = swim_python();
    if (swim_status_shown(&missing, !share)) return 1;
    /* a sweep folder (sweep.json) gets the family figures, a branch folder (branch.json) the
     * bifurcation diagram, a run folder the run's */
    char *probe = swim_path_join(argv[2], "sweep.json"), *bprobe = swim_path_join(argv[2], "branch.json");
    if (!probe || !bprobe) {
        free(probe);
        free(bprobe);
        swim_message(stderr, "swim plot: out of memory");
        return 1;
    }
    const int branch = access(bprobe, R_OK) == 0;
    const int sweep = !branch && access(probe, R_OK) == 0;
    free(probe);
    free(bprobe);
    char *script = swim_strprintf("%s/runtime/plot/%s", share,
                                  branch ? "plot_branch.py" : sweep ? "plot_family.py" : "plot_run.py");
    if (!script) {
        swim_message(stderr, "swim plot: out of memory");
        return 1;
    }
    /* the scripts call back `swim flow` / `swim inspect`: tell them which binary this is */
    if (!getenv("SWIM_BIN")) {
        char *self = realpath("/proc/self/exe", NULL);
        if (self) setenv("SWIM_BIN", self, 1);
        free(self);
    }
    if ((sweep || branch) && argc > 3) {
        swim_message(stderr, "swim plot: %s is a %s; its figures take no options (got '%s')", argv[2],
                     branch ? "branch of periodic orbits" : "sweep", argv[3]);
        free(script);
        return 2;
    }
    /* the run's options (--mark, --events, --only) are the script's to check */
    char **args = calloc((size_t)argc + 1, sizeof *args);
    if (!args) {
        swim_message(stderr, "swim plot: out of memory");
        free(script);
        return 1;
    }
    args[0] = (char *)python;
    args[1] = script;
    for (int i = 2; i < argc; i++) args[i] = argv[i];
    fflush(stdout);
    execvp(python, args);
    swim_message(stderr, "swim plot: cannot start %s: %s", python, strerror(errno));
    free(script);
    return 1;
}
