#include "shape/barrier.h"
#include "shape/shape.h"

#include <complex.h>
#include <lapacke.h>
#include <math.h>
#include "shape/quad.h"
#include <stdlib.h>
#include <string.h>

#define TWO_PI 6.28318530717958647692
#define TRAP_TOL 1e-14      /* predicted relative error at which a trapezoidal level is accepted */
#define PEAK_PERIODS 36.0   /* Q d >= 36: e^{-Qd} = 2e-16 */
#define GAUSS_TOL 1e-16     /* a priori bound per panel (relative to the panel's own size) */
#define QMIN 6              /* Gauss nodes per panel, at least ... */
#define QMAX 24             /* ... and at most (a panel needing more is halved) */
#define RHO_QMIN 100.0      /* GAUSS_TOL^(-1/(2 (QMIN - 2))): an ellipse this wide needs QMIN nodes */
#define MAX_DEPTH 64        /* halvings of one panel; beyond, a zero of J sits on the circle */
#define CLOSE 0.5           /* zeros closer than this to the real axis start panels at their foot */
#define PRECISE 0.1         /* zeros closer than this get the cancellation-free evaluation of J */
#define PRECISE_J 0.05      /* ... when J at their foot is below this fraction of |c_1|^2 */
#define NEAR 0.25           /* ... at the nodes within this angle of their foot */

struct swim_barrier_quad {
    int N, n;
    const double *lo;   /* the shape is x + lo exactly during a swim_barrier_w2_carry call, else NULL */
    double c1sq;        /* |c_1|^2 of the shape of the last fourier() */
    /* Nested trapezoidal rule: level 0 has q0 nodes 2 pi k / q0, level l >= 1 the q0 2^(l-1)
     * nodes that halve the spacing of the previous levels. For each level a table of
     * cos(j theta_k), sin(j theta_k), j = 0..N-1, stored [j][k] so the node loops vectorize. */
    int q0, levels;
    double *tcs[16], *tsn[16];
    int lnodes[16];
    /* Gauss-Legendre rules on [-1, 1], q = 1..QMAX nodes. */
    double gx[QMAX + 1][QMAX], gw[QMAX + 1][QMAX];
    /* Workspace: node arrays of the graded rule (grown on demand), the companion matrix, roots. */
    int cap;
    double *th, *base, *wt, *jv, *hr, *hi;   /* graded nodes: base + th, weight wt */
    double *ctr, *off;         /* th = ctr + off, ctr the centre of the node's panel (node_angles) */
    double *jnode;             /* J at the graded nodes of the last call (for the Hessian) */
    double *gcs;               /* cos, sin theta_k at the graded nodes */
    size_t gcap;
    double complex *comp, *roots;
    double complex *coef;      /* monic polynomial z^P J(z) / J_P, degree nroots */
    int nroots;                /* roots of the last call (a warm start), 0 when none */
    double complex *Jp;        /* Fourier coefficients J_p, p = 0..N-1 */
    /* Samples that bracket the minima of J: cos(p t_k), sin(p t_k) at t_k = 2 pi k / ns, [p][k] */
    int ns;
    double *scs, *ssn, *sJ;
};

/* ---- setup ------------------------------------------------------------------------------- */

/* Gauss-Legendre nodes and weights by Newton's method on the three-term recurrence, in long
 * double so that the double results are correctly rounded to a few ulps. */
static void gauss_legendre(int q, double *x, double *w)
{
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
        x[i] = (double)z;
        w[i] = (double)(2 / ((1 - z * z) * dp * dp));
    }
}

static int next_pow2(int v)
{
    int p = 1;
    while (p < v) p *= 2;
    return p;
}

/* Finest trapezoidal level before the graded rule: 256 nodes, more for many modes (J of degree
 * N-1 needs about 2N nodes per period just to be resolved). */
static int trap_max(int N) { return next_pow2(N * 16 > 512 ? N * 16 : 512); }

static int reserve(swim_barrier_quad *b, int nodes)
{
    if (nodes <= b->cap) return 0;
    int cap = b->cap ? b->cap : 256;
    while (cap < nodes) cap *= 2;
    double **arr[] = {&b->th, &b->base, &b->wt, &b->jv, &b->hr, &b->hi, &b->jnode, &b->ctr, &b->off};
    for (size_t i = 0; i < sizeof arr / sizeof arr[0]; i++) {
        double *p = realloc(*arr[i], sizeof(double) * (size_t)cap);
        if (!p) return -1;
        *arr[i] = p;
    }
    b->cap = cap;
    return 0;
}

static int reserve_tables(swim_barrier_quad *b, size_t entries)
{
    if (entries <= b->gcap) return 0;
    size_t cap = b->gcap ? b->gcap : 4096;
    while (cap < entries) cap *= 2;
    double *c = realloc(b->gcs, sizeof(double) * cap);
    if (!c) return -1;
    b->gcs = c;
    b->gcap = cap;
    return 0;
}

swim_barrier_quad *swim_barrier_quad_new(int modes)
{
    swim_barrier_quad *b = calloc(1, sizeof *b);
    if (!b) return NULL;
    b->N = modes;
    b->n = 2 * (modes + 1);
    const int w = modes > 0 ? modes : 1;
    b->q0 = next_pow2(modes * 2 > 16 ? modes * 2 : 16);
    for (int Q = b->q0; Q <= trap_max(modes); Q *= 2) {
        int l = b->levels++, m = l == 0 ? Q : Q / 2;
        b->lnodes[l] = m;
        b->tcs[l] = malloc(sizeof(double) * (size_t)m * (size_t)w);
        b->tsn[l] = malloc(sizeof(double) * (size_t)m * (size_t)w);
        if (!b->tcs[l] || !b->tsn[l]) {
            swim_barrier_quad_free(b);
            return NULL;
        }
        for (int k = 0; k < m; k++) {
            double th = l == 0 ? TWO_PI * k / Q : TWO_PI * (2 * k + 1) / Q;
            for (int j = 0; j < w; j++) {
                b->tcs[l][j * m + k] = cos(j * th);
                b->tsn[l][j * m + k] = sin(j * th);
            }
        }
    }
    for (int q = 1; q <= QMAX; q++) gauss_legendre(q, b->gx[q], b->gw[q]);
    int deg = 2 * (modes > 1 ? modes - 1 : 1);
    b->comp = malloc(sizeof(double complex) * (size_t)deg * (size_t)deg);
    b->roots = malloc(sizeof(double complex) * (size_t)deg);
    b->coef = malloc(sizeof(double complex) * (size_t)(deg + 1));
    b->Jp = malloc(sizeof(double complex) * (size_t)w);
    b->ns = 4 * (modes + 1) > 16 ? 4 * (modes + 1) : 16;
    b->scs = malloc(sizeof(double) * (size_t)b->ns * (size_t)w);
    b->ssn = malloc(sizeof(double) * (size_t)b->ns * (size_t)w);
    b->sJ = malloc(sizeof(double) * (size_t)b->ns);
    if (!b->scs || !b->ssn || !b->sJ) {
        swim_barrier_quad_free(b);
        return NULL;
    }
    for (int p = 0; p < w; p++)
        for (int k = 0; k < b->ns; k++) {
            b->scs[p * b->ns + k] = cos(p * TWO_PI * k / b->ns);
            b->ssn[p * b->ns + k] = sin(p * TWO_PI * k / b->ns);
        }
    if (!b->comp || !b->roots || !b->coef || !b->Jp || reserve(b, trap_max(modes) > 4096 ? trap_max(modes) : 4096) != 0) {
        swim_barrier_quad_free(b);
        return NULL;
    }
    return b;
}

void swim_barrier_quad_free(swim_barrier_quad *b)
{
    if (!b) return;
    for (int l = 0; l < b->levels; l++) {
        free(b->tcs[l]);
        free(b->tsn[l]);
    }
    free(b->th);
    free(b->base);
    free(b->wt);
    free(b->jv);
    free(b->jnode);
    free(b->ctr);
    free(b->off);
    free(b->gcs);
    free(b->hr);
    free(b->hi);
    free(b->comp);
    free(b->roots);
    free(b->coef);
    free(b->Jp);
    free(b->scs);
    free(b->ssn);
    free(b->sJ);
    free(b);
}

/* ---- sums over nodes --------------------------------------------------------------------- */

/* H_j = (j+1) c_{-(j+1)}: h = sum_j H_j e^{-i j theta} (ERRATA B2). */
static double complex coef_h(const double *x, int j)
{
    return (j + 1) * CMPLX(x[2 * (j + 1)], x[2 * (j + 1) + 1]);
}

/* Accumulators of a rule: S = sum w J^-alpha; for the gradient, sum w J^{-1-alpha} (times
 * dJ/da_1 = 2 a_1, dJ/db_1 = 2 b_1) and, for m = 1..N, sum w J^{-1-alpha} z^{m-1} h (ERRATA B3:
 * dJ/da_-m = -2m Re(z^{m-1} h), dJ/db_-m = -2m Im(z^{m-1} h)). */
typedef struct {
    double S, G0;
    double Gr[64], Gi[64];
} sums;

/* Sums over the nodes in 8 interleaved partial sums (node k into lane k % 8, two vectors of 4),
 * added up in a fixed order at the end: without reassociation (no -ffast-math) a single running
 * sum is a serial chain of additions that the compiler cannot vectorize. Only the rounding of
 * the sums changes. */
