/* summary.c -- summary.json as one JSON object built from the run's result (driver/summary.h). */
#include "driver/summary.h"

#include <math.h>
#include <string.h>
#include <sys/resource.h>

#include "io/json.h"
#include "kernel/coords.h"

/* Builders for the entries: each sets `bad` when out of memory, so that the summary is whole or absent. */
static void put(json_t *o, const char *key, json_t *v, int *bad) { *bad |= swim_json_set(o, key, v); }
static json_t *obj(void) { return json_object(); }
static json_t *boolean(int b) { return json_boolean(b); }
static json_t *count(long v) { return json_integer(v); }

/* Nothing run yet and nothing known (a stroke before its one call, libswim): the scene and where it is. */
static json_t *brief_summary(const swim_scene *s)
{
    json_t *o = obj();
    int bad = !o;
    if (o) {
        put(o, "scene", swim_json_str(s->path), &bad);
        put(o, "status", swim_json_str("not started"), &bad);
        put(o, "reason", swim_json_str("not run yet"), &bad);
        put(o, "rows", count(0), &bad);
    }
    if (bad) json_decref(o);
    return bad ? NULL : o;
}

static json_t *free_coordinates(const swim_scene *s)
{
    json_t *a = json_array();
    char name[24];
    for (int i = 0; a && i < s->n; i++)
        if (s->free_mask[i]) {
            swim_coord_name(i, name, sizeof name);
            if (json_array_append_new(a, swim_json_str(name)) != 0) {
                json_decref(a);
                return NULL;
            }
        }
    return a;
}

static json_t *effects(const swim_run_result *r, int *bad)
{
    json_t *o = obj();
    if (!o) return NULL;
    put(o, "elastic", boolean(r->effects.elastic), bad);
    put(o, "barrier", boolean(r->effects.barrier), bad);
    put(o, "damping", boolean(r->effects.damping), bad);
    put(o, "forcing", boolean(r->effects.forcing), bad);
    if (r->effects.energy_law) put(o, "energy_law", swim_json_str(r->effects.energy_law), bad);   /* only with a law */
    return o;
}

static json_t *kernel(const swim_run_result *r, int *bad)
{
    json_t *o = obj();
    if (!o) return NULL;
    const swim_compiled *k = r->compiled;
    put(o, "kind", swim_json_str(r->kernel_kind), bad);
    put(o, "state_dimension", count(r->state_dimension), bad);
    put(o, "cache", swim_json_str(k ? k->dir : ""), bad);
    put(o, "from_cache", boolean(k && k->from_cache), bad);
    put(o, "generate_seconds", swim_json_fmt("%.3f", k ? k->generate_seconds : 0.0), bad);
    put(o, "compile_seconds", swim_json_fmt("%.3f", k ? k->compile_seconds : 0.0), bad);
    return o;
}

/* status and reason: a run advanced part of the way (libswim) has neither completed nor failed yet */
static void status(json_t *o, const swim_run_result *r, int *bad)
{
    const int ended = r->finished || r->status;
    put(o, "status", swim_json_str(r->status ? "failed" : ended ? "completed" : r->rows > 0 ? "in progress" : "not started"),
        bad);
    if (ended) {
        put(o, "reason", swim_json_str(r->reason ? r->reason : "out of memory"), bad);
    } else {
        char so_far[96];
        if (r->rows > 0) snprintf(so_far, sizeof so_far, "advanced to t = %.6g, not yet to t_end", r->t_reached);
        else snprintf(so_far, sizeof so_far, "not run yet");
        put(o, "reason", swim_json_str(so_far), bad);
    }
}

static json_t *sensitivity(const swim_summary_context *x, int *bad)
{
    json_t *o = obj();
    if (!o) return NULL;
    put(o, "status", swim_json_str(x->sens_status ? x->sens_status : "skipped"), bad);
    put(o, "t_end", swim_json_num(x->sens_t), bad);
    put(o, "rows", count(x->sens_rows), bad);
    put(o, "t_reached", x->sens_rows > 0 ? swim_json_num(x->sens_t_last) : json_null(), bad);
    put(o, "method", swim_json_str(x->sens_method ? x->sens_method : "exact"), bad);
    put(o, "jacobians", count(x->sens_jacobians), bad);
    put(o, "rhs_evaluations", count(x->sens_rhs), bad);
    put(o, "seconds", swim_json_fmt("%.6g", x->sens_seconds), bad);
    put(o, "file", swim_json_str("sensitivity.csv"), bad);
    return o;
}

static json_t *final_state(const swim_run_result *r, int n, int *bad)
{
    json_t *o = obj();
    if (!o) return NULL;
    const double *y = r->final_state;
    put(o, "t", swim_json_num(r->t_reached), bad);
    put(o, "x", swim_json_num(y[0]), bad);
    put(o, "y", swim_json_num(y[1]), bad);
    put(o, "theta", swim_json_num(y[2]), bad);
    put(o, "c", swim_json_vec(y + 3, n), bad);
    put(o, "dc", swim_json_vec(y + 3 + n, n), bad);
    return o;
}

