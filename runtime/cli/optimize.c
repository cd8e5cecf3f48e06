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
#include "io/json.h"
#include "io/message.h"
#include "scene/keys.h"
#include "cli/report.h"


/* KEY=LO:HI into p->keys[i], lo, hi. A key is compared with the others and with the --set
 * overrides by the value it sets, whatever its spelling (shape.c0.am1 is shape.c0[2]): a value
 * varied twice, or varied and set, would leave one of them a dead variable the search "converges"
 * over. 0, or 2 after one line on stderr. */
static int parse_vary(swim_opt_problem *p, const char *spec, const swim_override *sets, int nsets)
{
    const int i = p->nkeys;
    if (i == SWIM_OPT_MAX_KEYS) {
        swim_message(stderr, "swim optimize: --vary: at most %d keys", SWIM_OPT_MAX_KEYS);
        return 2;
    }
    const char *eq = strchr(spec, '='), *colon = eq ? strchr(eq, ':') : NULL;
    char key[128], err[256];
    if (!eq || !colon || (size_t)(eq - spec) >= sizeof key) {
        swim_message(stderr, "swim optimize: --vary: expected KEY=LO:HI (e.g. parameters.A=0.5:4), got '%s'", spec);
        return 2;
    }
    snprintf(key, sizeof key, "%.*s", (int)(eq - spec), spec);
    memset(&p->keys[i], 0, sizeof p->keys[i]);
    if (swim_override_key(key, &p->keys[i], err, sizeof err) != 0) {
        swim_message(stderr, "swim optimize: --vary %s: %s", spec, err);
        return 2;
    }
    /* a value that can be varied continuously: a number of the scene (scene/keys.h) */
    const swim_scene_key *row = swim_scene_key_find(p->keys[i].table, p->keys[i].key);
    if (!row || !(row->kind == SWIM_KEY_NUMBER || row->kind == SWIM_KEY_VECTOR)) {
        swim_message(stderr, "swim optimize: --vary %s: %s (vary a number: a [parameters] value, an item of a "
                     "vector such as elastic.stiffness.am1, model.rho0, ...)", spec,
                     !row ? "not a key of a scene" : "not a number");
        return 2;
    }
    if (row->kind == SWIM_KEY_VECTOR && p->keys[i].index < 0) {
        swim_message(stderr, "swim optimize: --vary %s: %s.%s is a vector: vary one item of it (%s.%s.am1 or %s.%s[I])",
                     spec, row->table, row->key, row->table, row->key, row->table, row->key);
        return 2;
    }
    snprintf(p->keys[i].text, sizeof p->keys[i].text, "%s", key);
    char lo[64], *end;
    snprintf(lo, sizeof lo, "%.*s", (int)(colon - eq - 1), eq + 1);
    p->lo[i] = strtod(lo, &end);
    int ok = end != lo && *end == '\0' && isfinite(p->lo[i]);
    p->hi[i] = strtod(colon + 1, &end);
    ok = ok && end != colon + 1 && *end == '\0' && isfinite(p->hi[i]) && p->lo[i] < p->hi[i];
    if (!ok) {
        swim_message(stderr, "swim optimize: --vary %s: LO and HI must be finite numbers with LO < HI", spec);
        return 2;
    }
    char target[100];
    swim_override_target(&p->keys[i], target, sizeof target);
    for (int k = 0; k < i; k++)
        if (swim_override_same_target(&p->keys[k], &p->keys[i])) {
            swim_message(stderr, "swim optimize: --vary %s: varies %s, which --vary %s already varies (vary each "
                         "value once)", spec, target, p->keys[k].text);
            return 2;
        }
    for (int k = 0; k < nsets; k++)
        if (swim_override_same_target(&sets[k], &p->keys[i])) {
            swim_message(stderr, "swim optimize: --set %s: sets %s, which --vary %s varies (the set value would "
                         "never be used)", sets[k].text, target, spec);
            return 2;
        }
    p->nkeys++;
    return 0;
}

typedef struct {
    const swim_opt_problem *p;
    const char *best_path;
} json_job;