typedef double vec4 __attribute__((vector_size(4 * sizeof(double))));

static inline vec4 load4(const double *p)
{
    vec4 v;
    memcpy(&v, p, sizeof v);
    return v;
}

static inline double total8(vec4 a, vec4 b, double tail)
{
    const vec4 s = a + b;
    return ((s[0] + s[1]) + (s[2] + s[3])) + tail;
}

/* h and J at nodes k = 0..m-1 whose cos(j theta_k), sin(j theta_k) are cs[j m + k], sn[j m + k]
 * (structure of arrays). Blocks of 8 nodes outside, j inside: h stays in registers over the sum
 * instead of being loaded and stored once per j (the same operations per node, in the same order). */
static void node_values(const swim_barrier_quad *b, const double *cs, const double *sn, int m,
                        const double *x, double *hr, double *hi, double *J)
{
    const double c1 = x[0] * x[0] + x[1] * x[1];
    const int N = b->N, mv = m - m % 8;
    double Hr[64], Hi[64];
    for (int j = 0; j < N; j++) {
        const double complex H = coef_h(x, j);
        Hr[j] = creal(H);
        Hi[j] = cimag(H);
    }
    for (int k = 0; k < mv; k += 8) {
        vec4 r0 = {0}, r1 = {0}, i0 = {0}, i1 = {0};
        for (int j = 0; j < N; j++) {          /* H e^{-i j theta} */
            const double *c = cs + (size_t)j * m + k, *sj = sn + (size_t)j * m + k;
            const vec4 c0 = load4(c), c1v = load4(c + 4), s0 = load4(sj), s1 = load4(sj + 4);
            r0 += Hr[j] * c0 + Hi[j] * s0;
            r1 += Hr[j] * c1v + Hi[j] * s1;
            i0 += Hi[j] * c0 - Hr[j] * s0;
            i1 += Hi[j] * c1v - Hr[j] * s1;
        }
        memcpy(hr + k, &r0, sizeof r0);
        memcpy(hr + k + 4, &r1, sizeof r1);
        memcpy(hi + k, &i0, sizeof i0);
        memcpy(hi + k + 4, &i1, sizeof i1);
    }
    for (int k = mv; k < m; k++) {
        double r = 0.0, i = 0.0;
        for (int j = 0; j < N; j++) {
            r += Hr[j] * cs[(size_t)j * m + k] + Hi[j] * sn[(size_t)j * m + k];
            i += Hi[j] * cs[(size_t)j * m + k] - Hr[j] * sn[(size_t)j * m + k];
        }
        hr[k] = r;
        hi[k] = i;
    }
    for (int k = 0; k < m; k++) J[k] = c1 - hr[k] * hr[k] - hi[k] * hi[k];
}

/* f = w J^-alpha and g = w J^{-1-alpha} = f / J at n nodes (g holds J on entry; w NULL: 1). One
 * loop per exponent so that each vectorizes (1/sqrt and 1/J instead of pow for alpha = 1/2, 1;
 * sqrt vectorizes because this file is compiled without errno, runtime/shape/module.mk). */
static void weigh(double alpha, const double *w, double *g, int n, double *f)
{
    if (alpha == 0.5)   /* one division and one square root per node: they dominate the rule at small N */
        for (int k = 0; k < n; k++) {
            const double r = 1.0 / g[k];
            f[k] = (w ? w[k] : 1.0) * sqrt(r);
            g[k] = f[k] * r;
        }
    else if (alpha == 1.0)
        for (int k = 0; k < n; k++) {
            const double r = 1.0 / g[k];
            f[k] = (w ? w[k] : 1.0) * r;
            g[k] = f[k] * r;
        }
    else
        for (int k = 0; k < n; k++) {
            f[k] = (w ? w[k] : 1.0) * pow(g[k], -alpha);
            g[k] = f[k] / g[k];
        }
}

/* The gradient sums sum_k g_k z_k^j h_k, j = 0..N-1, at nodes z_k = c_k + i s_k without tables of
 * cos, sin(j theta): t_k = g_k h_k is multiplied by z_k once per j (error ~ j u, as the
 * angle-addition tables). Blocks of 8 nodes outside, j inside: t stays in registers, the sums in
 * 8 lanes per j (node k in lane k % 8), the rest of the nodes one by one. */
static void power_sums(const swim_barrier_quad *b, const double *c, const double *sn, int m, const double *hr,
                       const double *hi, const double *g, sums *s)
{
    const int N = b->N, mv = m - m % 8;
    vec4 ar[64][2], ai[64][2];
    memset(ar, 0, sizeof(vec4) * 2 * (size_t)N);
    memset(ai, 0, sizeof(vec4) * 2 * (size_t)N);
    for (int k = 0; k < mv; k += 8) {
        const vec4 c0 = load4(c + k), c1 = load4(c + k + 4), s0 = load4(sn + k), s1 = load4(sn + k + 4);
        const vec4 g0 = load4(g + k), g1 = load4(g + k + 4);
        vec4 tr0 = g0 * load4(hr + k), tr1 = g1 * load4(hr + k + 4);
        vec4 ti0 = g0 * load4(hi + k), ti1 = g1 * load4(hi + k + 4);
        for (int j = 0; j < N; j++) {
            ar[j][0] += tr0;
            ar[j][1] += tr1;
            ai[j][0] += ti0;
            ai[j][1] += ti1;
            const vec4 n0 = tr0 * c0 - ti0 * s0, n1 = tr1 * c1 - ti1 * s1;
            ti0 = tr0 * s0 + ti0 * c0;
            ti1 = tr1 * s1 + ti1 * c1;
            tr0 = n0;
            tr1 = n1;
        }
    }
    double rt[64] = {0}, it[64] = {0};
    for (int k = mv; k < m; k++) {
        double tr = g[k] * hr[k], ti = g[k] * hi[k];
        for (int j = 0; j < N; j++) {
            rt[j] += tr;
            it[j] += ti;
            const double a = tr * c[k] - ti * sn[k];
            ti = tr * sn[k] + ti * c[k];
            tr = a;
        }
    }
    for (int j = 0; j < N; j++) {
        s->Gr[j] += total8(ar[j][0], ar[j][1], rt[j]);
        s->Gi[j] += total8(ai[j][0], ai[j][1], it[j]);
    }
}

/* Adds the nodes with values J (overwritten by g = w J^{-1-alpha}) and weights w (NULL: 1) to
 * S and (grad) G0 of s. Returns 1 when J <= 0 at a node. */
#define CHUNK 256
static int weight_sums(int m, double *g, const double *w, double alpha, int grad, sums *s)
{
    int bad = 0;
    for (int k = 0; k < m; k++) bad |= !(g[k] > 0.0);
    if (bad) return 1;
    const int mv = m - m % 8;   /* nodes in whole blocks of 8; the rest are summed one by one */
    vec4 S0 = {0}, S1 = {0}, G0 = {0}, G1 = {0};
    double St = 0.0, Gt = 0.0;
    for (int k0 = 0; k0 < m; k0 += CHUNK) {
        double f[CHUNK];
        const int n = m - k0 < CHUNK ? m - k0 : CHUNK;
        weigh(alpha, w ? w + k0 : NULL, g + k0, n, f);
        for (int k = 0; k + 8 <= n && k0 + k < mv; k += 8) {
            S0 += load4(f + k);
            S1 += load4(f + k + 4);
            G0 += load4(g + k0 + k);
            G1 += load4(g + k0 + k + 4);
        }
        for (int k = k0 + n > mv ? mv - k0 : n; k < n; k++) {
            St += f[k];
            Gt += g[k0 + k];
        }
    }
    s->S += total8(S0, S1, St);
    if (grad) s->G0 += total8(G0, G1, Gt);
    return 0;
}

/* weight_sums, and (grad) the sums over g z^j h from the tables cs, sn of node_values. */
static int node_sums(const swim_barrier_quad *b, const double *cs, const double *sn, int m,
                     const double *hr, const double *hi, double *g, const double *w, double alpha,
                     int grad, sums *s)
{
    if (weight_sums(m, g, w, alpha, grad, s)) return 1;
    if (!grad) return 0;
    const int mv = m - m % 8;
    for (int j = 0; j < b->N; j++) {           /* sum g z^j h, z^j = cos + i sin */
        const double *c = cs + (size_t)j * m, *sj = sn + (size_t)j * m;
        vec4 r0 = {0}, r1 = {0}, i0 = {0}, i1 = {0};
        for (int k = 0; k < mv; k += 8) {
            const vec4 ca = load4(c + k), sa = load4(sj + k), ha = load4(hr + k), ia = load4(hi + k), ga = load4(g + k);
            const vec4 cb = load4(c + k + 4), sb = load4(sj + k + 4), hb = load4(hr + k + 4), ib = load4(hi + k + 4),
                       gb = load4(g + k + 4);
            r0 += ga * (ca * ha - sa * ia);
            i0 += ga * (ca * ia + sa * ha);
            r1 += gb * (cb * hb - sb * ib);
            i1 += gb * (cb * ib + sb * hb);
        }
        double rt = 0.0, it = 0.0;
        for (int k = mv; k < m; k++) {
            rt += g[k] * (c[k] * hr[k] - sj[k] * hi[k]);
            it += g[k] * (c[k] * hi[k] + sj[k] * hr[k]);
        }
        s->Gr[j] += total8(r0, r1, rt);
        s->Gi[j] += total8(i0, i1, it);
    }
    return 0;
}

