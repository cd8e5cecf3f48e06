/* Generated kernels against independent routes.
 *
 * - Values: the generated Mr, Nc, Md, K against tests/reference (plain loops over the paper's
 *   closed forms, no code shared with the generator), N = 0..7 (linked in) and 12, 15, 20
 *   (generated and cached at run time by runtime/codegen: the kernel `swim inspect` prints).
 * - Derivatives: generated dMr, dNc, dMd, dK and both forms of Gamma against numerical
 *   differentiation of the *reference* matrices: central differences with two levels of
 *   Richardson extrapolation (steps h, h/2, h/4; truncation error O(h^6)), h = 1e-2.
 * - The row diagnostics' blocks (row_blocks): the bits of mass and reduced, in the columns asked.
 * - Structure: K exactly symmetric, smallest eigenvalue of K (LAPACK dsyev) >= rho0 pi/(2(N+1))
 *   (Lemma 4.3), Gamma symmetric in its two velocity slots.
 * - Barrier W2 (shape/barrier.h): value and gradient against the reference and against
 *   Richardson differences; nodes and accuracy at Example 7's shape and at min J = 1e-4.
 * - A classical result the paper does not state: the added-mass tensor of an elliptic cylinder,
 *   m_xx = rho_f pi b^2, m_yy = rho_f pi a^2, m_rot = rho_f pi (a^2 - b^2)^2 / 8 for semi-axes
 *   a (along x) and b (Lamb, Hydrodynamics, 6th ed. 1932, section 72; Newman, Marine
 *   Hydrodynamics, 1977, table 4.2), rotated with the ellipse.
 * - A generator that fails: the status says which kernel and where its log is, keeps the end of
 *   the log, and nothing else is filled.
 */
#include <lapacke.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "capture.h"
#include "check.h"
#include "shape/barrier.h"
#include "shape/shape.h"
#include "reference/ref_model.h"
#include "codegen/codegen.h"
#include "kernel/swim_kernel.h"

#define NMAX (2 * (SWIM_KERNEL_MAX_MODES + 1))

static double urand(void) { return 2.0 * rand() / (double)RAND_MAX - 1.0; }

/* A random admissible shape: sum_m m |c_-m| <= 0.85 |c_1| guarantees J > 0 (2.4). */
static void random_shape(int N, double *x, double spread)
{
    double c1 = 1.0 + 0.2 * urand(), ang = 3.0 * urand();
    x[0] = c1 * cos(ang);
    x[1] = c1 * sin(ang);
    double w[SWIM_KERNEL_MAX_MODES + 1], tot = 0.0;
    for (int m = 1; m <= N; m++) {
        w[m] = fabs(urand()) / m;
        tot += m * w[m];
    }
    for (int m = 1; m <= N; m++) {
        double r = tot > 0 ? spread * c1 * w[m] / tot : 0.0, a = 3.14159 * urand();
        x[2 * m] = r * cos(a);
        x[2 * m + 1] = r * sin(a);
    }
}

static double max_abs(const double *a, int len)
{
    double m = 0.0;
    for (int i = 0; i < len; i++) m = fmax(m, fabs(a[i]));
    return m;
}

static double max_diff(const double *a, const double *b, int len)
{
    double m = 0.0;
    for (int i = 0; i < len; i++) m = fmax(m, fabs(a[i] - b[i]));
    return m;
}

/* Everything the reference computes at one shape, flattened: Mr | Nc | Md | K. */
static void ref_all(int N, const double *x, double rho0, double rhof, double *out)
{
    int n = 2 * (N + 1);
    ref_mass(N, x, rho0, rhof, out, out + 9, out + 9 + 3 * n, out + 9 + 3 * n + n * n);
}

