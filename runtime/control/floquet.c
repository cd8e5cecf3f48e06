#include "control/floquet.h"

#include <complex.h>
#include <errno.h>
#include <lapacke.h>
#include <math.h>
#include <signal.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "control/sensitivity.h"
#include "driver/run.h"
#include "io/clock.h"
#include "io/json.h"
#include "io/message.h"
#include "kernel/coords.h"
#include "ode/ode.h"
#include "shape/constraints.h"

/* Multipliers at 1 of a periodic orbit in a one-parameter family (energy) form a Jordan block:
 * an error eps in M moves them by ~sqrt(eps). With M accurate to ~1e-8, 1e-3 separates "on the
 * unit circle" from a genuine instability without calling that splitting unstable. */
#define FLOQUET_TOL SWIM_FLOQUET_TOL



typedef struct {
    double t[SWIM_FLOQUET_MAX_CROSSINGS + 1];
    int count;
} event_log;

static double section_extremum(double t, const double *y, const double *yp, void *data)
{
    (void)t; (void)y;
    return yp[*(const int *)data];
}

static double section_zero(double t, const double *y, const double *yp, void *data)
{
    (void)t; (void)yp;
    return y[*(const int *)data];
}

static void on_event(const swim_ode_event_hit *hit, void *data)
{
    event_log *log = data;
    if (log->count <= SWIM_FLOQUET_MAX_CROSSINGS) log->t[log->count] = hit->t;
    log->count++;
}

int swim_floquet_check(const swim_scene *s, const char *path, int what, swim_status *st)
{
    if ((what & SWIM_FLOQUET_NO_STROKE) && s->stroke) {
        /* A prescribed stroke gives the shape as a function of time: there is no shape state to
         * perturb, so no monodromy and no multipliers (swim run reports its strokes instead). */
        swim_status_fail_cmd(st, "floquet", path, "stroke", "%s: a prescribed stroke ([stroke]) has no free shape "
                             "dynamics, so no Floquet multipliers; swim run reports its period and displacement per "
                             "stroke", path);
        return 2;
    }
    /* the period is found from events of the scene's own integrator, which must locate them */
    if ((what & SWIM_FLOQUET_EVENTS) && !(swim_ode_capabilities(s->run.integrator) & SWIM_ODE_CAP_EVENTS)) {
        swim_status_fail_cmd(st, "floquet", path, "run.integrator", "%s: run.integrator = \"%s\" cannot locate the "
                             "section's events (no dense output); use one of %s (e.g. --set run.integrator=abm)", path,
                             s->run.integrator, swim_ode_method_list_with(SWIM_ODE_CAP_EVENTS));
        return 2;
    }
    return 0;
}

int swim_floquet_parse_section(const swim_dynamics *d, const char *cmd, const char *option, const char *spec,
                               swim_floquet_section *sec, char *text, size_t len, swim_status *st)
{
    char dflt[40];
    if (!spec) {   /* the first moving coordinate's maximum */
        char name[24];
        swim_coord_name(d->spec->free_index[0], name, sizeof name);
        snprintf(dflt, sizeof dflt, "%s:max", name);
        spec = dflt;
    }
    snprintf(text, len, "%s", spec);
    const char *colon = strchr(spec, ':');
    char col[32];
    if (!colon || (size_t)(colon - spec) >= sizeof col) goto bad;
    snprintf(col, sizeof col, "%.*s", (int)(colon - spec), spec);
    char kind[8];
    const char *colon2 = strchr(colon + 1, ':');
    sec->count = 1;
    if (colon2) {   /* :COUNT, the events the period spans */
        char *end;
        errno = 0;
        const long c = strtol(colon2 + 1, &end, 10);
        if (end == colon2 + 1 || *end || errno || c < 1 || c > SWIM_FLOQUET_MAX_CROSSINGS) {
            swim_status_fail_cmd(st, cmd, NULL, option, "--%s: '%s': the count after the second ':' is the number of "
                                 "events the period spans, an integer 1..%d, got '%s'", option, spec,
                                 SWIM_FLOQUET_MAX_CROSSINGS, colon2 + 1);
            return 2;
        }
        sec->count = (int)c;
    }
    const size_t klen = colon2 ? (size_t)(colon2 - colon - 1) : strlen(colon + 1);
    if (klen >= sizeof kind) goto bad;
    snprintf(kind, sizeof kind, "%.*s", (int)klen, colon + 1);
    if (strcmp(kind, "max") == 0) sec->kind = 'x';
    else if (strcmp(kind, "min") == 0) sec->kind = 'n';
    else if (strcmp(kind, "zero") == 0) sec->kind = 'z';
    else goto bad;
    const int vel = col[0] == 'd', nf = d->spec->nfree;
    for (int f = 0; f < nf; f++) {
        char name[24];
        swim_coord_name(d->spec->free_index[f], name, sizeof name);
        if (strcmp(name, col + vel) == 0) {
            sec->index = 3 + f + (vel ? nf : 0);
            return 0;
        }
    }
    swim_status_fail_cmd(st, cmd, NULL, option, "--%s: '%s' is not a moving coordinate of the scene or its velocity "
                         "(d + name)", option, col);
    return 2;
bad:
    swim_status_fail_cmd(st, cmd, NULL, option, "--%s: expected COLUMN:KIND[:COUNT] (KIND max, min or zero; COUNT the "
                         "events the period spans, 1 by default), e.g. am1:max or bm2:max:2, got '%s'", option, spec);
    return 2;
}