/* h and J at nodes k = 0..m-1 from c = cos theta_k, sn = sin theta_k alone: h = sum_j H_j w^j,
 * w = e^{-i theta} = c - i sn, by Horner (8 nodes at a time in vector registers). */
static void node_values_horner(const swim_barrier_quad *b, const double *c, const double *sn, int m,
                               const double *x, double *hr, double *hi, double *J)
{
    const double c1 = x[0] * x[0] + x[1] * x[1];
    const int N = b->N;
    if (N == 0) {
        for (int k = 0; k < m; k++) {
            hr[k] = hi[k] = 0.0;
            J[k] = c1;
        }
        return;
    }
    double Hr[64], Hi[64];
    for (int j = 0; j < N; j++) {
        const double complex H = coef_h(x, j);
        Hr[j] = creal(H);
        Hi[j] = cimag(H);
    }
    const int mv = m - m % 8;
    for (int k = 0; k < mv; k += 8) {   /* blocks of 8 nodes, h in registers over j */
        const vec4 c0 = load4(c + k), c1 = load4(c + k + 4), s0 = load4(sn + k), s1 = load4(sn + k + 4);
        vec4 r0 = {Hr[N - 1], Hr[N - 1], Hr[N - 1], Hr[N - 1]}, i0 = {Hi[N - 1], Hi[N - 1], Hi[N - 1], Hi[N - 1]};
        vec4 r1 = r0, i1 = i0;
        for (int j = N - 2; j >= 0; j--) {
            const vec4 a0 = r0 * c0 + i0 * s0 + Hr[j], a1 = r1 * c1 + i1 * s1 + Hr[j];
            i0 = i0 * c0 - r0 * s0 + Hi[j];
            i1 = i1 * c1 - r1 * s1 + Hi[j];
            r0 = a0;
            r1 = a1;
        }
        memcpy(hr + k, &r0, sizeof r0);
        memcpy(hr + k + 4, &r1, sizeof r1);
        memcpy(hi + k, &i0, sizeof i0);
        memcpy(hi + k + 4, &i1, sizeof i1);
    }
    for (int k = mv; k < m; k++) {
        double r = Hr[N - 1], i = Hi[N - 1];
        for (int j = N - 2; j >= 0; j--) {
            const double a = r * c[k] + i * sn[k] + Hr[j];
            i = i * c[k] - r * sn[k] + Hi[j];
            r = a;
        }
        hr[k] = r;
        hi[k] = i;
    }
    for (int k = 0; k < m; k++) J[k] = c1 - hr[k] * hr[k] - hi[k] * hi[k];
}

/* Adds the trapezoidal nodes of one level (tables cs, sn), with weight 1, to s. */
static int trap_level(const swim_barrier_quad *b, const double *cs, const double *sn, int m,
                      const double *x, double alpha, int grad, sums *s)
{
    node_values(b, cs, sn, m, x, b->hr, b->hi, b->jv);
    return node_sums(b, cs, sn, m, b->hr, b->hi, b->jv, NULL, alpha, grad, s);
}

/* W2 and the gradient from the accumulated sums with an overall weight `scale`. */
static void finish(const swim_barrier_quad *b, const sums *s, double scale, const double *x,
                   double eps, double alpha, double *W, double *grad)
{
    *W = eps / (2.0 * alpha) * scale * s->S;
    if (!grad) return;
    const double c = -0.5 * eps * scale;
    grad[0] = c * 2.0 * x[0] * s->G0;
    grad[1] = c * 2.0 * x[1] * s->G0;
    for (int m = 1; m <= b->N; m++) {
        grad[2 * m] = c * (-2.0 * m) * s->Gr[m - 1];
        grad[2 * m + 1] = c * (-2.0 * m) * s->Gi[m - 1];
    }
}

/* Change between two levels: |W - W'| and max_i |g_i - g'_i| (0 without a gradient). */
static void level_change(const double *g, const double *gp, int n, double W, double Wp, double *dW,
                         double *dg)
{
    *dW = fabs(W - Wp);
    *dg = 0.0;
    if (g)
        for (int i = 0; i < n; i++) {   /* maxima by comparison: fmax is a library call here */
            const double e = fabs(g[i] - gp[i]);
            if (e > *dg) *dg = e;
        }
}

/* Error of the finest level predicted from the last two changes D1 (Q/2 -> Q) and D2 (Q -> 2Q).
 * With near-singularities at distance d the error behaves like A Q^s e^{-Qd} (s = alpha - 1/2
 * for the value, alpha + 1/2 for the gradient: the Fourier coefficients of J^-alpha), so one
 * doubling multiplies it by about 2^s e^{-Qd} and the next by the square of that:
 * err(2Q) ~ D2 (D2 / D1)^2 2^s. The factor 8 covers s <= 3. */
static double predicted(double D1, double D2)
{
    if (D2 == 0.0) return 0.0;
    if (!(D1 > 0.0)) return INFINITY;
    double r = D2 / D1;
    return r < 1.0 ? 8.0 * D2 * r * r : INFINITY;
}

/* Whether the last two changes D1, D2 of a quantity of size `scale` say the finest level is
 * within TRAP_TOL: by the prediction, or because both are already that small -- changes at the
 * level of rounding, whose ratio is noise near 1 and would defeat the prediction forever (a
 * nearly circular shape then fell through to the graded rule). The a priori node count keeps a
 * change that vanishes by chance from passing alone. */
static int settled(double D1, double D2, double scale)
{
    const double tol = TRAP_TOL * scale;
    return predicted(D1, D2) <= tol || (D1 <= tol && D2 <= tol);
}

static double vmax(const double *g, int n)
{
    double m = 0.0;
    for (int i = 0; g && i < n; i++)
        if (fabs(g[i]) > m) m = fabs(g[i]);
    return m;
}

/* J_p, p = 0..N-1: J(theta) = J_0 + 2 Re sum_{p>=1} J_p e^{i p theta}, from
 * |h|^2 = sum_{j,l} H_j conj(H_l) e^{i (l-j) theta}. */
static void fourier(swim_barrier_quad *b, const double *x)
{
    const int N = b->N;
    for (int p = 0; p < N; p++) {
        double complex s = 0.0;
        for (int j = 0; j + p < N; j++) s += coef_h(x, j) * conj(coef_h(x, j + p));
        b->Jp[p] = -s;
    }
    b->c1sq = x[0] * x[0] + x[1] * x[1];
    if (N > 0) b->Jp[0] += b->c1sq;
}

/* J and its first two derivatives in theta from the coefficients J_p (fourier()). */
static void j_derivs(const swim_barrier_quad *b, double th, double *J, double *J1, double *J2)
{
    double complex z = cexp(I * th), zp = z;
    double s0 = creal(b->Jp[0]), s1 = 0.0, s2 = 0.0;
    for (int p = 1; p < b->N; p++) {
        double complex t = b->Jp[p] * zp;
        s0 += 2.0 * creal(t);
        s1 -= 2.0 * p * cimag(t);
        s2 -= 2.0 * p * p * creal(t);
        zp *= z;
    }
    *J = s0;
    *J1 = s1;
    *J2 = s2;
}

/* Half-width of the sharpest peak of J^-alpha: min over the local minima of J of
 * sqrt(2 J / J''), the distance from the real axis of the complex zeros of the local quadratic
 * model of J, which is where the trapezoidal rule's error e^{-Qd} comes from. The minima are
 * bracketed on max(16, 4(N+1)) samples and refined by Newton's method on J'. Returns 0 when J <= 0 at a
 * minimum (outside D), INFINITY when J has no minimum (constant), -1 when a minimum could not be
 * refined. The deepest sampled minimum is refined first, and a width below dstop is returned at
 * once: the caller then takes the graded rule whatever the other minima give (which also finds
 * a J <= 0 elsewhere: zeros of J on the circle). */
