/* Tests of runtime/model/barrier.c: W2 and grad W2 from min J = 0.5 down to 1e-10.
 *
 * The reference is computed independently, in binary128 throughout: J straight from ERRATA B2 at
 * every node, the minima of J located by dense sampling and golden-section search, and a composite
 * 30-point Gauss-Legendre rule on panels graded geometrically (ratio 2) toward every local
 * minimum down to a quarter of its width sqrt(J_min / J''), plus a uniform subdivision of the
 * rest. It shares no code with the rule under test (different panels, node counts, evaluation of
 * J and precision).
 */
#include "shape/barrier.h"
#include "shape/shape.h"

#include "check.h"

#include <math.h>
#include "shape/quad.h"
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

typedef __float128 real;
#define PI_Q M_PIq

static uint64_t rng_state = 88172645463325252ull;
static double urand(void)   /* xorshift64, uniform in (-1, 1) */
{
    rng_state ^= rng_state << 13;
    rng_state ^= rng_state >> 7;
    rng_state ^= rng_state << 17;
    return (double)(rng_state >> 11) / 4503599627370496.0 - 1.0;
}

/* J(theta) = |c_1|^2 - |h|^2, h = sum_{m=1}^N m c_-m e^{-i (m-1) theta} (ERRATA B2), and, when g
 * is not NULL, grad J (ERRATA B3: dJ/da_-m = -2m Re(z^{m-1} h), dJ/db_-m = -2m Im(z^{m-1} h)),
 * all in binary128. */
static real jgq(int N, const double *x, real th, real *g)
{
    const real c1 = cosq(th), s1 = sinq(th);
    real hr = 0, hi = 0, pr = 1, pi = 0;          /* e^{-i (m-1) theta} */
    for (int m = 1; m <= N; m++) {
        real ar = (real)m * x[2 * m], ai = (real)m * x[2 * m + 1];
        hr += ar * pr - ai * pi;
        hi += ar * pi + ai * pr;
        real t = pr * c1 + pi * s1;
        pi = pi * c1 - pr * s1;
        pr = t;
    }
    if (g) {
        g[0] = 2 * (real)x[0];
        g[1] = 2 * (real)x[1];
        real zr = 1, zi = 0;                      /* z^{m-1} */
        for (int m = 1; m <= N; m++) {
            g[2 * m] = -2 * m * (zr * hr - zi * hi);
            g[2 * m + 1] = -2 * m * (zr * hi + zi * hr);
            real t = zr * c1 - zi * s1;
            zi = zr * s1 + zi * c1;
            zr = t;
        }
    }
    return (real)x[0] * x[0] + (real)x[1] * x[1] - hr * hr - hi * hi;
}
static real jq(int N, const double *x, real th) { return jgq(N, x, th, NULL); }

static double gx30[30], gw30[30];
static void gauss30(void)
{
    const int q = 30;
    for (int i = 0; i < q; i++) {
        long double z = cosl(3.14159265358979323846264338327950288L * (i + 0.75L) / (q + 0.5L)), dp = 0;
        for (int it = 0; it < 100; it++) {
            long double p0 = 1, p1 = z;
            for (int k = 2; k <= q; k++) {
                long double p2 = ((2 * k - 1) * z * p1 - (k - 1) * p0) / k;
                p0 = p1;
                p1 = p2;
            }
            dp = q * (z * p1 - p0) / (z * z - 1);
            long double dz = p1 / dp;
            z -= dz;
            if (fabsl(dz) < 1e-19L) break;
        }
        gx30[i] = (double)z;
        gw30[i] = (double)(2 / ((1 - z * z) * dp * dp));
    }
}

static int cmp_real(const void *a, const void *b)
{
    real x = *(const real *)a, y = *(const real *)b;
    return x < y ? -1 : x > y;
}