/* d out / d x_r by Richardson-extrapolated central differences (O(h^6)). */
static void ref_all_deriv(int N, const double *x, int r, double rho0, double rhof, double h,
                          double *d)
{
    int n = 2 * (N + 1), len = 9 + 3 * n + 2 * n * n;
    double *p = malloc(sizeof(double) * len), *m = malloc(sizeof(double) * len);
    double *D[3];
    double xp[NMAX];
    for (int lev = 0; lev < 3; lev++) {
        double hh = h / (1 << lev);
        D[lev] = malloc(sizeof(double) * len);
        memcpy(xp, x, sizeof(double) * n);
        xp[r] = x[r] + hh;
        ref_all(N, xp, rho0, rhof, p);
        xp[r] = x[r] - hh;
        ref_all(N, xp, rho0, rhof, m);
        for (int i = 0; i < len; i++) D[lev][i] = (p[i] - m[i]) / (2 * hh);
    }
    for (int i = 0; i < len; i++) {
        double r1 = (4 * D[1][i] - D[0][i]) / 3, r2 = (4 * D[2][i] - D[1][i]) / 3;
        d[i] = (16 * r2 - r1) / 15;
    }
    for (int lev = 0; lev < 3; lev++) free(D[lev]);
    free(p);
    free(m);
}

static void check_values(const swim_kernel *k, int trials)
{
    const int N = k->modes, n = k->dim;
    double worst = 0.0;
    for (int t = 0; t < trials; t++) {
        double x[NMAX], rho0 = 0.5 + fabs(urand()), rhof = 0.5 + fabs(urand());
        random_shape(N, x, 0.85 * fabs(urand()));
        double Mr[9], Nc[3 * NMAX], Md[NMAX * NMAX], K[NMAX * NMAX];
        double rMr[9], rNc[3 * NMAX], rMd[NMAX * NMAX], rK[NMAX * NMAX];
        k->mass(x, rho0, rhof, Mr, Nc, Md);
        CHECK(k->reduced(x, NULL, rho0, rhof, K, NULL, NULL) == 0, "N=%d reduced failed", N);
        ref_mass(N, x, rho0, rhof, rMr, rNc, rMd, rK);
        double e1 = max_diff(Mr, rMr, 9) / max_abs(rMr, 9);
        double e2 = max_diff(Nc, rNc, 3 * n) / fmax(max_abs(rNc, 3 * n), max_abs(rMr, 9));
        double e3 = max_diff(Md, rMd, n * n) / max_abs(rMd, n * n);
        double e4 = max_diff(K, rK, n * n) / max_abs(rK, n * n);
        double e = fmax(fmax(e1, e2), fmax(e3, e4));
        worst = fmax(worst, e);
        CHECK(e <= 1e-13, "N=%d: kernel vs reference, relative error %.3g (Mr %.2g Nc %.2g Md %.2g K %.2g)",
              N, e, e1, e2, e3, e4);
        int sym = 1;
        for (int i = 0; i < n; i++)
            for (int j = 0; j < n; j++) sym &= K[i * n + j] == K[j * n + i];
        CHECK(sym, "N=%d: K not exactly symmetric", N);
        /* Lemma 4.3: c^T K c >= rho0 pi / (2(N+1)) |c|^2. */
        double A[NMAX * NMAX], ev[NMAX];
        memcpy(A, K, sizeof(double) * n * n);
        CHECK(LAPACKE_dsyev(LAPACK_ROW_MAJOR, 'N', 'U', n, A, n, ev) == 0, "dsyev failed");
        double nu = rho0 * M_PI / (2.0 * (N + 1));
        CHECK(ev[0] >= nu, "N=%d: smallest eigenvalue of K %.6g < nu_N = %.6g", N, ev[0], nu);
    }
    printf("  N=%2d values: max relative error vs reference %.2e (%d shapes)\n", N, worst, trials);
}

/* row_blocks against mass and reduced, bit for bit: Mr whole, Nc, P and Md in the columns where
 * v is not 0 (v with about half its entries 0, and v = 0 and v without a 0); a shape whose Mr
 * is not positive definite (NaN) is refused as by reduced. */
