/* swim periodic: a periodic orbit of the shape dynamics by Newton shooting
 * (runtime/control/periodic.h), into DIR/periodic.json and a report on stdout. */
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cli/args.h"
#include "cli/commands.h"
#include "cli/run_signals.h"
#include "problem/problem.h"
#include "control/periodic.h"
#include "io/files.h"
#include "io/message.h"

typedef struct {
    const swim_periodic *p;
    const swim_dynamics *d;
    const char *scene, *section;
} json_job;

static void fill(FILE *f, void *ctx)
{
    const json_job *j = ctx;
    swim_periodic_json(f, j->p, j->d, j->scene, j->section);
}

/* Each Newton iterate on stderr: the work can take minutes (and a test waits for it to begin). */
static void on_iterate(void *ctx, int it, double residual, double period)
{
    (void)ctx;
    swim_message(stderr, "swim periodic: Newton iterate %d: residual %.3g, T = %.12g", it, residual, period);
}

static void report(const swim_periodic *p, const char *scene, const char *json)
{
    if (p->stopped)
        printf("%s: STOPPED by %s: NO periodic orbit, the last Newton iterate (%d) kept (residual %.2g, not converged); "
               "%s\n", scene, swim_floquet_signal_name(p->stopped), p->iterations, p->residual, json);
    else
        printf("%s: %s periodic orbit after %d Newton iterations (residual %.2g); %s\n", scene,
               p->converged ? "a" : "NO", p->iterations, p->residual, json);
    if (isfinite(p->energy_target))
        printf("  period T = %.12g (guess %.10g from events), energy %.12g (target: the guess's %.12g; the family is "
               "by energy)\n", p->period, p->period_guess, p->energy, p->energy_target);
    else
        printf("  period T = %.12g (guess %.10g from events), energy %.12g\n", p->period, p->period_guess, p->energy);
    printf("  per period: dx = %.10g, dy = %.10g, dtheta = %.10g (body frame at the phase point)\n", p->dx, p->dy,
           p->dtheta);
    if (p->have_floquet)
        printf("  Floquet: %d tangent multipliers: %d exactly 1 (time shift, energy, symmetries), %d on the complement "
               "(max ||lambda| - 1| %.2g%s), %s; %ld RHS evaluations, %.2f s\n", p->floquet.nt, p->floquet.exact_ones,
               p->floquet.nc, p->floquet.comp_max_abs_dev, p->floquet.forced_one >= 0 ? ", one at 1 by reversibility" : "",
               p->floquet.stable ? "linearly stable" : "UNSTABLE", p->rhs_calls, p->seconds);
}