static double peak_width(const swim_barrier_quad *b, double dstop)
{
    const int M = b->ns;
    double *J = b->sJ, d = INFINITY;
    for (int k = 0; k < M; k++) J[k] = creal(b->Jp[0]);
    for (int p = 1; p < b->N; p++) {
        const double re = 2.0 * creal(b->Jp[p]), im = 2.0 * cimag(b->Jp[p]);
        const double *c = b->scs + (size_t)p * M, *sn = b->ssn + (size_t)p * M;
        for (int k = 0; k < M; k++) J[k] += re * c[k] - im * sn[k];
    }
    int deepest = 0;   /* the first of the smallest samples; its value kept in a register (a load
                          per sample through the index was a serial chain) */
    double jdeep = J[0];
    for (int k = 1; k < M; k++)
        if (J[k] < jdeep) {
            jdeep = J[k];
            deepest = k;
        }
    for (int i = -1; i < M; i++) {
        const int k = i < 0 ? deepest : i;
        if (i == deepest) continue;
        /* neighbours on the circle without an integer division per sample (M is not a constant) */
        const double left = J[k > 0 ? k - 1 : M - 1], right = J[k + 1 < M ? k + 1 : 0];
        if (!(J[k] < left && J[k] <= right)) continue;
        double th = TWO_PI * k / M, Jt, J1, J2;      /* Newton on J' from the sample */
        int converged = 0;
        for (int it = 0; it < 30; it++) {
            j_derivs(b, th, &Jt, &J1, &J2);
            if (!(J2 > 0.0)) break;
            double step = J1 / J2;
            /* What is wanted is J and J'' at the minimum, not its angle: at a distance e from it
             * J is too large by J'' e^2 / 2 = J (e / w)^2, w = sqrt(2 J / J''). Newton's step is
             * about e, so once it is below 1e-5 w the values here are those of the minimum to a
             * relative 1e-10, w and the node count with them; near J = 0 (w -> 0) the step must
             * still fall below 1e-10, as the test of J against 0 below needs. */
            const double w2 = 2.0 * Jt / J2, tol = w2 > 1e-10 ? 1e-5 * sqrt(w2) : 1e-10;
            if (fabs(step) < tol) {
                converged = 1;
                break;
            }
            if (fabs(step) > TWO_PI / M) step = step > 0 ? TWO_PI / M : -TWO_PI / M;
            th -= step;
        }
        /* A minimum Newton cannot pin down (a peak far narrower than the sampling, or J'' <= 0
         * on the way) is not estimated: the caller then takes the graded rule, which finds
         * every zero of J. */
        if (!converged) return -1.0;
        /* J is known here to the cancellation error of |c_1|^2 - |h|^2 only: within it, the
         * graded rule decides from J in extended precision at the foot */
        if (!(Jt > 1e-13 * b->c1sq)) return Jt > -1e-13 * b->c1sq ? -1.0 : 0.0;
        if (J2 > 0.0) d = fmin(d, sqrt(2.0 * Jt / J2));
        if (d < dstop) return d;
    }
    return d;
}

/* The nested trapezoidal rule, taken to Q >= PEAK_PERIODS / d nodes for the half-width d of the
 * sharpest peak (a priori: its error is about e^{-Qd}), and accepted when the error predicted
 * from the changes of the last two levels is below TRAP_TOL as well (a posteriori). The second
 * test alone can be fooled: the error of a level is the real part of a complex exponential and
 * one level can cancel by chance. Returns 0 (converged: W, grad set), 1 (outside D: J <= 0 at a
 * node or at a minimum), 2 (needs more than the finest level). */
static int trapezoid(swim_barrier_quad *b, const double *x, double eps, double alpha, double *W,
                     double *grad, int *nodes)
{
    fourier(b, x);
    const double d = b->N > 1 ? peak_width(b, PEAK_PERIODS / (trap_max(b->N) - (b->N - 1))) : INFINITY;
    if (d == 0.0) return 1;
    if (d < 0.0) return 2;
    /* the gradient's integrands carry e^{ik theta}, |k| <= N - 1 (ERRATA B3): their aliasing
     * error at Q nodes is that of J^-alpha at Q - (N - 1) */
    const double Qmin = PEAK_PERIODS / d + (b->N - 1);
    if (Qmin > trap_max(b->N)) return 2;
    sums s;
    memset(&s, 0, sizeof s);
    double Wprev = 0.0, gprev[2 * 64 + 2], dW1 = NAN, dg1 = NAN;
    int Q = 0;
    for (int l = 0; l < b->levels; l++) {
        int m = b->lnodes[l];
        if (trap_level(b, b->tcs[l], b->tsn[l], m, x, alpha, grad != NULL, &s)) return 1;
        Q += m;
        finish(b, &s, TWO_PI / Q, x, eps, alpha, W, grad);
        *nodes = Q;
        if (l > 0) {
            double dW, dg;
            level_change(grad, gprev, b->n, *W, Wprev, &dW, &dg);
            if (l > 1 && Q >= Qmin && settled(dW1, dW, fabs(*W)) && (!grad || settled(dg1, dg, vmax(grad, b->n))))
                return 0;
            dW1 = dW;
            dg1 = dg;
        }
        Wprev = *W;
        if (grad) memcpy(gprev, grad, sizeof(double) * (size_t)b->n);
    }
    return 2;
}

/* ---- the graded rule --------------------------------------------------------------------- */

/* sin d - d and cos d - 1 for |d| <= SERIES_MAX by their Taylor series to d^25 and d^24, in Horner
 * form in d^2 (truncation below 1.6^27/27! = 3e-22; no cancellation between the leading terms
 * 1, d and the rest, which are returned apart). */
#define SERIES_MAX 1.6
static const double inv_fact_odd[12] = {   /* (-1)^k / (2k+3)! */
    -1.0 / 6, 1.0 / 120, -1.0 / 5040, 1.0 / 362880, -1.0 / 39916800, 1.0 / 6227020800.0,
    -1.0 / 1307674368000.0, 1.0 / 355687428096000.0, -1.0 / 121645100408832000.0,
    1.0 / 51090942171709440000.0, -1.0 / 25852016738884976640000.0, 1.0 / 15511210043330985984000000.0};
static const double inv_fact_even[12] = {   /* (-1)^(k+1) / (2k+2)! */
    -1.0 / 2, 1.0 / 24, -1.0 / 720, 1.0 / 40320, -1.0 / 3628800, 1.0 / 479001600.0, -1.0 / 87178291200.0,
    1.0 / 20922789888000.0, -1.0 / 6402373705728000.0, 1.0 / 2432902008176640000.0,
    -1.0 / 1124000727777607680000.0, 1.0 / 620448401733239439360000.0};

static inline void sincos_series(double d, double *sm, double *cm)
{
    const double d2 = d * d;
    double ps = inv_fact_odd[11], pc = inv_fact_even[11];
    for (int k = 10; k >= 0; k--) {
        ps = ps * d2 + inv_fact_odd[k];
        pc = pc * d2 + inv_fact_even[k];
    }
    *sm = d * d2 * ps;   /* sin d - d */
    *cm = d2 * pc;       /* cos d - 1 */
}

/* cos and sin of d: the series where |d| <= SERIES_MAX, libm elsewhere. */
static inline void cos_sin(double d, double *c, double *s)
{
    if (fabs(d) <= SERIES_MAX) {
        double sm, cm;
        sincos_series(d, &sm, &cm);
        *c = 1.0 + cm;
        *s = d + sm;
    } else {
        *c = cos(d);
        *s = sin(d);
    }
}

/* cos and sin of the graded nodes base + th, th = ctr + off: one sincos per breakpoint
 * base, and the offsets of the panel centres from it and of the nodes from their centre (at most
 * half an interval between breakpoints, pi) by the series of cos_sin -- libm's sincos per panel
 * and node dominated the rule's cost at N = 20. Angle addition costs a few ulp (absolute: |h| and
 * the sums are O(1)). */
static void node_angles(const swim_barrier_quad *b, int nodes, double *c, double *s)
{
    for (int k = 0; k < nodes; k++) {   /* the offsets from the panel centres: a vector loop */
        double sm, cm;
        sincos_series(b->off[k], &sm, &cm);
        c[k] = 1.0 + cm;
        s[k] = b->off[k] + sm;
    }
    double C = 1.0, S = 0.0, Cb = 1.0, Sb = 0.0, last = NAN, lastb = NAN;
    for (int k = 0; k < nodes; k++) {
        if (b->base[k] != lastb) {
            lastb = b->base[k];
            Cb = cos(lastb);
            Sb = sin(lastb);
            last = NAN;
        }
        if (b->ctr[k] != last) {
            last = b->ctr[k];
            double cm, sm;
            cos_sin(last, &cm, &sm);
            C = Cb * cm - Sb * sm;
            S = Sb * cm + Cb * sm;
        }
        double cd = c[k], sd = s[k];
        if (!(fabs(b->off[k]) <= SERIES_MAX)) {
            cd = cos(b->off[k]);
            sd = sin(b->off[k]);
        }
        c[k] = C * cd - S * sd;
        s[k] = S * cd + C * sd;
    }
}

/* |z| for the moderate values here (roots near the unit circle, panel coordinates): hypot's
 * guard against overflow costs more than the rest of the Aberth sweep. */
static inline double modulus(double complex z) { return sqrt(creal(z) * creal(z) + cimag(z) * cimag(z)); }


/* Aberth-Ehrlich iteration from the roots of the last call: the shape moves little between two
 * calls (integrator stages), so a few cubically convergent sweeps, O(n^2) each, replace the
 * O(n^3) QR iteration. The simultaneous correction keeps the approximations apart (implicit
 * deflation). The roots only place panels and bound their error, to which a shift of 1e-11
 * does nothing measurable, so the result is accepted when every correction of a sweep is below
 * 1e-11, or when the corrections delta_i of a sweep predict that the next ones would be below
 * 1e-12 (next_error) -- and no two roots coincide; else the caller recomputes from scratch.
 * Returns 0 when accepted. */
#define MAX_ROOTS 128

/* Error left after an Aberth correction delta_i of root i, from the errors e_j of the others:
 * e_i' = e_i^2 sigma_i / (1 + e_i sigma_i), sigma_i = -sum_{j != i} e_j / ((z_i - zeta_j)(z_i - z_j))
 * (zeta the exact roots), so with |e_j| <= 2 |delta_j| (cubic convergence: the correction is the
 * error up to a far smaller part), D the distance from z_i to its nearest neighbour at the time
 * of its correction, E = max |delta| and T = sum |delta|, after the sweep
 *   |e_i'| <= 4 delta_i^2 |sigma_i| / (1 - 2 delta_i |sigma_i|),  |sigma_i| <= 2 T / ((D - 2E) (D - 4E)),
 * the neighbours having moved by up to 2E since D was measured. Infinity unless D > 8E. */
