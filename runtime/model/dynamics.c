#include "model/dynamics.h"

#include <lapacke.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "model/constraints.h"

#define SYSV_LWORK 64

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

int swim_dynamics_init(swim_dynamics *d, const swim_scene *s)
{
    memset(d, 0, sizeof *d);
    d->scene = s;
    d->k = s->kernel;
    d->n = s->n;
    d->dim = 3 + 2 * s->n + 1;
    int n = d->n, mmax = n + 2;
    d->K = malloc(sizeof(double) * n * n);
    d->P = malloc(sizeof(double) * 3 * n);
    d->gvv = malloc(sizeof(double) * n);
    d->rhs = malloc(sizeof(double) * n * (mmax + 1));
    d->G = malloc(sizeof(double) * n * mmax);
    d->A = malloc(sizeof(double) * (mmax * mmax + mmax));
    d->grad = malloc(sizeof(double) * n);
    d->ipiv_work = malloc(sizeof(double) * SYSV_LWORK * mmax);
    d->ipiv = malloc(sizeof(int) * mmax);
    d->proj = malloc(sizeof(double) * d->dim);
    if (!d->K || !d->P || !d->gvv || !d->rhs || !d->G || !d->A || !d->grad || !d->ipiv_work || !d->ipiv || !d->proj ||
        (s->barrier && swim_circle_init(&d->circle, s->modes, SWIM_BARRIER_MAX_NODES) != 0)) {
        swim_dynamics_free(d);
        return -1;
    }
    d->m = swim_constraint_rows(n, s->c0, s->free_mask, d->G);
    return 0;
}

void swim_dynamics_free(swim_dynamics *d)
{
    free(d->K); free(d->P); free(d->gvv); free(d->rhs); free(d->G); free(d->A); free(d->grad);
    free(d->ipiv_work); free(d->ipiv); free(d->proj);
    swim_circle_free(&d->circle);
    d->K = d->P = d->gvv = d->rhs = d->G = d->A = d->grad = d->ipiv_work = d->proj = NULL;
    d->ipiv = NULL;
}

void swim_dynamics_initial_state(const swim_dynamics *d, double *y)
{
    const swim_scene *s = d->scene;
    memset(y, 0, sizeof(double) * d->dim);
    memcpy(y + 3, s->c0, sizeof(double) * s->n);
    memcpy(y + 3 + s->n, s->dc0, sizeof(double) * s->n);
}

static double seconds(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return ts.tv_sec + 1e-9 * ts.tv_nsec;
}

/* Generalized force f = -<Gamma, v, v> - grad W - D v + F(t); also the power F.v - v^T D v. */
static int generalized_force(swim_dynamics *d, double t, const double *c, const double *v,
                             double *f, double *power)
{
    const swim_scene *s = d->scene;
    const int n = d->n;
    double pw = 0.0;
    for (int i = 0; i < n; i++) f[i] = -d->gvv[i];
    if (s->elastic)
        for (int i = 0; i < n; i++) f[i] -= s->stiffness[i] * (c[i] - s->reference[i]);
    if (s->barrier) {
        if (!isfinite(swim_barrier_adaptive(&d->circle, d->k->barrier_sums, d->n, c, s->epsilon,
                                            s->alpha, d->grad, NULL, NULL)))
            return SWIM_DYN_EBARRIER;
        for (int i = 0; i < n; i++) f[i] -= d->grad[i];
    }
    if (s->damped)
        for (int i = 0; i < n; i++) {
            f[i] -= s->damping[i] * v[i];
            pw -= s->damping[i] * v[i] * v[i];
        }
    if (s->forced) {
        double ft = swim_expr_eval(s->forcing, t);
        for (int i = 0; i < n; i++) {
            f[i] += ft * s->direction[i];
            pw += ft * s->direction[i] * v[i];
        }
    }
    *power = pw;
    return 0;
}

