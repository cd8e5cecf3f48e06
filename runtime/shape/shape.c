#include "shape/shape.h"

#include "kernel/coords.h"

#include <math.h>
#include "shape/quad.h"
#include <stdlib.h>
#include <string.h>

#define TWO_PI 6.28318530717958647692
#define NEWTON_MAXIT 40

/* p[m-1] = m c_{-m} (re, im): the coefficients of P (see shape.h). */
static void coefficients(int modes, const double *x, double *pr, double *pi)
{
    for (int m = 1; m <= modes; m++) {
        const int i = swim_coord_index(-m);
        pr[m - 1] = m * x[i];
        pi[m - 1] = m * x[i + 1];
    }
}

/* J and its first two derivatives in theta at theta (d1, d2 may be NULL). With
 * w = e^{-i theta}: P_theta = sum -i(m-1) p_m w^{m-1}, P_thetatheta = sum -(m-1)^2 p_m w^{m-1};
 * J' = -2 Re(conj(P) P_theta), J'' = -2 (|P_theta|^2 + Re(conj(P) P_thetatheta)). */
static double j_derivs(int modes, double c1sq, const double *pr, const double *pi, double theta, double *d1,
                       double *d2)
{
    const double cr = cos(theta), ci = -sin(theta);
    double wr = 1.0, wi = 0.0;            /* w^{m-1} */
    double Pr = 0, Pi = 0, Qr = 0, Qi = 0, Rr = 0, Ri = 0;   /* P, sum (m-1) p w^{m-1}, sum (m-1)^2 p w^{m-1} */
    for (int m = 1; m <= modes; m++) {
        const double tr = pr[m - 1] * wr - pi[m - 1] * wi, ti = pr[m - 1] * wi + pi[m - 1] * wr;
        const double k = m - 1;
        Pr += tr; Pi += ti;
        Qr += k * tr; Qi += k * ti;
        Rr += k * k * tr; Ri += k * k * ti;
        const double nr = wr * cr - wi * ci;
        wi = wr * ci + wi * cr;
        wr = nr;
    }
    /* P_theta = -i Q, P_thetatheta = -R */
    const double Ptr = Qi, Pti = -Qr;
    if (d1) *d1 = -2.0 * (Pr * Ptr + Pi * Pti);
    if (d2) *d2 = -2.0 * (Ptr * Ptr + Pti * Pti - (Pr * Rr + Pi * Ri));
    return c1sq - (Pr * Pr + Pi * Pi);
}

/* The local minimum of J in [a, b] (J'(a) < 0 < J'(b) expected) by Newton on J' = 0, kept inside
 * the bracket (bisection when Newton would leave it or J'' <= 0). Newton converges quadratically;
 * it stops once the step is below 1e-9, where J is exact to ~J'' 1e-18 (rounding). Returns J
 * there, angle in *th. */
static double refine(int modes, double c1sq, const double *pr, const double *pi, double a, double b, double t0,
                     double *th)
{
    double t = t0, best = INFINITY, tbest = t0;
    for (int it = 0; it < NEWTON_MAXIT; it++) {
        double d1, d2, J = j_derivs(modes, c1sq, pr, pi, t, &d1, &d2);
        if (J < best) { best = J; tbest = t; }
        if (d1 > 0) b = t; else if (d1 < 0) a = t; else break;
        double next = d2 > 0 ? t - d1 / d2 : 0.5 * (a + b);
        if (!(next > a && next < b)) next = 0.5 * (a + b);
        if (fabs(next - t) <= 1e-9 || b - a <= 1e-9) {
            t = next;
            J = j_derivs(modes, c1sq, pr, pi, t, NULL, NULL);
            if (J < best) { best = J; tbest = t; }
            break;
        }
        t = next;
    }
    *th = tbest;
    return best;
}

/* min J (with its angle in *theta). With sign_only, a value of the right sign is enough: when
 * the samples decide it (all above the largest dip between them, or one at or below 0) the
 * refinement is skipped and the value returned only has the sign of min J. */
