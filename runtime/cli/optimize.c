/* swim optimize: the values of scene keys, within bounds, that maximize or minimize a quantity
 * of the run (runtime/control/optimize.h): DIR/optimize.csv (one row per iteration),
 * DIR/optimize.json, DIR/best.toml and DIR/convergence.png (runtime/plot/plot_optimize.py). */
#include <errno.h>
#include <math.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/wait.h>
#include <unistd.h>

#include "cli/args.h"
#include "cli/commands.h"
#include "cli/run_signals.h"
#include "problem/problem.h"
#include "control/optimize.h"
#include "io/files.h"
#include "io/message.h"
#include "scene/keys.h"
#include "cli/report.h"


typedef struct {
    const swim_opt_problem *p;
    const char *best_path;
} json_job;

static void write_json(FILE *f, void *ctx)
{
    const json_job *j = ctx;
    swim_opt_json(f, j->p, j->best_path);
}

/* runtime/plot/plot_optimize.py DIR: convergence.png. 0, or nonzero (said on stderr). */
static int plot(const char *dir)
{
    swim_status missing = {0};
    const char *share = swim_share_dir(&missing), *python = swim_python();
    if (swim_status_shown(&missing, !share)) return 1;
    char *script = swim_strprintf("%s/runtime/plot/plot_optimize.py", share);
    if (!script) return 1;
    fflush(stdout);
    pid_t pid = fork();
    if (pid == 0) {
        execlp(python, python, script, dir, (char *)NULL);
        _exit(127);
    }
    int st = 0;
    if (pid < 0 || waitpid(pid, &st, 0) < 0 || !WIFEXITED(st) || WEXITSTATUS(st) != 0) {
        swim_message(stderr, "swim optimize: the convergence plot failed (%s); the results are written", script);
        free(script);
        return 1;
    }
    free(script);
    return 0;
}