static json_t *residuals(const swim_run_result *r, int *bad)
{
    json_t *o = obj();
    if (!o) return NULL;
    put(o, "volume", swim_json_fmt("%.3g", r->res_volume), bad);
    put(o, "volume_rate", swim_json_fmt("%.3g", r->res_volume_rate), bad);
    put(o, "angular", swim_json_fmt("%.3g", r->res_angular), bad);
    put(o, "locks", swim_json_fmt("%.3g", r->res_locks), bad);
    return o;
}

static json_t *stiff_switch(const swim_run_result *r, const swim_scene *s, int *bad)
{
    if (!(r->switch_t >= 0)) return json_null();
    json_t *o = obj();
    if (!o) return NULL;
    put(o, "t", swim_json_num(r->switch_t), bad);
    put(o, "from", swim_json_str(s->run.integrator), bad);
    put(o, "to", swim_json_str(s->run.stiff_fallback), bad);
    return o;
}

/* the checks at every step, the shifted origin, impacts and the energy balance in the error test */
static void features(json_t *o, const swim_run_result *r, int *bad)
{
    json_t *v = obj();
    if (v) {
        put(v, "enabled", boolean(r->step_checks), bad);
        put(v, "steps", count(r->step_check_steps), bad);
        put(v, "seconds", swim_json_fmt("%.6f", r->step_check_seconds), bad);
    }
    put(o, "step_checks", v, bad);
    if ((v = obj())) {
        put(v, "enabled", boolean(r->origin_shift_enabled), bad);
        put(v, "restarts", count(r->shifts), bad);
    }
    put(o, "origin_shift", v, bad);
    if ((v = obj())) {
        put(v, "enabled", boolean(r->impacts_enabled), bad);
        put(v, "impact_depth", swim_json_fmt("%.3g", r->impact_depth), bad);
        put(v, "count", count(r->impacts), bad);
        put(v, "first_t", r->impacts ? swim_json_num(r->impact_first_t) : json_null(), bad);
        put(v, "last_t", r->impacts ? swim_json_num(r->impact_last_t) : json_null(), bad);
        put(v, "jmin_max", r->impacts ? swim_json_fmt("%.3g", r->impact_j_max) : json_null(), bad);
        put(v, "turning_min", r->impacts ? swim_json_fmt("%.3g", r->impact_reach_min) : json_null(), bad);
    }
    put(o, "impacts", v, bad);
    if ((v = obj())) {
        put(v, "enabled", boolean(r->energy_control), bad);
        put(v, "tolerance", swim_json_fmt("%.3g", r->energy_control_tol), bad);
        put(v, "rejected_steps", count(r->stats.rejected_invariant), bad);
    }
    put(o, "energy_control", v, bad);
}

static json_t *provenance(const swim_summary_context *x, const swim_compiled *kernel, int *bad)
{
    json_t *o = obj();
    if (!o) return NULL;
    put(o, "swim_version", swim_json_str(SWIM_VERSION), bad);
    put(o, "command", swim_json_str(x->command), bad);
    put(o, "scene_original", swim_json_str(x->scene_original), bad);
    json_t *sets = json_array();
    for (int i = 0; sets && i < x->nsets; i++) *bad |= json_array_append_new(sets, swim_json_str(x->sets[i].text));
    put(o, "overrides", sets, bad);
    /* the cache entry's name is the hash of the kernel's key (codegen.h); linked-in kernels have none */
    const char *slash = kernel && kernel->dir[0] ? strrchr(kernel->dir, '/') : NULL;
    put(o, "kernel_key", swim_json_str(kernel && kernel->dir[0] ? (slash ? slash + 1 : kernel->dir) : "linked in"), bad);
    return o;
}

/* Where the time went and which Jacobian was used. */
static json_t *stats(const swim_run_result *r, int *bad)
{
    json_t *o = obj();
    if (!o) return NULL;
    const swim_ode_stats *st = &r->stats;
    put(o, "steps", count(st->steps), bad);
    put(o, "rhs_evaluations", count(st->rhs_evals), bad);
    put(o, "rejected_steps", count(st->rejected), bad);
    put(o, "jacobian_evaluations", count(st->jac_evals), bad);
    put(o, "last_step", swim_json_fmt("%.6g", st->last_h), bad);
    put(o, "last_order", count(st->last_order), bad);
    put(o, "stiffness_suspected", boolean(st->stiff_suspected), bad);
    json_t *hist = json_array();
    for (int i = 0; hist && i < 13; i++) *bad |= json_array_append_new(hist, count(st->order_hist[i]));
    put(o, "order_histogram", hist, bad);
    put(o, "integrate_seconds", swim_json_fmt("%.6f", r->integrate_seconds), bad);
    put(o, "diagnostics_seconds", swim_json_fmt("%.6f", r->diagnostics_seconds), bad);
    put(o, "output_seconds", swim_json_fmt("%.6f", r->output_seconds), bad);
    put(o, "rhs_seconds", swim_json_fmt("%.6f", r->rhs_seconds), bad);
    put(o, "wall_seconds", swim_json_fmt("%.6f", r->wall_seconds), bad);
    put(o, "ns_per_rhs", swim_json_fmt("%.1f", r->rhs_calls ? 1e9 * r->rhs_seconds / r->rhs_calls : 0.0), bad);
    struct rusage ru;
    getrusage(RUSAGE_SELF, &ru);
    put(o, "max_rss_kb", count(ru.ru_maxrss), bad);
    put(o, "jacobian", swim_json_str(r->jacobian ? r->jacobian : "none"), bad);
    put(o, "exact_jacobian_calls", count(r->jacobian_calls), bad);
    put(o, "jacobian_seconds", swim_json_fmt("%.6f", r->jacobian_seconds), bad);
    return o;
}