int swim_floquet_period(swim_dynamics *d, const char *cmd, const swim_floquet_section *sec, double t_max,
                        const char *t_max_from, const char *section_option, const double *ys0, double *t1,
                        double *period, swim_status *st)
{
    const swim_scene *s = d->scene;
    const int n = swim_dynamics_state_dim(d);
    double *y = malloc(sizeof(double) * n);
    if (!y) {
        swim_status_fail_cmd(st, cmd, NULL, NULL, "out of memory");
        return 1;
    }
    memcpy(y, ys0, sizeof(double) * n);
    int index = sec->index;
    event_log log = {{0, 0}, 0};
    swim_ode_event ev = {sec->kind == 'z' ? section_zero : section_extremum, &index,
                         sec->kind == 'x' ? -1 : +1, 0};
    swim_ode_system sys = {swim_dynamics_rhs, (size_t)n, d, NULL};
    swim_ode_options o;
    swim_run_ode_options(&s->run, &o);   /* the scene's integrator, as swim run has it */
    if (s->run.projection && (swim_ode_capabilities(s->run.integrator) & SWIM_ODE_CAP_PROJECTION)) o.project = swim_dynamics_project;
    o.events = &ev;
    o.nevents = 1;
    o.on_event = on_event;
    o.on_event_data = &log;
    swim_ode *ode = NULL;
    int rc = swim_ode_create(s->run.integrator, &sys, &o, 0.0, y, &ode);
    const double dt = s->run.output_step;
    const int want = sec->count + 1;
    for (double t = dt; rc == SWIM_ODE_OK && log.count < want && t < t_max + dt; t += dt)
        rc = swim_ode_advance(ode, fmin(t, t_max), y);
    const int stopped = d->interrupt && *d->interrupt;   /* the caller's to say */
    if (rc != SWIM_ODE_OK && !stopped)
        swim_status_fail_cmd(st, cmd, NULL, NULL, "the run for the period failed: %s", swim_ode_strerror(rc));
    else if (log.count < want && !stopped) {
        char many[16];
        snprintf(many, sizeof many, want == 2 ? "two" : "%d", want);
        swim_status_fail_cmd(st, cmd, NULL, NULL, "fewer than %s events of the section before t = %g: no period "
                             "(raise %s or choose another section with %s)", many, t_max, t_max_from, section_option);
    }
    swim_ode_free(ode);
    free(y);
    if (rc != SWIM_ODE_OK || log.count < want) return 1;
    *t1 = log.t[0];
    *period = log.t[sec->count] - log.t[0];
    return 0;
}

/* Gradients (rows of C, on the carried state) of mu^2(c), G1(c).cdot, G2(c).cdot; rows that
 * vanish on the carried coordinates are dropped. Returns the number of rows. */
