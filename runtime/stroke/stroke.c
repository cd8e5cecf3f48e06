#include "stroke/stroke.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "io/clock.h"
#include "kernel/coords.h"
#include "shape/shape.h"

const char *swim_stroke_strerror(int code)
{
    switch (code < 0 ? -code : code) {
    case SWIM_RHS_OK: return "ok";
    case SWIM_RHS_ENAN: return "a stroke law or the state is NaN or Inf";
    case SWIM_RHS_EMASS: return "the mass matrix Mr or K is not positive definite";
    case SWIM_STROKE_EVOLUME: return "no c1 keeps the volume (2.5): |c1|^2 = mu^2 + sum m|c_-m|^2 <= 0";
    case SWIM_STROKE_EINTERRUPT: return "interrupted";
    default: return "unknown right-hand-side failure";
    }
}

/* The prescribed coordinates at t over `base`: c, c', c'' (full length; 0 velocity elsewhere). */
static int prescribed(const swim_stroke *st, double t, double *c, double *dc, double *ddc)
{
    const swim_stroke_kernel *law = st->law;
    double v[SWIM_NMAX], dv[SWIM_NMAX], ddv[SWIM_NMAX];
    memcpy(c, st->base, sizeof(double) * st->n);
    memset(dc, 0, sizeof(double) * st->n);
    memset(ddc, 0, sizeof(double) * st->n);
    law->eval(t, st->par, v, dv, ddv);
    for (int k = 0; k < law->count; k++) {
        if (!isfinite(v[k]) || !isfinite(dv[k]) || !isfinite(ddv[k])) return SWIM_RHS_ENAN;
        c[law->index[k]] = v[k];
        dc[law->index[k]] = dv[k];
        ddc[law->index[k]] = ddv[k];
    }
    return 0;
}

/* c1 = rho e^{i psi} with rho^2 = mu^2 + V (2.5) and rho^2 psi'/2 + A = 0 (2.14), where
 * V = sum_{m>=1} m |c_-m|^2 and A = sum_{m>=1} (b'_-m a_-m - a'_-m b_-m)/(m+1); c1' and c1''
 * from the exact derivatives of V and A. */
static int complete_c1(const swim_stroke *st, double psi, double *c, double *dc, double *ddc, double *dpsi)
{
    double V = 0.0, dV = 0.0, ddV = 0.0, A = 0.0, dA = 0.0;
    for (int i = 2; i < st->n; i += 2) {
        const double m = i / 2, a = c[i], b = c[i + 1], da = dc[i], db = dc[i + 1];
        V += m * (a * a + b * b);
        dV += 2.0 * m * (a * da + b * db);
        ddV += 2.0 * m * (da * da + db * db + a * ddc[i] + b * ddc[i + 1]);
        A += (db * a - da * b) / (m + 1.0);
        dA += (ddc[i + 1] * a - ddc[i] * b) / (m + 1.0);   /* the a'b' terms cancel */
    }
    const double rho2 = st->mu2 + V;
    if (!(rho2 > 0.0)) return SWIM_STROKE_EVOLUME;
    const double rho = sqrt(rho2), drho = dV / (2.0 * rho), ddrho = (0.5 * ddV - drho * drho) / rho;
    const double w = -2.0 * A / rho2, dw = -2.0 * dA / rho2 + 4.0 * A * drho / (rho2 * rho);
    const double cp = cos(psi), sp = sin(psi);
    /* c1' = (rho' + i rho psi') e^{i psi}, c1'' = (rho'' - rho psi'^2 + i (2 rho' psi' + rho psi'')) e^{i psi} */
    const double u1 = drho, v1 = rho * w, u2 = ddrho - rho * w * w, v2 = 2.0 * drho * w + rho * dw;
    c[0] = rho * cp;
    c[1] = rho * sp;
    dc[0] = u1 * cp - v1 * sp;
    dc[1] = u1 * sp + v1 * cp;
    ddc[0] = u2 * cp - v2 * sp;
    ddc[1] = u2 * sp + v2 * cp;
    *dpsi = w;
    return 0;
}

int swim_stroke_shape(const swim_stroke *st, double t, double psi, double *c, double *dc, double *ddc, double *dpsi)
{
    *dpsi = 0.0;
    int rc = prescribed(st, t, c, dc, ddc);
    if (rc == 0 && st->complete) rc = complete_c1(st, psi, c, dc, ddc, dpsi);
    return rc;
}