/* The command, with the scene file's text kept in *text (read once; the caller frees it). */
static int optimize_command(int argc, char **argv, char **text)
{
    static swim_override sets[SWIM_OPT_MAX_SETS];
    static swim_opt_problem p;
    memset(&p, 0, sizeof p);
    int nsets = swim_args_take_sets("optimize", &argc, argv, 2, sets, (int)(sizeof sets / sizeof sets[0]));
    if (nsets < 0) return 2;
    const char *vary[SWIM_OPT_MAX_KEYS + 1];
    int nvary = swim_args_take_all("optimize", &argc, argv, 2, "vary", vary, SWIM_OPT_MAX_KEYS + 1);
    if (nvary < 0) return 2;
    swim_opt opts[] = {
        {"vary", 2, NULL, "KEY=LO:HI", "a run-time scene key searched within [LO, HI] (at least one; keys: "
                                       "models/README.md, e.g. parameters.A=0.5:4)"},
        {"maximize", 1, NULL, "QUANTITY", "the quantity at t_end to make largest: x, y, theta, displacement, work, "
                                          "forcing_work, displacement_per_work or energy"},
        {"minimize", 1, NULL, "QUANTITY", "the quantity to make smallest (one of --maximize and --minimize)"},
        {"out", 1, NULL, "DIR", "the output folder (default: out/NAME-optimize)"},
        {"method", 1, NULL, "nelder-mead|bfgs", "Nelder-Mead without gradients (default), or BFGS with the gradient "
                                                "from the exact sensitivities (x, y, theta, displacement, work, energy)"},
        {"starts", 1, NULL, "K", "K local searches, 1..64: from the middle of the box, then from space-filling "
                                 "(Halton) points; the best of all is kept (default 1)"},
        {"max-iter", 1, NULL, "K", "at most K iterations per start, 1..100000 (default 60)"},
        {"tol", 1, NULL, "S", "a search stops when the simplex is smaller than S in the transformed variables "
                              "(Nelder-Mead) or its gradient there is (BFGS); the best value must also hold to "
                              "S max(1, |value|) at 100x tighter rtol and atol (default 1e-3)"},
        {"set", 2, NULL, "KEY=VALUE", "a scene value overridden before the scene is validated (as for swim run)"},
        {"quiet", 0, NULL, NULL, "no iteration lines on stderr; the result line stays on stdout"}};
    const int nopts = (int)(sizeof opts / sizeof opts[0]);
    const char *pos[1];
    int npos = 0;
    const int prc = swim_args_parse("optimize", argc, argv, 2, opts, nopts, pos, 1, &npos);
    if (prc) return prc;
    if (npos != 1) {
        swim_message(stderr, "swim optimize: expected one scene file, e.g. swim optimize models/selfpropelled.toml "
                     "--vary parameters.A=0.5:4 --maximize displacement_per_work");
        return 2;
    }
    if (nvary == 0) {
        swim_message(stderr, "swim optimize: --vary KEY=LO:HI is required (at least one key)");
        return 2;
    }
    p.scene_path = pos[0];
    p.sets = sets;
    p.nsets = nsets;
    swim_status vst = SWIM_STATUS_STDERR;
    for (int i = 0; i < nvary; i++)
        if (swim_status_shown(&vst, swim_opt_vary(&p, vary[i], &vst))) return 2;
    const char *qmax = swim_args_get(opts, nopts, "maximize"), *qmin = swim_args_get(opts, nopts, "minimize");
    if (!!qmax == !!qmin) {
        swim_message(stderr, "swim optimize: give exactly one of --maximize QUANTITY or --minimize QUANTITY (%s)",
                     swim_quantity_list());
        return 2;
    }
    const char *qname = qmax ? qmax : qmin;
    const char *v;
    if ((p.quantity = swim_quantity_index(qname)) < 0) {
        swim_message(stderr, "swim optimize: --%s: unknown quantity '%s' (%s)", qmax ? "maximize" : "minimize",
                     qname, swim_quantity_list());
        return 2;
    }
    p.maximize = qmax != NULL;
    p.method = SWIM_OPT_NELDER_MEAD;
    p.starts = 1;
    if ((v = swim_args_get(opts, nopts, "method"))) {
        if (strcmp(v, "bfgs") == 0) p.method = SWIM_OPT_BFGS;
        else if (strcmp(v, "nelder-mead") != 0) {
            swim_message(stderr, "swim optimize: --method: expected nelder-mead or bfgs, got '%s'", v);
            return 2;
        }
    }
    double starts = p.starts, max_iter = 60;
    p.tol = 1e-3;
    if (swim_args_bounded("optimize", opts, nopts, "starts", &starts) ||
        swim_args_bounded("optimize", opts, nopts, "max-iter", &max_iter) ||
        swim_args_bounded("optimize", opts, nopts, "tol", &p.tol))
        return 2;
    p.starts = (int)starts;
    p.max_iter = (int)max_iter;
    p.quiet = swim_args_get(opts, nopts, "quiet") != NULL;
    swim_status rst = SWIM_STATUS_STDERR;
    *text = swim_scene_read(pos[0], &p.scene_len, &rst);   /* the one read of the file */
    if (swim_status_shown(&rst, *text ? 0 : 2)) return 2;
    p.scene_text = *text;
    /* a key the scene does not have, or a quantity it cannot give, is one line and exit 2 before any run */
    swim_status cst = SWIM_STATUS_STDERR;
    if (swim_status_shown(&cst, swim_opt_check(&p, &cst))) return 2;
    const char *out = swim_args_get(opts, nopts, "out");
    char *dir = swim_args_out_dir(out, pos[0], "optimize");
    char *csv = dir ? swim_path_join(dir, "optimize.csv") : NULL, *best = dir ? swim_path_join(dir, "best.toml") : NULL;
    char *json = dir ? swim_path_join(dir, "optimize.json") : NULL;
    if (!csv || !best || !json || swim_mkdirs(dir) != 0 || !(p.log_csv = fopen(csv, "w"))) {
        swim_message(stderr, "swim optimize: --out: cannot write into %s: %s", dir ? dir : "(out of memory)",
                     strerror(errno));
        free(dir); free(csv); free(best); free(json);
        return 2;
    }
    /* SIGINT, SIGTERM and SIGHUP alike end the search with what it has (run_signals.h) */
    swim_run_signals sig;
    swim_run_stop = 0;
    p.interrupt = (volatile int *)&swim_run_stop;
    swim_run_signals_install(&sig);
    swim_status st = SWIM_STATUS_STDERR;   /* the iteration lines as they come, a failure after */
    p.status = &st;
    int rc = swim_opt_run(&p);
    swim_run_signals_restore(&sig);
    swim_status_print(&st, stderr);
    if (fclose(p.log_csv) != 0) rc = 1;
    p.log_csv = NULL;
    if (rc != 0) {
        swim_message(stderr, "swim optimize: no run succeeded (%ld evaluations): nothing to report", p.evaluations);
    } else {
        const int best_written = swim_opt_write_scene(&p, best) == 0;
        if (!best_written) {
            swim_message(stderr, "swim optimize: cannot write %s: %s", best, strerror(errno));
            rc = 1;
        }
        json_job job = {&p, best};
        if (swim_replace_file_with(json, write_json, &job) != 0) {
            swim_message(stderr, "swim optimize: cannot write %s: %s", json, strerror(errno));
            rc = 1;
        }
        const int holds = swim_opt_holds(&p);
        swim_message(stdout, "%s: %s %s = %.10g after %d iterations, %ld runs (%ld failed; %s, %d start%s, best from "
                     "start %d), %.1f s%s", pos[0], p.maximize ? "largest" : "smallest", qname, p.best_q, p.iterations,
                     p.evaluations, p.failed, p.method == SWIM_OPT_BFGS ? "BFGS" : "Nelder-Mead", p.nstarts,
                     p.nstarts == 1 ? "" : "s", p.best_start + 1, p.seconds,
                     p.interrupted ? (swim_run_stop == SIGHUP ? " -- INTERRUPTED (SIGHUP): the best so far, not converged"
                                      : swim_run_stop == SIGTERM ? " -- INTERRUPTED (SIGTERM): the best so far, not converged"
                                                                 : " -- INTERRUPTED: the best so far, not converged")
                     : !p.search_converged ? " -- NOT converged (raise --max-iter)"
                     : !holds ? " -- NOT converged: the value does not hold at tighter tolerances" : "");
        if (!p.interrupted) {
            if (p.tight_status == 0)
                swim_message(stdout, "  at rtol/100, atol/100: %s = %.10g (change %.3g; tolerance %.3g: %s)", qname,
                             p.tight_q, p.tight_change, p.value_tol, holds ? "holds" : "does NOT hold");
            else
                swim_message(stdout, "  at rtol/100, atol/100 the best point's run failed: its value is not confirmed");
        }
        for (int i = 0; i < p.nkeys; i++)
            swim_message(stdout, "  %s = %.10g  (range %g .. %g)", p.keys[i].text, p.best_value[i], p.lo[i], p.hi[i]);
        swim_message(stdout, "  best scene %s; log %s", best_written ? best : "NOT written", csv);
        plot(dir);   /* a missing figure is said, the results stand */
        if (rc == 0 && !p.converged) rc = 1;   /* written, but not the optimum asked for */
    }
    free(dir); free(csv); free(best); free(json);
    return rc;
}

int swim_cmd_optimize(int argc, char **argv)
{
    char *text = NULL;
    const int rc = optimize_command(argc, argv, &text);
    free(text);
    return rc;
}