static int constraint_gradients(swim_dynamics *d, const double *ys, double *C)
{
    const swim_scene *s = d->scene;
    const int nf = d->spec->nfree, n2 = 2 * nf, N = swim_dynamics_state_dim(d), n = s->n;
    double *yp = malloc(sizeof(double) * N), *full = malloc(sizeof(double) * d->dim);
    double G[(SWIM_NMAX + 2) * SWIM_NMAX], h[2][3];
    int rows = 0;
    if (!yp || !full) { free(yp); free(full); return -1; }
    double grad[3][SWIM_FLOQUET_MAX];
    for (int j = 0; j < n2; j++) {
        const double step = 1e-6 * (1.0 + fabs(ys[3 + j]));
        for (int side = 0; side < 2; side++) {
            memcpy(yp, ys, sizeof(double) * N);
            yp[3 + j] += side ? -step : step;
            swim_dynamics_unpack(d, yp, full);
            const double *c = full + 3, *v = full + 3 + n;
            swim_constraint_rows(n, c, s->free_mask, G);
            h[side][0] = swim_area_constant(n, c);
            h[side][1] = h[side][2] = 0.0;
            for (int f = 0; f < nf; f++) {
                const int i = d->spec->free_index[f];
                h[side][1] += G[i] * v[i];
                h[side][2] += G[n + i] * v[i];
            }
        }
        for (int r = 0; r < 3; r++) grad[r][j] = (h[0][r] - h[1][r]) / (2 * step);
    }
    double norm[3] = {0, 0, 0}, big = 0.0;
    for (int r = 0; r < 3; r++) {
        for (int j = 0; j < n2; j++) norm[r] += grad[r][j] * grad[r][j];
        big = fmax(big, norm[r]);
    }
    for (int r = 0; r < 3; r++)
        if (norm[r] > 1e-20 * big && norm[r] > 0) memcpy(C + (size_t)(rows++) * n2, grad[r], sizeof(double) * n2);
    free(yp);
    free(full);
    return rows;
}

/* Orthonormal basis (columns of B, n2 x nt) of the null space of C (rows x n2). Returns nt. */
static int tangent_basis(const double *C, int rows, int n2, double *B)
{
    double A[3 * SWIM_FLOQUET_MAX], sv[SWIM_FLOQUET_MAX], superb[SWIM_FLOQUET_MAX];
    double *VT = malloc(sizeof(double) * n2 * n2);
    if (!VT) return -1;
    int rank = 0;
    if (rows > 0) {
        memcpy(A, C, sizeof(double) * rows * n2);
        if (LAPACKE_dgesvd(LAPACK_ROW_MAJOR, 'N', 'A', rows, n2, A, n2, sv, NULL, 1, VT, n2, superb) != 0) {
            free(VT);
            return -1;
        }
        for (int r = 0; r < rows && r < n2; r++) rank += sv[r] > 1e-10 * sv[0];
    } else {
        for (int i = 0; i < n2; i++)
            for (int j = 0; j < n2; j++) VT[i * n2 + j] = i == j;
    }
    const int nt = n2 - rank;
    for (int i = 0; i < n2; i++)
        for (int k = 0; k < nt; k++) B[i * nt + k] = VT[(rank + k) * n2 + i];
    free(VT);
    return nt;
}

static int eigenvalues(const double *M, int n, double *re, double *im)
{
    double *A = malloc(sizeof(double) * n * n);
    if (!A) return -1;
    memcpy(A, M, sizeof(double) * n * n);
    int rc = LAPACKE_dgeev(LAPACK_ROW_MAJOR, 'N', 'N', n, A, n, re, im, NULL, 1, NULL, 1) == 0 ? 0 : -1;
    free(A);
    return rc;
}

int swim_floquet_eigenvalues(const double *M, int n, double *re, double *im) { return eigenvalues(M, n, re, im); }

static double determinant(const double *M, int n)
{
    double *A = malloc(sizeof(double) * n * n);
    lapack_int ipiv[SWIM_FLOQUET_MAX];
    if (!A) return NAN;
    memcpy(A, M, sizeof(double) * n * n);
    double det = 1.0;
    if (LAPACKE_dgetrf(LAPACK_ROW_MAJOR, n, n, A, n, ipiv) < 0) det = NAN;
    for (int i = 0; i < n && isfinite(det); i++) det *= (ipiv[i] != i + 1 ? -1.0 : 1.0) * A[i * n + i];
    free(A);
    return det;
}

/* max over lambda of min_j |lambda_j - 1/lambda|: how far the spectrum is from closed under
 * inversion (0 for reciprocal pairs). */
static double reciprocal_residual(const double *re, const double *im, int n)
{
    double r = 0.0;
    for (int a = 0; a < n; a++) {
        const double complex inv = 1.0 / (re[a] + I * im[a]);
        double best = INFINITY;
        for (int b = 0; b < n; b++) best = fmin(best, cabs(re[b] + I * im[b] - inv));
        r = fmax(r, best);
    }
    return n > 0 ? r : 0.0;
}

