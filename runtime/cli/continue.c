/* swim continue: a branch of periodic orbits in the energy or a run-time scene key
 * (runtime/control/continuation.h), into DIR/branch.csv and DIR/branch.json. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cli/args.h"
#include "cli/commands.h"
#include "control/continuation.h"
#include "control/model_setup.h"
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
    if (end == s2 || *end || !(o->start == o->start) || !(o->stop == o->stop) || o->start == o->stop) goto bad;
    return 0;
bad:
    swim_message(stderr, "swim continue: --param: expected KEY=START:STOP with START != STOP (KEY energy or a run-time "
                 "scene key), e.g. energy=0.1:0.3, got '%s'", v ? v : "");
    return 2;
}

int swim_cmd_continue(int argc, char **argv)
{
    swim_override sets[SWIM_SETUP_MAX_SETS];
    int nsets = swim_args_take_sets("continue", &argc, argv, 2, sets, (int)(sizeof sets / sizeof sets[0]));
    if (nsets < 0) return 2;
    swim_opt opts[] = {
        {"param", 1, NULL, "KEY=START:STOP", "the parameter of the branch and its range: energy (a conservative "
                                             "scene's family of orbits) or a run-time scene key such as "
                                             "elastic.stiffness[4] or model.rho0 (required)"},
        {"max-points", 1, NULL, "K", "K evenly spaced parameter values from START to STOP, 2..1000 (default 11)"},
        {"guess-event", 1, NULL, "COLUMN:KIND", "the section of the first orbit's guess, as for swim periodic "
                                                "(default: the first moving coordinate's max)"},
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
    swim_cont_options o = {NULL, 0, 0, 11, {1e-11, 20, 1e-12, 1e-14, 0.0}};
    char key[128];
    if (parse_param(swim_args_get(opts, nopts, "param"), &o, key, sizeof key)) return 2;
    const char *v;
    long k;
    if ((v = swim_args_get(opts, nopts, "max-points"))) {
        if (swim_args_int("continue", "max-points", v, 2, SWIM_CONT_MAX_POINTS, &k)) return 2;
        o.points = (int)k;
    }
    if ((v = swim_args_get(opts, nopts, "tol"))) {
        if (swim_args_double("continue", "tol", v, &o.periodic.tol)) return 2;
        if (!(o.periodic.tol > 0 && o.periodic.tol < 1)) {
            swim_message(stderr, "swim continue: --tol: must be in (0, 1), got '%s'", v);
            return 2;
        }
    }
    static swim_model_setup m;
    char section[64];
    swim_floquet_section sec;
    int rc = swim_periodic_setup(&m, "continue", pos[0], sets, nsets, swim_args_get(opts, nopts, "generic") != NULL,
                                 swim_args_get(opts, nopts, "quiet") != NULL, swim_args_get(opts, nopts, "guess-event"),
                                 &sec, section, sizeof section);
    if (rc) return rc;
    o.periodic.t_max = m.s.t_end;
    const char *out = swim_args_get(opts, nopts, "out");
    char *dir = swim_args_out_dir(out, pos[0], "continue");
    char *csv = dir ? swim_path_join(dir, "branch.csv") : NULL, *json = dir ? swim_path_join(dir, "branch.json") : NULL;
    if (!csv || !json || swim_mkdirs(dir) != 0) {
        swim_message(stderr, "swim continue: --out: cannot create %s", dir ? dir : "(out of memory)");
        free(dir); free(csv); free(json);
        swim_setup_close(&m);
        return 2;
    }
    swim_branch b;
    rc = swim_continue(&m.d, &m.s, &sec, &o, &b);
    if (rc == 0) {
        out_job job = {&b, pos[0], key};
        if (swim_replace_file_with(csv, fill_csv, &job) != 0 || swim_replace_file_with(json, fill_json, &job) != 0) {
            swim_message(stderr, "swim continue: cannot write %s", dir);
            rc = 1;
        }
        printf("%s: %d of %d points of the branch in %s = %.6g .. %.6g (the scene's orbit at %.10g); %s, %s\n", pos[0],
               b.n, o.points, key, o.start, o.stop, b.param0, csv, json);
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
    swim_setup_close(&m);
    return rc;
}