static double next_error(double delta, double D, double E, double T)
{
    if (!(D > 8.0 * E)) return INFINITY;
    const double sigma = 2.0 * T / ((D - 2.0 * E) * (D - 4.0 * E)), t = 2.0 * delta * sigma;
    return t < 0.5 ? 2.0 * delta * t / (1.0 - t) : INFINITY;
}

static int polish_roots(swim_barrier_quad *b, int n)
{
    if (n > MAX_ROOTS) return -1;
    const double complex *a = b->coef;
    double complex *z = b->roots;
    /* structure of arrays: Horner runs over all roots at once (p and p' at z_i do not change in a
     * sweep until z_i itself is corrected, so they are evaluated up front), the repulsion sums over
     * the other roots */
    double zr[MAX_ROOTS], zi[MAX_ROOTS], pr[MAX_ROOTS], pim[MAX_ROOTS], dr_[MAX_ROOTS], di_[MAX_ROOTS];
    double st[MAX_ROOTS], dmin[MAX_ROOTS];
    for (int i = 0; i < n; i++) {
        zr[i] = creal(z[i]);
        zi[i] = cimag(z[i]);
    }
    int accepted = 0;
    for (int sweep = 0; sweep < 8 && !accepted; sweep++) {
        for (int i = 0; i < n; i++) {
            pr[i] = 1.0;
            pim[i] = dr_[i] = di_[i] = 0.0;
        }
        for (int k = n - 1; k >= 0; k--) {   /* p and p' (monic) by Horner */
            const double ar = creal(a[k]), ai = cimag(a[k]);
            for (int i = 0; i < n; i++) {
                const double ndr = (dr_[i] * zr[i] - di_[i] * zi[i]) + pr[i];
                const double ndi = (dr_[i] * zi[i] + di_[i] * zr[i]) + pim[i];
                const double npr = (pr[i] * zr[i] - pim[i] * zi[i]) + ar;
                const double npi = (pr[i] * zi[i] + pim[i] * zr[i]) + ai;
                dr_[i] = ndr;
                di_[i] = ndi;
                pr[i] = npr;
                pim[i] = npi;
            }
        }
        double worst = 0.0, E = 0.0, T = 0.0;
        for (int i = 0; i < n; i++) {
            st[i] = 0.0;
            dmin[i] = INFINITY;
            if (pr[i] == 0.0 && pim[i] == 0.0) continue;
            /* sum of 1/(z_i - z_j) as conj(d)/|d|^2, and the nearest neighbour; the term j = i
             * (d = 0) is masked out */
            vec4 rr = {0}, ri = {0}, dm = {INFINITY, INFINITY, INFINITY, INFINITY};
            const vec4 xi = {zr[i], zr[i], zr[i], zr[i]}, yi = {zi[i], zi[i], zi[i], zi[i]};
            int j = 0;
            for (; j + 4 <= n; j += 4) {
                const vec4 dx = xi - load4(zr + j), dy = yi - load4(zi + j), d2 = dx * dx + dy * dy;
                const vec4 q = 1.0 / d2;
                typedef long long mask4 __attribute__((vector_size(4 * sizeof(long long))));
                const mask4 keep = (mask4)(d2 != 0.0);
                const vec4 qk = (vec4)((mask4)q & keep);
                rr += dx * qk;
                ri -= dy * qk;
                const mask4 lt = (mask4)(d2 < dm) & keep;
                dm = (vec4)(((mask4)d2 & lt) | ((mask4)dm & ~lt));
            }
            double sr = (rr[0] + rr[1]) + (rr[2] + rr[3]), si = (ri[0] + ri[1]) + (ri[2] + ri[3]);
            double d2min = fmin(fmin(dm[0], dm[1]), fmin(dm[2], dm[3]));
            for (; j < n; j++) {
                if (j == i) continue;
                const double dx = zr[i] - zr[j], dy = zi[i] - zi[j], d2 = dx * dx + dy * dy, q = 1.0 / d2;
                sr += dx * q;
                si -= dy * q;
                d2min = fmin(d2min, d2);
            }
            /* w = p / p', step = w / (1 - w rep) */
            const double den = dr_[i] * dr_[i] + di_[i] * di_[i];
            const double wr = (pr[i] * dr_[i] + pim[i] * di_[i]) / den, wi = (pim[i] * dr_[i] - pr[i] * di_[i]) / den;
            const double ur = 1.0 - (wr * sr - wi * si), ui = -(wr * si + wi * sr), uu = ur * ur + ui * ui;
            const double sr_ = (wr * ur + wi * ui) / uu, si_ = (wi * ur - wr * ui) / uu;
            if (!isfinite(sr_) || !isfinite(si_)) return -1;
            zr[i] -= sr_;
            zi[i] -= si_;
            st[i] = sqrt(sr_ * sr_ + si_ * si_);
            dmin[i] = sqrt(d2min);
            E = fmax(E, st[i]);
            T += st[i];
            worst = fmax(worst, st[i] / (1.0 + sqrt(zr[i] * zr[i] + zi[i] * zi[i])));
        }
        accepted = worst < 1e-11;
        if (!accepted && worst < 1e-3) {
            double pred = 0.0;
            for (int i = 0; i < n && pred < 1e-12; i++)
                pred = fmax(pred, next_error(st[i], dmin[i], E, T) / (1.0 + sqrt(zr[i] * zr[i] + zi[i] * zi[i])));
            accepted = pred < 1e-12;
        }
    }
    for (int i = 0; i < n; i++) z[i] = CMPLX(zr[i], zi[i]);
    if (!accepted) return -1;
    for (int i = 0; i < n; i++) {   /* |z_i - z_j| < 1e-8 (1 + |z_i|), squared: O(n^2) without hypot */
        const double lim = 1e-8 * (1.0 + modulus(z[i])), lim2 = lim * lim;
        for (int j = i + 1; j < n; j++) {
            const double dx = zr[i] - zr[j], dy = zi[i] - zi[j];
            if (dx * dx + dy * dy < lim2) return -1;
        }
    }
    return 0;
}

/* The zeros of J in the upper half of the theta plane (one of each pair z, 1/conj z of zeros of
 * z^P J(z)), as theta = arg z + i |log |z||. Returns how many, or -1 on a LAPACK failure. */
static int zeros(swim_barrier_quad *b, double complex *out)
{
    int P = 0;
    for (int p = 1; p < b->N; p++)
        if (b->Jp[p] != 0.0) P = p;
    if (P == 0) return 0;
    const int n = 2 * P;
    /* monic z^n + a_{n-1} z^{n-1} + ... + a_0, coefficients P_k of z^{k-P} J: P_{P+p} = J_p,
     * P_{P-p} = conj(J_p) */
    const double complex lead = b->Jp[P];
    for (int k = 0; k < n; k++) {
        int p = k - P;
        b->coef[k] = (p >= 0 ? b->Jp[p] : conj(b->Jp[-p])) / lead;
    }
    if (b->nroots != n || polish_roots(b, n) != 0) {
        /* from scratch: eigenvalues of the companion matrix, in upper Hessenberg form */
        b->nroots = 0;
        double complex *C = b->comp;   /* column-major */
        memset(C, 0, sizeof(double complex) * (size_t)n * (size_t)n);
        for (int k = 0; k < n; k++) C[(size_t)(n - 1 - k) * n + 0] = -b->coef[k];   /* row 0 */
        for (int i = 1; i < n; i++) C[(size_t)(i - 1) * n + i] = 1.0;   /* subdiagonal */
        lapack_int info = LAPACKE_zhseqr(LAPACK_COL_MAJOR, 'E', 'N', n, 1, n,
                                         (lapack_complex_double *)C, n,
                                         (lapack_complex_double *)b->roots, NULL, 1);
        if (info != 0) return -1;
        b->nroots = n;
    }
    int r = 0;
    for (int i = 0; i < n; i++) {
        double a = modulus(b->roots[i]);
        if (a > 1.0) continue;     /* its mirror 1/conj(z) is in the list too */
        out[r++] = CMPLX(fmod(carg(b->roots[i]) + TWO_PI, TWO_PI), -log(a));
    }
    return r;
}

/* J and J' at a complex angle th in binary128, at the shape x + b->lo: with w = e^{-i th},
 * J = |c_1|^2 - P(w) Q(1/w), P(w) = sum_j H_j w^j, Q(v) = sum_j conj(H_j) v^j (on the real axis
 * Q(1/w) = conj P(w)), and dw/dth = -i w, d(1/w)/dth = i/w. */
static void j_complex_q(const swim_barrier_quad *b, const double *x, __complex128 th, __complex128 *J,
                        __complex128 *J1)
{
    const double *lo = b->lo;
    __complex128 mi, w, v, p = 0, dp = 0, q = 0, dq = 0;
    __real__ mi = 0;
    __imag__ mi = -1;
    w = cexpq(mi * th);
    v = 1 / w;
    for (int j = b->N - 1; j >= 0; j--) {   /* Horner, with derivatives */
        const int r = 2 * (j + 1);
        __complex128 H;
        __real__ H = (j + 1) * ((__float128)x[r] + (lo ? lo[r] : 0.0));
        __imag__ H = (j + 1) * ((__float128)x[r + 1] + (lo ? lo[r + 1] : 0.0));
        dp = dp * w + p;
        p = p * w + H;
        dq = dq * v + q;
        q = q * v + conjq(H);
    }
    const __float128 a1 = (__float128)x[0] + (lo ? lo[0] : 0.0), b1 = (__float128)x[1] + (lo ? lo[1] : 0.0);
    *J = a1 * a1 + b1 * b1 - p * q;
    *J1 = -(dp * (mi * w) * q - p * dq * (mi * v));
}