static double jmin_impl(int modes, const double *x, double *theta, int sign_only)
{
    const double c1sq = x[0] * x[0] + x[1] * x[1];
    if (theta) *theta = 0.0;
    if (modes <= 1) {   /* P is constant: J too */
        double J = modes == 1 ? c1sq - (x[2] * x[2] + x[3] * x[3]) : c1sq;
        return isnan(J) ? NAN : J;
    }
    double pr[SWIM_KERNEL_MAX_MODES], pi[SWIM_KERNEL_MAX_MODES];
    coefficients(modes, x, pr, pi);
    while (modes > 1 && pr[modes - 1] == 0.0 && pi[modes - 1] == 0.0) modes--;   /* locked at 0: a lower degree */
    if (modes == 1) {
        const double J = c1sq - (pr[0] * pr[0] + pi[0] * pi[0]);
        return isnan(J) ? NAN : J;
    }
    if (modes == 2) {
        /* |p1 + p2 w| is largest where p2 w has the argument of p1: the triangle inequality is
         * attained, min J = |c_1|^2 - (|p1| + |p2|)^2 at w = e^{i(arg p1 - arg p2)} */
        const double m1 = sqrt(pr[0] * pr[0] + pi[0] * pi[0]), m2 = sqrt(pr[1] * pr[1] + pi[1] * pi[1]);
        const double J = c1sq - (m1 + m2) * (m1 + m2);
        if (isnan(J)) return NAN;
        if (theta) {
            double th = atan2(pi[1], pr[1]) - atan2(pi[0], pr[0]);   /* -arg w */
            th = fmod(th, TWO_PI);
            *theta = th < 0 ? th + TWO_PI : th;
        }
        return J;
    }
    /* |J''| <= 2 (|P_theta|^2 + |P||P_thetatheta|) <= 2 (s1^2 + s0 s2), s_j = sum (m-1)^j |p_m|:
     * between two samples h apart, the minimum lies at most J''max h^2 / 8 below the nearer one. */
    double s0 = 0, s1 = 0, s2 = 0;
    for (int m = 1; m <= modes; m++) {
        const double a = sqrt(pr[m - 1] * pr[m - 1] + pi[m - 1] * pi[m - 1]), k = m - 1;
        s0 += a; s1 += k * a; s2 += k * k * a;
    }
    const int S = 8 * (modes + 1);
    const double h = TWO_PI / S, margin = 2.0 * (s1 * s1 + s0 * s2) * h * h / 8.0;
    double Js[8 * (SWIM_KERNEL_MAX_MODES + 1)];
    /* samples at theta_q = q h; w_q = e^{-i q h} by rotation, restarted exactly every 16 samples.
     * The runs of 16 are independent: they advance side by side, so that their chains of
     * dependent products overlap instead of following one another (each w_q is the same
     * sequence of operations as in one run after the other). */
    enum { RUN = 16, RUNS = (8 * (SWIM_KERNEL_MAX_MODES + 1) + RUN - 1) / RUN };
    double wr[8 * (SWIM_KERNEL_MAX_MODES + 1)], wi[8 * (SWIM_KERNEL_MAX_MODES + 1)];
    double Pr[8 * (SWIM_KERNEL_MAX_MODES + 1)], Pi[8 * (SWIM_KERNEL_MAX_MODES + 1)];
    const double rr = cos(h), ri = -sin(h);
    double zr[RUNS], zi[RUNS], best = INFINITY;
    const int runs = (S + RUN - 1) / RUN;
    for (int r = 0; r < runs; r++) {
        const int q = r * RUN;
        zr[r] = cos(q * h);
        zi[r] = -sin(q * h);
    }
    for (int j = 0; j < RUN; j++)
        for (int r = 0; r < runs; r++) {
            const int q = r * RUN + j;
            if (q >= S) continue;
            wr[q] = zr[r];
            wi[q] = zi[r];
            const double nr = zr[r] * rr - zi[r] * ri;
            zi[r] = zr[r] * ri + zi[r] * rr;
            zr[r] = nr;
        }
    for (int q = 0; q < S; q++) {
        Pr[q] = pr[modes - 1];
        Pi[q] = pi[modes - 1];
    }
    for (int m = modes - 1; m >= 1; m--)   /* Horner in w, all samples at once (a vector loop) */
        for (int q = 0; q < S; q++) {
            const double nr = Pr[q] * wr[q] - Pi[q] * wi[q] + pr[m - 1];
            Pi[q] = Pr[q] * wi[q] + Pi[q] * wr[q] + pi[m - 1];
            Pr[q] = nr;
        }
    for (int q = 0; q < S; q++) Js[q] = c1sq - (Pr[q] * Pr[q] + Pi[q] * Pi[q]);
    /* the smallest sample, the first where there are several: the minimum over 8 lanes (exact,
     * so in any order; S is a multiple of 8), then its first index -- a search that kept the
     * index with the value was a serial chain of comparisons over all samples */
    double lane[8];
    int finite = 1;
    for (int l = 0; l < 8; l++) lane[l] = INFINITY;
    for (int q = 0; q < S; q += 8)
        for (int l = 0; l < 8; l++) {
            const double J = Js[q + l];
            finite &= J == J;
            lane[l] = J < lane[l] ? J : lane[l];
        }
    if (!finite) return NAN;
    for (int l = 0; l < 8; l++) best = lane[l] < best ? lane[l] : best;
    int qbest = 0;
    while (!(Js[qbest] == best)) qbest++;
    best = Js[qbest];   /* of the first such sample (+0 or -0 alike) */
    if (sign_only && (best - margin > 0 || !(best > 0))) return best - margin > 0 ? best : fmin(best, 0.0);
    /* the angle goes with the value: a minimum lying on a sample (a mirror-symmetric shape has
     * it at 0, pi/2, pi or 3pi/2) may refine to a value a rounding above the sample's, and then
     * the sample -- its value and its angle -- is the answer (d/dt min J and the precise J near
     * the barrier are taken at this angle) */
    double jmin = best, tmin = qbest * h;
    for (int q = 0; q < S; q++) {
        /* the neighbours on the circle without an integer division per sample (S is no constant) */
        const double Jq = Js[q], Jl = Js[q > 0 ? q - 1 : S - 1], Jr = Js[q + 1 < S ? q + 1 : 0];
        if (Jq > Jl || Jq > Jr || Jq > best + margin) continue;
        if (Jq == Jl && q > 0) continue;   /* a flat run: refine it once */
        /* Newton starts at the vertex of the parabola through the three samples */
        const double curv = Jl - 2.0 * Jq + Jr;
        double t0 = q * h;
        if (curv > 0) t0 += fmax(-0.5, fmin(0.5, 0.5 * (Jl - Jr) / curv)) * h;
        double th;
        double J = refine(modes, c1sq, pr, pi, (q - 1) * h, (q + 1) * h, t0, &th);
        if (J <= jmin) { jmin = J; tmin = th; }
    }
    if (theta) {
        tmin = fmod(tmin, TWO_PI);
        *theta = tmin < 0 ? tmin + TWO_PI : tmin;
    }
    return jmin;
}

