/* swim continue: a branch of periodic orbits in the energy or a run-time scene key
 * (runtime/control/continuation.h), into DIR/branch.csv and DIR/branch.json. */
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cli/args.h"
#include "cli/commands.h"
#include "cli/run_signals.h"
#include "control/continuation.h"
#include "problem/problem.h"
#include "io/files.h"
#include "io/message.h"

typedef struct {
    const swim_branch *b;
    const char *scene, *key;
} out_job;

static void fill_csv(FILE *f, void *ctx)
{
    const out_job *j = ctx;
    swim_branch_csv(f, j->b, j->key);
}

static void fill_json(FILE *f, void *ctx)
{
    const out_job *j = ctx;
    swim_branch_json(f, j->b, j->scene, j->key);
}

/* KEY=START:STOP into o. 0 or 2 (said). */
static int parse_param(const char *v, swim_cont_options *o, char *key, size_t len)
{
    const char *eq = v ? strchr(v, '=') : NULL;
    char *end;
    if (!eq || eq == v || (size_t)(eq - v) >= len) goto bad;
    snprintf(key, len, "%.*s", (int)(eq - v), v);
    o->key = key;
    o->start = strtod(eq + 1, &end);
    if (end == eq + 1 || *end != ':') goto bad;
    const char *s2 = end + 1;
    o->stop = strtod(s2, &end);
    if (end == s2 || *end || !isfinite(o->start) || !isfinite(o->stop) || o->start == o->stop) goto bad;
    return 0;
bad:
    swim_message(stderr, "swim continue: --param: expected KEY=START:STOP with START != STOP, finite numbers (KEY "
                 "energy or a run-time scene key), e.g. energy=0.1:0.3, got '%s'", v ? v : "");
    return 2;
}

/* A branch in a scene key runs through every value from START to STOP: both ends are read into
 * the scene as an override would be (the values swim run --set refuses, such as rhof = 0 or a
 * negative stiffness, refused here before any work; the scene's bounds are intervals, so the
 * values between the ends pass too). 0 or 2 (said, naming --param). */
static int check_ends(const char *scene, const swim_override *sets, int nsets, const swim_cont_options *o,
                      const char *given)
{
    if (strcmp(o->key, "energy") == 0) return 0;
    swim_override ov[SWIM_PROBLEM_CLI_SETS + 1];
    memcpy(ov, sets, sizeof(swim_override) * (size_t)nsets);
    const double ends[2] = {o->start, o->stop};
    for (int e = 0; e < 2; e++) {
        char text[200], err[256];
        snprintf(text, sizeof text, "%s=%.17g", o->key, ends[e]);
        if (swim_override_parse(text, &ov[nsets], err, sizeof err) != 0) {
            swim_message(stderr, "swim continue: --param %s: %s", given, err);
            return 2;
        }
        snprintf(ov[nsets].text, sizeof ov[nsets].text, "--param %s (at %s = %.10g)", given, o->key, ends[e]);
        swim_scene s;
        swim_status st = SWIM_STATUS_STDERR;
        if (swim_status_shown(&st, swim_scene_load_with(scene, ov, nsets + 1, &s, &st))) return 2;
        swim_scene_free(&s);
    }
    return 0;
}

/* Each point of the branch on stderr: a branch can take minutes (and a test waits for it to begin). */
static void on_point(void *ctx, double param, double period)
{
    (void)ctx;
    swim_message(stderr, "swim continue: point at %.10g: period %.12g", param, period);
}

