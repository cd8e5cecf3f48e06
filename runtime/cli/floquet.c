/* swim floquet: monodromy matrix and Floquet multipliers of a periodic stroke
 * (runtime/control/floquet.h), into DIR/floquet.json and a table on stdout. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cli/args.h"
#include "cli/commands.h"
#include "cli/run_signals.h"
#include "control/floquet.h"
#include "problem/problem.h"
#include "ode/ode.h"
#include "io/files.h"
#include "io/message.h"
#include "kernel/coords.h"

typedef struct {
    const swim_floquet *fl;
    const char *scene, *section;
} json_job;

static void fill(FILE *f, void *ctx)
{
    const json_job *j = ctx;
    swim_floquet_json(f, j->fl, j->scene, j->section);
}

/* The period found, on stderr: the variational equations that follow can take long (and a test
 * waits for this line). */
static void on_period(void *ctx, double t_first, double period)
{
    (void)ctx;
    swim_message(stderr, "swim floquet: period T = %.12g (events at %.10g and %.10g); now the variational equations",
                 period, t_first, t_first + period);
}

int swim_cmd_floquet(int argc, char **argv)
{
    swim_override sets[SWIM_PROBLEM_CLI_SETS];
    int nsets = swim_args_take_sets("floquet", &argc, argv, 2, sets, (int)(sizeof sets / sizeof sets[0]));
    if (nsets < 0) return 2;
    swim_opt opts[] = {
        {"out", 1, NULL, "DIR", "the output folder of floquet.json (default: out/NAME-floquet)"},
        {"event", 1, NULL, "COLUMN:KIND[:COUNT]", "the section that defines the period: two successive events of a "
                                                  "moving coordinate or its velocity, KIND max, min or zero (default: "
                                                  "the first moving coordinate's max, e.g. am1:max); with COUNT, the "
                                                  "period spans COUNT events after the first (1..16, e.g. bm2:max:2)"},
        {"t-max", 1, NULL, "T", "how long to look for the two events (default: the scene's run.t_end)"},
        {"set", 2, NULL, "KEY=VALUE", "a scene value overridden before the scene is validated (as for swim run)"},
        {"quiet", 0, NULL, NULL, "no notices on stderr (kernel generation); the table stays on stdout"},
        {"generic", 0, NULL, NULL, "use the generic kernel of N modes, not one specialized to the scene"}};
    const int nopts = (int)(sizeof opts / sizeof opts[0]);
    const char *pos[1];
    int npos = 0;
    const int prc = swim_args_parse("floquet", argc, argv, 2, opts, nopts, pos, 1, &npos);
    if (prc) return prc;
    if (npos != 1) {
        swim_message(stderr, "swim floquet: expected one scene file, e.g. swim floquet models/example3.toml");
        return 2;
    }
    const int quiet = swim_args_get(opts, nopts, "quiet") != NULL;
    double t_max = 0.0;
    if (swim_args_bounded("floquet", opts, nopts, "t-max", &t_max)) return 2;
    static swim_problem m;
    swim_status st = SWIM_STATUS_STDERR;
    int rc = swim_status_shown(&st, swim_problem_read(&m, &(swim_problem_source){.path = pos[0], .sets = sets, .nsets = nsets}, &st));
    if (rc == 0) rc = swim_status_shown(&st, swim_floquet_check(m.s, pos[0], SWIM_FLOQUET_NO_STROKE, &st));
    if (rc == 0 && t_max > 0) rc = swim_args_steps_bounded("floquet", "t-max", t_max, m.s->run.output_step);
    if (rc == 0)
        rc = swim_status_shown(&st, swim_problem_kernels(&m, "floquet", swim_args_get(opts, nopts, "generic") != NULL,
                                                         quiet ? 0 : 1, &st));
    if (rc) {
        swim_problem_close(&m);
        return rc;
    }
    if (swim_status_shown(&st, swim_floquet_check(m.s, pos[0], SWIM_FLOQUET_EVENTS, &st))) {
        swim_problem_close(&m);
        return 2;
    }
    char section[64];
    swim_floquet_section sec;
    if ((rc = swim_status_shown(&st, swim_floquet_parse_section(&m.d, "floquet", "event", swim_args_get(opts, nopts,
                                                                "event"), &sec, section, sizeof section, &st)))) {
        swim_problem_close(&m);
        return rc;
    }
    const char *out = swim_args_get(opts, nopts, "out");
    char *dir = swim_args_out_dir(out, pos[0], "floquet");
    char *json = dir ? swim_path_join(dir, "floquet.json") : NULL;
    if (!json || swim_mkdirs(dir) != 0) {
        swim_message(stderr, "swim floquet: --out: cannot create %s", dir ? dir : "(out of memory)");
        free(dir); free(json);
        swim_problem_close(&m);
        return 2;
    }
    /* SIGINT, SIGTERM and SIGHUP alike stop the work; floquet.json then says so (run_signals.h) */
    swim_floquet fl;
    swim_run_signals sig;
    swim_run_stop = 0;
    m.d.interrupt = (volatile int *)&swim_run_stop;
    swim_run_signals_install(&sig);
    rc = swim_floquet_compute(&m.d, &sec, t_max > 0 ? t_max : m.s->run.t_end, quiet ? NULL : on_period, NULL, &fl, &st);
    swim_run_signals_restore(&sig);
    swim_status_shown(&st, rc);
    if (rc == 0 && fl.stopped) {
        json_job job = {&fl, pos[0], section};
        const int written = swim_replace_file_with(json, fill, &job) == 0;
        printf("%s: STOPPED by %s before the monodromy was complete: no multipliers; %s\n", pos[0],
               swim_floquet_signal_name(fl.stopped), written ? json : "floquet.json NOT written");
        swim_message(stderr, "swim floquet: %s: stopped by %s (period %s); %s", pos[0],
                     swim_floquet_signal_name(fl.stopped), fl.period == fl.period ? "found" : "not yet found",
                     written ? json : "floquet.json could not be written");
        rc = 1;
    } else if (rc == 0) {
        json_job job = {&fl, pos[0], section};
        if (swim_replace_file_with(json, fill, &job) != 0) {
            swim_message(stderr, "swim floquet: cannot write %s", json);
            rc = 1;
        }
        swim_message(stdout, "%s: Floquet multipliers of the stroke (section %s) in %s", pos[0], section, json);
        swim_floquet_table(stdout, &fl);
        printf("  %ld RHS evaluations of the variational equations, %.3f s\n", fl.rhs_calls, fl.seconds);
        if (!fl.periodic) {   /* what was computed is kept, but it is not what was asked */
            swim_message(stderr, "swim floquet: %s: no periodic orbit: with T between two events of %s, x(T) "
                         "differs from x(0) by %.2g relative (tolerance %.0e); results kept in %s",
                         pos[0], section, fl.closure_rel, SWIM_FLOQUET_CLOSURE_TOL, json);
            rc = 1;
        }
    }
    swim_floquet_free(&fl);
    free(dir);
    free(json);
    swim_problem_close(&m);
    return rc;
}
