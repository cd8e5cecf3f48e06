#include "model/dynamics.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "io/clock.h"
#include "kernel/coords.h"
#include "shape/constraints.h"
#include "shape/shape.h"

const char *swim_dynamics_strerror(int code)
{
    switch (code < 0 ? -code : code) {
    case SWIM_DYN_OK: return "ok";
    case SWIM_DYN_ENAN: return "NaN or Inf in the state";
    case SWIM_DYN_EBARRIER: return "the shape left the admissible set D (J <= 0 on the circle)";
    case SWIM_DYN_EMASS: return "the reduced mass matrix K is not positive definite";
    case SWIM_DYN_ECONSTRAINT: return "the constraint system (4.12) is singular (dependent constraints)";
    case SWIM_DYN_EINTERRUPT: return "interrupted (SIGINT)";
    default: return "unknown right-hand-side failure";
    }
}

int swim_dynamics_init(swim_dynamics *d, const swim_scene *s, const swim_kernel *k)
{
    memset(d, 0, sizeof *d);
    d->scene = s;
    d->k = k;
    d->n = s->n;
    d->dim = 3 + 2 * s->n + 1;
    int n = d->n, mmax = n + 2;
    d->K = malloc(sizeof(double) * n * n);
    d->P = malloc(sizeof(double) * 3 * n);
    d->G = malloc(sizeof(double) * n * mmax);
    d->proj = malloc(sizeof(double) * d->dim);
    d->gbar = malloc(sizeof(double) * n);
    if (s->barrier) {
        d->barrier = swim_barrier_quad_new(s->modes);
        d->diag_barrier = swim_barrier_quad_new(s->modes);
    }
    if (!d->K || !d->P || !d->G || !d->proj || !d->gbar || (s->barrier && (!d->barrier || !d->diag_barrier))) {
        swim_dynamics_free(d);
        return -1;
    }
    d->m = swim_constraint_rows(n, s->c0, s->free_mask, d->G);
    d->mu0 = swim_area_constant(n, s->c0);
    for (int i = 0; i < n; i++)
        if (s->free_mask[i]) d->free_at[d->nfree++] = i;
    return 0;
}

void swim_dynamics_free(swim_dynamics *d)
{
    free(d->K); free(d->P); free(d->G); free(d->proj); free(d->gbar);
    swim_barrier_quad_free(d->barrier);
    swim_barrier_quad_free(d->diag_barrier);
    swim_barrier_quad_free(d->aside_barrier);
    swim_barrier_quad_free(d->aside_diag);
    d->aside_barrier = d->aside_diag = NULL;
    free(d->origin);
    free(d->hi);
    d->K = d->P = d->G = d->proj = d->gbar = d->origin = d->hi = NULL;
    d->barrier = d->diag_barrier = NULL;
}

void swim_dynamics_initial_state(const swim_dynamics *d, double *y)
{
    const swim_scene *s = d->scene;
    memset(y, 0, sizeof(double) * d->dim);
    memcpy(y + 3, s->c0, sizeof(double) * s->n);
    memcpy(y + 3 + s->n, s->dc0, sizeof(double) * s->n);
}


/* The barrier callback of scene kernels: W2's gradient from shape/barrier.h at the full shape x,
 * restricted to the coordinates the kernel carries. A generic kernel always asks; without a
 * barrier in the scene the gradient is zero. */
static int scene_barrier(const double *x, double *grad, void *ctx)
{
    swim_dynamics *d = ctx;
    const swim_scene *s = d->scene;
    const int nf = d->spec->nfree;
    if (!s->barrier) {
        memset(grad, 0, sizeof(double) * nf);
        return 0;
    }
    double W;
    int rc = swim_barrier_w2_carry(d->barrier, x, d->lo_valid ? d->x_lo : NULL, s->epsilon, s->alpha, &W, d->gbar,
                                   NULL);
    d->w2_valid = rc == SWIM_BARRIER_OK;
    if (rc != SWIM_BARRIER_OK) return SWIM_RHS_EBARRIER;
    d->w2_last = W;
    memcpy(d->w2_x, x, sizeof(double) * d->n);
    for (int f = 0; f < nf; f++) grad[f] = d->gbar[d->spec->free_index[f]];
    return 0;
}