/* The checks of the structure, on M, the tangent basis B, f(x0) and grad E(x0). */
static void structure(swim_floquet *fl, const double *B, const double *f, const double *gE)
{
    const int n2 = fl->n2, nt = fl->nt;
    double *MB = calloc((size_t)(n2 * nt), sizeof(double)), *Mt = fl->Mt = calloc((size_t)(nt * nt), sizeof(double));
    if (!MB || !Mt) {
        free(MB);
        return;
    }
    for (int i = 0; i < n2; i++)
        for (int k = 0; k < nt; k++)
            for (int j = 0; j < n2; j++) MB[i * nt + k] += fl->M[i * n2 + j] * B[j * nt + k];
    for (int a = 0; a < nt; a++)
        for (int k = 0; k < nt; k++)
            for (int i = 0; i < n2; i++) Mt[a * nt + k] += B[i * nt + a] * MB[i * nt + k];
    eigenvalues(Mt, nt, fl->tre, fl->tim);
    fl->det_tangent = determinant(Mt, nt);
    double r = 0.0, fn = 0.0;
    for (int i = 0; i < n2; i++) {
        double mf = 0.0;
        for (int j = 0; j < n2; j++) mf += fl->M[i * n2 + j] * f[j];
        r += (mf - f[i]) * (mf - f[i]);
        fn += f[i] * f[i];
    }
    fl->flow_residual = sqrt(r / fmax(fn, 1e-300));
    double er = 0.0, en = 0.0;   /* (grad E M - grad E) B: energy is conserved on the manifold only */
    for (int k = 0; k < nt; k++) {
        double a = 0.0, b = 0.0;
        for (int i = 0; i < n2; i++) {
            a += gE[i] * MB[i * nt + k];
            b += gE[i] * B[i * nt + k];
        }
        er += (a - b) * (a - b);
        en += b * b;
    }
    fl->energy_residual = sqrt(er / fmax(en, 1e-300));
    fl->reciprocal_residual = reciprocal_residual(fl->tre, fl->tim, nt);
    fl->max_abs_dev = 0.0;
    fl->unit_count = 0;
    for (int a = 0; a < nt; a++) {
        const double complex lam = fl->tre[a] + I * fl->tim[a];
        fl->max_abs_dev = fmax(fl->max_abs_dev, fabs(cabs(lam) - 1.0));
        fl->unit_count += cabs(lam - 1.0) < FLOQUET_TOL;
    }
    fl->tol = FLOQUET_TOL;
    free(MB);
}

/* grad E on the carried shape state, by central differences of the diagnostics. */
static int energy_gradient(swim_dynamics *d, const double *ys, double *gE)
{
    const int nf = d->spec->nfree, N = swim_dynamics_state_dim(d);
    double *yp = malloc(sizeof(double) * N), *full = malloc(sizeof(double) * d->dim);
    int rc = yp && full ? 0 : -1;
    for (int j = 0; j < 2 * nf && rc == 0; j++) {
        const double step = 1e-6 * (1.0 + fabs(ys[3 + j]));
        double E[2] = {0.0, 0.0};
        for (int side = 0; side < 2 && rc == 0; side++) {
            swim_diag g;
            memcpy(yp, ys, sizeof(double) * N);
            yp[3 + j] += side ? -step : step;
            swim_dynamics_unpack(d, yp, full);
            rc = swim_dynamics_diagnostics(d, full, &g);
            E[side] = g.energy;
        }
        gE[j] = (E[0] - E[1]) / (2 * step);
    }
    free(yp);
    free(full);
    return rc;
}

const char *const swim_floquet_symmetry_names[SWIM_FLOQUET_NSYM] = {
    "rotation of the shape in the body frame (c_k -> e^{i psi} c_k)",
    "rotation of the disk's parametrization (c_k -> e^{i k phi} c_k)",
    "the parametrization turned against the body, c_1 fixed (c_k -> e^{i (k - 1) phi} c_k)"};

/* The mode number k of coordinate pair p of c = (c_1, c_-1, c_-2, ...): 1, -1, -2, ... */
static double mode_number(int pair) { return pair == 0 ? 1.0 : -(double)pair; }

/* The generators at the shape state (z = (c, cdot) of the carried coordinates) of the three
 * rotations, each c_k -> e^{i m_k t} c_k with m_k = 1, k or k - 1: d/dt (a_k, b_k) = m_k (-b_k, a_k).
 * One is representable when every mode it moves (m_k c_k != 0) is carried whole; on the tangent
 * space, and how far M is from fixing it. */