/* Local minima of J (binary128), refined by golden-section search. */
static int minima(int N, const double *x, real *th, real *jv, real *width)
{
    const int M = 16 * (N + 1);
    real *J = malloc(sizeof(real) * M);
    for (int k = 0; k < M; k++) J[k] = jq(N, x, 2 * PI_Q * k / M);
    int n = 0;
    for (int k = 0; k < M && n < 64; k++) {
        real jl = J[(k + M - 1) % M], jr = J[(k + 1) % M];
        if (!(J[k] < jl && J[k] <= jr)) continue;
        real a = 2 * PI_Q * (k - 1) / M, b = 2 * PI_Q * (k + 1) / M, g = (sqrtq(5) - 1) / 2;
        real c = b - g * (b - a), d = a + g * (b - a), fc = jq(N, x, c), fd = jq(N, x, d);
        for (int it = 0; it < 120; it++) {
            if (fc < fd) { b = d; d = c; fd = fc; c = b - g * (b - a); fc = jq(N, x, c); }
            else         { a = c; c = d; fc = fd; d = a + g * (b - a); fd = jq(N, x, d); }
        }
        real t = (a + b) / 2, Jt = jq(N, x, t), h = 1e-6Q;
        real J2 = (jq(N, x, t + h) - 2 * Jt + jq(N, x, t - h)) / (h * h);
        th[n] = t;
        jv[n] = Jt;
        width[n] = J2 > 0 ? sqrtq(fabsq(Jt) / J2) : 1;
        n++;
    }
    free(J);
    return n;
}

/* Reference W2 and gradient (binary128, 30-point Gauss on graded panels) for each of the na
 * exponents alpha[a], into W[a] and grad + a * NG: J and its gradient are evaluated once per node
 * for all of them, since they are nearly all of the reference's time. Returns min J. */
enum { NG = 2 * 33 + 2, NA = 3 };
static double reference(int N, const double *x, double eps, const double *alpha, int na, double *W,
                        double *grad)
{
    real th[64], jv[64], wd[64];
    int nm = minima(N, x, th, jv, wd);
    int cap = 4096, nb = 0;
    real *brk = malloc(sizeof(real) * cap);
    real jmin = 1e300Q;
    for (int k = 0; k < 8 * (N + 1); k++) brk[nb++] = 2 * PI_Q * k / (8 * (N + 1));
    for (int i = 0; i < nm; i++) {
        if (jv[i] < jmin) jmin = jv[i];
        for (real r = wd[i] / 4; r < PI_Q && nb < cap - 2; r *= 2) {
            brk[nb++] = fmodq(th[i] + r + 2 * PI_Q, 2 * PI_Q);
            brk[nb++] = fmodq(th[i] - r + 4 * PI_Q, 2 * PI_Q);
        }
        brk[nb++] = fmodq(th[i] + 2 * PI_Q, 2 * PI_Q);
    }
    qsort(brk, nb, sizeof(real), cmp_real);
    real S[NA] = {0}, G[NA][NG];
    const int n = 2 * (N + 1);
    for (int a = 0; a < na; a++)
        for (int i = 0; i < n; i++) G[a][i] = 0;
    for (int p = 0; p < nb; p++) {
        real u = brk[p], v = p + 1 < nb ? brk[p + 1] : brk[0] + 2 * PI_Q;
        if (!(v > u)) continue;
        real mid = (u + v) / 2, half = (v - u) / 2;
        for (int k = 0; k < 30; k++) {
            real t = mid + half * gx30[k], w = half * gw30[k];
            real g[NG];
            real J = jgq(N, x, t, g);
            for (int a = 0; a < na; a++) {
                real f = powq(J, -(real)alpha[a]);
                S[a] += w * f;
                for (int i = 0; i < n; i++) G[a][i] += w * f / J * g[i];
            }
        }
    }
    free(brk);
    for (int a = 0; a < na; a++) {
        W[a] = (double)(eps / (2 * alpha[a]) * S[a]);
        for (int i = 0; i < n; i++) grad[a * NG + i] = (double)(-0.5 * eps * G[a][i]);
    }
    return (double)jmin;
}

/* The binary128 reference is nearly all of this program's time (software floating point). Built
 * with AddressSanitizer -- which checks the rule's memory use, not its accuracy: the plain build
 * does that -- the program compares one shape in REF_EVERY with it; every shape still runs the
 * rule and must give finite values. */
#if defined(__SANITIZE_ADDRESS__)
#define REF_EVERY 8
#else
#define REF_EVERY 1
#endif
static int reference_due(void)
{
    static int cases;
    return cases++ % REF_EVERY == 0;
}