static void check_row_blocks(const swim_kernel *k, int trials)
{
    const int N = k->modes, n = k->dim;
    int same = 1, columns = 1;
    for (int t = 0; t < trials + 2; t++) {
        double x[NMAX], v[NMAX], rho0 = 0.5 + fabs(urand()), rhof = 0.5 + fabs(urand());
        random_shape(N, x, 0.85 * fabs(urand()));
        for (int i = 0; i < n; i++) v[i] = t == trials ? 0.0 : t == trials + 1 || urand() > 0.0 ? urand() : 0.0;
        double Mr[9], Nc[3 * NMAX], Md[NMAX * NMAX], P[3 * NMAX];
        double bMr[9], bNc[3 * NMAX], bMd[NMAX * NMAX], bP[3 * NMAX];
        int idx[NMAX], m = k->row_blocks(x, v, rho0, rhof, bMr, bNc, bP, idx, bMd);
        k->mass(x, rho0, rhof, Mr, Nc, Md);
        CHECK(k->reduced(x, NULL, rho0, rhof, NULL, P, NULL) == 0, "N=%d reduced failed", N);
        int want = 0;
        for (int i = 0; i < n; i++)
            if (v[i] != 0.0) columns &= m > want && idx[want++] == i;
        columns &= m == want;
        if (m != want) continue;
        same &= memcmp(Mr, bMr, sizeof Mr) == 0;
        for (int a = 0; a < m; a++) {
            for (int p = 0; p < 3; p++)
                same &= memcmp(&Nc[p * n + idx[a]], &bNc[p * m + a], sizeof(double)) == 0 &&
                        memcmp(&P[p * n + idx[a]], &bP[p * m + a], sizeof(double)) == 0;
            for (int b = 0; b < m; b++) same &= memcmp(&Md[idx[a] * n + idx[b]], &bMd[a * m + b], sizeof(double)) == 0;
        }
    }
    CHECK(columns, "N=%d: row_blocks lists the columns where v is not 0", N);
    CHECK(same, "N=%d: row_blocks gives the bits of mass and reduced", N);
    double x[NMAX], v[NMAX], Mr[9], Nc[3 * NMAX], Md[NMAX * NMAX], P[3 * NMAX];
    int idx[NMAX];
    random_shape(N, x, 0.5);
    for (int i = 0; i < n; i++) v[i] = 1.0;
    x[0] = NAN;
    CHECK(k->row_blocks(x, v, 1.0, 1.0, Mr, Nc, P, idx, Md) == -1 && k->reduced(x, NULL, 1.0, 1.0, NULL, P, NULL) == -1,
          "N=%d: row_blocks refuses a shape whose Mr is not positive definite, as reduced", N);
}