int swim_cmd_continue(int argc, char **argv)
{
    swim_override sets[SWIM_PROBLEM_CLI_SETS];
    int nsets = swim_args_take_sets("continue", &argc, argv, 2, sets, (int)(sizeof sets / sizeof sets[0]));
    if (nsets < 0) return 2;
    swim_opt opts[] = {
        {"param", 1, NULL, "KEY=START:STOP", "the parameter of the branch and its range: energy (a conservative "
                                             "scene's family of orbits) or a run-time scene key such as "
                                             "elastic.stiffness[4] or model.rho0 (required)"},
        {"max-points", 1, NULL, "K", "K evenly spaced parameter values from START to STOP, 2..1000 (default 11)"},
        {"guess-event", 1, NULL, "COLUMN:KIND[:COUNT]", "the section of the first orbit's guess, as for swim "
                                                        "periodic (default: the first moving coordinate's max)"},
        {"out", 1, NULL, "DIR", "the output folder of branch.csv and branch.json (default: out/NAME-continue)"},
        {"tol", 1, NULL, "R", "each orbit to max |phi_T(z) - z| <= R times the state's scale (default 1e-11)"},
        {"set", 2, NULL, "KEY=VALUE", "a scene value overridden before the scene is validated (as for swim run)"},
        {"generic", 0, NULL, NULL, "use the generic kernel of N modes, not one specialized to the scene"},
        {"quiet", 0, NULL, NULL, "no notices on stderr (kernel generation); the report stays on stdout"}};
    const int nopts = (int)(sizeof opts / sizeof opts[0]);
    const char *pos[1];
    int npos = 0;
    const int prc = swim_args_parse("continue", argc, argv, 2, opts, nopts, pos, 1, &npos);
    if (prc) return prc;
    if (npos != 1) {
        swim_message(stderr, "swim continue: expected one scene file, e.g. swim continue models/example1.toml "
                     "--param energy=0.1:0.3");
        return 2;
    }
    swim_cont_options o = {NULL, 0, 0, 11, {1e-11, 20, 1e-12, 1e-14, 0.0, "continue", "run.t_end (--set run.t_end=T)", NULL, NULL, NULL}, NULL, NULL};
    char key[128];
    if (parse_param(swim_args_get(opts, nopts, "param"), &o, key, sizeof key)) return 2;
    double points = o.points;
    if (swim_args_bounded("continue", opts, nopts, "max-points", &points) ||
        swim_args_bounded("continue", opts, nopts, "tol", &o.periodic.tol))
        return 2;
    o.points = (int)points;
    if (check_ends(pos[0], sets, nsets, &o, swim_args_get(opts, nopts, "param"))) return 2;
    /* the output folder before any work: a branch may take minutes */
    char *dir = swim_args_out_dir(swim_args_get(opts, nopts, "out"), pos[0], "continue");
    static const char *const outputs[] = {"branch.csv", "branch.json"};
    if (swim_args_out_ready("continue", dir, outputs, 2)) {
        free(dir);
        return 2;
    }
    char *csv = swim_path_join(dir, "branch.csv"), *json = swim_path_join(dir, "branch.json");
    static swim_problem m;
    char section[64];
    swim_floquet_section sec;
    swim_status st = SWIM_STATUS_STDERR;
    int rc = csv && json ? swim_status_shown(&st, swim_periodic_setup(&m, "continue", pos[0], sets, nsets,
                                                                      swim_args_get(opts, nopts, "generic") != NULL,
                                                                      swim_args_get(opts, nopts, "quiet") != NULL,
                                                                      swim_args_get(opts, nopts, "guess-event"), &sec,
                                                                      section, sizeof section, &st))
                         : (swim_message(stderr, "swim continue: out of memory"), 1);
    if (rc) {
        free(dir); free(csv); free(json);
        return rc;
    }
    o.periodic.t_max = m.s->run.t_end;
    if (!swim_args_get(opts, nopts, "quiet")) o.progress = on_point;
    /* SIGINT, SIGTERM and SIGHUP alike stop the branch; the points so far are written (run_signals.h) */
    swim_branch b;
    swim_run_signals sig;
    swim_run_stop = 0;
    m.d.interrupt = (volatile int *)&swim_run_stop;
    swim_run_signals_install(&sig);
    rc = swim_continue(&m.d, m.s, &sec, &o, &b, &st);
    swim_run_signals_restore(&sig);
    swim_status_shown(&st, rc);
    if (rc == 0) {
        out_job job = {&b, pos[0], key};
        const char *failed = swim_mkdirs(dir) != 0 ? dir : swim_replace_file_with(csv, fill_csv, &job) != 0 ? csv
                             : swim_replace_file_with(json, fill_json, &job) != 0 ? json : NULL;
        if (failed) {
            swim_message(stderr, "swim continue: cannot write %s: %s", failed, strerror(errno));
            rc = 1;
        }
        printf("%s: %d of %d points of the branch in %s = %.6g .. %.6g (the scene's orbit at %.10g); %s%s%s\n", pos[0],
               b.n, o.points, key, o.start, o.stop, b.param0, failed ? "branch.csv and branch.json NOT written"
               : csv, failed ? "" : ", ", failed ? "" : json);
        for (int i = 0; i < b.nspecial; i++)
            printf("  %s between %s = %.10g and %.10g (%s)\n", b.special[i].kind, key, b.special[i].lo,
                   b.special[i].hi, b.special[i].refined ? "refined by bisection" : b.special[i].why);
        printf("  %ld RHS evaluations, %.2f s\n", b.rhs_calls, b.seconds);
        for (int s = 0; s < 2; s++)
            if (b.ended[s][0]) {
                swim_message(stderr, "swim continue: %s: the branch ended early: %s", pos[0], b.ended[s]);
                rc = 1;
            }
    }
    swim_branch_free(&b);
    free(dir);
    free(csv);
    free(json);
    swim_problem_close(&m);
    return rc;
}