static void symmetries(swim_dynamics *d, const double *ys, swim_floquet *fl)
{
    const int nf = d->spec->nfree, n2 = 2 * nf, nt = fl->nt, n = d->scene->n;
    double *full = malloc(sizeof(double) * d->dim);
    if (!full) return;
    swim_dynamics_unpack(d, ys, full);
    const double *c = full + 3;
    int carried[2 * SWIM_NMAX];
    for (int i = 0; i < n; i++) carried[i] = -1;
    for (int f = 0; f < nf; f++) carried[d->spec->free_index[f]] = f;
    for (int s = 0; s < SWIM_FLOQUET_NSYM; s++) {
        double *g = fl->symmetry[s], gt[SWIM_FLOQUET_MAX], u[SWIM_FLOQUET_MAX];
        int ok = 1;
        memset(g, 0, sizeof(double) * n2);
        for (int pair = 0; 2 * pair + 1 < n && ok; pair++) {
            const double k = mode_number(pair), m = s == 0 ? 1.0 : s == 1 ? k : k - 1.0;
            const int ia = 2 * pair, ib = ia + 1, fa = carried[ia], fb = carried[ib];
            if (m == 0.0 || (c[ia] == 0.0 && c[ib] == 0.0 && fa < 0 && fb < 0)) continue;   /* not moved */
            if (fa < 0 || fb < 0) { ok = 0; break; }
            g[fa] = -m * ys[3 + fb];
            g[fb] = m * ys[3 + fa];
            g[nf + fa] = -m * ys[3 + nf + fb];
            g[nf + fb] = m * ys[3 + nf + fa];
        }
        fl->symmetry_residual[s] = NAN;
        if (!ok) {
            memset(g, 0, sizeof(double) * n2);
            continue;
        }
        for (int a = 0; a < nt; a++) {   /* on the tangent space: B B^T g */
            u[a] = 0.0;
            for (int i = 0; i < n2; i++) u[a] += fl->B[i * nt + a] * g[i];
        }
        double gn = 0.0, rn = 0.0;
        for (int i = 0; i < n2; i++) {
            gt[i] = 0.0;
            for (int a = 0; a < nt; a++) gt[i] += fl->B[i * nt + a] * u[a];
            gn += gt[i] * gt[i];
        }
        if (!(gn > 0)) continue;
        for (int i = 0; i < n2; i++) {
            double mg = 0.0;
            for (int j = 0; j < n2; j++) mg += fl->M[i * n2 + j] * gt[j];
            rn += (mg - gt[i]) * (mg - gt[i]);
        }
        memcpy(g, gt, sizeof(double) * n2);
        fl->symmetry_residual[s] = sqrt(rn / gn);
    }
    free(full);
}

/* The multipliers on the complement of those known to be 1 (floquet.h: M_c = Q^T M_t Q). */
static void complement(swim_floquet *fl)
{
    const int n2 = fl->n2, nt = fl->nt;
    double rows[(2 + SWIM_FLOQUET_NSYM) * SWIM_FLOQUET_MAX];
    int nr = 0;
    fl->energy_conserved = fl->energy_residual <= SWIM_FLOQUET_SYMMETRY_TOL;
    const double *known[2 + SWIM_FLOQUET_NSYM];
    known[nr++] = fl->flow;
    if (fl->energy_conserved) known[nr++] = fl->grad_energy;
    for (int s = 0; s < SWIM_FLOQUET_NSYM; s++)
        if (fl->symmetry_residual[s] <= SWIM_FLOQUET_SYMMETRY_TOL) known[nr++] = fl->symmetry[s];
    for (int r = 0; r < nr; r++)   /* each on the tangent space: B^T v */
        for (int a = 0; a < nt; a++) {
            double t = 0.0;
            for (int i = 0; i < n2; i++) t += fl->B[i * nt + a] * known[r][i];
            rows[r * nt + a] = t;
        }
    double *Q = malloc(sizeof(double) * (size_t)nt * (size_t)nt);
    double *MtQ = malloc(sizeof(double) * (size_t)nt * (size_t)nt * 2);
    const double *Mt = fl->Mt;   /* structure()'s */
    fl->forced_one = -1;
    fl->nc = 0;
    if (!Q || !MtQ || !Mt) goto done;
    const int nc = tangent_basis(rows, nr, nt, Q);   /* orthogonal to grad E and to W */
    if (nc < 0) goto done;
    fl->exact_ones = nt - nc;
    fl->nc = nc;
    double *Mc = MtQ + nt * nt;
    for (int a = 0; a < nt; a++)
        for (int k = 0; k < nc; k++) {
            double t = 0.0;
            for (int b = 0; b < nt; b++) t += Mt[a * nt + b] * Q[b * nc + k];
            MtQ[a * nc + k] = t;
        }
    for (int k = 0; k < nc; k++)
        for (int l = 0; l < nc; l++) {
            double t = 0.0;
            for (int a = 0; a < nt; a++) t += Q[a * nc + k] * MtQ[a * nc + l];
            Mc[k * nc + l] = t;
        }
    if (nc > 0 && eigenvalues(Mc, nc, fl->cre, fl->cim) != 0) {
        fl->nc = 0;
        goto done;
    }
    fl->comp_reciprocal = reciprocal_residual(fl->cre, fl->cim, nc);
    fl->comp_max_abs_dev = 0.0;
    for (int k = 0; k < nc; k++) fl->comp_max_abs_dev = fmax(fl->comp_max_abs_dev, fabs(hypot(fl->cre[k], fl->cim[k]) - 1.0));
    if (nc % 2 == 1 && fl->comp_reciprocal <= FLOQUET_TOL) {
        double best = INFINITY;
        for (int k = 0; k < nc; k++)
            if (fl->cim[k] == 0.0 && fabs(fl->cre[k] - 1.0) < best) {
                best = fabs(fl->cre[k] - 1.0);
                fl->forced_one = k;
            }
    }
done:
    free(Q);
    free(MtQ);
}