static void fill_json(FILE *f, void *ctx)
{
    const json_job *j = ctx;
    const swim_opt_problem *p = j->p;
    fprintf(f, "{\n  \"scene\": ");
    swim_json_string(f, p->scene_path);
    fprintf(f, ",\n  \"quantity\": ");
    swim_json_string(f, swim_quantity_name(p->quantity));
    fprintf(f, ",\n  \"goal\": \"%s\",\n  \"best\": {", p->maximize ? "maximize" : "minimize");
    for (int i = 0; i < p->nkeys; i++) {
        fprintf(f, "%s", i ? ", " : "");
        swim_json_string(f, p->keys[i].text);
        fprintf(f, ": ");
        swim_json_number(f, p->best_value[i]);
    }
    fprintf(f, "},\n  \"bounds\": {");
    for (int i = 0; i < p->nkeys; i++) {
        fprintf(f, "%s", i ? ", " : "");
        swim_json_string(f, p->keys[i].text);
        fprintf(f, ": [");
        swim_json_number(f, p->lo[i]);
        fprintf(f, ", ");
        swim_json_number(f, p->hi[i]);
        fprintf(f, "]");
    }
    fprintf(f, "},\n  \"value\": ");
    swim_json_number(f, p->best_q);
    fprintf(f, ",\n  \"final\": {\"x\": ");
    swim_json_number(f, p->best.x);
    fprintf(f, ", \"y\": ");
    swim_json_number(f, p->best.y);
    fprintf(f, ", \"theta\": ");
    swim_json_number(f, p->best.theta);
    fprintf(f, ", \"work\": ");
    swim_json_number(f, p->best.work);
    fprintf(f, ", \"forcing_work\": ");
    swim_json_number(f, p->best.forcing_work);
    fprintf(f, ", \"energy\": ");
    swim_json_number(f, p->best.energy);
    fprintf(f, "},\n  \"method\": \"%s\",\n  \"tolerance\": ", p->method == SWIM_OPT_BFGS ? "bfgs" : "nelder-mead");
    swim_json_number(f, p->tol);
    fprintf(f, ",\n  \"tight_check\": {\"rtol_factor\": 0.01, \"status\": \"%s\", \"value\": ",
            p->tight_status == 0 ? "completed" : "failed");
    swim_json_number(f, p->tight_status == 0 ? p->tight_q : NAN);
    fprintf(f, ", \"change\": ");
    swim_json_number(f, p->tight_status == 0 ? p->tight_change : NAN);
    fprintf(f, ", \"value_tolerance\": ");
    swim_json_number(f, p->value_tol);
    fprintf(f, ", \"holds\": %s},\n  \"search_converged\": %s,\n  \"best_start\": %d,\n  \"starts\": [",
            p->tight_status == 0 && fabs(p->tight_change) <= p->value_tol ? "true" : "false",
            p->search_converged ? "true" : "false", p->best_start + 1);
    for (int s = 0; s < p->nstarts; s++) {
        const swim_opt_start *st = &p->start[s];
        fprintf(f, "%s\n    {\"start\": {", s ? "," : "");
        for (int i = 0; i < p->nkeys; i++) {
            fprintf(f, "%s", i ? ", " : "");
            swim_json_string(f, p->keys[i].text);
            fprintf(f, ": ");
            swim_json_number(f, st->start[i]);
        }
        fprintf(f, "}, \"best\": {");
        for (int i = 0; i < p->nkeys; i++) {
            fprintf(f, "%s", i ? ", " : "");
            swim_json_string(f, p->keys[i].text);
            fprintf(f, ": ");
            swim_json_number(f, st->ok ? st->best_value[i] : NAN);
        }
        fprintf(f, "}, \"value\": ");
        swim_json_number(f, st->ok ? st->best_q : NAN);
        fprintf(f, ", \"iterations\": %d, \"evaluations\": %ld, \"converged\": %s}", st->iterations,
                st->evaluations, st->converged ? "true" : "false");
    }
    fprintf(f, "\n  ],\n  \"iterations\": %d,\n  \"evaluations\": %ld,\n  \"gradient_evaluations\": %ld,\n"
            "  \"failed_evaluations\": %ld,\n  \"seconds\": ", p->iterations, p->evaluations, p->gradients, p->failed);
    swim_json_number(f, p->seconds);
    fprintf(f, ",\n  \"converged\": %s,\n  \"interrupted\": %s,\n  \"best_scene\": ",
            p->converged ? "true" : "false", p->interrupted ? "true" : "false");
    swim_json_string(f, j->best_path);
    fprintf(f, "\n}\n");
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
    for (int i = 0; i < nvary; i++)
        if (parse_vary(&p, vary[i], sets, nsets)) return 2;
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
    if (p.method == SWIM_OPT_BFGS && !swim_opt_has_gradient(p.quantity)) {
        swim_message(stderr, "swim optimize: --method bfgs: %s has no gradient from the sensitivities (W_F is not "
                     "a state of the equations); use --method nelder-mead", qname);
        return 2;
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
    p.scene_path = pos[0];
    swim_status rst = SWIM_STATUS_STDERR;
    *text = swim_scene_read(pos[0], &p.scene_len, &rst);   /* the one read of the file */
    if (swim_status_shown(&rst, *text ? 0 : 2)) return 2;
    p.scene_text = *text;
    p.sets = sets;
    p.nsets = nsets;
    /* The scene with the keys at the middle of their ranges is read and checked now: a key the
     * scene does not have, or a quantity it cannot give, is one line and exit 2 before any run. */
    {
        swim_override ov[SWIM_OPT_MAX_SETS + SWIM_OPT_MAX_KEYS];
        int k = 0;
        for (int i = 0; i < nsets; i++) ov[k++] = sets[i];
        for (int i = 0; i < p.nkeys; i++) ov[k++] = p.keys[i];
        /* every key at LO, then at HI, then in the middle (kept): a bound the scene refuses is
         * refused now, named by its --vary, not met by a run halfway through the search */
        swim_scene s;
        for (int at = 0; at < 3; at++) {
            for (int i = 0; i < p.nkeys; i++) {
                swim_override *o = &ov[nsets + i];
                o->value = at == 0 ? p.lo[i] : at == 1 ? p.hi[i] : 0.5 * (p.lo[i] + p.hi[i]);
                snprintf(o->text, sizeof o->text, "--vary %s=%.10g:%.10g (at %s = %.10g)", p.keys[i].text, p.lo[i],
                         p.hi[i], p.keys[i].text, o->value);
            }
            swim_status st = SWIM_STATUS_STDERR;
            if (swim_status_shown(&st, swim_scene_parse_with(p.scene_text, p.scene_len, pos[0], ov, k, &s, &st))) return 2;
            if (at < 2) swim_scene_free(&s);
        }
        const int forced = s.forced || s.stroke;   /* a stroke's work is the body's positive work */
        const int stroke = s.stroke || s.stroke_count > 0;
        swim_scene_free(&s);
        if (p.method == SWIM_OPT_BFGS && stroke) {
            swim_message(stderr, "swim optimize: --method bfgs: %s is a prescribed stroke, which has no "
                         "sensitivities; use --method nelder-mead", pos[0]);
            return 2;
        }
        swim_status st = SWIM_STATUS_STDERR;
        if (p.method == SWIM_OPT_BFGS && swim_status_shown(&st, swim_opt_check_gradient(&p, ov, k, &st))) return 2;
        if ((p.quantity == SWIM_Q_DISPLACEMENT_PER_WORK || p.quantity == SWIM_Q_FORCING_WORK) && !forced) {
            swim_message(stderr, "swim optimize: %s: %s needs a [forcing] law (the work of F(t)) or a [stroke] "
                         "(the positive work of the body)", pos[0], qname);
            return 2;
        }
    }
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
        if (swim_replace_file_with(json, fill_json, &job) != 0) {
            swim_message(stderr, "swim optimize: cannot write %s: %s", json, strerror(errno));
            rc = 1;
        }
        const int holds = p.tight_status == 0 && fabs(p.tight_change) <= p.value_tol;
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
