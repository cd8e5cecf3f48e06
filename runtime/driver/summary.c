#include "driver/summary.h"

#include <math.h>
#include <string.h>
#include <sys/resource.h>

#include "driver/run_internal.h"
#include "io/json.h"
#include "kernel/coords.h"

void swim_run_summary_json(FILE *f, const swim_run *c, const swim_summary_context *x)
{
    if (c->stroke && !c->res.is_stroke) {   /* a stroke not run yet (libswim) */
        fprintf(f, "{\n  \"scene\": ");
        swim_json_string(f, c->req.scene->path);
        fprintf(f, ",\n  \"status\": \"not started\",\n  \"reason\": \"not run yet\",\n  \"rows\": 0\n}\n");
        return;
    }
    if (c->stroke) {
        swim_stroke_summary_json(f, c->stroke, x);
        return;
    }
    const swim_scene *s = c->s;
    const run_report *r = &c->r;
    const swim_ode_stats *st = &c->total;
    const swim_dynamics *d = &c->d;
    const swim_compiled *sp = c->spz;
    const double wall_s = c->res.wall_seconds;
    const double *y = c->y;
    char name[24];
    fprintf(f, "{\n  \"scene\": ");
    swim_json_string(f, s->path);
    fprintf(f, ",\n  \"title\": ");
    swim_json_string(f, s->title);
    fprintf(f, ",\n  \"out\": ");
    swim_json_string(f, x->out ? x->out : "");
    fprintf(f, ",\n  \"modes\": %d,\n  \"rho0\": %.17g,\n  \"rhof\": %.17g,\n  \"integrator\": ", s->modes, s->rho0, s->rhof);
    swim_json_string(f, r->used);
    fprintf(f, ",\n  \"integrator_switch_t\": ");
    swim_json_number(f, r->switch_t >= 0 ? r->switch_t : NAN);
    fprintf(f, ",\n  \"rtol\": %.3g,\n  \"atol\": %.3g,\n  \"step_lookahead\": %d,\n  \"free\": [", s->rtol, s->atol, s->step_lookahead);
    for (int i = 0, first = 1; i < s->n; i++)
        if (s->free_mask[i]) {
            swim_coord_name(i, name, sizeof name);
            fprintf(f, "%s\"%s\"", first ? "" : ", ", name);
            first = 0;
        }
    fprintf(f, "],\n  \"effects\": {\"elastic\": %s, \"barrier\": %s, \"damping\": %s, \"forcing\": %s",
            s->elastic ? "true" : "false", s->barrier ? "true" : "false", s->damped ? "true" : "false",
            s->forced ? "true" : "false");
    if (s->energy_text) {   /* only with a law: other summaries are unchanged */
        fprintf(f, ", \"energy_law\": ");
        swim_json_string(f, s->energy_text);
    }
    fprintf(f, "},\n");
    fprintf(f, "  \"kernel\": {\"kind\": \"%s\", \"state_dimension\": %d, \"cache\": ",
            d->generic ? "generic" : "specialized", swim_dynamics_state_dim(d));
    swim_json_string(f, sp->dir);
    fprintf(f, ", \"from_cache\": %s, \"generate_seconds\": %.3f, \"compile_seconds\": %.3f},\n",
            sp->from_cache ? "true" : "false", sp->generate_seconds, sp->compile_seconds);
    fprintf(f, "  \"projection\": {\"enabled\": %s, \"steps\": %ld, \"max_change\": %.3g},\n",
            s->projection && (swim_ode_capabilities(s->integrator) & SWIM_ODE_CAP_PROJECTION) ? "true" : "false",
            d->projections, d->max_projection);
    /* a run advanced part of the way (libswim) has neither completed nor failed yet */
    const int ended = c->res.finished || r->status;
    fprintf(f, "  \"status\": \"%s\",\n  \"reason\": ",
            r->status ? "failed" : ended ? "completed" : r->rows > 0 ? "in progress" : "not started");
    if (ended) {
        swim_json_string(f, r->reason ? r->reason : "out of memory");
    } else {
        char so_far[96];
        if (r->rows > 0) snprintf(so_far, sizeof so_far, "advanced to t = %.6g, not yet to t_end", r->t_reached);
        else snprintf(so_far, sizeof so_far, "not run yet");
        swim_json_string(f, so_far);
    }
    fprintf(f, ",\n  \"t_end\": %.17g,\n  \"t_reached\": %.17g,\n  \"rows\": %ld,\n", s->t_end, r->t_reached, r->rows);
    if (x->sensitivity) {
        fprintf(f, "  \"sensitivity\": {\"status\": \"%s\", \"t_end\": %.17g, \"rows\": %ld, \"t_reached\": ",
                x->sens_status ? x->sens_status : "skipped", x->sens_t, x->sens_rows);
        if (x->sens_rows > 0) swim_json_number(f, x->sens_t_last);
        else fprintf(f, "null");
        fprintf(f, ", \"method\": \"%s\", \"jacobians\": %ld, \"rhs_evaluations\": %ld, \"seconds\": %.6g, "
                "\"file\": \"sensitivity.csv\"},\n", x->sens_method ? x->sens_method : "exact", x->sens_jacobians,
                x->sens_rhs, x->sens_seconds);
    }
    if (x->more) x->more(f, x->more_ctx);
    fprintf(f, "  \"initial_velocity_projected\": %s,\n  \"projection_change\": %.3g,\n",
            s->projection_change > 0 ? "true" : "false", s->projection_change);
    fprintf(f, "  \"final_state\": {\"t\": %.17g, \"x\": %.17g, \"y\": %.17g, \"theta\": %.17g, \"c\": ", r->t_reached, y[0], y[1], y[2]);
    swim_json_vector(f, y + 3, s->n);
    fprintf(f, ", \"dc\": ");
    swim_json_vector(f, y + 3 + s->n, s->n);
    fprintf(f, "},\n  \"energy_initial\": ");
    swim_json_number(f, r->e0);
    fprintf(f, ",\n  \"energy_drift_abs\": ");
    swim_json_number(f, r->drift_abs);
    fprintf(f, ",\n  \"forcing_work\": ");
    swim_json_number(f, s->forced ? c->res.forcing_work : NAN);
    fprintf(f, ",\n  \"energy_drift_rel\": ");
    swim_json_number(f, r->emax > 0 ? r->drift_abs / r->emax : 0.0);
    fprintf(f, ",\n  \"max_residuals\": {\"volume\": %.3g, \"volume_rate\": %.3g, \"angular\": %.3g, \"locks\": %.3g},\n",
            r->res_volume, r->res_volume_rate, r->res_angular, r->res_locks);
    fprintf(f, "  \"jmin\": ");
    swim_json_number(f, r->jmin);
    fprintf(f, ",\n  \"jmin_t\": ");
    swim_json_number(f, r->jmin_t);
    fprintf(f, ",\n  \"left_D_t\": ");
    swim_json_number(f, r->left_t);
    fprintf(f, ",\n  \"stiff_switch\": ");
    if (r->switch_t >= 0) {
        fprintf(f, "{\"t\": %.17g, \"from\": ", r->switch_t);
        swim_json_string(f, s->integrator);
        fprintf(f, ", \"to\": ");
        swim_json_string(f, s->stiff_fallback);
        fputc('}', f);
    } else {
        fputs("null", f);
    }
    fprintf(f, ",\n  \"step_checks\": {\"enabled\": %s, \"steps\": %ld, \"seconds\": %.6f}",
            c->watch_ready ? "true" : "false", c->watch.r.steps, swim_clock_sample_total(&c->watch.time));
    fprintf(f, ",\n  \"origin_shift\": {\"enabled\": %s, \"restarts\": %ld}", c->shift_ok || c->shifts ? "true" : "false",
            c->shifts);
    fprintf(f, ",\n  \"impacts\": {\"enabled\": %s, \"impact_depth\": %.3g, \"count\": %ld",
            c->ys_shift && s->impact_depth > 0 ? "true" : "false", s->impact_depth, c->impacts);
    if (c->impacts)
        fprintf(f, ", \"first_t\": %.17g, \"last_t\": %.17g, \"jmin_max\": %.3g, \"turning_min\": %.3g}", c->impact_first_t,
                c->impact_last_t, c->impact_j_max, c->impact_reach_min);
    else
        fprintf(f, ", \"first_t\": null, \"last_t\": null, \"jmin_max\": null, \"turning_min\": null}");
    fprintf(f, ",\n  \"energy_control\": {\"enabled\": %s, \"tolerance\": %.3g, \"rejected_steps\": %ld}",
            c->invariant_on ? "true" : "false", c->invariant_on ? c->o.invariant_tol : 0.0, c->total.rejected_invariant);
    swim_run_events_json(c->events, f);   /* "events", "event_stop", "periodic" (with events) */
    /* which Jacobian the BDF methods use for the state: the kernel's exact one or differences (the calls and
     * time count the variational equations' Jacobians too) */
    const swim_run_timing t = {r->integrate_seconds, r->diagnostics_seconds, r->output_seconds, swim_dynamics_rhs_seconds(d), wall_s,
                               d->rhs_calls, c->sys_state.jacobian ? "exact" : "differences", d->jac_calls, d->jac_seconds};
    swim_summary_provenance_json(f, x, sp);
    swim_run_stats_json(f, st, &t);
    fprintf(f, "\n}\n");
}