/* Near the boundary of D the zeros of J come in pairs a +- i d with d ~ sqrt(2 min J / J'') (the
 * minimum of J at a): a nearly double root of the polynomial, which double precision places only
 * to ~sqrt(u) ~ 1e-8 -- at min J ~ 1e-16 that is d itself, and the pair may even land on the
 * circle. Every zero closer than REFINE to the real axis is recomputed by Newton's method in
 * binary128 from the quadratic model at its foot, a + i sqrt(2 J(a) / J''(a)) (J(a) in double-double, shape.h),
 * which lies next to the upper zero of the pair; repeats are dropped. */
#define REFINE 1e-5
static int refine_close(const swim_barrier_quad *b, const double *x, double complex *z, int nz)
{
    int m = 0;
    for (int r = 0; r < nz; r++) {
        double complex zr = z[r];
        double J, J1, J2 = 0.0, Jd;
        if (cimag(zr) < REFINE) {
            j_derivs(b, creal(zr), &Jd, &J1, &J2);
            J = swim_shape_j_precise(b->N, x, b->lo, creal(zr), NULL);
            if (!(J > 0.0)) return -1;   /* outside D */
        }
        if (cimag(zr) < REFINE && J2 > 0.0) {
            __complex128 th;
            __real__ th = creal(zr);
            __imag__ th = sqrt(2.0 * J / J2);
            for (int it = 0; it < 30; it++) {
                __complex128 Jc, J1c;
                j_complex_q(b, x, th, &Jc, &J1c);
                const __complex128 step = Jc / J1c;
                th -= step;
                if (cabsq(step) <= 1e-30Q * (1 + cabsq(th))) break;
            }
            zr = CMPLX((double)crealq(th), fabs((double)cimagq(th)));
            if (!isfinite(creal(zr)) || !isfinite(cimag(zr))) return -1;
            zr = CMPLX(fmod(creal(zr) + 2.0 * TWO_PI, TWO_PI), cimag(zr));
        }
        int dup = 0;
        for (int k = 0; k < m && !dup; k++) dup = modulus(z[k] - zr) < 1e-12;
        if (!dup) z[m++] = zr;
    }
    return m;
}

/* Parameter of the Bernstein ellipse of [-1, 1] through zeta = x + iy: rho = a + b with the
 * semi-axes a^2 = b^2 + 1 (foci +-1), and b^2 the positive root of b^4 + (1 - x^2 - y^2) b^2 - y^2
 * = 0, taken in the form without cancellation on either side of the unit circle (a zeta close to
 * the interval, y -> 0 inside it, is the case that matters: rho - 1 ~ b). No complex square roots. */
static double bernstein(double complex zeta)
{
    const double x = creal(zeta), y = cimag(zeta), s = x * x + y * y - 1.0, disc = sqrt(s * s + 4.0 * y * y);
    const double b2 = s >= 0.0 ? 0.5 * (s + disc) : (disc - s > 0.0 ? 2.0 * y * y / (disc - s) : 0.0);
    return sqrt(b2 + 1.0) + sqrt(b2);
}

/* Gauss nodes needed on [base + u, base + v] so that no zero of J is inside the ellipse of the
 * error bound; 0 when more than QMAX are needed (the panel must be halved). */
static int panel_nodes(const double complex *z, int nz, double base, double u, double v, int K)
{
    const double mid = 0.5 * (u + v), half = 0.5 * (v - u);
    /* A zero outside the ellipse E_rho of the running minimum cannot lower it: it is outside
     * when |zeta| exceeds the semi-major axis (rho + 1/rho)/2 or |Im zeta| the semi-minor
     * (rho - 1/rho)/2, two tests without square roots that skip most zeros. rho starts at
     * RHO_QMIN, beyond which QMIN nodes are enough anyway. */
    double rho = RHO_QMIN;
    double amaj = 0.5 * (rho + 1.0 / rho), amin = 0.5 * (rho - 1.0 / rho);
    for (int r = 0; r < nz; r++)
        for (int k = -1; k <= 1; k++) {
            double complex zeta = ((z[r] + k * TWO_PI - base) - mid) / half;
            const double re = creal(zeta), im = cimag(zeta);
            if (fabs(im) >= amin || re * re + im * im >= amaj * amaj) continue;
            const double rz = bernstein(zeta);
            if (rz < rho) {
                rho = rz;
                amaj = 0.5 * (rho + 1.0 / rho);
                amin = 0.5 * (rho - 1.0 / rho);
            }
        }
    if (!(rho > 1.0)) return 0;
    const double L = log(1.0 / GAUSS_TOL), smax = log(rho), q0 = ceil(L / (2.0 * smax)) + 2.0;
    if (!(q0 <= QMAX)) return 0;   /* before the conversion: near a zero q0 is huge */
    int q = q0 < QMIN ? QMIN : (int)q0;
    /* The gradient's integrands also carry e^{ik theta}, |k| <= K (z^{m-1} h, ERRATA B3), which
     * grows like e^{K half sinh s} on the ellipse of parameter e^s: the bound of q nodes is then
     * e^{K half sinh s - 2 (q - 2) s}, least at cosh s = 2 (q - 2) / (K half), s no larger than the
     * zeros allow. On long panels far from the zeros this, not J, decides (at N = 32 a 35-node
     * rule that ignored it got the gradient wrong by 260 %). */
    const double kl = K * half;
    if (kl * sinh(smax) > 0.1)   /* below, the factor e^0.1 is within the margin of the + 2 */
        for (; q <= QMAX; q++) {
            const double c = 2.0 * (q - 2) / kl, s = c > 1.0 ? fmin(smax, acosh(c)) : 0.0;
            if (2.0 * (q - 2) * s - kl * sinh(s) >= L) break;
        }
    return q > QMAX ? 0 : q;
}

/* J(a) and J'(a) in double-double (shape.h): near a zero of J their double values would carry the
 * cancellation error of |c_1|^2 - |h|^2, and the rounding of a shifted shape (b->lo). */
static void precise_base(const swim_barrier_quad *b, const double *x, double a, double *J, double *J1)
{
    *J = swim_shape_j_precise(b->N, x, b->lo, a, J1);
}

/* sin s - s without cancellation. */
static double sin_minus(double s)
{
    if (fabs(s) > SERIES_MAX) return sin(s) - s;
    double sm, cm;
    sincos_series(s, &sm, &cm);
    return sm;
}

/* J(a + s) = J(a) + J'(a) s + 2 Re sum_p B_p F_p(s), B_p = J_p e^{ipa}, F_p = e^{ips} - 1 - ips,
 * by F_{p+1} = F_p e^{is} + F_1 + i p s (e^{is} - 1): every term is O(s^2). For m <= PBLOCK
 * offsets s at once, in structure-of-arrays form (p outside, the offsets inside, only the real
 * part of the sum kept) so that the loop over the offsets vectorizes; each value is the same
 * sequence of operations as one complex recurrence per offset. */
#define PBLOCK 64
static void precise_J(const swim_barrier_quad *b, const double complex *B, double Ja, double J1a,
                      const double *s, int m, double *J)
{
    double E1r[PBLOCK], E1i[PBLOCK], F1r[PBLOCK], F1i[PBLOCK], Fr[PBLOCK], Fi[PBLOCK], acc[PBLOCK];
    for (int k = 0; k < m; k++) {
        double sh, ch, sm;
        cos_sin(0.5 * s[k], &ch, &sh);
        E1r[k] = F1r[k] = -2.0 * sh * sh;
        F1i[k] = sm = sin_minus(s[k]);
        E1i[k] = s[k] + sm;   /* sin s */
        Fr[k] = F1r[k];
        Fi[k] = F1i[k];
        acc[k] = 0.0;
    }
    for (int p = 1; p < b->N; p++) {
        const double Br = creal(B[p]), Bi = cimag(B[p]);
        for (int k = 0; k < m; k++) {
            const double er = 1.0 + E1r[k], ei = E1i[k], ps = p * s[k];
            acc[k] += Br * Fr[k] - Bi * Fi[k];
            const double nr = (Fr[k] * er - Fi[k] * ei + F1r[k]) - ps * E1i[k];
            Fi[k] = (Fr[k] * ei + Fi[k] * er + F1i[k]) + ps * E1r[k];
            Fr[k] = nr;
        }
    }
    for (int k = 0; k < m; k++) J[k] = Ja + J1a * s[k] + 2.0 * acc[k];
}

typedef struct {
    double a, Ja, J1a;
    double complex B[64];
} center;

static double wrap(double t)
{
    t = fmod(t, TWO_PI);
    if (t > 0.5 * TWO_PI) t -= TWO_PI;
    if (t < -0.5 * TWO_PI) t += TWO_PI;
    return t;
}