static int all_finite(double W, const double *g, int n)
{
    int ok = isfinite(W);
    for (int i = 0; i < n; i++) ok &= isfinite(g[i]);
    return ok;
}

/* A random shape whose min J is about `target`: random c_-m decaying like m^-decay, scaled. */
static void make_shape(int N, double decay, double target, double *x)
{
    const int n = 2 * (N + 1);
    memset(x, 0, sizeof(double) * n);
    double ang = M_PI * urand();
    x[0] = cos(ang);
    x[1] = sin(ang);
    for (int m = 1; m <= N; m++) {
        x[2 * m] = urand() / pow(m, decay);
        x[2 * m + 1] = urand() / pow(m, decay);
    }
    if (N <= 1) {    /* J = |c_1|^2 - |c_-1|^2 is constant */
        x[2] *= 0.5;
        x[3] *= 0.5;
        return;
    }
    /* max |h|^2 = 1 - min J at scale 1, then scale h */
    real th[64], jv[64], wd[64];
    int nm = minima(N, x, th, jv, wd);
    real jm = 1;
    for (int i = 0; i < nm; i++) if (jv[i] < jm) jm = jv[i];
    real hmax = 1 - jm, s = sqrtq((1 - (real)target) / hmax);
    for (int i = 2; i < n; i++) x[i] = (double)(s * x[i]);
}

static double max_abs_diff(const double *a, const double *b, int n, double *scale)
{
    double d = 0, m = 0;
    for (int i = 0; i < n; i++) {
        d = fmax(d, fabs(a[i] - b[i]));
        m = fmax(m, fabs(b[i]));
    }
    *scale = m;
    return d;
}

static void accuracy(void)
{
    static const int modes[] = {0, 1, 2, 3, 5, 8, 12, 20, 32};
    static const double targets[] = {0.5, 1e-2, 1e-4, 1e-6, 1e-8, 1e-10};
    static const double alphas[NA] = {0.5, 1.0, 1.5};
    double worst = 0, worst_g = 0;
    printf("%4s %6s %9s %5s %8s %6s %9s %9s\n", "N", "decay", "min J", "alpha", "rule", "nodes",
           "err W", "err grad");
    for (size_t a = 0; a < sizeof modes / sizeof *modes; a++) {
        const int N = modes[a], n = 2 * (N + 1);
        swim_barrier_quad *b = swim_barrier_quad_new(N);
        CHECK(b != NULL, "swim_barrier_quad_new(%d)", N);
        for (int decay = 1; decay <= 2; decay++)
            for (size_t t = 0; t < sizeof targets / sizeof *targets; t++) {
                if (N <= 1 && t > 0) break;    /* J is constant: nothing to approach */
                double x[NG], Wr[NA], gr[NA * NG], jmin = 0.0;
                make_shape(N, decay, targets[t], x);
                const int due = reference_due();
                if (due) jmin = reference(N, x, 0.03, alphas, NA, Wr, gr);
                for (int k = 0; k < NA; k++) {
                    double W, g[NG], scale;
                    swim_barrier_info info;
                    const int rc = swim_barrier_w2(b, x, 0.03, alphas[k], &W, g, &info);
                    if (!due) {
                        CHECK(rc == SWIM_BARRIER_OK && all_finite(W, g, n), "N=%d target %g: rc %d", N, targets[t], rc);
                        continue;
                    }
                    CHECK(rc == SWIM_BARRIER_OK, "N=%d min J %g: rc %d", N, jmin, rc);
                    double eW = fabs(W - Wr[k]) / fabs(Wr[k]);
                    double eg = max_abs_diff(g, gr + k * NG, n, &scale) / scale;
                    worst = fmax(worst, eW);
                    worst_g = fmax(worst_g, eg);
                    printf("%4d %6d %9.2e %5.2g %8s %6d %9.1e %9.1e\n", N, decay, jmin, alphas[k],
                           info.graded ? "graded" : "trapez", info.nodes, eW, eg);
                    CHECK(eW <= 1e-12, "N=%d decay %d min J %.3g alpha %g: W rel error %.2e",
                          N, decay, jmin, alphas[k], eW);
                    CHECK(eg <= 1e-12, "N=%d decay %d min J %.3g alpha %g: grad rel error %.2e",
                          N, decay, jmin, alphas[k], eg);
                }
            }
        swim_barrier_quad_free(b);
    }
    printf("worst relative error: W %.2e, grad %.2e\n", worst, worst_g);
}