static void check_derivatives(const swim_kernel *k, int trials)
{
    const int N = k->modes, n = k->dim, len = 9 + 3 * n + 2 * n * n;
    double worst_m = 0.0, worst_k = 0.0, worst_g = 0.0, worst_c = 0.0;
    double *dMr = malloc(sizeof(double) * n * 9), *dNc = malloc(sizeof(double) * n * 3 * n);
    double *dMd = malloc(sizeof(double) * n * n * n), *dK = malloc(sizeof(double) * n * n * n);
    double *G = malloc(sizeof(double) * n * n * n), *fd = malloc(sizeof(double) * n * len);
    double *Gfd = malloc(sizeof(double) * n * n * n);
    for (int t = 0; t < trials; t++) {
        double x[NMAX], v[NMAX], rho0 = 0.5 + fabs(urand()), rhof = 0.5 + fabs(urand());
        random_shape(N, x, 0.7 * fabs(urand()));
        for (int i = 0; i < n; i++) v[i] = urand();
        CHECK(k->mass_deriv(x, rho0, rhof, dMr, dNc, dMd) == 0, "N=%d mass_deriv failed", N);
        CHECK(k->reduced_deriv(x, rho0, rhof, dK, G) == 0, "N=%d reduced_deriv failed", N);
        for (int r = 0; r < n; r++) ref_all_deriv(N, x, r, rho0, rhof, 1e-2, fd + (size_t)r * len);
        double scale_m = 0.0, err_m = 0.0, scale_k = 0.0, err_k = 0.0;
        for (int r = 0; r < n; r++) {
            const double *f = fd + (size_t)r * len;
            scale_m = fmax(scale_m, fmax(max_abs(f, 9 + 3 * n + n * n), 1.0));
            err_m = fmax(err_m, max_diff(dMr + 9 * r, f, 9));
            err_m = fmax(err_m, max_diff(dNc + 3 * n * r, f + 9, 3 * n));
            err_m = fmax(err_m, max_diff(dMd + n * n * r, f + 9 + 3 * n, n * n));
            scale_k = fmax(scale_k, max_abs(f + 9 + 3 * n + n * n, n * n));
            err_k = fmax(err_k, max_diff(dK + n * n * r, f + 9 + 3 * n + n * n, n * n));
        }
        worst_m = fmax(worst_m, err_m / scale_m);
        worst_k = fmax(worst_k, err_k / fmax(scale_k, 1.0));
        /* Gamma from the differenced dK (ERRATA C1), both forms compared with it. */
        for (int i = 0; i < n; i++)
            for (int j = 0; j < n; j++)
                for (int l = 0; l < n; l++) {
                    const double *dl = fd + (size_t)l * len + 9 + 3 * n + n * n;
                    const double *dj = fd + (size_t)j * len + 9 + 3 * n + n * n;
                    const double *di = fd + (size_t)i * len + 9 + 3 * n + n * n;
                    Gfd[(i * n + j) * n + l] = 0.5 * (dl[i * n + j] + dj[i * n + l] - di[j * n + l]);
                }
        double gscale = fmax(max_abs(Gfd, n * n * n), 1.0);
        worst_g = fmax(worst_g, max_diff(G, Gfd, n * n * n) / gscale);
        double gvv[NMAX], K[NMAX * NMAX], gfd[NMAX], gfull[NMAX];
        CHECK(k->reduced(x, v, rho0, rhof, K, NULL, gvv) == 0, "reduced failed");
        int sym = 1;
        for (int i = 0; i < n; i++) {
            gfd[i] = gfull[i] = 0.0;
            for (int j = 0; j < n; j++)
                for (int l = 0; l < n; l++) {
                    gfd[i] += Gfd[(i * n + j) * n + l] * v[j] * v[l];
                    gfull[i] += G[(i * n + j) * n + l] * v[j] * v[l];
                    sym &= G[(i * n + j) * n + l] == G[(i * n + l) * n + j];
                }
        }
        CHECK(sym, "N=%d: Gamma not symmetric in its velocity slots", N);
        double cs = fmax(max_abs(gfd, n), 1.0);
        worst_c = fmax(worst_c, max_diff(gvv, gfd, n) / cs);
        CHECK(max_diff(gvv, gfull, n) <= 1e-12 * cs, "N=%d: contracted Gamma vs full tensor %.3g", N,
              max_diff(gvv, gfull, n));
    }
    /* Richardson O(h^6) with h = 1e-2 leaves ~1e-10 truncation and ~1e-13 rounding error. */
    CHECK(worst_m <= 1e-8, "N=%d: dM vs differences %.3g", N, worst_m);
    CHECK(worst_k <= 1e-8, "N=%d: dK vs differences %.3g", N, worst_k);
    CHECK(worst_g <= 1e-8, "N=%d: Gamma tensor vs differences %.3g", N, worst_g);
    CHECK(worst_c <= 1e-8, "N=%d: contracted Gamma vs differences %.3g", N, worst_c);
    printf("  N=%2d derivatives vs Richardson differences: dM %.1e dK %.1e Gamma %.1e Gamma(v,v) %.1e\n",
           N, worst_m, worst_k, worst_g, worst_c);
    free(dMr); free(dNc); free(dMd); free(dK); free(G); free(fd); free(Gfd);
}