/* Graded composite Gauss-Legendre rule (see barrier.h). Returns 0, 1 (outside D), -1 (memory). */
static int graded(swim_barrier_quad *b, const double *x, double eps, double alpha, double *W,
                  double *grad, swim_barrier_info *info)
{
    const int N = b->N;
    double complex z[128];
    int nz = zeros(b, z);   /* J_p: fourier() of x, by trapezoid() just before */
    if (nz < 0) return -1;
    nz = refine_close(b, x, z, nz);
    if (nz < 0) return 1;
    /* panel starts: feet of the close zeros, sorted, without repeats */
    double brk[128];
    int nb = 0;
    double dmin = INFINITY;
    for (int r = 0; r < nz; r++) {
        dmin = fmin(dmin, cimag(z[r]));
        if (cimag(z[r]) < CLOSE) brk[nb++] = creal(z[r]);   /* in [0, 2 pi) */
    }
    if (info) info->dist = dmin;
    for (int i = 1; i < nb; i++)
        for (int j = i; j > 0 && brk[j] < brk[j - 1]; j--) {
            double t = brk[j];
            brk[j] = brk[j - 1];
            brk[j - 1] = t;
        }
    int u = 0;
    for (int i = 0; i < nb; i++)
        if (u == 0 || brk[i] - brk[u - 1] > 1e-13) brk[u++] = brk[i];
    nb = u;
    if (nb == 0) brk[nb++] = 0.0;
    /* centers of the cancellation-free evaluation */
    center cen[16];
    int nc = 0;
    for (int r = 0; r < nz && nc < 16; r++) {
        if (cimag(z[r]) >= PRECISE) continue;
        double a = creal(z[r]);
        {   /* where J stays above PRECISE_J |c_1|^2 near the foot, double precision loses no more
             * than ~1e-14 relative: extended precision (costly) only where it is needed */
            double Jd, J1d, J2d;
            j_derivs(b, a, &Jd, &J1d, &J2d);
            if (Jd > PRECISE_J * (x[0] * x[0] + x[1] * x[1])) continue;
        }
        int dup = 0;
        for (int c = 0; c < nc; c++) dup |= fabs(wrap(cen[c].a - a)) < 1e-13;
        if (dup) continue;
        center *c = &cen[nc++];
        c->a = a;
        precise_base(b, x, a, &c->Ja, &c->J1a);
        if (!(c->Ja > 0.0)) return 1;
        for (int p = 1; p < N; p++) c->B[p] = b->Jp[p] * cexp(I * (p * a));
    }
    /* Panels by halving until the a priori bound holds. Each interval between two breakpoints
     * is cut in the middle and each half is laid out in offsets from its own breakpoint: near a
     * zero the panels are as small as 1e-6, and absolute angles would round their nodes by a
     * relative 1e-10. */
    int nodes = 0, panels = 0;
    struct { double u, v; int depth; } stack[2 * MAX_DEPTH + 8];
    for (int i = 0; i < nb; i++)
        for (int side = 0; side < 2; side++) {
            const double base = brk[i];
            const double next = i + 1 < nb ? brk[i + 1] : brk[0] + TWO_PI;
            const double prev = i > 0 ? brk[i - 1] : brk[nb - 1] - TWO_PI;
            int sp = 0;
            stack[sp].u = side ? 0.0 : -0.5 * (base - prev);
            stack[sp].v = side ? 0.5 * (next - base) : 0.0;
            stack[sp++].depth = 0;
            while (sp > 0) {
                double pu = stack[sp - 1].u, pv = stack[sp - 1].v;
                int depth = stack[--sp].depth;
                int q = panel_nodes(z, nz, base, pu, pv, N - 1);
                if (q == 0) {
                    if (depth >= MAX_DEPTH) return 1;   /* a zero of J on the circle itself */
                    double pm = 0.5 * (pu + pv);
                    stack[sp].u = pm; stack[sp].v = pv; stack[sp++].depth = depth + 1;
                    stack[sp].u = pu; stack[sp].v = pm; stack[sp++].depth = depth + 1;
                    continue;
                }
                if (reserve(b, nodes + q) != 0) return -1;
                const double mid = 0.5 * (pu + pv), half = 0.5 * (pv - pu);
                for (int k = 0; k < q; k++) {
                    b->base[nodes] = base;
                    b->th[nodes] = mid + half * b->gx[q][k];
                    b->ctr[nodes] = mid;
                    b->off[nodes] = half * b->gx[q][k];
                    b->wt[nodes++] = half * b->gw[q][k];
                }
                panels++;
            }
        }
    /* cos, sin theta_k at the nodes; h and J by Horner in e^{-i theta}, the gradient sums by
     * powers of e^{i theta} (power_sums): no tables of cos, sin(j theta) */
    if (reserve_tables(b, 2 * (size_t)nodes) != 0) return -1;
    double *cs = b->gcs;
    node_angles(b, nodes, cs, cs + nodes);
    node_values_horner(b, cs, cs + nodes, nodes, x, b->hr, b->hi, b->jv);
    for (int c = 0; c < nc; c++)   /* nodes near a close zero: offsets from its foot */
        for (int k0 = 0; k0 < nodes;) {
            int idx[PBLOCK], m = 0;
            double off[PBLOCK], Jp[PBLOCK];
            for (; k0 < nodes && m < PBLOCK; k0++)
                if (b->base[k0] == cen[c].a && fabs(b->th[k0]) < NEAR) {
                    idx[m] = k0;
                    off[m++] = b->th[k0];
                }
            precise_J(b, cen[c].B, cen[c].Ja, cen[c].J1a, off, m, Jp);
            for (int i = 0; i < m; i++) b->jv[idx[i]] = Jp[i];
        }
    memcpy(b->jnode, b->jv, sizeof(double) * (size_t)nodes);   /* node_sums overwrites jv */
    sums s;
    memset(&s, 0, sizeof s);
    if (weight_sums(nodes, b->jv, b->wt, alpha, grad != NULL, &s)) return 1;
    if (grad) power_sums(b, cs, cs + nodes, nodes, b->hr, b->hi, b->jv, &s);
    finish(b, &s, 1.0, x, eps, alpha, W, grad);
    if (info) {
        info->nodes = nodes;
        info->panels = panels;
    }
    return 0;
}

int swim_barrier_w2(swim_barrier_quad *b, const double *x, double eps, double alpha, double *W,
                      double *grad, swim_barrier_info *info)
{
    swim_barrier_info local;
    if (!info) info = &local;
    memset(info, 0, sizeof *info);
    double gtmp[2 * 64 + 2];
    double *g = grad ? gtmp : NULL;
    int rc = trapezoid(b, x, eps, alpha, W, g, &info->nodes);
    if (rc == 2) {
        info->graded = 1;
        rc = graded(b, x, eps, alpha, W, g, info);
    }
    if (rc == 1) {
        *W = INFINITY;
        return SWIM_BARRIER_OUTSIDE;
    }
    if (rc < 0) return SWIM_BARRIER_ENOMEM;
    if (grad) memcpy(grad, gtmp, sizeof(double) * (size_t)b->n);
    return SWIM_BARRIER_OK;
}

int swim_barrier_w2_carry(swim_barrier_quad *b, const double *x, const double *lo, double eps, double alpha,
                          double *W, double *grad, swim_barrier_info *info)
{
    b->lo = lo;
    const int rc = swim_barrier_w2(b, x, eps, alpha, W, grad, info);
    b->lo = NULL;
    return rc;
}

double swim_barrier_reach(swim_barrier_quad *b, const double *x, double eps, double alpha,
                          double energy, double *kappa)
{
    double W, g[2 * 64 + 2];
    if (swim_barrier_w2(b, x, eps, alpha, &W, g, NULL) != SWIM_BARRIER_OK) return NAN;
    const double c1 = x[0] * x[0] + x[1] * x[1];
    const double integral = -(g[0] * x[0] + g[1] * x[1]) / (eps * c1);   /* int J^(-1-alpha) */
    const double j0 = swim_shape_jmin(b->N, x);
    const double k = 0.5 * eps * j0 * integral;
    if (kappa) *kappa = k;
    if (!(j0 > 0.0) || !(k > 0.0)) return NAN;
    const double p = alpha - 0.5;
    if (fabs(p) < 1e-12) return j0 * exp(-energy / k);
    const double base = 1.0 + energy * p / k;
    return base > 0.0 ? j0 * pow(base, -1.0 / p) : 0.0;
}

/* J^-alpha, without pow() for the two exponents the paper uses. */
static double jpow(double J, double alpha)
{
    if (alpha == 0.5) return 1.0 / sqrt(J);
    if (alpha == 1.0) return 1.0 / J;
    return pow(J, -alpha);
}

/* ---- the Hessian ------------------------------------------------------------------------- */

/* The Hessian is assembled from a few Fourier sums over the nodes rather than a rank-one update
 * per node (O(N) work per node instead of O(n^2)). With a = wt (alpha+1) J^{-alpha-2},
 * g = wt J^{-alpha-1} and p_m = -2m z^{m-1} h (= dJ/da_-m + i dJ/db_-m, ERRATA B3):
 *   A0 = sum a,  Q_m = sum a z^{m-1} h,  F1_d = sum a |h|^2 z^d,  F2_e = sum a h^2 z^e,
 *   cp + i sp = sum g z^p,
 * since p_m conj(p_l) = 4ml z^{m-l} |h|^2 and p_m p_l = 4ml z^{m+l-2} h^2. */
typedef struct {
    double A0, cp[64], sp[64];
    double complex Q[64], F1[64], F2[128];
} hess_sums;