int swim_cmd_periodic(int argc, char **argv)
{
    swim_override sets[SWIM_PROBLEM_CLI_SETS];
    int nsets = swim_args_take_sets("periodic", &argc, argv, 2, sets, (int)(sizeof sets / sizeof sets[0]));
    if (nsets < 0) return 2;
    swim_opt opts[] = {
        {"guess-event", 1, NULL, "COLUMN:KIND[:COUNT]", "the section whose two successive events give the guess "
                                                        "(state and period) from a plain run: a moving coordinate or "
                                                        "its velocity, KIND max, min or zero (default: the first moving "
                                                        "coordinate's max); with COUNT the period spans COUNT events "
                                                        "after the first (1..16: bm2:max:2 for a libration beyond 90 "
                                                        "degrees, which passes bm2's maximum twice)"},
        {"out", 1, NULL, "DIR", "the output folder of periodic.json (default: out/NAME-periodic)"},
        {"tol", 1, NULL, "R", "converged when max |phi_T(z) - z| <= R times the state's scale (default 1e-11)"},
        {"max-iter", 1, NULL, "K", "at most K Newton iterations, 1..40 (default 20)"},
        {"t-max", 1, NULL, "T", "how long the guess run looks for two events (default: the scene's run.t_end)"},
        {"set", 2, NULL, "KEY=VALUE", "a scene value overridden before the scene is validated (as for swim run)"},
        {"generic", 0, NULL, NULL, "use the generic kernel of N modes, not one specialized to the scene"},
        {"quiet", 0, NULL, NULL, "no notices on stderr (kernel generation); the report stays on stdout"}};
    const int nopts = (int)(sizeof opts / sizeof opts[0]);
    const char *pos[1];
    int npos = 0;
    const int prc = swim_args_parse("periodic", argc, argv, 2, opts, nopts, pos, 1, &npos);
    if (prc) return prc;
    if (npos != 1) {
        swim_message(stderr, "swim periodic: expected one scene file, e.g. swim periodic models/example3.toml");
        return 2;
    }
    swim_periodic_options o = {1e-11, 20, 1e-12, 1e-14, 0.0, "periodic", "--t-max", NULL, NULL, NULL};
    double iters = o.max_iter;
    if (swim_args_bounded("periodic", opts, nopts, "tol", &o.tol) ||
        swim_args_bounded("periodic", opts, nopts, "max-iter", &iters) ||
        swim_args_bounded("periodic", opts, nopts, "t-max", &o.t_max))
        return 2;
    o.max_iter = (int)iters;
    const int quiet = swim_args_get(opts, nopts, "quiet") != NULL;
    /* the output folder before any work: the Newton iteration may take minutes */
    char *dir = swim_args_out_dir(swim_args_get(opts, nopts, "out"), pos[0], "periodic");
    static const char *const outputs[] = {"periodic.json"};
    if (swim_args_out_ready("periodic", dir, outputs, 1)) {
        free(dir);
        return 2;
    }
    char *json = swim_path_join(dir, "periodic.json");
    static swim_problem m;
    char section[64];
    swim_floquet_section sec;
    swim_status st = SWIM_STATUS_STDERR;
    int rc = json ? swim_status_shown(&st, swim_periodic_setup(&m, "periodic", pos[0], sets, nsets,
                                                               swim_args_get(opts, nopts, "generic") != NULL, quiet,
                                                               swim_args_get(opts, nopts, "guess-event"), &sec, section,
                                                               sizeof section, &st))
                  : (swim_message(stderr, "swim periodic: out of memory"), 1);
    if (rc) {
        free(dir);
        free(json);
        return rc;
    }
    if (o.t_max <= 0) o.t_max = m.s->run.t_end;
    else if (swim_args_steps_bounded("periodic", "t-max", o.t_max, m.s->run.output_step)) rc = 2;
    if (rc) {
        free(dir);
        free(json);
        swim_problem_close(&m);
        return rc;
    }
    if (!quiet) o.progress = on_iterate;
    /* SIGINT, SIGTERM and SIGHUP alike stop the work; what it has is written (run_signals.h) */
    swim_periodic p;
    swim_run_signals sig;
    swim_run_stop = 0;
    m.d.interrupt = (volatile int *)&swim_run_stop;
    swim_run_signals_install(&sig);
    rc = swim_periodic_solve(&m.d, &sec, &o, &p, &st);
    swim_run_signals_restore(&sig);
    swim_status_shown(&st, rc);
    if (rc == 0) {   /* converged or not, the history is kept */
        json_job job = {&p, &m.d, pos[0], section};
        const int written = swim_mkdirs(dir) == 0 && swim_replace_file_with(json, fill, &job) == 0;
        if (!written) {
            swim_message(stderr, "swim periodic: cannot write %s: %s", json, strerror(errno));
            rc = 1;
        }
        report(&p, pos[0], written ? json : "periodic.json NOT written");
        if (p.stopped) {
            swim_message(stderr, "swim periodic: %s: stopped by %s after %d Newton iterations, not converged (the "
                         "last iterate and its residual %.2g are in %s)", pos[0], swim_floquet_signal_name(p.stopped),
                         p.iterations, p.residual, rc ? "nothing: it could not be written" : json);
            rc = 1;
        } else if (!p.converged) {
            swim_message(stderr, "swim periodic: %s: Newton did not converge: %s (residual %.2g > %.2g after %d "
                         "iterations; the history is in %s)", pos[0], p.why, p.residual, o.tol, p.iterations,
                         rc ? "nothing: it could not be written" : json);
            rc = 1;
        }
    }
    swim_periodic_free(&p);
    free(dir);
    free(json);
    swim_problem_close(&m);
    return rc;
}