static int rhs_body(swim_dynamics *d, double t, const double *y, double *dy)
{
    const swim_scene *s = d->scene;
    const int n = d->n, dim = d->dim;
    const double *c = y + 3, *v = y + 3 + n;
    for (int i = 0; i < dim; i++)
        if (!isfinite(y[i])) return SWIM_DYN_ENAN;
    if (d->k->reduced(c, v, s->rho0, s->rhof, d->K, d->P, d->gvv) != 0) return SWIM_DYN_EMASS;
    double *B = d->rhs, power;
    int rc = generalized_force(d, t, c, v, B, &power);
    if (rc) return rc;
    /* Columns 1..m of B: G^T (G row-major m x n is G^T column-major n x m). */
    const int m = swim_constraint_rows(n, c, s->free_mask, B + n);
    /* K is symmetric, so its row-major storage is also column-major. */
    if (LAPACKE_dpotrf_work(LAPACK_COL_MAJOR, 'L', n, d->K, n) != 0) return SWIM_DYN_EMASS;
    memcpy(d->G, B + n, sizeof(double) * n * m);
    LAPACKE_dpotrs_work(LAPACK_COL_MAJOR, 'L', n, m + 1, d->K, n, B, n);
    /* (4.12): (G K^-1 G^T) lambda = -(DG[v]).v - G K^-1 f */
    double *A = d->A, *lam = d->A + m * m;
    for (int i = 0; i < m; i++) {
        const double *gi = d->G + (size_t)i * n;
        double s0 = 0.0;
        for (int k = 0; k < n; k++) s0 += gi[k] * B[k];
        lam[i] = -s0;
        for (int j = 0; j < m; j++) {
            const double *zj = B + (size_t)(j + 1) * n;
            double sj = 0.0;
            for (int k = 0; k < n; k++) sj += gi[k] * zj[k];
            A[i + j * m] = sj;
        }
    }
    lam[0] -= swim_constraint_curvature_g1(n, v);
    if (LAPACKE_dsysv_work(LAPACK_COL_MAJOR, 'L', m, 1, A, m, d->ipiv, lam, m, d->ipiv_work,
                           SYSV_LWORK * m) != 0)
        return SWIM_DYN_ECONSTRAINT;
    double *acc = dy + 3 + n;
    for (int k = 0; k < n; k++) acc[k] = B[k];
    for (int j = 0; j < m; j++) {
        const double *zj = B + (size_t)(j + 1) * n;
        for (int k = 0; k < n; k++) acc[k] += lam[j] * zj[k];
    }
    /* (3.21): q' = R(theta) q*, q* = P cdot */
    double qs[3] = {0.0, 0.0, 0.0};
    for (int p = 0; p < 3; p++)
        for (int k = 0; k < n; k++) qs[p] += d->P[p * n + k] * v[k];
    const double ct = cos(y[2]), st = sin(y[2]);
    dy[0] = ct * qs[0] - st * qs[1];
    dy[1] = st * qs[0] + ct * qs[1];
    dy[2] = qs[2];
    memcpy(dy + 3, v, sizeof(double) * n);
    dy[3 + 2 * n] = power;
    for (int i = 0; i < dim; i++)
        if (!isfinite(dy[i])) return SWIM_DYN_ENAN;
    return 0;
}

/* The barrier callback of scene kernels: the same adaptive quadrature as the generic path, on
 * the scene kernel's own J (gradient on the free coordinates). */
static int scene_barrier(const double *x, double *grad, void *ctx)
{
    swim_dynamics *d = ctx;
    const swim_scene *s = d->scene;
    double W = swim_barrier_adaptive(&d->circle, d->spec->barrier_sums, d->spec->nfree, x,
                                     s->epsilon, s->alpha, grad, NULL, NULL);
    return isfinite(W) ? 0 : SWIM_RHS_EBARRIER;
}

void swim_dynamics_use_scene_kernel(swim_dynamics *d, const swim_scene_kernel *spec)
{
    const swim_scene *s = d->scene;
    d->spec = spec;
    swim_scene_params *p = &d->spec_params;
    memset(p, 0, sizeof *p);
    p->rho0 = s->rho0;
    p->rhof = s->rhof;
    p->x_locked = s->c0;
    p->stiffness = s->stiffness;
    p->reference = s->reference;
    p->damping = s->damping;
    p->direction = s->direction;
    p->barrier = scene_barrier;
    p->barrier_ctx = d;
}

int swim_dynamics_state_dim(const swim_dynamics *d)
{
    return d->spec ? 4 + 2 * d->spec->nfree : d->dim;
}