int swim_floquet_compute(swim_dynamics *d, const swim_floquet_section *sec, double t_max,
                         void (*on_period)(void *ctx, double t_first, double period), void *ctx, swim_floquet *fl,
                         swim_status *st)
{
    memset(fl, 0, sizeof *fl);
    if (d->scene->stroke || !d->spec) {   /* a prescribed shape has no shape state to perturb */
        swim_status_fail_cmd(st, "floquet", d->scene->path, NULL, "%s: a prescribed stroke has no free shape dynamics",
                             d->scene->path);
        return 1;
    }
    const double t0 = swim_clock_seconds();
    const int N = swim_dynamics_state_dim(d);
    double *full = calloc((size_t)d->dim, sizeof(double)), *ys = malloc(sizeof(double) * N);
    int rc = 1;
    if (!full || !ys) {
        swim_status_fail_cmd(st, "floquet", NULL, NULL, "out of memory");
    } else {
        swim_dynamics_initial_state(d, full);
        swim_dynamics_pack(d, full, ys);
        double t_first = NAN, period = NAN;
        if (swim_floquet_period(d, "floquet", sec, t_max, "--t-max", "--event", ys, &t_first, &period, st) == 0) {
            if (on_period) on_period(ctx, t_first, period);
            rc = swim_floquet_at(d, ys, period, fl, st);   /* the monodromy based at t = 0 */
            fl->t_first = t_first;
        }
        if (rc != 0 && d->interrupt && *d->interrupt) {   /* stopped: what is known, said as such */
            swim_floquet_free(fl);
            memset(fl, 0, sizeof *fl);
            fl->stopped = *d->interrupt;
            fl->period = period;
            fl->t_first = t_first;
            rc = 0;
        }
    }
    free(full);
    free(ys);
    fl->seconds = swim_clock_seconds() - t0;
    return rc;
}