json_t *swim_run_summary(const swim_run *run, const swim_summary_context *x)
{
    const swim_run_request *req = swim_run_get_request(run);
    const swim_scene *s = req->scene;
    const swim_run_result *r = swim_run_get_result(run);
    if (r->summary_brief) return brief_summary(s);
    json_t *o = obj();
    if (!o) return NULL;
    int bad = 0;
    put(o, "scene", swim_json_str(s->path), &bad);
    put(o, "title", swim_json_str(s->title), &bad);
    put(o, "out", swim_json_str(x->out ? x->out : ""), &bad);
    put(o, "modes", count(s->modes), &bad);
    put(o, "rho0", swim_json_num(s->rho0), &bad);
    put(o, "rhof", swim_json_num(s->rhof), &bad);
    put(o, "integrator", swim_json_str(r->used), &bad);
    put(o, "integrator_switch_t", swim_json_num(r->switch_t >= 0 ? r->switch_t : NAN), &bad);
    put(o, "rtol", swim_json_fmt("%.3g", s->run.rtol), &bad);
    put(o, "atol", swim_json_fmt("%.3g", s->run.atol), &bad);
    put(o, "step_lookahead", count(r->step_lookahead), &bad);
    put(o, "free", free_coordinates(s), &bad);
    put(o, "effects", effects(r, &bad), &bad);
    put(o, "kernel", kernel(r, &bad), &bad);
    json_t *proj = obj();
    if (proj) {
        put(proj, "enabled", boolean(r->projection), &bad);
        put(proj, "steps", count(r->projection_steps), &bad);
        put(proj, "max_change", swim_json_fmt("%.3g", r->projection_max_change), &bad);
    }
    put(o, "projection", proj, &bad);
    status(o, r, &bad);
    put(o, "t_end", swim_json_num(s->run.t_end), &bad);
    put(o, "t_reached", swim_json_num(r->t_reached), &bad);
    put(o, "rows", count(r->rows), &bad);
    if (x->sensitivity) put(o, "sensitivity", sensitivity(x, &bad), &bad);
    if (x->more) bad |= x->more(o, x->more_ctx);
    put(o, "initial_velocity_projected", boolean(r->projection_change > 0), &bad);
    put(o, "projection_change", swim_json_fmt("%.3g", r->projection_change), &bad);
    put(o, "final_state", final_state(r, s->n, &bad), &bad);
    put(o, "energy_initial", swim_json_num(r->e0), &bad);
    put(o, "energy_drift_abs", swim_json_num(r->drift_abs), &bad);
    put(o, "forcing_work", swim_json_num(r->effects.forcing ? r->forcing_work : NAN), &bad);
    put(o, "energy_drift_rel", swim_json_num(r->emax > 0 ? r->drift_abs / r->emax : 0.0), &bad);
    put(o, "max_residuals", residuals(r, &bad), &bad);
    put(o, "jmin", swim_json_num(r->jmin), &bad);
    put(o, "jmin_t", swim_json_num(r->jmin_t), &bad);
    put(o, "left_D_t", swim_json_num(r->left_t), &bad);
    put(o, "stiff_switch", stiff_switch(r, s, &bad), &bad);
    features(o, r, &bad);
    if (req->events) bad |= swim_run_events_summary(req->events, o);   /* "events", "event_stop", "periodic" */
    bad |= swim_run_kind_summary(run, o);                            /* the kind's own (a stroke's "stroke") */
    put(o, "provenance", provenance(x, r->compiled, &bad), &bad);
    put(o, "stats", stats(r, &bad), &bad);
    if (bad) {
        json_decref(o);
        return NULL;
    }
    return o;
}

int swim_run_summary_json(FILE *f, const swim_run *run, const swim_summary_context *x)
{
    json_t *o = swim_run_summary(run, x);
    if (!o) return -1;
    swim_json_write(f, o);
    json_decref(o);
    return 0;
}