/* Its Hessian for the exact Jacobian: gradient and Hessian of W2 at the full shape x (same
 * nodes), restricted to the carried coordinates. */
static int scene_barrier_hessian(const double *x, double *grad, double *hess, void *ctx)
{
    swim_dynamics *d = ctx;
    const swim_scene *s = d->scene;
    const int nf = d->spec->nfree, n = d->n;
    if (!s->barrier) {
        memset(grad, 0, sizeof(double) * nf);
        memset(hess, 0, sizeof(double) * nf * nf);
        return 0;
    }
    double W, *full = malloc(sizeof(double) * n * n);
    if (!full) return -1;
    int rc = swim_barrier_hessian(d->barrier, x, s->epsilon, s->alpha, &W, d->gbar, full, NULL);
    if (rc == SWIM_BARRIER_OK) {
        const int *fi = d->spec->free_index;
        for (int f = 0; f < nf; f++) {
            grad[f] = d->gbar[fi[f]];
            for (int g = 0; g < nf; g++) hess[nf * f + g] = full[n * fi[f] + fi[g]];
        }
    }
    free(full);
    if (rc == SWIM_BARRIER_ENOMEM) return -1;
    return rc == SWIM_BARRIER_OK ? 0 : SWIM_RHS_EBARRIER;
}

void swim_dynamics_use_scene_kernel(swim_dynamics *d, const swim_scene_kernel *spec, int generic)
{
    const swim_scene *s = d->scene;
    d->spec = spec;
    d->generic = generic;
    swim_scene_params *p = &d->spec_params;
    memset(p, 0, sizeof *p);
    p->rho0 = s->rho0;
    p->rhof = s->rhof;
    p->x_locked = s->c0;
    p->stiffness = s->stiffness;
    p->reference = s->reference;
    p->damping = s->damping;
    p->direction = s->direction;
    p->free_mask = s->free_mask;
    p->barrier = scene_barrier;
    p->barrier_ctx = d;
    p->law_params = s->param_values;
    p->barrier_hessian = scene_barrier_hessian;
    d->carries_locked = spec->nfree != d->nfree ||
                        memcmp(spec->free_index, d->free_at, sizeof(int) * (size_t)d->nfree) != 0;
}

int swim_dynamics_state_dim(const swim_dynamics *d)
{
    return 4 + 2 * d->spec->nfree;
}

void swim_dynamics_pack(const swim_dynamics *d, const double *full, double *state)
{
    const int n = d->n, nf = d->spec->nfree;
    memcpy(state, full, 3 * sizeof(double));
    for (int f = 0; f < nf; f++) {
        state[3 + f] = full[3 + d->spec->free_index[f]];
        state[3 + nf + f] = full[3 + n + d->spec->free_index[f]];
    }
    state[3 + 2 * nf] = full[3 + 2 * n];
    if (d->origin)
        for (int i = 0; i < 4 + 2 * nf; i++) state[i] -= d->origin[i];
}

/* origin + u as doubles into hi (the state itself without an origin). */
static const double *absolute(const swim_dynamics *d, const double *u, double *hi)
{
    if (!d->origin) return u;
    const int m = 4 + 2 * d->spec->nfree;
    for (int i = 0; i < m; i++) hi[i] = d->origin[i] + u[i];
    return hi;
}

void swim_dynamics_unpack(const swim_dynamics *d, const double *ustate, double *full)
{
    const int n = d->n, nf = d->spec->nfree;
    double buf[4 + 4 * (SWIM_KERNEL_MAX_MODES + 1)];
    const double *state = absolute(d, ustate, buf);
    memcpy(full, state, 3 * sizeof(double));
    /* locked coordinates keep c0, live: a sensitivity's difference quotient moves a locked value
     * in place (model/sensitivity.c) */
    memcpy(full + 3, d->scene->c0, sizeof(double) * n);
    memset(full + 3 + n, 0, sizeof(double) * n);
    for (int f = 0; f < nf; f++) {
        full[3 + d->spec->free_index[f]] = state[3 + f];
        full[3 + n + d->spec->free_index[f]] = state[3 + nf + f];
    }
    full[3 + 2 * n] = state[3 + 2 * nf];
}