int swim_stroke_init(swim_stroke *st, const swim_scene *s, const swim_kernel *k, const swim_stroke_kernel *law,
                     const double *par)
{
    memset(st, 0, sizeof *st);
    st->scene = s;
    st->k = k;
    st->law = law;
    st->par = par;
    st->n = s->n;
    st->complete = s->stroke_complete_c1;
    memcpy(st->base, s->c0, sizeof(double) * s->n);
    st->K = malloc(sizeof(double) * s->n * s->n);
    st->P = malloc(sizeof(double) * 3 * s->n);
    st->g = malloc(sizeof(double) * s->n);
    if (!st->K || !st->P || !st->g) {
        swim_stroke_free(st);
        return -1;
    }
    double c[SWIM_NMAX], dc[SWIM_NMAX], ddc[SWIM_NMAX];
    int rc = prescribed(st, 0.0, c, dc, ddc);
    if (rc != 0) return rc;
    if (st->complete) {   /* c1(0) = c0's c1: its modulus fixes the volume, its argument psi(0) */
        const double r2 = s->c0[0] * s->c0[0] + s->c0[1] * s->c0[1];
        if (!(r2 > 0.0)) return SWIM_STROKE_EVOLUME;
        c[0] = s->c0[0];
        c[1] = s->c0[1];
        st->psi0 = atan2(s->c0[1], s->c0[0]);
    }
    st->mu2 = swim_area_constant(s->n, c);
    return 0;
}

void swim_stroke_free(swim_stroke *st)
{
    free(st->K);
    free(st->P);
    free(st->g);
    st->K = st->P = st->g = NULL;
}

void swim_stroke_initial_state(const swim_stroke *st, double *y)
{
    memset(y, 0, sizeof(double) * SWIM_STROKE_DIM);
    y[SWIM_STROKE_PSI] = st->psi0;
}


/* q* = P c' in the body frame, and P = c'.(K c'' + <Gamma, c', c'>), at shape c. */
static int rigid_and_power(swim_stroke *st, const double *c, const double *dc, const double *ddc, double *qs,
                           double *power)
{
    const swim_scene *s = st->scene;
    const int n = st->n;
    if (st->k->reduced(c, dc, s->rho0, s->rhof, st->K, st->P, st->g) != 0) return SWIM_RHS_EMASS;
    double p = 0.0;
    for (int r = 0; r < 3; r++) {
        qs[r] = 0.0;
        for (int k = 0; k < n; k++) qs[r] += st->P[r * n + k] * dc[k];
    }
    for (int i = 0; i < n; i++) {
        double f = st->g[i];
        for (int j = 0; j < n; j++) f += st->K[i * n + j] * ddc[j];
        p += dc[i] * f;
    }
    *power = p;
    return 0;
}

int swim_stroke_rhs(double t, const double *y, double *dy, void *params)
{
    swim_stroke *st = params;
    const double t0 = swim_clock_seconds();
    st->rhs_calls++;
    st->last_rhs_t = t;
    if (st->interrupt && *st->interrupt) return -SWIM_STROKE_EINTERRUPT;
    for (int i = 0; i < SWIM_STROKE_DIM; i++)
        if (!isfinite(y[i])) return SWIM_RHS_ENAN;
    double c[SWIM_NMAX], dc[SWIM_NMAX], ddc[SWIM_NMAX], dpsi, qs[3], power;
    int rc = swim_stroke_shape(st, t, y[SWIM_STROKE_PSI], c, dc, ddc, &dpsi);
    if (rc == 0) rc = rigid_and_power(st, c, dc, ddc, qs, &power);
    if (rc == 0) {
        swim_to_fixed_frame(y[2], qs, dy);   /* (3.21) */
        dy[SWIM_STROKE_PSI] = dpsi;          /* (2.14) */
        dy[SWIM_STROKE_WORK] = power;
        for (int i = 0; i < SWIM_STROKE_DIM; i++)
            if (!isfinite(dy[i])) rc = SWIM_RHS_ENAN;
    }
    st->rhs_seconds += swim_clock_seconds() - t0;
    return rc;
}