int swim_floquet_at(swim_dynamics *d, const double *ys, double period, swim_floquet *fl, swim_status *st)
{
    memset(fl, 0, sizeof *fl);
    const double t0 = swim_clock_seconds();
    const int nf = d->spec->nfree, n2 = 2 * nf, N = swim_dynamics_state_dim(d);
    fl->n2 = n2;
    fl->period = period;
    double *f = malloc(sizeof(double) * N), *C = malloc(sizeof(double) * 3 * n2);
    double *Y = NULL;
    swim_sens S;
    int have_sens = 0, rc = 1;
    fl->M = malloc(sizeof(double) * n2 * n2);
    fl->B = malloc(sizeof(double) * n2 * n2);
    if (!f || !C || !fl->B || !fl->M) goto oom;
    if (swim_sens_init(&S, d) != 0) goto oom;
    have_sens = 1;
    for (int j = 0; j < n2; j++)
        if (swim_sens_add_state(&S, 3 + j, "x") != 0) goto oom;
    const int dimY = swim_sens_dimension(&S);
    if (!(Y = malloc(sizeof(double) * dimY))) goto oom;
    swim_sens_initial(&S, ys, Y);
    swim_ode_system sys = {swim_sens_rhs, (size_t)dimY, &S, NULL};
    swim_ode_options o;
    swim_run_ode_options(&d->scene->run, &o);
    if (!swim_sens_exact(&S)) {   /* as swim_sens_write_run: the differences' noise */
        o.rtol = fmax(d->scene->run.rtol, 1e-10);
        o.atol = fmax(d->scene->run.atol, 1e-12);
    }
    swim_ode *ode = NULL;
    int orc = swim_ode_create(d->scene->run.integrator, &sys, &o, 0.0, Y, &ode);
    if (orc == SWIM_ODE_OK) orc = swim_ode_advance(ode, period, Y);
    if (ode) {
        swim_ode_stats st;
        swim_ode_get_stats(ode, &st);
        fl->rhs_calls = st.rhs_evals;
        swim_ode_free(ode);
    }
    if (orc != SWIM_ODE_OK) {
        if (!(d->interrupt && *d->interrupt))   /* stopped: the caller's to say */
            swim_status_fail_cmd(st, "floquet", NULL, NULL, "the variational equations failed: %s", swim_ode_strerror(orc));
        goto done;
    }
    double scale = d->scene->run.atol;
    for (int i = 0; i < n2; i++) {
        fl->closure = fmax(fl->closure, fabs(Y[3 + i] - ys[3 + i]));
        scale = fmax(scale, fabs(ys[3 + i]));
        for (int j = 0; j < n2; j++) fl->M[i * n2 + j] = Y[(size_t)(j + 1) * N + 3 + i];
    }
    fl->closure_rel = fl->closure / scale;
    fl->periodic = fl->closure_rel <= SWIM_FLOQUET_CLOSURE_TOL;
    if (eigenvalues(fl->M, n2, fl->re, fl->im) != 0) goto oom;
    if (swim_dynamics_rhs(0.0, ys, f, d) != 0 || energy_gradient(d, ys, fl->grad_energy) != 0) {
        swim_status_fail_cmd(st, "floquet", NULL, NULL, "the right-hand side or the energy failed at the initial state");
        goto done;
    }
    memcpy(fl->flow, f + 3, sizeof(double) * n2);
    const int rows = constraint_gradients(d, ys, C);
    if (rows < 0 || (fl->nt = tangent_basis(C, rows, n2, fl->B)) < 0) goto oom;
    structure(fl, fl->B, fl->flow, fl->grad_energy);
    symmetries(d, ys, fl);
    complement(fl);
    fl->stable = fl->periodic && fl->nc == fl->nt - fl->exact_ones && fl->comp_max_abs_dev <= FLOQUET_TOL;
    rc = 0;
    goto done;
oom:
    swim_status_fail_cmd(st, "floquet", NULL, NULL, "out of memory");
done:
    if (have_sens) swim_sens_free(&S);
    free(f); free(C); free(Y);
    fl->seconds = swim_clock_seconds() - t0;
    return rc;
}

const char *swim_floquet_signal_name(int sig)
{
    return sig == SIGINT ? "SIGINT" : sig == SIGTERM ? "SIGTERM" : sig == SIGHUP ? "SIGHUP" : "a signal";
}

void swim_floquet_free(swim_floquet *fl)
{
    free(fl->M);
    free(fl->B);
    free(fl->Mt);
    fl->M = fl->B = fl->Mt = NULL;
}

static void multipliers_json(FILE *f, const double *re, const double *im, int n)
{
    fprintf(f, "[");
    for (int i = 0; i < n; i++) {
        fprintf(f, "%s\n    {\"re\": ", i ? "," : "");
        swim_json_number(f, re[i]);
        fprintf(f, ", \"im\": ");
        swim_json_number(f, im[i]);
        fprintf(f, ", \"abs\": ");
        swim_json_number(f, hypot(re[i], im[i]));
        fprintf(f, "}");
    }
    fprintf(f, "\n  ]");
}

void swim_floquet_checks_json(FILE *f, const swim_floquet *fl)
{
    fprintf(f, "{\"flow_residual\": ");
    swim_json_number(f, fl->flow_residual);
    fprintf(f, ", \"energy_residual\": ");
    swim_json_number(f, fl->energy_residual);
    fprintf(f, ", \"reciprocal_residual\": ");
    swim_json_number(f, fl->reciprocal_residual);
    fprintf(f, ", \"det_tangent\": ");
    swim_json_number(f, fl->det_tangent);
    fprintf(f, ", \"max_abs_deviation\": ");
    swim_json_number(f, fl->max_abs_dev);
    fprintf(f, ", \"multipliers_at_1\": %d, \"tolerance\": ", fl->unit_count);
    swim_json_number(f, fl->tol);
    fprintf(f, ", \"exact_ones\": %d, \"complement_dimension\": %d, \"complement_reciprocal_residual\": ",
            fl->exact_ones, fl->nc);
    swim_json_number(f, fl->comp_reciprocal);
    fprintf(f, ", \"complement_max_abs_deviation\": ");
    swim_json_number(f, fl->comp_max_abs_dev);
    fprintf(f, ", \"multipliers_complement\": ");
    multipliers_json(f, fl->cre, fl->cim, fl->nc);
    fprintf(f, "}");
}