void swim_summary_provenance_json(FILE *f, const swim_summary_context *x, const swim_compiled *kernel)
{
    fprintf(f, ",\n  \"provenance\": {\"swim_version\": \"%s\", \"command\": ", SWIM_VERSION);
    if (x->command) swim_json_string(f, x->command);
    else fputs("null", f);
    fprintf(f, ", \"scene_original\": ");
    if (x->scene_original) swim_json_string(f, x->scene_original);
    else fputs("null", f);
    fprintf(f, ", \"overrides\": [");
    for (int i = 0; i < x->nsets; i++) {
        if (i) fputs(", ", f);
        swim_json_string(f, x->sets[i].text);
    }
    /* the cache entry's name is the hash of the kernel's key (codegen.h); linked-in kernels have none */
    const char *slash = kernel && kernel->dir[0] ? strrchr(kernel->dir, '/') : NULL;
    fprintf(f, "], \"kernel_key\": ");
    if (kernel && kernel->dir[0]) swim_json_string(f, slash ? slash + 1 : kernel->dir);
    else swim_json_string(f, "linked in");
    fputc('}', f);
}

void swim_run_stats_json(FILE *f, const swim_ode_stats *st, const swim_run_timing *t)
{
    fprintf(f, ",\n  \"stats\": {\"steps\": %ld, \"rhs_evaluations\": %ld, \"rejected_steps\": %ld, "
            "\"jacobian_evaluations\": %ld, \"last_step\": %.6g, \"last_order\": %d, \"stiffness_suspected\": %s,\n"
            "            \"order_histogram\": [",
            st->steps, st->rhs_evals, st->rejected, st->jac_evals, st->last_h, st->last_order,
            st->stiff_suspected ? "true" : "false");
    for (int i = 0; i < 13; i++) fprintf(f, "%s%ld", i ? ", " : "", st->order_hist[i]);
    struct rusage ru;
    getrusage(RUSAGE_SELF, &ru);
    fprintf(f, "],\n            \"integrate_seconds\": %.6f, \"diagnostics_seconds\": %.6f, \"output_seconds\": %.6f,",
            t->integrate, t->diagnostics, t->output);
    fprintf(f, "\n            \"rhs_seconds\": %.6f, \"wall_seconds\": %.6f, \"ns_per_rhs\": %.1f, \"max_rss_kb\": %ld,",
            t->rhs, t->wall, t->rhs_calls ? 1e9 * t->rhs / t->rhs_calls : 0.0, ru.ru_maxrss);
    fprintf(f, "\n            \"jacobian\": \"%s\", \"exact_jacobian_calls\": %ld, \"jacobian_seconds\": %.6f}",
            t->jacobian, t->jacobian_calls, t->jacobian_seconds);
}