double swim_shape_jmin_at(int modes, const double *x, double *theta) { return jmin_impl(modes, x, theta, 0); }

double swim_shape_jmin(int modes, const double *x) { return jmin_impl(modes, x, NULL, 0); }

double swim_shape_j_rate(int modes, const double *x, const double *v, double theta)
{
    /* J = |c_1|^2 - |P|^2: dJ/dt = 2 Re(conj(c_1) c_1') - 2 Re(conj(P) P(v)), P linear in c */
    double rate = 2.0 * (x[0] * v[0] + x[1] * v[1]);
    const double cr = cos(theta), ci = -sin(theta);
    double wr = 1.0, wi = 0.0, Pr = 0, Pi = 0, Vr = 0, Vi = 0;
    for (int m = 1; m <= modes; m++) {
        const int i = swim_coord_index(-m);
        Pr += m * (x[i] * wr - x[i + 1] * wi);
        Pi += m * (x[i] * wi + x[i + 1] * wr);
        Vr += m * (v[i] * wr - v[i + 1] * wi);
        Vi += m * (v[i] * wi + v[i + 1] * wr);
        const double nr = wr * cr - wi * ci;
        wi = wr * ci + wi * cr;
        wr = nr;
    }
    return rate - 2.0 * (Pr * Vr + Pi * Vi);
}

