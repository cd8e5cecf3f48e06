/* bin/swim: command-line front end. `swim --help` lists the commands with an example each. */
#include <stdio.h>
#include <string.h>

#include "cli/args.h"
#include "cli/commands.h"
#include "cli/run_signals.h"
#include "io/message.h"
#include "cli/report.h"
#include "kernel/swim_kernel.h"
#include "lib/swim.h"

typedef struct {
    const char *name;
    int (*run)(int argc, char **argv);
    const char *summary;
    const char *example;
} command;

static const command commands[] = {
    {"inspect", swim_cmd_inspect,
     "mass matrices, reduced mass K and Christoffel symbol at one shape, as JSON\n"
     "           --modes N --shape a1,b1,... [--velocity V1,...] [--rho0 RHO] [--rhof RHO] [--full]\n"
     "           [--energy LAW [--param NAME=VALUE ...]]",
     "swim inspect --modes 1 --shape 1,0,0.2,0 --velocity 0,0,0.1,0.3 --full"},
    {"run", swim_cmd_run,
     "simulate a scene: DIR/trajectory.csv, summary.json, scene.toml (as run; the file as given: scene.original.toml)\n"
     "           [--out DIR] [--t-end T] [--output-step DT] [--rtol R] [--atol A]\n"
     "           [--integrator NAME] [--generic] [--no-projection] [--step-lookahead P]\n"
     "           [--trace-steps FILE] [--event COLUMN:KIND[:stop]]... [--snapshots] [--quiet]\n"
     "           [--set KEY=VALUE ...] [--summary-only]\n"
     "           [--sensitivity KEY[,KEY...]] [--sensitivity-steps all|state]\n"
     "           [--sensitivity-method exact|differences] [--sensitivity-initial]\n"
     "           [--lyapunov [--lyapunov-interval T]] (the largest Lyapunov exponent and its verdict)\n"
     "           a scene with a [stroke] table is a prescribed stroke: (3.21) only (models/stroke_loop.toml),\n"
     "           without --sensitivity (a prescribed shape has no free dynamics to differentiate)",
     "swim run models/example3.toml --out out/example3 --rtol=1e-10"},
    {"flow", swim_cmd_flow,
     "body, density rho0/J and fluid velocity at chosen times of a run, as JSON\n"
     "           [--times t1,t2,...|--frames K] [--out FILE|-] (default: 10 frames, DIR/snapshots.json)",
     "swim flow out/example3 --times 3.17,3.95,6.07,9.5 --out fig48.json"},
    {"animate", swim_cmd_animate,
     "DIR/animation.mp4: body, flow, path and energy over time (ffmpeg)\n"
     "           [--fps F] [--duration S] [--out FILE]",
     "swim animate out/example3 --fps 25 --duration 15"},
    {"sweep", swim_cmd_sweep,
     "a family of runs: DIR/members.csv, sweep.json, members/ID/summary.json\n"
     "           --out DIR --vary KEY=SPEC [--vary ...] [--zip] [--jobs J] [--keep trajectories]\n"
     "           [--format csv|hdf5] [--progress S] [--set KEY=VALUE ...] [run options]\n"
     "           SPEC: START:STOP:COUNT, log:START:STOP:COUNT, V1,V2,...",
     "swim sweep models/example1.toml --out out/fig42 --vary shape.dc0.bm2=-0.7,0.7 --keep trajectories"},
    {"floquet", swim_cmd_floquet,
     "monodromy matrix and Floquet multipliers of a periodic stroke: DIR/floquet.json, a table\n"
     "           [--event COLUMN:KIND[:COUNT] (default: first moving coordinate, max)] [--t-max T] [--out DIR]\n"
     "           [--set KEY=VALUE ...] [--generic] [--quiet]",
     "swim floquet models/example3.toml --event am1:max --out out/example3-floquet"},
    {"periodic", swim_cmd_periodic,
     "a periodic orbit of the shape dynamics by Newton shooting: DIR/periodic.json (period,\n"
     "           phase point, displacement per period, Newton history, Floquet multipliers)\n"
     "           [--guess-event COLUMN:KIND[:COUNT]] [--out DIR] [--tol R] [--max-iter K] [--t-max T] [--set KEY=VALUE ...]\n"
     "           [--generic] [--quiet]",
     "swim periodic models/example1.toml --guess-event am1:max --out out/example1-periodic"},
    {"continue", swim_cmd_continue,
     "a branch of periodic orbits in the energy or a run-time scene key: DIR/branch.csv, branch.json\n"
     "           --param KEY=START:STOP [--max-points K] [--guess-event COLUMN:KIND[:COUNT]] [--out DIR] [--tol R]\n"
     "           [--set KEY=VALUE ...] [--generic] [--quiet]",
     "swim continue models/example1.toml --param energy=0.05:0.3 --max-points 6"},
    {"optimize", swim_cmd_optimize,
     "best values of scene keys within bounds for a quantity of the run (Nelder-Mead or BFGS):\n"
     "           DIR/optimize.csv, optimize.json, best.toml, convergence.png\n"
     "           --vary KEY=LO:HI [--vary ...] (--maximize|--minimize) QUANTITY [--out DIR]\n"
     "           [--method nelder-mead|bfgs] [--starts K] [--max-iter K] [--tol S] [--set KEY=VALUE ...]\n"
     "           [--quiet]; QUANTITY: x, y, theta,\n"
     "           displacement, work, forcing_work, displacement_per_work, energy (at t_end)",
     "swim optimize models/selfpropelled.toml --set run.t_end=30 --vary parameters.A=0.5:4 --maximize displacement_per_work"},
    {"cache", swim_cmd_cache,
     "the kernel cache: where it is, what it holds, removing entries\n"
     "           path | list | clean [--older-than D (days, or with s, m, h, d; default: every entry)]",
     "swim cache clean --older-than 30d"},
    {"export", swim_cmd_export,
     "a self-contained C source tree for one scene: `make -C DIR` builds DIR/simulate (C, GSL, LAPACK;\n"
     "           no Python), which writes what swim run writes, digit for digit\n"
     "           --out DIR [--set KEY=VALUE ...] [--quiet]; DIR/simulate [--out OUT] [--t-end T] [--output-step H]\n"
     "           [--rtol R] [--atol A] [--event COL:KIND ...] [--set ...]",
     "swim export models/example3.toml --out out/example3-src && make -C out/example3-src"},
    {"plot", swim_cmd_plot, "PNG figures of a run directory, or of a sweep directory (matplotlib)\n"
     "           [--mark T1,T2,...] [--events all|COLUMN:KIND,...] [--only NAME ...]\n"
     "           marks: the times given and the events selected; without either, the first 12 event times",
     "swim plot out/fig48 --mark 3.166805989,3.951942753,6.074806130,9.499689605"},
};