void swim_dynamics_pack(const swim_dynamics *d, const double *full, double *state)
{
    if (!d->spec) {
        memcpy(state, full, sizeof(double) * d->dim);
        return;
    }
    const int n = d->n, nf = d->spec->nfree;
    memcpy(state, full, 3 * sizeof(double));
    for (int f = 0; f < nf; f++) {
        state[3 + f] = full[3 + d->spec->free_index[f]];
        state[3 + nf + f] = full[3 + n + d->spec->free_index[f]];
    }
    state[3 + 2 * nf] = full[3 + 2 * n];
}

void swim_dynamics_unpack(const swim_dynamics *d, const double *state, double *full)
{
    if (!d->spec) {
        memcpy(full, state, sizeof(double) * d->dim);
        return;
    }
    const int n = d->n, nf = d->spec->nfree;
    memcpy(full, state, 3 * sizeof(double));
    memcpy(full + 3, d->scene->c0, sizeof(double) * n);   /* locked coordinates keep c0 */
    memset(full + 3 + n, 0, sizeof(double) * n);
    for (int f = 0; f < nf; f++) {
        full[3 + d->spec->free_index[f]] = state[3 + f];
        full[3 + n + d->spec->free_index[f]] = state[3 + nf + f];
    }
    full[3 + 2 * n] = state[3 + 2 * nf];
}

int swim_dynamics_rhs(double t, const double *y, double *dy, void *params)
{
    swim_dynamics *d = params;
    double t0 = seconds();
    int rc;
    if (d->interrupt && *d->interrupt) rc = -SWIM_DYN_EINTERRUPT;   /* fatal: negative */
    else if (d->spec) rc = d->spec->rhs(t, y, dy, &d->spec_params);
    else rc = rhs_body(d, t, y, dy);
    d->rhs_seconds += seconds() - t0;
    d->rhs_calls++;
    d->last_rhs_t = t;
    return rc;
}

int swim_dynamics_diagnostics(swim_dynamics *d, const double *y, swim_diag *o)
{
    const swim_scene *s = d->scene;
    const int n = d->n;
    const double *c = y + 3, *v = y + 3 + n;
    memset(o, 0, sizeof *o);
    double Mr[9], *Nc = malloc(sizeof(double) * 3 * n), *Md = malloc(sizeof(double) * n * n);
    if (!Nc || !Md) { free(Nc); free(Md); return -1; }
    d->k->mass(c, s->rho0, s->rhof, Mr, Nc, Md);
    if (d->k->reduced(c, NULL, s->rho0, s->rhof, d->K, d->P, NULL) != 0) { free(Nc); free(Md); return -1; }
    double q[3] = {0, 0, 0};
    for (int p = 0; p < 3; p++)
        for (int k = 0; k < n; k++) q[p] += d->P[p * n + k] * v[k];
    const double b = s->rho0 * M_PI, Ic = d->k->inertia(c, NULL);
    /* (1/2) X^T M X with X = (q*, cdot): the total kinetic energy, = (1/2) cdot^T K cdot. */
    double T = 0.0, Ncv[3] = {0, 0, 0};
    for (int p = 0; p < 3; p++) {
        for (int r = 0; r < 3; r++) T += q[p] * Mr[3 * p + r] * q[r];
        for (int k = 0; k < n; k++) Ncv[p] += Nc[p * n + k] * v[k];
        T += 2.0 * q[p] * Ncv[p];
    }
    for (int i = 0; i < n; i++)
        for (int j = 0; j < n; j++) T += v[i] * Md[i * n + j] * v[j];
    T *= 0.5;
    o->kinetic_rigid = 0.5 * b * (q[0] * q[0] + q[1] * q[1] + Ic * q[2] * q[2]);
    for (int i = 0; i < n; i++) {
        int ak = i < 2 ? 1 : i / 2;
        o->kinetic_shape += 0.5 * b * v[i] * v[i] / (ak + 1);   /* (2.17) */
    }
    o->kinetic_fluid = T - o->kinetic_rigid - o->kinetic_shape;
    if (s->elastic)
        for (int i = 0; i < n; i++) o->w1 += 0.5 * s->stiffness[i] * (c[i] - s->reference[i]) * (c[i] - s->reference[i]);
    if (s->barrier)
        o->w2 = swim_barrier_adaptive(&d->circle, d->k->barrier_sums, n, c, s->epsilon, s->alpha,
                                      NULL, NULL, NULL);
    o->energy = T + o->w1 + o->w2;
    o->work = y[3 + 2 * n];
    /* Impulses (section 3.3): body (m r*, I omega), fluid from the rigid motion (added mass),
     * fluid from the deformation N cdot; their sum is zero (3.19). Linear parts to the fixed frame. */
    double body[3] = {b * q[0], b * q[1], b * Ic * q[2]}, fr[3];
    for (int p = 0; p < 3; p++) {
        fr[p] = -body[p];
        for (int r = 0; r < 3; r++) fr[p] += Mr[3 * p + r] * q[r];
    }
    const double ct = cos(y[2]), st = sin(y[2]);
    const double *src[3] = {body, fr, Ncv};
    double *dst[3] = {o->impulse_body, o->impulse_fluid_rigid, o->impulse_fluid_shape};
    for (int a = 0; a < 3; a++) {
        dst[a][0] = ct * src[a][0] - st * src[a][1];
        dst[a][1] = st * src[a][0] + ct * src[a][1];
        dst[a][2] = src[a][2];
    }
    memcpy(o->rigid_velocity, q, sizeof q);
    o->res_volume = swim_area_constant(n, c) - swim_area_constant(n, s->c0);
    double *G = d->G;
    int m = swim_constraint_rows(n, c, s->free_mask, G);
    for (int k = 0; k < n; k++) {
        o->res_volume_rate += G[k] * v[k];
        o->res_angular += G[n + k] * v[k];
    }
    for (int j = 2; j < m; j++) {
        int i = swim_constraint_locked_index(n, s->free_mask, j);
        o->res_locks = fmax(o->res_locks, fabs(c[i] - s->c0[i]) + fabs(v[i]));
    }
    o->jmin = swim_shape_jmin(d->k, c);
    free(Nc);
    free(Md);
    return 0;
}