/* Whether the shape of integrator state y lies in D (4.1). Without a barrier nothing else keeps a
 * trial state of a step inside D (the equations are polynomial in c and go on outside it), so
 * the right-hand side refuses such states itself: the step is retried smaller, and a trajectory
 * that really leaves D ends at the crossing instead of running on through a non-physical shape.
 * With a barrier, its quadrature refuses them (SWIM_RHS_EBARRIER). */
static int shape_in_D(const swim_dynamics *d, const double *y)
{
    double c[2 * (SWIM_KERNEL_MAX_MODES + 1)];
    const int nf = d->spec->nfree;
    memcpy(c, d->scene->c0, sizeof(double) * d->n);
    for (int f = 0; f < nf; f++) c[d->spec->free_index[f]] = y[3 + f];
    return swim_shape_in_D(d->scene->modes, c);
}

int swim_dynamics_set_origin(swim_dynamics *d, const double *origin)
{
    const int m = swim_dynamics_state_dim(d);
    d->bal_valid = d->bal_memo = 0;   /* the same u means another state now */
    d->proj_valid = 0;
    if (!origin) {
        free(d->origin);
        d->origin = NULL;
        return 0;
    }
    if (!d->origin) d->origin = malloc(sizeof(double) * m);
    if (!d->hi) d->hi = malloc(sizeof(double) * m);
    if (!d->origin || !d->hi) {
        free(d->origin);
        d->origin = NULL;
        return -1;
    }
    memcpy(d->origin, origin, sizeof(double) * m);
    return 0;
}

int swim_dynamics_rebase(swim_dynamics *d, double *u, int clear)
{
    const int m = swim_dynamics_state_dim(d);
    double o[4 + 4 * (SWIM_KERNEL_MAX_MODES + 1)];
    for (int i = 0; i < m; i++) {
        const double a = d->origin ? d->origin[i] : 0.0, b = u[i], sum = a + b, bb = sum - a;
        o[i] = sum;
        u[i] = clear ? sum : (a - (sum - bb)) + (b - bb);   /* TwoSum: a + b = sum + u exactly */
    }
    return swim_dynamics_set_origin(d, clear ? NULL : o);
}

/* What the shape coordinates of origin + u lose when rounded to doubles (TwoSum), full layout. */
static void shape_lo(const swim_dynamics *d, const double *u, double *lo)
{
    memset(lo, 0, sizeof(double) * d->n);
    if (!d->origin) return;
    for (int f = 0; f < d->spec->nfree; f++) {
        const double a = d->origin[3 + f], b = u[3 + f], sum = a + b, bb = sum - a;
        lo[d->spec->free_index[f]] = (a - (sum - bb)) + (b - bb);
    }
}

/* With an origin: the kernel's state origin + u rounded into d->hi, and what the shape
 * coordinates lost to that rounding into d->x_lo (full layout) for the barrier. */
static const double *split_state(swim_dynamics *d, const double *u)
{
    if (!d->origin) return u;
    absolute(d, u, d->hi);
    shape_lo(d, u, d->x_lo);
    d->lo_valid = 1;
    return d->hi;
}

double swim_dynamics_jmin(const swim_dynamics *d, const double *u, double *theta)
{
    double full[4 + 4 * (SWIM_KERNEL_MAX_MODES + 1)];
    swim_dynamics_unpack(d, u, full);
    return swim_dynamics_jmin_unpacked(d, u, full, theta);
}