/* The sums above over nodes k = 0..m-1 (z_k = c_k + i s_k, h_k, J_k, weight w_k or, with w
 * NULL, wu), added to hs. As power_sums: blocks of 8 nodes outside, the powers inside, each sum
 * in 8 lanes (node k in lane k % 8) that total8 adds up once; the nodes after the last block
 * one by one. z^p and a h z^p advance by a multiplication per power. */
static void hess_sums_add(int N, double alpha, const double *c, const double *sn, const double *hr,
                          const double *hi, const double *J, const double *w, double wu, int m,
                          hess_sums *hs)
{
    typedef struct {
        vec4 v[2];
    } lanes;
    static const lanes zero;
    lanes A0 = zero, cp[64], sp[64], Qr[64], Qi[64], F1r[64], F1i[64], F2r[128], F2i[128];
    const int P = N > 0 ? N : 1, P2 = 2 * N - 1 > 0 ? 2 * N - 1 : 0, mv = m - m % 8;
    for (int p = 0; p < P; p++) cp[p] = sp[p] = Qr[p] = Qi[p] = F1r[p] = F1i[p] = zero;
    for (int q = 0; q < P2; q++) F2r[q] = F2i[q] = zero;
    for (int k = 0; k < mv; k += 8)
        for (int h = 0; h < 2; h++) {   /* nodes k + 4h .. k + 4h + 3 */
            const int o = k + 4 * h;
            double gv[4], av[4];
            for (int i = 0; i < 4; i++) {
                const double Jk = J[o + i];
                gv[i] = (w ? w[o + i] : wu) * jpow(Jk, alpha) / Jk;   /* wt J^{-alpha-1} */
                av[i] = (alpha + 1.0) * gv[i] / Jk;                   /* wt (alpha+1) J^{-alpha-2} */
            }
            const vec4 g = load4(gv), a = load4(av), zr = load4(c + o), zi = load4(sn + o);
            const vec4 xr = load4(hr + o), xi = load4(hi + o);
            A0.v[h] += a;
            const vec4 ah2 = a * (xr * xr + xi * xi);
            vec4 er = {1.0, 1.0, 1.0, 1.0}, ei = {0.0, 0.0, 0.0, 0.0}, tr = a * xr, ti = a * xi;
            for (int p = 0; p < N; p++) {   /* z^p, p = 0..N-1 */
                cp[p].v[h] += g * er;
                sp[p].v[h] += g * ei;
                F1r[p].v[h] += ah2 * er;
                F1i[p].v[h] += ah2 * ei;
                Qr[p].v[h] += tr;
                Qi[p].v[h] += ti;
                const vec4 t2 = tr * zr - ti * zi, e2 = er * zr - ei * zi;
                ti = tr * zi + ti * zr;
                ei = er * zi + ei * zr;
                tr = t2;
                er = e2;
            }
            if (N == 0) cp[0].v[h] += g;
            vec4 fr = a * (xr * xr - xi * xi), fi = a * (2.0 * xr * xi);   /* a h^2 */
            for (int q = 0; q < P2; q++) {
                F2r[q].v[h] += fr;
                F2i[q].v[h] += fi;
                const vec4 f2 = fr * zr - fi * zi;
                fi = fr * zi + fi * zr;
                fr = f2;
            }
        }
    double tA0 = 0.0, tcp[64] = {0}, tsp[64] = {0}, tQr[64] = {0}, tQi[64] = {0}, tF1r[64] = {0},
           tF1i[64] = {0}, tF2r[128] = {0}, tF2i[128] = {0};
    for (int k = mv; k < m; k++) {
        const double g = (w ? w[k] : wu) * jpow(J[k], alpha) / J[k], a = (alpha + 1.0) * g / J[k];
        const double zr = c[k], zi = sn[k], xr = hr[k], xi = hi[k];
        tA0 += a;
        const double ah2 = a * (xr * xr + xi * xi);
        double er = 1.0, ei = 0.0, tr = a * xr, ti = a * xi;
        for (int p = 0; p < N; p++) {
            tcp[p] += g * er;
            tsp[p] += g * ei;
            tF1r[p] += ah2 * er;
            tF1i[p] += ah2 * ei;
            tQr[p] += tr;
            tQi[p] += ti;
            const double t2 = tr * zr - ti * zi, e2 = er * zr - ei * zi;
            ti = tr * zi + ti * zr;
            ei = er * zi + ei * zr;
            tr = t2;
            er = e2;
        }
        if (N == 0) tcp[0] += g;
        double fr = a * (xr * xr - xi * xi), fi = a * (2.0 * xr * xi);
        for (int q = 0; q < P2; q++) {
            tF2r[q] += fr;
            tF2i[q] += fi;
            const double f2 = fr * zr - fi * zi;
            fi = fr * zi + fi * zr;
            fr = f2;
        }
    }
    hs->A0 += total8(A0.v[0], A0.v[1], tA0);
    for (int p = 0; p < P; p++) {
        hs->cp[p] += total8(cp[p].v[0], cp[p].v[1], tcp[p]);
        hs->sp[p] += total8(sp[p].v[0], sp[p].v[1], tsp[p]);
        hs->Q[p] += CMPLX(total8(Qr[p].v[0], Qr[p].v[1], tQr[p]), total8(Qi[p].v[0], Qi[p].v[1], tQi[p]));
        hs->F1[p] += CMPLX(total8(F1r[p].v[0], F1r[p].v[1], tF1r[p]), total8(F1i[p].v[0], F1i[p].v[1], tF1i[p]));
    }
    for (int q = 0; q < P2; q++)
        hs->F2[q] += CMPLX(total8(F2r[q].v[0], F2r[q].v[1], tF2r[q]), total8(F2i[q].v[0], F2i[q].v[1], tF2i[q]));
}

int swim_barrier_hessian(swim_barrier_quad *b, const double *x, double eps, double alpha,
                         double *W, double *grad, double *hess, swim_barrier_info *info)
{
    swim_barrier_info local;
    if (!info) info = &local;
    int rc = swim_barrier_w2(b, x, eps, alpha, W, grad, info);
    if (rc != SWIM_BARRIER_OK) return rc;
    const int N = b->N, n = b->n;
    hess_sums hs;
    memset(&hs, 0, sizeof hs);
    if (!info->graded) {
        /* the levels of the nested trapezoidal rule that swim_barrier_w2 accepted: h and J at
         * their nodes as trap_level has them, cos and sin theta from the level's table (its row
         * j = 1; for N < 2 no power of z is read) */
        const int Q = info->nodes;
        for (int l = 0, used = 0; l < b->levels && used < Q; used += b->lnodes[l], l++) {
            const int m = b->lnodes[l];
            node_values(b, b->tcs[l], b->tsn[l], m, x, b->hr, b->hi, b->jv);
            const double *zc = N >= 2 ? b->tcs[l] + m : b->tcs[l], *zs = N >= 2 ? b->tsn[l] + m : b->tsn[l];
            hess_sums_add(N, alpha, zc, zs, b->hr, b->hi, b->jv, NULL, TWO_PI / Q, m, &hs);
        }
    } else {
        const int m = info->nodes;   /* the graded nodes of the call above: cos, sin theta in gcs */
        hess_sums_add(N, alpha, b->gcs, b->gcs + m, b->hr, b->hi, b->jnode, b->wt, 0.0, m, &hs);
    }
    /* hess W2 = eps/2 (sum a u u^T - sum g d2J), u = grad J = (2 a_1, 2 b_1, Re p_m, Im p_m);
     * d2J: 2 on a_1, b_1; for the modes -m, -l (ERRATA B2)
     * d2/da da = d2/db db = -2ml cos((l-m) th), d2/da_m db_l = -2ml sin((l-m) th). */
    const double c = 0.5 * eps;
    for (int i = 0; i < n; i++)
        for (int j = i; j < n; j++) {
            double uu, d2 = 0.0;
            if (j < 2) {
                uu = 4.0 * x[i] * x[j] * hs.A0;
                d2 = i == j ? 2.0 * hs.cp[0] : 0.0;
            } else if (i < 2) {
                const int l = j / 2;
                const double complex q = -2.0 * l * hs.Q[l - 1];
                uu = 2.0 * x[i] * (j % 2 ? cimag(q) : creal(q));
            } else {
                const int m = i / 2, l = j / 2, d = l - m;   /* d >= 0 */
                const double w = 4.0 * m * l;
                const double complex P1 = w * conj(hs.F1[d]), P2 = w * hs.F2[m + l - 2];
                if (i % 2 == 0 && j % 2 == 0) uu = 0.5 * creal(P1 + P2);
                else if (i % 2 && j % 2) uu = 0.5 * creal(P1 - P2);
                else if (i % 2 == 0) uu = 0.5 * cimag(P2 - P1);   /* Re p_m Im p_l */
                else uu = 0.5 * cimag(P1 + P2);                   /* Im p_m Re p_l */
                const double v2 = -0.5 * w;                       /* -2ml */
                if (i % 2 == j % 2) d2 = v2 * hs.cp[d];
                else if (i % 2 == 0) d2 = v2 * hs.sp[d];          /* a_m, b_l: sin((l-m) th) */
                else d2 = -v2 * hs.sp[d];                         /* b_m, a_l: sin((m-l) th) */
            }
            const double v = c * (uu - d2);
            hess[(size_t)i * n + j] = hess[(size_t)j * n + i] = v;
        }
    return SWIM_BARRIER_OK;
}