int swim_shape_jmin_rate(int modes, const double *x, const double *v, double *J, double *rate)
{
    double pr[SWIM_KERNEL_MAX_MODES], pi[SWIM_KERNEL_MAX_MODES], vr[SWIM_KERNEL_MAX_MODES], vi[SWIM_KERNEL_MAX_MODES];
    if (modes < 1) return 0;
    coefficients(modes, x, pr, pi);
    coefficients(modes, v, vr, vi);
    while (modes > 1 && pr[modes - 1] == 0.0 && pi[modes - 1] == 0.0) modes--;   /* as jmin_impl */
    const double c1sq = x[0] * x[0] + x[1] * x[1], c1rate = 2.0 * (x[0] * v[0] + x[1] * v[1]);
    if (modes == 1) {   /* J = |c_1|^2 - |p_1|^2 on the whole circle */
        *J = c1sq - (pr[0] * pr[0] + pi[0] * pi[0]);
        *rate = c1rate - 2.0 * (pr[0] * vr[0] + pi[0] * vi[0]);
        return !isnan(*J);
    }
    if (modes != 2) return 0;
    const double m1 = sqrt(pr[0] * pr[0] + pi[0] * pi[0]), m2 = sqrt(pr[1] * pr[1] + pi[1] * pi[1]);
    if (!(m1 > 0.0 && m2 > 0.0)) return 0;
    *J = c1sq - (m1 + m2) * (m1 + m2);
    const double m1rate = (pr[0] * vr[0] + pi[0] * vi[0]) / m1, m2rate = (pr[1] * vr[1] + pi[1] * vi[1]) / m2;
    *rate = c1rate - 2.0 * (m1 + m2) * (m1rate + m2rate);
    return !isnan(*J);
}

int swim_shape_in_D(int modes, const double *x)
{
    double bound = 0.0;
    for (int m = 1; m <= modes; m++) {
        const int i = swim_coord_index(-m);
        /* a mode at 0 adds +0 (its root is a latency chain of its own): the same sum without it */
        if (x[i] != 0.0 || x[i + 1] != 0.0) bound += m * sqrt(x[i] * x[i] + x[i + 1] * x[i + 1]);
    }
    const double c1 = sqrt(x[0] * x[0] + x[1] * x[1]);
    if (c1 > bound * (1.0 + 1e-12)) return 1;   /* margin: J > 0 with room for rounding */
    return jmin_impl(modes, x, NULL, 1) > 0.0;
}

/* ---- double-double arithmetic (value hi + lo, |lo| <= ulp(hi)/2: 106 bits) ------------------ */

typedef struct {
    double hi, lo;
} dd;

static inline dd dd_fast_sum(double a, double b)   /* |a| >= |b| */
{
    const double s = a + b;
    return (dd){s, b - (s - a)};
}

static inline dd dd_sum(double a, double b)        /* a + b exactly (Knuth's TwoSum) */
{
    const double s = a + b, bb = s - a;
    return (dd){s, (a - (s - bb)) + (b - bb)};
}

static inline dd dd_add(dd x, dd y)
{
    dd s = dd_sum(x.hi, y.hi), t = dd_sum(x.lo, y.lo);
    s.lo += t.hi;
    s = dd_fast_sum(s.hi, s.lo);
    s.lo += t.lo;
    return dd_fast_sum(s.hi, s.lo);
}

static inline dd dd_neg(dd x) { return (dd){-x.hi, -x.lo}; }

static inline dd dd_mul(dd x, dd y)
{
    const double p = x.hi * y.hi, e = fma(x.hi, y.hi, -p);   /* x.hi y.hi exactly: p + e */
    return dd_fast_sum(p, e + (x.hi * y.lo + x.lo * y.hi));
}

static inline dd dd_mul_d(dd x, double d)
{
    const double p = x.hi * d, e = fma(x.hi, d, -p);
    return dd_fast_sum(p, e + x.lo * d);
}

static inline dd dd_div_d(dd x, double d)
{
    const double q = x.hi / d, p = q * d, e = fma(q, d, -p);   /* q d = p + e exactly */
    return dd_fast_sum(q, ((x.hi - p) - e + x.lo) / d);
}

