/* sweep_args.c -- the command line of `swim sweep` (and of bin/swim-mpi sweep) into a sweep
 * plan (sweep/sweep.h). */
#include "cli/sweep_args.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "cli/args.h"
#include "cli/run_settings.h"
#include "io/message.h"
#include "ode/ode.h"
#include "scene/keys.h"
#include "sweep/family_hdf5.h"

/* One fixed override; option names the run option it came from (t-end, ...), NULL for a --set. */
static int add_set(sweep_plan *p, const char *text, const char *option)
{
    char err[256];
    if (p->nsets >= SWEEP_MAX_SETS) {
        swim_message(stderr, "swim %s: more than %d overrides", p->cmd, SWEEP_MAX_SETS);
        return 2;
    }
    if (swim_override_parse(text, &p->sets[p->nsets], err, sizeof err) != 0) {
        swim_message(stderr, "swim %s: --set: %s", p->cmd, err);
        return 2;
    }
    p->set_option[p->nsets++] = option;
    return 0;
}

/* How fixed override i was given, for messages: "--set KEY=VALUE" or "--t-end VALUE". */
static void set_label(const sweep_plan *p, int i, char *buf, size_t len)
{
    if (p->set_option[i]) snprintf(buf, len, "--%s %s", p->set_option[i], strchr(p->sets[i].text, '=') + 1);
    else snprintf(buf, len, "--set %s", p->sets[i].text);
}

/* Each value is varied or set once, whatever the spelling of its key (shape.c0.am1 and
 * shape.c0[2] are one value): a second --vary of it, or a --set of a varied value, would be
 * dead (one of them never reaches the members, yet members.csv would show its values), and two
 * --set of it with different values are ambiguous. 0, or 2 after one line. */
static int check_distinct_keys(const sweep_plan *p)
{
    char target[100], a[200], b[200];
    for (int i = 0; i < p->nvary; i++) {
        swim_override_target(&p->vary[i].tmpl, target, sizeof target);
        for (int j = 0; j < i; j++)
            if (swim_override_same_target(&p->vary[j].tmpl, &p->vary[i].tmpl)) {
                swim_message(stderr, "swim %s: --vary %s: varies %s, which --vary %s already varies (vary each "
                             "value once)", p->cmd, p->vary[i].key, target, p->vary[j].key);
                return 2;
            }
        for (int j = 0; j < p->nsets; j++)
            if (swim_override_same_target(&p->sets[j], &p->vary[i].tmpl)) {
                set_label(p, j, a, sizeof a);
                swim_message(stderr, "swim %s: %s: sets %s, which --vary %s varies (the set value would never be "
                             "used)", p->cmd, a, target, p->vary[i].key);
                return 2;
            }
    }
    int earlier, j = swim_override_conflict(p->sets, p->nsets, &earlier);
    if (j >= 0) {
        swim_override_target(&p->sets[j], target, sizeof target);
        set_label(p, j, a, sizeof a);
        set_label(p, earlier, b, sizeof b);
        swim_message(stderr, "swim %s: %s: sets %s, which %s already sets to another value (give each value "
                     "once)", p->cmd, a, target, b);
        return 2;
    }
    return 0;
}