double swim_dynamics_jmin_unpacked(const swim_dynamics *d, const double *u, const double *full, double *theta)
{
    double lo[2 * (SWIM_KERNEL_MAX_MODES + 1)], th;
    const int modes = d->scene->modes;
    double J = swim_shape_jmin_at(modes, full + 3, &th);
    if (d->origin && !isnan(J) && J < 1e-3 * (full[3] * full[3] + full[4] * full[4])) {
        shape_lo(d, u, lo);
        J = swim_shape_j_precise(modes, full + 3, lo, th, NULL);
    }
    if (theta) *theta = th;
    return J;
}

int swim_dynamics_rhs(double t, const double *u, double *dy, void *params)
{
    swim_dynamics *d = params;
    const int timed = swim_clock_sample_start(&d->rhs_time);
    int rc;
    const double *y = split_state(d, u);
    if (d->interrupt && *d->interrupt) rc = -SWIM_DYN_EINTERRUPT;   /* fatal: negative */
    else if (!d->scene->barrier && !shape_in_D(d, y)) rc = SWIM_DYN_EBARRIER;
    else rc = d->spec->rhs(d->t_origin + t, y, dy, &d->spec_params);
    d->lo_valid = 0;
    d->bal_valid = d->bal_track && rc == 0 && (!d->scene->barrier || d->w2_valid);
    d->bal_memo = 0;
    if (d->bal_valid) memcpy(d->bal_u, u, sizeof(double) * (size_t)swim_dynamics_state_dim(d));
    swim_clock_sample_stop(&d->rhs_time, timed);
    d->rhs_calls++;
    d->last_rhs_t = d->t_origin + t;
    return rc;
}

double swim_dynamics_rhs_seconds(const swim_dynamics *d) { return swim_clock_sample_total(&d->rhs_time); }

double swim_dynamics_w2(swim_dynamics *d, const double *c)
{
    const swim_scene *s = d->scene;
    if (!s->barrier) return 0.0;
    if (d->w2_valid && memcmp(d->w2_x, c, sizeof(double) * d->n) == 0) return d->w2_last;
    double W;
    return swim_barrier_w2(d->diag_barrier, c, s->epsilon, s->alpha, &W, NULL, NULL) == 0 ? W : INFINITY;
}

double swim_dynamics_w_law(const swim_dynamics *d, const double *c)
{
    if (!d->scene->energy || !d->spec || !d->spec->material) return 0.0;
    double W;
    return d->spec->material(c, &d->spec_params, &W, NULL, NULL) == 0 ? W : NAN;
}

/* W1 (section 4.1.1): (1/2) sum R_i (c_i - c_ref,i)^2. */
static double elastic_energy(const swim_scene *s, const double *c)
{
    double W1 = 0.0;
    if (s->elastic)
        for (int i = 0; i < s->n; i++) W1 += 0.5 * s->stiffness[i] * (c[i] - s->reference[i]) * (c[i] - s->reference[i]);
    return W1;
}

void swim_dynamics_track_balance(swim_dynamics *d, int on)
{
    d->bal_track = on;
    d->bal_valid = d->bal_memo = 0;
    d->spec_params.kinetic = on ? &d->bal_kinetic : NULL;
}