/* W2 and its gradient (shape/barrier.h) against the reference (tests/reference, trapezoidal rule
 * on 2048 nodes, exact to rounding at these shapes) and against Richardson differences of W2. */
static void check_barrier(const swim_kernel *k)
{
    const int N = k->modes, n = k->dim;
    swim_barrier_quad *b = swim_barrier_quad_new(N);
    CHECK(b != NULL, "barrier quadrature");
    for (int t = 0; t < 4; t++) {
        double x[NMAX], g[NMAX], rg[NMAX], eps = 0.03, alpha = t % 2 ? 1.0 : 0.5, W;
        random_shape(N, x, 0.8);
        CHECK(swim_barrier_w2(b, x, eps, alpha, &W, g, NULL) == SWIM_BARRIER_OK, "W2 inside D");
        double rW = ref_barrier(N, x, eps, alpha, 2048, rg);
        CHECK_CLOSE(W, rW, 1e-13, "W2 vs reference");
        CHECK(max_diff(g, rg, n) <= 1e-12 * fmax(max_abs(rg, n), 1.0), "N=%d: grad W2 vs reference", N);
        double worst = 0.0;
        for (int r = 0; r < n; r++) {
            double xp[NMAX], D[3];
            for (int lev = 0; lev < 3; lev++) {
                double h = 1e-3 / (1 << lev), wp, wm;
                memcpy(xp, x, sizeof(double) * n);
                xp[r] += h;
                swim_barrier_w2(b, xp, eps, alpha, &wp, NULL, NULL);
                xp[r] -= 2 * h;
                swim_barrier_w2(b, xp, eps, alpha, &wm, NULL, NULL);
                D[lev] = (wp - wm) / (2 * h);
            }
            double r1 = (4 * D[1] - D[0]) / 3, r2 = (4 * D[2] - D[1]) / 3, d = (16 * r2 - r1) / 15;
            worst = fmax(worst, fabs(d - g[r]));
        }
        CHECK(worst <= 1e-8 * fmax(max_abs(g, n), 1.0), "N=%d: grad W2 vs differences %.3g", N, worst);
    }
    double x0[NMAX] = {1.0}, W0;
    swim_barrier_w2(b, x0, 0.03, 0.5, &W0, NULL, NULL);
    CHECK_CLOSE(W0, M_PI * 0.03 / 0.5, 1e-15, "W2 at the unit circle = pi eps / alpha (ERRATA B2)");
    swim_barrier_quad_free(b);
}

/* Example 7's initial shape (min J = 0.0396, ERRATA D5): the nested trapezoidal rule stops well
 * below the 256 nodes ERRATA B4 used, at the reference's value. */
static void check_quadrature_nodes(void)
{
    double x[16] = {1, 0, 0.5, 0, 0, 0.24};
    double jmin = swim_shape_jmin(7, x);
    CHECK(fabs(jmin - 0.0396) < 5e-5, "Example 7 initial min J %.6f (ERRATA D5: 0.0396)", jmin);
    swim_barrier_quad *b = swim_barrier_quad_new(7);
    swim_barrier_info info;
    double W, g[16], rg[16];
    swim_barrier_w2(b, x, 0.03, 0.5, &W, g, &info);
    double Wref = ref_barrier(7, x, 0.03, 0.5, 4096, rg);
    printf("  W2 at min J = %.4f: %s rule, %d nodes, relative error %.1e\n", jmin,
           info.graded ? "graded" : "trapezoidal", info.nodes, fabs(W - Wref) / Wref);
    CHECK(!info.graded && info.nodes <= 256, "Example 7: %d nodes", info.nodes);
    CHECK(fabs(W - Wref) <= 1e-13 * Wref, "Example 7: W2 %.17g vs %.17g", W, Wref);
    CHECK(max_diff(g, rg, 16) <= 1e-12 * max_abs(rg, 16), "Example 7: grad W2");
    swim_barrier_quad_free(b);
}