int sweep_parse(sweep_plan *p, const char *cmd, int argc, char **argv, int first)
{
    memset(p, 0, sizeof *p);
    p->lock_fd = -1;
    snprintf(p->cmd, sizeof p->cmd, "%s", cmd);
    const char *varies[SWEEP_MAX_VARY + 1], *sets[SWEEP_MAX_SETS];
    int nv = swim_args_take_all(cmd, &argc, argv, first, "vary", varies, SWEEP_MAX_VARY);
    if (nv < 0) return 2;
    int ns = swim_args_take_all(cmd, &argc, argv, first, "set", sets, SWEEP_MAX_SETS - 5);   /* 5: --t-end, --rtol, ... */
    if (ns < 0) return 2;
    swim_opt opts[40] = {
        {"out", 1, NULL, "DIR", "the sweep's folder (required): sweep.json, members.csv, members/ID/"},
        {"vary", 2, NULL, "KEY=SPEC", "a varied scene key; SPEC START:STOP:COUNT, log:START:STOP:COUNT or V1,V2,...; "
                                      "the members are the grid of every --vary (the last varies fastest)"},
        {"zip", 0, NULL, NULL, "pair the --vary lists (same length) instead of taking their grid"},
        {"jobs", 1, NULL, "J", "members run at once, 1..4096 (default: the machine's cores)"},
        {"keep", 1, NULL, "summaries|trajectories", "what a member keeps besides its summary (default summaries)"},
        {"format", 1, NULL, "csv|hdf5", "hdf5: also DIR/family.h5, the family in one file for h5py (default csv)"},
        {"progress", 1, NULL, "S", "when stderr is not a terminal: a progress line every S seconds (default 10) and at "
                                   "every tenth of the members; on a terminal one line is redrawn"},
        {"set", 2, NULL, "KEY=VALUE", "a scene value every member gets (as for swim run)"},
        {"t-end", 1, NULL, "T", "final time of every member (run.t_end)"},
        {"output-step", 1, NULL, "H", "time between output rows (run.output_step)"},
        {"rtol", 1, NULL, "R", "relative tolerance (run.rtol)"},
        {"atol", 1, NULL, "A", "absolute tolerance (run.atol)"},
        {"integrator", 1, NULL, "NAME", swim_run_settings_integrator_help()},
        {"generic", 0, NULL, NULL, "use the generic kernel of N modes, not ones specialized to the scene"},
        {"no-projection", 0, NULL, NULL, "members without the projection on the constraints (run.projection = false)"},
        {"quiet", 0, NULL, NULL, "no progress lines and no notices; the final report stays on stdout"}};
    int nopts = 16;
    swim_run_settings_key_options(opts, &nopts, 40);   /* --step-lookahead, ... (scene/keys.h) */
    const char *pos[1];
    int npos = 0;
    const int prc = swim_args_parse(cmd, argc, argv, first, opts, nopts, pos, 1, &npos);
    if (prc) return prc;
    if (npos != 1) {
        swim_message(stderr, "swim %s: expected one scene file, e.g. swim %s models/example1.toml --out out/fam "
                     "--vary shape.dc0.bm2=-1:1:11", cmd, cmd);
        return 2;
    }
    if (strlen(pos[0]) >= sizeof p->scene) {
        swim_message(stderr, "swim %s: the scene path has %zu characters, more than the system's limit of %zu",
                     cmd, strlen(pos[0]), sizeof p->scene - 1);
        return 2;
    }
    snprintf(p->scene, sizeof p->scene, "%s", pos[0]);
    const char *v = swim_args_get(opts, nopts, "out");
    if (!v || !*v) {
        swim_message(stderr, "swim %s: --out DIR is required (the sweep's directory)", cmd);
        return 2;
    }
    if (strlen(v) >= sizeof p->dir - 32) {   /* room for DIR/members/NNNNN/summary.json */
        swim_message(stderr, "swim %s: --out: the path has %zu characters, more than the %zu a sweep folder may have "
                     "(the system's limit of %d less its members' names)", cmd, strlen(v), sizeof p->dir - 33, SWIM_SWEEP_PATH);
        return 2;
    }
    snprintf(p->dir, sizeof p->dir, "%s", v);
    if (nv == 0) {
        swim_message(stderr, "swim %s: at least one --vary KEY=SPEC is required", cmd);
        return 2;
    }
    p->nvary = nv;
    for (int i = 0; i < nv; i++) {
        sweep_vary *w = &p->vary[i];
        const char *eq = strchr(varies[i], '=');
        char err[300];
        if (!eq || eq == varies[i] || (size_t)(eq - varies[i]) >= sizeof w->key) {
            swim_message(stderr, "swim %s: --vary: expected KEY=SPEC, got '%s'", cmd, varies[i]);
            return 2;
        }
        snprintf(w->key, sizeof w->key, "%.*s", (int)(eq - varies[i]), varies[i]);
        w->spec = eq + 1;   /* argv outlives the plan; a list of any length is kept whole */
        if (swim_override_key(w->key, &w->tmpl, err, sizeof err) != 0) {
            swim_message(stderr, "swim %s: --vary %s: %s", cmd, varies[i], err);
            return 2;
        }
        if (sweep_parse_spec(w->spec, &w->values, &w->count, err, sizeof err) != 0) {
            swim_message(stderr, "swim %s: --vary %s: %s", cmd, w->key, err);
            return 2;
        }
    }
    p->zip = swim_args_get(opts, nopts, "zip") != NULL;
    p->members = p->zip ? p->vary[0].count : 1;
    for (int i = 0; i < nv; i++) {
        if (p->zip && p->vary[i].count != p->members) {
            swim_message(stderr, "swim %s: --zip: --vary %s has %ld values but --vary %s has %ld (zip pairs them, "
                         "so the counts must agree)", cmd, p->vary[0].key, p->vary[0].count, p->vary[i].key, p->vary[i].count);
            return 2;
        }
        if (!p->zip) {
            if (p->members > SWEEP_MAX_MEMBERS / p->vary[i].count) {
                swim_message(stderr, "swim %s: the grid has more than %ld members", cmd, SWEEP_MAX_MEMBERS);
                return 2;
            }
            p->members *= p->vary[i].count;
        }
    }
    long cores = sysconf(_SC_NPROCESSORS_ONLN);
    p->jobs = cores > 0 ? cores : 1;
    double jobs = (double)p->jobs;
    if (swim_args_bounded(cmd, opts, nopts, "jobs", &jobs)) return 2;
    p->jobs = (long)jobs;
    if ((v = swim_args_get(opts, nopts, "keep"))) {
        if (strcmp(v, "trajectories") == 0) p->keep_trajectories = 1;
        else if (strcmp(v, "summaries") != 0) {
            swim_message(stderr, "swim %s: --keep: expected 'summaries' (default) or 'trajectories', got '%s'", cmd, v);
            return 2;
        }
    }
    /* Run options that are scene values (scene/keys.h: the rows with an option, but the
     * integrator, which the members get from the plan) become overrides, so every member
     * validates them. */
    int nkeys;
    const swim_scene_key *keys = swim_scene_keys(&nkeys);
    for (int i = 0; i < nkeys; i++)
        if (keys[i].option && keys[i].kind != SWIM_KEY_TEXT && (v = swim_args_get(opts, nopts, keys[i].option))) {
            char text[200];
            snprintf(text, sizeof text, "%s.%s=%s", keys[i].table, keys[i].key, v);
            if (add_set(p, text, keys[i].option)) return 2;
        }
    for (int i = 0; i < ns; i++)
        if (add_set(p, sets[i], NULL)) return 2;
    if (check_distinct_keys(p)) return 2;
    if ((v = swim_args_get(opts, nopts, "integrator"))) {
        int known = 0;
        for (const char *const *m = swim_ode_methods(); *m; m++) known |= strcmp(*m, v) == 0;
        if (!known || strlen(v) >= sizeof p->integrator) {
            swim_message(stderr, "swim %s: --integrator: unknown integrator '%s'", cmd, v);
            return 2;
        }
        snprintf(p->integrator, sizeof p->integrator, "%s", v);
    }
    p->generic = swim_args_get(opts, nopts, "generic") != NULL;
    p->no_projection = swim_args_get(opts, nopts, "no-projection") != NULL;
    p->quiet = swim_args_get(opts, nopts, "quiet") != NULL;
    if ((v = swim_args_get(opts, nopts, "format"))) {
        char why[512];
        if (strcmp(v, "hdf5") == 0) {
            p->format_hdf5 = 1;
            if (sweep_family_hdf5_ready(why, sizeof why) != 0) {
                swim_message(stderr, "swim %s: --format hdf5: %s", cmd, why);
                return 2;
            }
        } else if (strcmp(v, "csv") != 0) {
            swim_message(stderr, "swim %s: --format: expected 'csv' (default) or 'hdf5', got '%s'", cmd, v);
            return 2;
        }
    }
    p->progress_every = 10.0;
    if (swim_args_bounded(cmd, opts, nopts, "progress", &p->progress_every)) return 2;
    ssize_t len = readlink("/proc/self/exe", p->exe, sizeof p->exe - 1);
    if (len <= 0) {
        swim_message(stderr, "swim %s: cannot find the program itself (/proc/self/exe)", cmd);
        return 2;
    }
    p->exe[len] = '\0';
    p->in_process = 1;
    return 0;
}