static void usage(FILE *f)
{
    int modes[64], count = swim_kernel_list(modes, 64);
    fprintf(f, "usage: swim COMMAND [options]   (swim --version: the version)\n\ncommands:\n");
    for (size_t i = 0; i < sizeof commands / sizeof commands[0]; i++)
        fprintf(f, "  %-8s %s\n           e.g. %s\n", commands[i].name, commands[i].summary,
                commands[i].example);
    fprintf(f, "\nkernels linked in: N =");
    for (int i = 0; i < count && i < 64; i++) fprintf(f, " %d", modes[i]);
    fprintf(f, "; any other N up to %d is generated and cached on first use\n", SWIM_KERNEL_MAX_MODES);
    fprintf(f, "options take `--name value` or `--name=value`.\n");
}

int main(int argc, char **argv)
{
    swim_kernel_hooks_install();   /* the program owns its signals and what a kernel build prints */
    if (argc < 2) {
        usage(stderr);
        return 2;
    }
    if (strcmp(argv[1], "--help") == 0 || strcmp(argv[1], "-h") == 0 || strcmp(argv[1], "help") == 0) {
        usage(stdout);
        return swim_stdout_finish("--help", 0);
    }
    if (strcmp(argv[1], "--version") == 0 || strcmp(argv[1], "version") == 0) {
        printf("swim %s\n", swim_version());   /* VERSION's number, as libswim and swim.pc report it */
        return swim_stdout_finish("--version", 0);
    }
    for (size_t i = 0; i < sizeof commands / sizeof commands[0]; i++)
        if (strcmp(argv[1], commands[i].name) == 0) {
            for (int a = 2; a < argc; a++)
                if (strcmp(argv[a], "--help") == 0 || strcmp(argv[a], "-h") == 0) {
                    /* the synopsis here; the options from the command's own parser table */
                    printf("swim %s: %s\n  e.g. %s\n\n", commands[i].name, commands[i].summary, commands[i].example);
                    const int rc = commands[i].run(argc, argv);
                    return swim_stdout_finish(commands[i].name, rc == SWIM_ARGS_HELP ? 0 : rc);
                }
            const int rc = commands[i].run(argc, argv);
            /* A report lost at the flush is a failure of every command that prints one; swim
             * sweep checks its own (its report and its exit status are made together). */
            return strcmp(commands[i].name, "sweep") == 0 ? rc : swim_stdout_finish(commands[i].name, rc);
        }
    swim_message(stderr, "swim: unknown command '%s' (see swim --help)", argv[1]);
    return 2;
}