/* Near the boundary of D (min J = 1e-4) a 256-node trapezoidal rule is visibly off; the graded
 * rule matches a 65536-node trapezoidal rule with a few hundred nodes. */
static void check_near_boundary_quadrature(void)
{
    double x[6] = {1, 0, 0.5, 0, 0, 0.5 * (sqrt(1 - 1e-4) - 0.5)};
    double jmin = swim_shape_jmin(2, x);
    CHECK(fabs(jmin - 1e-4) < 1e-9, "near-boundary shape: min J %.6g, want 1e-4", jmin);
    swim_barrier_quad *b = swim_barrier_quad_new(2);
    swim_barrier_info info;
    double W, g[6], gf[6];
    CHECK(swim_barrier_w2(b, x, 0.03, 0.5, &W, g, &info) == SWIM_BARRIER_OK, "near boundary: inside D");
    double Wf = ref_barrier(2, x, 0.03, 0.5, 65536, gf);
    double Wb = ref_barrier(2, x, 0.03, 0.5, 256, NULL);
    CHECK(info.graded && info.nodes < 600, "near boundary: %s rule with %d nodes",
          info.graded ? "graded" : "trapezoidal", info.nodes);
    CHECK(fabs(W - Wf) <= 1e-12 * Wf, "near boundary W2 %.17g vs 65536 nodes %.17g", W, Wf);
    CHECK(max_diff(g, gf, 6) <= 1e-11 * max_abs(gf, 6), "near boundary grad W2: %.3g", max_diff(g, gf, 6));
    CHECK(fabs(Wb - Wf) > 1e-6 * Wf, "the 256-node rule should be visibly off at min J = 1e-4");
    printf("  W2 at min J = 1e-4: graded rule %d nodes, error %.1e; 256 trapezoidal nodes error %.1e\n",
           info.nodes, fabs(W - Wf) / Wf, fabs(Wb - Wf) / Wf);
    swim_barrier_quad_free(b);
}

static void check_ellipse_added_mass(void)
{
    const swim_kernel *k = swim_kernel_find(1);
    const double rhof = 1.3;
    for (int t = 0; t < 5; t++) {
        double s = 0.8 + 0.4 * fabs(urand()), e = 0.9 * fabs(urand()), phi = 3 * urand();
        /* phi(z) = s (z + e e^{i 2 psi}/z) is an ellipse with semi-axes s(1+e), s(1-e),
         * major axis at angle psi. */
        double psi = 0.5 * phi;
        double x[4] = {s, 0.0, s * e * cos(phi), s * e * sin(phi)};
        double Mr[9], Mr0[9];
        k->mass(x, 1.0, rhof, Mr, NULL, NULL);
        k->mass(x, 1e-300, rhof, Mr0, NULL, NULL); /* body part vanishes: fluid part only */
        double a = s * (1 + e), b = s * (1 - e);
        double ma = rhof * M_PI * b * b, mb = rhof * M_PI * a * a;  /* along, across the major axis */
        double cp = cos(psi), sp = sin(psi);
        double mxx = ma * cp * cp + mb * sp * sp, myy = ma * sp * sp + mb * cp * cp;
        double mxy = (ma - mb) * cp * sp, mrot = rhof * M_PI * pow(a * a - b * b, 2) / 8.0;
        CHECK_CLOSE(Mr0[0], mxx, 1e-13, "ellipse added mass xx");
        CHECK_CLOSE(Mr0[4], myy, 1e-13, "ellipse added mass yy");
        CHECK_CLOSE(Mr0[1], mxy, 1e-13, "ellipse added mass xy");
        CHECK_CLOSE(Mr0[8], mrot, 1e-13, "ellipse added moment of inertia");
        CHECK(fabs(Mr0[2]) < 1e-13 && fabs(Mr0[5]) < 1e-13, "ellipse: no translation-rotation coupling");
        (void)Mr;
    }
}