/* cos and sin of the double theta to about 2^-104: theta - k pi/2 in binary128 (the only
 * binary128 operations; pi/2 to 113 bits keeps |theta| < 1e6 exact to far below 2^-106), then
 * the Taylor series of both on |r| <= pi/4, whose terms r^n/n! fall below 2^-110 by n = 29. */
static void dd_cos_sin(double theta, dd *c, dd *sn)
{
    const __float128 halfpi = M_PIq / 2;
    const double k = nearbyint(theta / (double)halfpi);
    const __float128 rq = (__float128)theta - (__float128)k * halfpi;
    const double rh = (double)rq;
    const dd r = {rh, (double)(rq - (__float128)rh)};
    dd cr = {1.0, 0.0}, sr = r, t = r;
    for (int n = 2; n <= 29; n++) {
        t = dd_div_d(dd_mul(t, r), (double)n);   /* r^n / n! */
        if (n % 2 == 0) cr = dd_add(cr, n % 4 == 0 ? t : dd_neg(t));
        else sr = dd_add(sr, n % 4 == 1 ? t : dd_neg(t));
    }
    switch (((long long)k % 4 + 4) % 4) {   /* theta = r + k pi/2 */
    case 0: *c = cr; *sn = sr; break;
    case 1: *c = dd_neg(sr); *sn = cr; break;
    case 2: *c = dd_neg(cr); *sn = dd_neg(sr); break;
    default: *c = sr; *sn = dd_neg(cr); break;
    }
}

/* J and J' in double-double at the shape x + lo: P = sum_j H_j conj(z)^j and
 * dP/dtheta = sum -i j H_j conj(z)^j by powers of conj(z) = e^{-i theta} (as the binary128
 * evaluation it replaces, a fifth of its cost), J = |c_1|^2 - |P|^2, J' = -2 Re(conj(P) dP). The
 * error is a few 1e-31 of the terms (|c_1|^2 ~ |P|^2), against their difference J down to 1e-16
 * of them: still far below the rounding of the result to double. */
double swim_shape_j_precise(int modes, const double *x, const double *lo, double theta, double *J1)
{
    if (fabs(theta) > 1e6) theta = fmod(theta, TWO_PI);   /* keeps dd_cos_sin's reduction exact */
    dd zr, zi;
    dd_cos_sin(theta, &zr, &zi);
    zi = dd_neg(zi);                                    /* conj(z) = e^{-i theta} */
    dd pr = {1.0, 0.0}, pi = {0.0, 0.0};               /* conj(z)^j */
    dd hr = {0.0, 0.0}, hi = {0.0, 0.0}, dr = {0.0, 0.0}, di = {0.0, 0.0};
    for (int j = 0; j < modes; j++) {
        const int r = 2 * (j + 1);
        const dd Hr = dd_mul_d(dd_sum(x[r], lo ? lo[r] : 0.0), j + 1);
        const dd Hi = dd_mul_d(dd_sum(x[r + 1], lo ? lo[r + 1] : 0.0), j + 1);
        const dd tr = dd_add(dd_mul(Hr, pr), dd_neg(dd_mul(Hi, pi)));
        const dd ti = dd_add(dd_mul(Hr, pi), dd_mul(Hi, pr));
        hr = dd_add(hr, tr);
        hi = dd_add(hi, ti);
        dr = dd_add(dr, dd_mul_d(ti, j));   /* -i j (tr + i ti) = j ti - i j tr */
        di = dd_add(di, dd_neg(dd_mul_d(tr, j)));
        const dd nr = dd_add(dd_mul(pr, zr), dd_neg(dd_mul(pi, zi)));
        pi = dd_add(dd_mul(pr, zi), dd_mul(pi, zr));
        pr = nr;
    }
    const dd a1 = dd_sum(x[0], lo ? lo[0] : 0.0), b1 = dd_sum(x[1], lo ? lo[1] : 0.0);
    if (J1) {
        const dd g = dd_add(dd_mul(hr, dr), dd_mul(hi, di));
        *J1 = -2.0 * (g.hi + g.lo);
    }
    const dd J = dd_add(dd_add(dd_mul(a1, a1), dd_mul(b1, b1)), dd_neg(dd_add(dd_mul(hr, hr), dd_mul(hi, hi))));
    return J.hi + J.lo;
}