int swim_stroke_full_state(swim_stroke *st, double t, const double *y, double *full, double *power)
{
    const int n = st->n;
    double ddc[SWIM_NMAX], dpsi, qs[3], p;
    memcpy(full, y, 3 * sizeof(double));
    int rc = swim_stroke_shape(st, t, y[SWIM_STROKE_PSI], full + 3, full + 3 + n, ddc, &dpsi);
    full[3 + 2 * n] = y[SWIM_STROKE_WORK];
    if (rc == 0 && power) {
        rc = rigid_and_power(st, full + 3, full + 3 + n, ddc, qs, &p);
        *power = p;
    }
    return rc;
}

int swim_stroke_energy_power(swim_stroke *st, double t, double psi, double *E, double *P)
{
    const int n = st->n;
    double c[SWIM_NMAX], dc[SWIM_NMAX], ddc[SWIM_NMAX], dpsi, qs[3];
    int rc = swim_stroke_shape(st, t, psi, c, dc, ddc, &dpsi);
    if (rc == 0) rc = rigid_and_power(st, c, dc, ddc, qs, P);
    if (rc != 0) return rc;
    double e = 0.0;
    for (int i = 0; i < n; i++)
        for (int j = 0; j < n; j++) e += dc[i] * st->K[i * n + j] * dc[j];
    *E = 0.5 * e;
    return 0;
}

/* psi' at (t, psi): it depends on the prescribed coordinates only. */
static double phase_rate(const swim_stroke *st, double t, double psi)
{
    double c[SWIM_NMAX], dc[SWIM_NMAX], ddc[SWIM_NMAX], dpsi = 0.0;
    return swim_stroke_shape(st, t, psi, c, dc, ddc, &dpsi) == 0 ? dpsi : 0.0;
}

/* Cubic Hermite interpolation of psi on [w->t, t1]. */
static double phase_between(const swim_stroke_poswork *w, double t1, double psi1, double dpsi1, double t)
{
    const double h = t1 - w->t, s = (t - w->t) / h, s2 = s * s, s3 = s2 * s;
    return (2 * s3 - 3 * s2 + 1) * w->psi + (s3 - 2 * s2 + s) * h * w->dpsi + (-2 * s3 + 3 * s2) * psi1
           + (s3 - s2) * h * dpsi1;
}

int swim_stroke_poswork_add(swim_stroke *st, swim_stroke_poswork *w, double t, double psi)
{
    double E, P;
    const double dpsi = phase_rate(st, t, psi);
    int rc = swim_stroke_energy_power(st, t, psi, &E, &P);
    if (rc != 0) return rc;
    if (w->have && t > w->t) {
        if (w->P >= 0.0 && P >= 0.0) {
            w->total += E - w->E;
        } else if ((w->P >= 0.0) != (P >= 0.0)) {   /* one zero of P in between */
            double lo = w->t, hi = t, Em = E, Pm;
            for (int it = 0; it < 60 && hi - lo > 1e-15 * fmax(1.0, fabs(hi)); it++) {
                const double mid = 0.5 * (lo + hi);
                rc = swim_stroke_energy_power(st, mid, phase_between(w, t, psi, dpsi, mid), &Em, &Pm);
                if (rc != 0) return rc;
                if ((Pm >= 0.0) == (w->P >= 0.0)) lo = mid;
                else hi = mid;
            }
            rc = swim_stroke_energy_power(st, 0.5 * (lo + hi), phase_between(w, t, psi, dpsi, 0.5 * (lo + hi)), &Em, &Pm);
            if (rc != 0) return rc;
            w->total += w->P >= 0.0 ? Em - w->E : E - Em;
        }
    }
    w->have = 1;
    w->t = t;
    w->psi = psi;
    w->dpsi = dpsi;
    w->E = E;
    w->P = P;
    return 0;
}

/* ---- allowability ------------------------------------------------------------------------ */

/* The residuals of (2.8), (2.14) and (2.5) at one time and the sizes of their terms. */
typedef struct {
    double volume_rate, volume_rate_scale, angular, angular_scale, volume, volume_scale;
} residuals;