double swim_dynamics_balance(double t, const double *u, double *noise, void *params)
{
    swim_dynamics *d = params;
    const swim_scene *s = d->scene;
    const int n = d->n, nf = d->spec->nfree;
    double full[4 + 4 * (SWIM_KERNEL_MAX_MODES + 1)], gbuf[2 * (SWIM_KERNEL_MAX_MODES + 1)];
    const int hit = d->bal_valid && memcmp(u, d->bal_u, sizeof(double) * (size_t)swim_dynamics_state_dim(d)) == 0;
    if (hit && d->bal_memo && !noise) return d->bal_memo_b;   /* what the lines below gave for this u */
    swim_dynamics_unpack(d, u, full);
    const double *c = full + 3, *v = full + 3 + n, *g = d->gbar;   /* grad W2 at c */
    double T = 0.0, W2 = 0.0;
    (void)t;   /* E and the work are functions of the state alone */
    if (hit) {
        T = d->bal_kinetic;
        if (s->barrier) W2 = d->w2_last;
    } else {
        if (d->k->reduced(c, NULL, s->rho0, s->rhof, d->K, d->P, NULL) != 0) return NAN;
        for (int i = 0; i < n; i++) {
            if (v[i] == 0.0) continue;
            double r = 0.0;
            for (int j = 0; j < n; j++) r += d->K[i * n + j] * v[j];
            T += 0.5 * v[i] * r;
        }
        if (s->barrier && d->w2_valid && memcmp(d->w2_x, c, sizeof(double) * n) == 0) {
            W2 = d->w2_last;   /* the right-hand side's last shape (its stages share the shape) */
        } else if (s->barrier) {   /* with an origin, from the exact shape origin + u, as the right-hand side */
            double lo[2 * (SWIM_KERNEL_MAX_MODES + 1)];
            if (d->origin) shape_lo(d, u, lo);
            if (swim_barrier_w2_carry(d->diag_barrier, c, d->origin ? lo : NULL, s->epsilon, s->alpha, &W2, gbuf,
                                      NULL) != SWIM_BARRIER_OK)
                return NAN;
            g = gbuf;
        }
    }
    const double W1 = elastic_energy(s, c) + swim_dynamics_w_law(d, c), work = full[3 + 2 * n];
    if (noise) {
        /* What rounding leaves of B: the sums (~dim u of each term), the barrier rule (chosen by
         * error, ~1e-14 of W2 between two rules), and W2 through the rounding of the carried state
         * (the shape itself, or u with an origin): u |dW2/du_i| |u_i|, which near the boundary
         * (dW2 ~ kappa dJ / min J) can exceed any tolerance -- the limit behind shifting. */
        const double uu = 1.11e-16;
        double r = (4 + 2 * nf) * uu * (T + W1) + uu * fabs(work) + 2e-14 * W2;
        if (s->barrier)
            for (int f = 0; f < nf; f++) r += 4.0 * uu * fabs(g[d->spec->free_index[f]] * u[3 + f]);
        /* a state the projection has just corrected: that correction is driven by residuals at the
         * rounding level, not by the step, and near the boundary W2 amplifies it (dW2 = g . dc) */
        if (s->barrier && d->proj_valid &&
            memcmp(u, d->proj_out, sizeof(double) * (size_t)swim_dynamics_state_dim(d)) == 0)
            for (int f = 0; f < nf; f++) r += fabs(g[d->spec->free_index[f]] * d->proj_delta[3 + f]);
        *noise = r;
    }
    const double B = T + W1 + W2 - work;
    if (hit) {   /* from u, the by-products and the scene alone: the same value at the next ask */
        d->bal_memo = 1;
        d->bal_memo_b = B;
    }
    return B;
}

int swim_dynamics_jacobian(double t, const double *y, double *J, void *params)
{
    return swim_dynamics_jacobian_params(params, t, y, J, 0, NULL, NULL);
}

int swim_dynamics_jacobian_params(swim_dynamics *d, double t, const double *y, double *J, int np,
                                  const swim_param *param, double *dp)
{
    double t0 = swim_clock_seconds();
    int rc;
    if (d->interrupt && *d->interrupt) rc = -SWIM_DYN_EINTERRUPT;
    else if (!d->spec->jacobian_params) rc = -SWIM_DYN_ENAN;   /* a kernel without one: run.c does not ask */
    else {
        swim_barrier_quad *own = d->barrier;   /* the Jacobian's barrier calls on the quadrature aside */
        if (d->aside_barrier) d->barrier = d->aside_barrier;
        rc = d->spec->jacobian_params(d->t_origin + t, split_state(d, y), J, np, param, dp, &d->spec_params);
        d->barrier = own;
    }
    d->lo_valid = 0;
    if (rc < 0 && rc != -SWIM_DYN_EINTERRUPT) rc = -SWIM_DYN_ENAN;
    d->jac_seconds += swim_clock_seconds() - t0;
    d->jac_calls++;
    return rc;
}