void swim_floquet_json(FILE *f, const swim_floquet *fl, const char *scene, const char *section)
{
    fprintf(f, "{\n  \"scene\": ");
    swim_json_string(f, scene);
    fprintf(f, ",\n  \"section\": ");
    swim_json_string(f, section);
    fprintf(f, ",\n  \"status\": \"%s\"", fl->stopped ? "stopped" : "computed");
    fprintf(f, ",\n  \"period\": ");
    swim_json_number(f, fl->period);
    fprintf(f, ",\n  \"first_event\": ");
    swim_json_number(f, fl->t_first);
    if (fl->stopped) {   /* the monodromy was not finished: nothing more to say */
        fprintf(f, ",\n  \"signal\": \"%s\",\n  \"periodic\": false,\n  \"seconds\": ",
                swim_floquet_signal_name(fl->stopped));
        swim_json_number(f, fl->seconds);
        fprintf(f, "\n}\n");
        return;
    }
    /* the monodromy is the map over [0, T] from the scene's initial state, not from the first
     * event: a Floquet matrix based elsewhere on the orbit is similar, same multipliers */
    fprintf(f, ",\n  \"base\": \"t = 0 (the scene's initial state; the period is the time between the events at "
               "first_event and first_event + period)\"");
    fprintf(f, ",\n  \"closure\": ");
    swim_json_number(f, fl->closure);
    fprintf(f, ",\n  \"closure_relative\": ");
    swim_json_number(f, fl->closure_rel);
    fprintf(f, ",\n  \"closure_tolerance\": ");
    swim_json_number(f, SWIM_FLOQUET_CLOSURE_TOL);
    fprintf(f, ",\n  \"periodic\": %s", fl->periodic ? "true" : "false");
    fprintf(f, ",\n  \"dimension\": %d,\n  \"tangent_dimension\": %d,\n  \"multipliers_tangent\": ", fl->n2, fl->nt);
    multipliers_json(f, fl->tre, fl->tim, fl->nt);
    fprintf(f, ",\n  \"multipliers_full\": ");
    multipliers_json(f, fl->re, fl->im, fl->n2);
    fprintf(f, ",\n  \"checks\": ");
    swim_floquet_checks_json(f, fl);
    fprintf(f, ",\n  \"stable\": %s,\n  \"monodromy\": ", !fl->periodic ? "null" : fl->stable ? "true" : "false");
    swim_json_matrix(f, fl->M, fl->n2, fl->n2, 2);
    fprintf(f, ",\n  \"rhs_evaluations\": %ld,\n  \"seconds\": ", fl->rhs_calls);
    swim_json_number(f, fl->seconds);
    fprintf(f, "\n}\n");
}

void swim_floquet_table(FILE *f, const swim_floquet *fl)
{
    fprintf(f, "period T = %.10g (first event at t = %.10g), closure |x(T) - x(0)| = %.2g (relative %.2g)\n",
            fl->period, fl->t_first, fl->closure, fl->closure_rel);
    fprintf(f, "multipliers on the constraint manifold (%d of %d; r and theta are cyclic: trivial 1s, left out):\n",
            fl->nt, fl->n2);
    fprintf(f, "  %-24s %-24s %-14s %s\n", "re", "im", "|lambda|", "arg/pi");
    for (int i = 0; i < fl->nt; i++)
        fprintf(f, "  %-24.15g %-24.15g %-14.10f %.6f\n", fl->tre[i], fl->tim[i], hypot(fl->tre[i], fl->tim[i]),
                atan2(fl->tim[i], fl->tre[i]) / M_PI);
    fprintf(f, "checks: flow direction |Mf - f|/|f| = %.2g; energy |(dE M - dE) B|/|dE B| = %.2g; "
            "reciprocal pairs %.2g; det M_t = %.12g; at 1: %d\n",
            fl->flow_residual, fl->energy_residual, fl->reciprocal_residual, fl->det_tangent, fl->unit_count);
    if (!fl->periodic)   /* the multipliers of a map over [0, T] that is not a period: no verdict */
        fprintf(f, "NO PERIODIC ORBIT: the orbit does not close after T (relative closure %.2g > %.0e); "
                "the multipliers above are not Floquet multipliers\n", fl->closure_rel, SWIM_FLOQUET_CLOSURE_TOL);
    else
        fprintf(f, "%s: %d multipliers exactly 1 (time shift%s, symmetries) taken out; on the %d-dimensional "
                "complement max ||lambda| - 1| = %.3g (tolerance %.0e)%s\n",
                fl->stable ? "linearly stable (all |lambda| = 1)" : "UNSTABLE", fl->exact_ones,
                fl->energy_conserved ? ", energy" : "", fl->nc, fl->comp_max_abs_dev, fl->tol,
                fl->forced_one >= 0 ? "; one of them at 1 by reversibility (reciprocal pairs, odd dimension)" : "");
}