static void constraint_residuals(int n, const double *c, const double *dc, double mu2, residuals *r)
{
    memset(r, 0, sizeof *r);
    for (int i = 0; i < n; i += 2) {
        const int k = swim_coord_mode(i);
        const double a = c[i], b = c[i + 1], da = dc[i], db = dc[i + 1], w = 1.0 / (abs(k) + 1);
        r->volume_rate += k * (a * da + b * db);                          /* (2.8) */
        r->volume_rate_scale += abs(k) * (fabs(a * da) + fabs(b * db));
        r->angular += w * (db * a - da * b);                              /* (2.14) */
        r->angular_scale += w * (fabs(db * a) + fabs(da * b));
        r->volume += k * (a * a + b * b);                                 /* (2.5) */
        r->volume_scale += abs(k) * (a * a + b * b);
    }
    r->volume -= mu2;
}

/* Beyond round-off: more than 1e-10 of the size of the terms (a few hundred roundings of
 * sums of O(n) products; a stroke that is not allowable misses by O(1) of them). */
static int beyond_roundoff(double value, double scale) { return fabs(value) > 1e-10 * scale + 1e-300; }

static int check_at(const swim_stroke *st, double t, int shape_too, double *psi, double *t_last, char *why, size_t len)
{
    const int n = st->n;
    double c[SWIM_NMAX], dc[SWIM_NMAX], ddc[SWIM_NMAX], dpsi = 0.0;
    /* psi for the completed c1: integrated on the samples (trapezoid); (2.8) and (2.14) do not
     * depend on it, min J depends on it only through the orientation of c1, which is why this
     * crude rule serves for the check. */
    int rc = swim_stroke_shape(st, t, *psi, c, dc, ddc, &dpsi);
    if (rc == 0 && st->complete) {
        double c2[SWIM_NMAX], dc2[SWIM_NMAX], ddc2[SWIM_NMAX], dpsi2;
        rc = swim_stroke_shape(st, *t_last, *psi, c2, dc2, ddc2, &dpsi2);
        if (rc == 0) {
            *psi += 0.5 * (t - *t_last) * (dpsi + dpsi2);
            rc = swim_stroke_shape(st, t, *psi, c, dc, ddc, &dpsi);
        }
    }
    *t_last = t;
    if (rc == SWIM_RHS_ENAN) {
        snprintf(why, len, "a stroke law or one of its derivatives is NaN or Inf");
        return 1;
    }
    if (rc != 0) {
        snprintf(why, len, "%s", swim_stroke_strerror(rc));
        return 1;
    }
    residuals r;
    constraint_residuals(n, c, dc, st->mu2, &r);
    if (beyond_roundoff(r.volume_rate, r.volume_rate_scale)) {
        snprintf(why, len, "the volume constraint (2.8) fails: sum k (a_k a'_k + b_k b'_k) = %.6g (terms of size %.3g)",
                 r.volume_rate, r.volume_rate_scale);
        return 1;
    }
    if (beyond_roundoff(r.angular, r.angular_scale)) {
        snprintf(why, len, "the angular constraint (2.14) fails: sum (b'_k a_k - a'_k b_k)/(|k|+1) = %.6g (terms of size %.3g)",
                 r.angular, r.angular_scale);
        return 1;
    }
    if (beyond_roundoff(r.volume, r.volume_scale)) {
        snprintf(why, len, "the volume (2.5) changed: sum k |c_k|^2 - mu^2 = %.6g (mu^2 = %.6g)", r.volume, st->mu2);
        return 1;
    }
    const double jmin = shape_too ? swim_shape_jmin(st->scene->modes, c) : 1.0;
    if (!(jmin > 0.0)) {
        snprintf(why, len, "the shape leaves the admissible set D (4.1): min J = %.4g", jmin);
        return 1;
    }
    return 0;
}

int swim_stroke_check(const swim_stroke *st, double t_end, double output_step, long samples, double *t_bad,
                      char *why, size_t whylen)
{
    /* the union of the equal steps and the output times, in increasing order */
    const long rows = (long)fmin(floor(t_end / output_step + 1e-9), 1e6);
    const double h = t_end / samples;
    const long rstride = rows / 2048 > 1 ? rows / 2048 : 1;
    double psi = st->psi0, t_last = 0.0;
    long i = 0, r = 0;
    for (;;) {
        const double ti = i <= samples ? fmin(i * h, t_end) : INFINITY;
        const double tr = r <= rows ? fmin(r * output_step, t_end) : INFINITY;
        const double t = fmin(ti, tr);
        if (!isfinite(t)) break;
        /* min J (the costly part: 64(N+1) values of J) at every 8th step and at most ~2048 of the
         * output times (the run itself checks every row) */
        const int shape_too = (ti <= t && i % 8 == 0) || (tr <= t && r % rstride == 0);
        if (ti <= t) i++;
        if (tr <= t) r++;
        if (check_at(st, t, shape_too, &psi, &t_last, why, whylen)) {
            *t_bad = t;
            return 1;
        }
    }
    return 0;
}