int swim_dynamics_project(double t, double *ys, void *params)
{
    swim_dynamics *d = params;
    const swim_scene *s = d->scene;
    const int n = d->n;
    double *y = d->proj, *c = y + 3, *v = y + 3 + n, change = 0.0;
    (void)t;
    swim_dynamics_unpack(d, ys, y);
    for (int i = 0; i < n; i++)
        if (!s->free_mask[i]) {
            change = fmax(change, fabs(c[i] - s->c0[i]) + fabs(v[i]));
            c[i] = s->c0[i];
            v[i] = 0.0;
        }
    /* Volume (2.5): mu^2(c) = mu0^2, Newton along the free part of grad mu^2 = 2 G1. */
    const double mu0 = swim_area_constant(n, s->c0);
    for (int it = 0; it < 2; it++) {
        double r = swim_area_constant(n, c) - mu0, gg = 0.0;
        double g[2 * (SWIM_KERNEL_MAX_MODES + 1)];
        for (int i = 0; i < n; i++) {
            int k = i < 2 ? 1 : -(i / 2);
            g[i] = s->free_mask[i] ? 2.0 * k * c[i] : 0.0;
            gg += g[i] * g[i];
        }
        if (!(gg > 0.0) || r == 0.0) break;
        for (int i = 0; i < n; i++) {
            c[i] -= r * g[i] / gg;
            change = fmax(change, fabs(r * g[i] / gg));
        }
    }
    /* Velocity: v <- v - G^T (G G^T)^-1 G v on the free coordinates (l2-orthogonal, as for the
     * initial data; a K-orthogonal projection changed the energy drift of the T = 1000 runs by
     * less than 1 % at twice the cost, since it needs K). */
    double *G = d->G;
    swim_constraint_rows(n, c, s->free_mask, G);
    for (int j = 0; j < 2; j++)
        for (int i = 0; i < n; i++)
            if (!s->free_mask[i]) G[j * n + i] = 0.0;
    double A[2][2] = {{0, 0}, {0, 0}}, b[2] = {0, 0}, lam[2] = {0, 0};
    for (int i = 0; i < n; i++)
        for (int j = 0; j < 2; j++) {
            b[j] += G[j * n + i] * v[i];
            for (int l = 0; l < 2; l++) A[j][l] += G[j * n + i] * G[l * n + i];
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
    for (int i = 0; i < n; i++) {
        double dv = lam[0] * G[i] + lam[1] * G[n + i];
        v[i] -= dv;
        change = fmax(change, fabs(dv));
    }
    swim_dynamics_pack(d, y, ys);
    d->projections++;
    d->max_projection = fmax(d->max_projection, change);
    return 0;
}