int swim_dynamics_set_aside(swim_dynamics *d)
{
    if (!d->scene->barrier || d->aside_barrier) return 0;
    d->aside_barrier = swim_barrier_quad_new(d->scene->modes);
    d->aside_diag = swim_barrier_quad_new(d->scene->modes);
    return d->aside_barrier && d->aside_diag ? 0 : -1;
}

int swim_dynamics_diagnostics_aside(swim_dynamics *d, const double *y, swim_diag *o)
{
    swim_barrier_quad *own = d->diag_barrier;
    if (d->aside_diag) d->diag_barrier = d->aside_diag;
    const int rc = swim_dynamics_diagnostics(d, y, o);
    d->diag_barrier = own;
    return rc;
}

/* swim_to_fixed_frame (3.21) of three vectors at one angle theta, with one cos and sin of it:
 * each rotated vector is the one swim_to_fixed_frame gives. */
static void to_fixed_frame3(double theta, const double *a, const double *b, const double *c, double *fa, double *fb,
                            double *fc)
{
    const double ct = cos(theta), st = sin(theta);
    const double *in[3] = {a, b, c};
    double *out[3] = {fa, fb, fc};
    for (int j = 0; j < 3; j++) {
        const double u = in[j][0], w = in[j][1];
        out[j][0] = ct * u - st * w;
        out[j][1] = st * u + ct * w;
        out[j][2] = in[j][2];
    }
}

int swim_dynamics_diagnostics(swim_dynamics *d, const double *y, swim_diag *o)
{
    const swim_scene *s = d->scene;
    const int n = d->n;
    const double *c = y + 3, *v = y + 3 + n;
    memset(o, 0, sizeof *o);
    /* on the stack (35 kB at the largest N): this runs at every output row */
    enum { NMAX = 2 * (SWIM_KERNEL_MAX_MODES + 1) };
    double Mr[9], Nc[3 * NMAX], P[3 * NMAX], Md[NMAX * NMAX];
    int on[NMAX];
    /* Mr, and Nc, P and Md on the velocities that are not 0 (the locked ones are), from one
     * evaluation of the boundary data; fails when Mr is not positive definite. The sums over
     * the velocities below leave out their terms with v_k = 0: adding an exact zero to a sum
     * that started at +0 changes no bit (it is never -0: x + (-x) rounds to +0). */
    const int m = d->k->row_blocks(c, v, s->rho0, s->rhof, Mr, Nc, P, on, Md);
    if (m < 0) return -1;
    double q[3] = {0, 0, 0};
    for (int p = 0; p < 3; p++)
        for (int a = 0; a < m; a++) q[p] += P[p * m + a] * v[on[a]];
    const double b = s->rho0 * M_PI, Ic = d->k->inertia(c, NULL);
    /* (1/2) X^T M X with X = (q*, cdot): the total kinetic energy, = (1/2) cdot^T K cdot. */
    double T = 0.0, Ncv[3] = {0, 0, 0};
    for (int p = 0; p < 3; p++) {
        for (int r = 0; r < 3; r++) T += q[p] * Mr[3 * p + r] * q[r];
        for (int a = 0; a < m; a++) Ncv[p] += Nc[p * m + a] * v[on[a]];
        T += 2.0 * q[p] * Ncv[p];
    }
    for (int e = 0; e < m; e++)
        for (int f = 0; f < m; f++) T += v[on[e]] * Md[e * m + f] * v[on[f]];
    T *= 0.5;
    o->kinetic_rigid = 0.5 * b * (q[0] * q[0] + q[1] * q[1] + Ic * q[2] * q[2]);
    for (int a = 0; a < m; a++) {   /* (2.17), over the velocities that are not 0 as above */
        const int i = on[a];
        o->kinetic_shape += 0.5 * b * v[i] * v[i] / (abs(swim_coord_mode(i)) + 1);
    }
    o->kinetic_fluid = T - o->kinetic_rigid - o->kinetic_shape;
    o->w1 = elastic_energy(s, c);
    if (s->barrier) o->w2 = swim_dynamics_w2(d, c);
    o->energy = T + o->w1 + o->w2;
    o->work = y[3 + 2 * n];
    /* Impulses (section 3.3): body (m r*, I omega), fluid from the rigid motion (added mass),
     * fluid from the deformation N cdot; their sum is zero (3.19). Linear parts to the fixed frame. */
    double body[3] = {b * q[0], b * q[1], b * Ic * q[2]}, fr[3];
    for (int p = 0; p < 3; p++) {
        fr[p] = -body[p];
        for (int r = 0; r < 3; r++) fr[p] += Mr[3 * p + r] * q[r];
    }
    to_fixed_frame3(y[2], body, fr, Ncv, o->impulse_body, o->impulse_fluid_rigid, o->impulse_fluid_shape);
    memcpy(o->rigid_velocity, q, sizeof q);
    swim_constraint_residuals res;
    swim_constraint_residuals_at(n, c, v, s->c0, d->mu0, s->free_mask, &res);
    o->res_volume = res.volume;
    o->res_volume_rate = res.volume_rate;
    o->res_angular = res.angular;
    o->res_locks = res.locks;
    o->jmin = swim_shape_jmin(s->modes, c);
    if (s->energy) {   /* the energy law's W, last: the rest of this function compiles as without it */
        o->w_law = swim_dynamics_w_law(d, c);
        o->energy += o->w_law;
    }
    return 0;
}