/* A generator that prints two lines and fails, in a cache of its own: the cause in the status
 * (one line: which kernel, the log), the log's end in its detail. */
static void check_failed_build_status(void)
{
    char dir[] = "/tmp/swim-kernels-fail-XXXXXX", script[96], cache[96];
    if (!mkdtemp(dir)) {
        CHECK(0, "a temporary folder");
        return;
    }
    snprintf(script, sizeof script, "%s/python", dir);
    snprintf(cache, sizeof cache, "%s/cache", dir);
    FILE *f = fopen(script, "w");
    if (f) {
        fputs("#!/bin/sh\necho first words\necho the generator gave up here >&2\nexit 3\n", f);
        fclose(f);
    }
    chmod(script, 0700);
    const env_saved py = env_set("SWIM_PYTHON", script), ca = env_set("SWIM_CACHE", cache);
    swim_status st = {0};
    swim_compiled c;
    const int rc = swim_codegen_kernel(9, &c, 0, &st);
    env_restore(py);
    env_restore(ca);
    char msg[512];
    swim_status_message(&st, msg, sizeof msg);
    CHECK(rc == -1 && st.failed && st.nlines == 1 && strncmp(msg, "generating the kernel for N = 9 failed (see ", 44) == 0 &&
          strstr(msg, "/build.log)"), "a failed generation: %d, %d lines, '%s'", rc, st.nlines, msg);
    CHECK(strstr(st.detail, "first words\n") && strstr(st.detail, "the generator gave up here"),
          "the status keeps the end of build.log: '%s'", st.detail);
    CHECK(st.file[0] == '\0' && st.line == 0 && st.key[0] == '\0', "no file, line or key for a build");
    char cmd[160];
    snprintf(cmd, sizeof cmd, "rm -rf '%s'", dir);
    if (system(cmd) != 0) fprintf(stderr, "cannot remove %s\n", dir);
}

int main(void)
{
    srand(12345);
    int modes[32], count = swim_kernel_list(modes, 30);
    const swim_kernel *ks[33];
    for (int i = 0; i < count; i++) ks[i] = swim_kernel_find(modes[i]);
    CHECK(count == 8 && swim_kernel_find(12) == NULL, "N = 0..7 linked in, N = 12 not");
    static const int extra_modes[] = {12, 15, 20};
    swim_compiled extra[3];
    for (int e = 0; e < 3; e++) {
        int rc = swim_codegen_kernel(extra_modes[e], &extra[e], 0, NULL);
        CHECK(rc == 0 && extra[e].kernel && extra[e].kernel->modes == extra_modes[e],
              "the N = %d kernel is generated on demand", extra_modes[e]);
        if (rc == 0) ks[count++] = extra[e].kernel;
    }
    for (int i = 0; i < count; i++) {
        check_values(ks[i], ks[i]->modes >= 20 ? 5 : 20);
        check_row_blocks(ks[i], 4);
        if (ks[i]->modes >= 20) continue;  /* N = 20: values only (CI time) */
        check_derivatives(ks[i], ks[i]->modes >= 12 ? 1 : 3);
        if (ks[i]->modes > 12) continue;   /* N = 15: values and derivatives only */
        check_barrier(ks[i]);
    }
    check_quadrature_nodes();
    check_near_boundary_quadrature();
    check_ellipse_added_mass();
    for (int e = 0; e < 3; e++) swim_compiled_close(&extra[e]);
    check_failed_build_status();
    return check_report("test_kernels");
}
