/* flow.c -- the flow map as a driver run (driver/flow.h). */
#include "driver/flow.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "codegen/codegen.h"

/* Central differences leave ~1e-10 relative noise in s' (model/sensitivity.c): an error test
 * tighter than that fights the noise (Example 3 at rtol 1e-12: 7x the evaluations and a result
 * wrong by 1e-2 relative), so columns by differences in the error test are integrated at no
 * tighter than these. */
#define SENS_RTOL_MIN 1e-10
#define SENS_ATOL_MIN 1e-12

/* The columns of v on S (initialized on d). 0, or a key's code (2 refused, 1 out of memory). */
static int add_columns(swim_sens *S, swim_scene *scene, const swim_flow_vars *v, swim_status *st)
{
    S->error_control = v->error_control;
    for (int j = 0; j < v->state_count; j++)
        if (swim_sens_add_state(S, v->state_from + j, "x") != 0) {
            swim_status_fail(st, NULL, NULL, 0, NULL, "out of memory");
            return 1;
        }
    for (int k = 0; k < v->nkeys; k++) {
        const int rc = swim_sens_add_key(S, scene, v->cmd, v->keys[k], st);
        if (rc) return rc;
    }
    return 0;
}

int swim_flow_attach(swim_flow *f, swim_run *run, const swim_flow_vars *v, swim_status *st)
{
    swim_sens *S = &f->S;
    if (swim_sens_init(S, swim_run_dynamics(run)) != 0) {
        swim_status_fail(st, NULL, NULL, 0, NULL, "out of memory");
        return 1;
    }
    f->have_sens = 1;
    int rc = add_columns(S, swim_run_get_request(run)->scene, v, st);
    if (rc || S->nkeys == 0) return rc;
    /* the columns' start: d y0 / d y0_j a unit vector, d y0 / d p that of the key (model/sensitivity.h) */
    const int n = S->dim;
    const size_t dim = (size_t)S->nkeys * (size_t)n;
    double *y0 = malloc(sizeof(double) * dim);
    if (!y0) {
        swim_status_fail(st, NULL, NULL, 0, NULL, "out of memory");
        return 1;
    }
    for (int k = 0; k < S->nkeys; k++) memcpy(y0 + (size_t)k * n, S->keys[k].s0, sizeof(double) * n);
    const swim_run_variational var = {dim, swim_sens_rhs, S, y0, v->error_control, NULL, NULL, 0.0, 0, 0, 0, 0};
    rc = swim_run_set_variational(run, &var, st);
    free(y0);
    return rc;
}

int swim_flow_final(swim_flow *f)
{
    const swim_run_result *r = swim_run_get_result(f->run);
    const swim_run_var_result *v = swim_run_get_var_result(f->run);
    const int n = swim_dynamics_state_dim(swim_run_dynamics(f->run));
    const int N = f->have_sens && f->S.nkeys ? swim_sens_dimension(&f->S) : n;
    f->t = r->t_reached;
    f->rhs_calls = r->stats.rhs_evals;
    free(f->Y);
    f->Y = NULL;
    if (!v->final) {
        f->reason = v->reason[0] ? v->reason : "out of memory";
        return -1;
    }
    if (!(f->Y = malloc(sizeof(double) * (size_t)N))) return -1;
    memcpy(f->Y, v->final, sizeof(double) * (size_t)N);
    return 0;
}

int swim_flow_map(const swim_flow_request *req, swim_flow *f, swim_status *st)
{
    memset(f, 0, sizeof *f);
    swim_dynamics *model = (swim_dynamics *)req->model;   /* its scene's values: keys perturb and restore them */
    swim_scene *scene = (swim_scene *)model->scene;
    double rtol = req->rtol, atol = req->atol;
    if (req->vars.error_control && (req->vars.state_count || req->vars.nkeys)) {
        /* columns by differences in the error test: the tolerances floored for their noise */
        swim_sens probe;
        if (swim_sens_init(&probe, model) != 0) {
            swim_status_fail(st, NULL, NULL, 0, NULL, "out of memory");
            return 1;
        }
        const int rc = add_columns(&probe, scene, &req->vars, st);
        const int exact = rc == 0 && swim_sens_exact(&probe);
        swim_sens_free(&probe);
        if (rc) return rc;
        if (!exact) {
            rtol = fmax(rtol > 0 ? rtol : scene->run.rtol, SENS_RTOL_MIN);
            atol = fmax(atol > 0 ? atol : scene->run.atol, SENS_ATOL_MIN);
        }
    }
    /* the model's kernels as the run takes them (only the kernel and the right-hand side are read) */
    swim_compiled *k = calloc(2, sizeof *k);
    if (!k) {
        swim_status_fail(st, NULL, NULL, 0, NULL, "out of memory");
        return 1;
    }
    k[0].kernel = model->k;
    k[1].scene = model->spec;
    f->compiled = k;
    f->set = scene->run;
    f->set.t_end = f->set.output_step = req->t_end;
    if (rtol > 0) f->set.rtol = rtol;
    if (atol > 0) f->set.atol = atol;
    const swim_run_request rr = {.scene = scene, .kernel = &k[0], .system = &k[1], .generic = model->generic,
                                 .stop = (volatile sig_atomic_t *)model->interrupt, .settings = &f->set,
                                 .y0 = req->y0, .section = req->section};
    int rc = swim_run_open(&rr, &f->run, st);
    if (rc) return rc;
    if ((rc = swim_flow_attach(f, f->run, &req->vars, st)) != 0) return rc;
    const swim_run_result *r = (swim_run_integrate(f->run), swim_run_get_result(f->run));
    f->t = r->t_reached;
    f->rhs_calls = r->stats.rhs_evals;
    f->section_ended = r->status == 0 && r->event_stop;
    if (r->status != 0) {
        f->reason = r->reason ? r->reason : "out of memory";
        return 1;
    }
    if (swim_flow_final(f) != 0) {
        if (!f->reason) f->reason = "out of memory";
        return 1;
    }
    return 0;
}

void swim_flow_free(swim_flow *f)
{
    if (f->have_sens) swim_sens_free(&f->S);
    swim_run_free(f->run);
    free(f->Y);
    free(f->compiled);
    memset(f, 0, sizeof *f);
}