/* fmax(a, b) for a never NaN, without the library call (the projection runs at every step). */
static inline double larger(double a, double b) { return b > a ? b : a; }

int swim_dynamics_project(double t, double *ys, void *params)
{
    swim_dynamics *d = params;
    const swim_scene *s = d->scene;
    const int n = d->n;
    double *y = d->proj, *c = y + 3, *v = y + 3 + n, change = 0.0;
    double before[4 + 4 * (SWIM_KERNEL_MAX_MODES + 1)];
    const int m = swim_dynamics_state_dim(d);
    (void)t;
    if (d->origin) memcpy(before, absolute(d, ys, d->hi), sizeof(double) * m);
    /* what the projection changes is read by the balance's noise, with a barrier only */
    const int keep = s->barrier;
    if (keep) memcpy(d->proj_delta, ys, sizeof(double) * m);
    swim_dynamics_unpack(d, ys, y);
    const int *free_at = d->free_at, nfree = d->nfree;
    /* A kernel that carries only the free coordinates leaves the locked ones at c0 and cdot 0
     * (unpack); one that carries them all may have moved them: put them back. */
    if (d->carries_locked)
        for (int i = 0; i < n; i++)
            if (!s->free_mask[i]) {
                change = larger(change, fabs(c[i] - s->c0[i]) + fabs(v[i]));
                c[i] = s->c0[i];
                v[i] = 0.0;
            }
    /* Volume (2.5): mu^2(c) = mu0^2, Newton along the free part of grad mu^2 = 2 G1. With an
     * origin the residual is taken from the exact shape origin + u (what c lost to rounding is
     * in d->x_lo) and the corrections go to u alone (dcx): the residual of the rounded shape is
     * rounding noise of 1e-16, and correcting it would put that noise back into u. */
    const double mu0 = d->mu0;
    double dcx[2 * (SWIM_KERNEL_MAX_MODES + 1)], c_hi[2 * (SWIM_KERNEL_MAX_MODES + 1)];
    const int shifted = d->origin != NULL;
    if (shifted) {   /* dcx is read with an origin only */
        memset(dcx, 0, sizeof(double) * (size_t)n);
        split_state(d, ys);
        d->lo_valid = 0;
        memcpy(c_hi, c, sizeof(double) * n);
    }
    for (int it = 0; it < 2; it++) {
        double r, gg = 0.0;
        if (shifted) {
            __float128 mu2 = 0;
            for (int i = 0; i < n; i++) {
                const __float128 x = (__float128)c_hi[i] + d->x_lo[i] + dcx[i];
                mu2 += swim_coord_mode(i) * x * x;
            }
            r = (double)(mu2 - mu0);
        } else {
            r = swim_area_constant_moving(n, c) - mu0;
        }
        /* over the free coordinates only: a locked one's gradient entry is 0, and adding the
         * exact zeros it gave to sums that start at +0 changed no bit (a NaN residual, which left
         * NaN there as well, fails the step either way) */
        double g[2 * (SWIM_KERNEL_MAX_MODES + 1)];
        for (int f = 0; f < nfree; f++) {
            const int i = free_at[f];
            g[i] = 2.0 * swim_coord_mode(i) * c[i];
            gg += g[i] * g[i];
        }
        if (!(gg > 0.0) || r == 0.0) break;
        for (int f = 0; f < nfree; f++) {
            const int i = free_at[f];
            c[i] -= r * g[i] / gg;
            if (shifted) dcx[i] -= r * g[i] / gg;
            change = larger(change, fabs(r * g[i] / gg));
        }
    }
    /* Velocity: v <- v - G^T (G G^T)^-1 G v on the free coordinates (l2-orthogonal, as for the
     * initial data; a K-orthogonal projection changed the energy drift of the T = 1000 runs by
     * less than 1 % at twice the cost, since it needs K). G's rows 0 and 1 (swim_constraint_rows,
     * the same expressions) on the free coordinates; the locked columns, zeros, are left out of
     * the sums as above. */
    double G[2][2 * (SWIM_KERNEL_MAX_MODES + 1)];
    double A[2][2] = {{0, 0}, {0, 0}}, b[2] = {0, 0}, lam[2] = {0, 0};
    for (int f = 0; f < nfree; f++) {
        const int i = free_at[f], k = swim_coord_mode(i), ak = abs(k);
        G[0][i] = k * c[i];
        G[1][i] = i % 2 ? -c[i - 1] / (ak + 1) : c[i + 1] / (ak + 1);
        for (int j = 0; j < 2; j++) {
            b[j] += G[j][i] * v[i];
            for (int l = 0; l < 2; l++) A[j][l] += G[j][i] * G[l][i];
        }
    }
    const double scale = A[0][0] + A[1][1] + 1e-300;
    const int use0 = A[0][0] > 1e-13 * scale, use1 = A[1][1] > 1e-13 * scale;
    const double det = A[0][0] * A[1][1] - A[0][1] * A[1][0];
    if (use0 && use1 && fabs(det) > 1e-13 * A[0][0] * A[1][1]) {
        lam[0] = (b[0] * A[1][1] - A[0][1] * b[1]) / det;
        lam[1] = (A[0][0] * b[1] - A[1][0] * b[0]) / det;
    } else if (use0) {
        lam[0] = b[0] / A[0][0];
    } else if (use1) {
        lam[1] = b[1] / A[1][1];
    }
    for (int f = 0; f < nfree; f++) {
        const int i = free_at[f];
        double dv = lam[0] * G[0][i] + lam[1] * G[1][i];
        v[i] -= dv;
        change = larger(change, fabs(dv));
    }
    if (shifted) {
        /* the corrections go to u itself: packing origin + u rounded would drop u's low bits */
        double after[4 + 4 * (SWIM_KERNEL_MAX_MODES + 1)], *o = d->origin;
        const int nf = d->spec->nfree;
        d->origin = NULL;
        swim_dynamics_pack(d, y, after);
        d->origin = o;
        for (int i = 0; i < m; i++) {
            const int shape = i >= 3 && i < 3 + nf && s->free_mask[d->spec->free_index[i - 3]];
            ys[i] += shape ? dcx[d->spec->free_index[i - 3]] : after[i] - before[i];
        }
    } else {
        swim_dynamics_pack(d, y, ys);
    }
    if (keep) {
        for (int i = 0; i < m; i++) d->proj_delta[i] = ys[i] - d->proj_delta[i];
        memcpy(d->proj_out, ys, sizeof(double) * m);
        d->proj_valid = 1;
    }
    d->projections++;
    d->max_projection = larger(d->max_projection, change);   /* change is never NaN (larger) */
    return 0;
}