/* Shapes with only the low modes excited at large N (the soft scenes start so): J has few zeros,
 * so the graded rule's panels are long, while the gradient's integrands carry e^{ik theta} up to
 * |k| = N - 1 (ERRATA B3). Every component of the gradient must still meet the contract. */
static void sparse(void)
{
    static const int modes[] = {12, 20, 32};
    static const double targets[] = {0.9, 0.44, 1e-2, 1e-4, 1e-7, 1e-10};
    double worst = 0, worst_g = 0;
    for (size_t a = 0; a < sizeof modes / sizeof *modes; a++) {
        const int N = modes[a], n = 2 * (N + 1);
        swim_barrier_quad *b = swim_barrier_quad_new(N);
        for (size_t t = 0; t < sizeof targets / sizeof *targets; t++)
            for (int trial = 0; trial < 3; trial++) {
                double x[NG], Wr[2], gr[2 * NG], jmin = 0.0;
                make_shape(3, 1, targets[t], x);   /* c_1, c_-1 .. c_-3 */
                for (int i = 8; i < n; i++) x[i] = 0.0;
                static const double alphas[2] = {0.5, 1.0};
                const int due = reference_due();
                if (due) jmin = reference(N, x, 0.03, alphas, 2, Wr, gr);
                for (int k = 0; k < 2; k++) {
                    double W, g[NG], scale;
                    swim_barrier_info info;
                    const int rc = swim_barrier_w2(b, x, 0.03, alphas[k], &W, g, &info);
                    if (!due) {
                        CHECK(rc == SWIM_BARRIER_OK && all_finite(W, g, n), "sparse N=%d target %g: rc %d", N,
                              targets[t], rc);
                        continue;
                    }
                    const double eW = fabs(W - Wr[k]) / fabs(Wr[k]);
                    const double eg = max_abs_diff(g, gr + k * NG, n, &scale) / scale;
                    worst = fmax(worst, eW);
                    worst_g = fmax(worst_g, eg);
                    CHECK(rc == SWIM_BARRIER_OK && eW <= 1e-12 && eg <= 1e-12,
                          "sparse N=%d min J %.3g alpha %g (%s, %d nodes): W rel error %.2e, grad %.2e", N, jmin,
                          alphas[k], info.graded ? "graded" : "trapezoidal", info.nodes, eW, eg);
                }
            }
        swim_barrier_quad_free(b);
    }
    printf("low modes only at N = 12, 20, 32: worst relative error W %.2e, grad %.2e\n", worst, worst_g);
}

/* swim_barrier_reach against W2 along the path it models: scaling c_1 moves J down uniformly
 * (J = |c_1|^2 - |h|^2), so the shape whose min J is s is x with |c_1|^2 lowered by j0 - s. The
 * energy the estimate assigns to depth s must be the rise of W2 along that path, to the accuracy
 * of the asymptotic model (the regular part of the integral is neglected). */