/* ---- period ------------------------------------------------------------------------------ */

/* |c(T) - c(0)|^2 + |c'(T) - c'(0)|^2 over the prescribed coordinates, and its derivative. */
static double distance(const swim_stroke *st, const double *c0, const double *dc0, double T, double *slope)
{
    double c[SWIM_NMAX], dc[SWIM_NMAX], ddc[SWIM_NMAX], d = 0.0, s = 0.0;
    st->law->eval(T, st->par, c, dc, ddc);
    for (int k = 0; k < st->law->count; k++) {
        d += (c[k] - c0[k]) * (c[k] - c0[k]) + (dc[k] - dc0[k]) * (dc[k] - dc0[k]);
        s += 2.0 * ((c[k] - c0[k]) * dc[k] + (dc[k] - dc0[k]) * ddc[k]);
    }
    if (slope) *slope = s;
    return isfinite(d) ? d : INFINITY;
}

/* The laws at s and s + T agree (c and c') to `tol` at 16 points s of [0, T]. */
static int repeats(const swim_stroke *st, double T, double tol)
{
    double a[SWIM_NMAX], da[SWIM_NMAX], dda[SWIM_NMAX], b[SWIM_NMAX], db[SWIM_NMAX], ddb[SWIM_NMAX];
    for (int j = 0; j < 16; j++) {
        const double s = T * (j + 0.37) / 16.0;
        st->law->eval(s, st->par, a, da, dda);
        st->law->eval(s + T, st->par, b, db, ddb);
        for (int k = 0; k < st->law->count; k++)
            if (!(fabs(a[k] - b[k]) <= tol && fabs(da[k] - db[k]) <= tol)) return 0;
    }
    return 1;
}

double swim_stroke_detect_period(const swim_stroke *st, double t_end)
{
    enum { M = 4096 };
    double c0[SWIM_NMAX], dc0[SWIM_NMAX], ddc0[SWIM_NMAX], d[M + 2], scale = 0.0, dmax = 0.0;
    st->law->eval(0.0, st->par, c0, dc0, ddc0);
    for (int k = 0; k < st->law->count; k++) scale += c0[k] * c0[k] + dc0[k] * dc0[k];
    const double h = t_end / M;
    /* one sample past t_end, so that a period equal to t_end is bracketed too */
    for (int j = 0; j <= M + 1; j++) {
        d[j] = j ? distance(st, c0, dc0, j * h, NULL) : 0.0;
        if (isfinite(d[j])) dmax = fmax(dmax, d[j]);
    }
    if (!(dmax > 0.0)) return 0.0;   /* the laws do not move */
    for (int j = 1; j <= M; j++) {
        if (!(d[j] <= d[j - 1] && d[j] <= d[j + 1]) || !(d[j] < 1e-2 * dmax)) continue;
        /* d'(T) goes from - to + across the minimum: bisection to round-off */
        double lo = (j - 1) * h, hi = (j + 1) * h, s;
        distance(st, c0, dc0, lo, &s);
        if (s > 0.0) continue;
        distance(st, c0, dc0, hi, &s);
        if (s < 0.0) continue;
        for (int it = 0; it < 200 && hi - lo > 4e-16 * hi; it++) {
            const double mid = 0.5 * (lo + hi);
            distance(st, c0, dc0, mid, &s);
            if (s < 0.0) lo = mid;
            else hi = mid;
        }
        const double T = 0.5 * (lo + hi);
        if (T > t_end * (1 + 1e-12)) break;
        if (distance(st, c0, dc0, T, NULL) <= 1e-16 * (1.0 + scale) && repeats(st, T, 1e-7 * (1.0 + sqrt(scale))))
            return T;
    }
    return 0.0;
}