static void reach(void)
{
    static const int Ns[] = {3, 7, 15};
    static const double alphas[] = {0.5, 1.0, 1.5};
    double worst = 0.0;
    for (int in = 0; in < 3; in++) {
        const int N = Ns[in], n = 2 * (N + 1);
        swim_barrier_quad *b = swim_barrier_quad_new(N);
        double x[66], y[66];
        make_shape(N, 1.0, 1e-3, x);
        const double j0 = swim_shape_jmin(N, x), c1 = x[0] * x[0] + x[1] * x[1];
        for (int ia = 0; ia < 3; ia++)
            for (double s = 1e-5; s >= 1e-9; s *= 1e-2) {
                const double a = alphas[ia], p = a - 0.5, eps = 0.03;
                double kappa, W0, W1;
                swim_barrier_reach(b, x, eps, a, 0.0, &kappa);
                const double energy = p == 0.0 ? kappa * log(j0 / s)
                                               : kappa / p * (pow(j0 / s, p) - 1.0);
                const double got = swim_barrier_reach(b, x, eps, a, energy, NULL);
                CHECK(fabs(got / s - 1.0) < 1e-9, "N=%d alpha %g: reach %.6g for %.6g", N, a, got, s);
                memcpy(y, x, sizeof(double) * n);
                const double f = sqrt((c1 - (j0 - s)) / c1);
                y[0] *= f;
                y[1] *= f;
                swim_barrier_w2(b, x, eps, a, &W0, NULL, NULL);
                swim_barrier_w2(b, y, eps, a, &W1, NULL, NULL);
                const double rel = fabs((W1 - W0) - energy) / (W1 - W0);
                worst = fmax(worst, rel);
                CHECK(rel < 0.05, "N=%d alpha %g s %g: W2 rises %.6g, estimate %.6g", N, a, s,
                      W1 - W0, energy);
            }
        swim_barrier_quad_free(b);
    }
    printf("reach estimate vs W2 along the path, min J 1e-3 -> 1e-5 .. 1e-9: worst %.2e\n", worst);
}

/* swim_shape_j_precise at the minimum of J (where |c_1|^2 - |h|^2 cancels down to min J) against
 * J in binary128 at the shape x + lo, lo a rounding-sized carry: the value to its rounding to
 * double plus ~1e-30 |c_1|^2 (the extended precision), J' to 1e-15 of its terms. */
static real jq_lo(int N, const double *x, const double *lo, real th)
{
    real hr = 0, hi = 0;
    for (int m = 1; m <= N; m++) {
        const real ar = m * ((real)x[2 * m] + lo[2 * m]), ai = m * ((real)x[2 * m + 1] + lo[2 * m + 1]);
        const real c = cosq((m - 1) * th), sn = sinq((m - 1) * th);
        hr += ar * c + ai * sn;                   /* (ar + i ai) e^{-i (m-1) theta} */
        hi += ai * c - ar * sn;
    }
    const real a1 = (real)x[0] + lo[0], b1 = (real)x[1] + lo[1];
    return a1 * a1 + b1 * b1 - hr * hr - hi * hi;
}

static void precise_j(void)
{
    static const int modes[] = {3, 8, 20, 32};
    static const double targets[] = {1e-4, 1e-8, 1e-12, 1e-15};
    double worst = 0, worst1 = 0;
    for (size_t a = 0; a < sizeof modes / sizeof *modes; a++)
        for (size_t t = 0; t < sizeof targets / sizeof *targets; t++) {
            const int N = modes[a], n = 2 * (N + 1);
            double x[2 * 33 + 2], lo[2 * 33 + 2];
            make_shape(N, 1, targets[t], x);
            for (int i = 0; i < n; i++) lo[i] = 0.5 * urand() * x[i] * 0x1p-52;
            real th[64], jv[64], wd[64];
            const int nm = minima(N, x, th, jv, wd);
            for (int i = 0; i < nm; i++) {
                const double a0 = (double)th[i];
                double J1;
                const double J = swim_shape_j_precise(N, x, lo, a0, &J1);
                const real Jr = jq_lo(N, x, lo, a0), h = 1e-12Q;
                const real J1r = (jq_lo(N, x, lo, a0 + h) - jq_lo(N, x, lo, a0 - h)) / (2 * h);
                const double err = fabs((double)(J - Jr)) - 1.2e-16 * fabs((double)Jr);   /* beyond rounding */
                const double err1 = fabs((double)(J1 - J1r)) / (1.0 + fabs((double)J1r));
                worst = fmax(worst, err);
                worst1 = fmax(worst1, err1);
                CHECK(err <= 1e-29, "N=%d J %.3g at %.6f: |J - ref| exceeds rounding by %.2e", N, (double)Jr, a0, err);
                CHECK(err1 <= 1e-15, "N=%d J %.3g at %.6f: J' error %.2e", N, (double)Jr, a0, err1);
            }
        }
    printf("swim_shape_j_precise at the minima of J down to 1e-15: beyond rounding %.2e absolute, J' %.2e\n",
           worst, worst1);
}

int main(void)
{
    gauss30();
    reach();
    accuracy();
    sparse();
    precise_j();
    return check_report("test_barrier");
}
