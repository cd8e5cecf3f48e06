/* Self-checks of the independent reference implementation tests/reference/ref_model.c.
 * (a) closed-form mass matrices vs the complex form of the fluid energy (ERRATA A9),
 * (b) symmetry of Mr, Md, K,
 * (c) J = 1 and W2 = pi eps/alpha at the unit circle,
 * (d) barrier gradient (ERRATA B3) vs central finite differences of W2,
 * (e) the rotating unit circle has zero added inertia,
 * plus: K as the Schur complement (energy with zero impulse), ellipse added masses,
 * and the identity v . Gamma(v,v) = 1/2 D_v(v^T K v) for ref_christoffel_fd. */
#include "check.h"
#include "reference/ref_model.h"

#include <stdlib.h>
#include <string.h>

static const double PI = 3.14159265358979323846264338327950288;

static unsigned long long rng_state = 0x9E3779B97F4A7C15ULL;

/* Uniform in [-1, 1). */
static double urand(void)
{
    rng_state ^= rng_state << 13;
    rng_state ^= rng_state >> 7;
    rng_state ^= rng_state << 17;
    return 2.0 * ((rng_state >> 11) * (1.0 / 9007199254740992.0)) - 1.0;
}

/* Random admissible shape: c_1 near 1, small c_-m, scaled until min J > 0.1. */
static void random_shape(int N, double *x)
{
    x[0] = 1.0 + 0.1 * urand();
    x[1] = 0.1 * urand();
    for (int m = 1; m <= N; m++) {
        x[2 * m] = 0.4 * urand() / m;
        x[2 * m + 1] = 0.4 * urand() / m;
    }
    while (ref_min_jacobian(N, x, 512) <= 0.1)
        for (int m = 1; m <= N; m++) {
            x[2 * m] *= 0.8;
            x[2 * m + 1] *= 0.8;
        }
}

static double max_abs(const double *v, int len)
{
    double m = 0.0;
    for (int i = 0; i < len; i++)
        if (fabs(v[i]) > m) m = fabs(v[i]);
    return m;
}

int main(void)
{
    const double rho0 = 1.3, rhof = 0.7;
    double err_a = 0, err_schur = 0, err_sym = 0, err_grad = 0, err_gamma = 0;
    double err_null = 0, err_grad4 = 0;

    for (int N = 0; N <= 7; N++) {
        const int n = ref_ncoords(N);
        const int G = 3 + n;
        double *x = malloc(n * sizeof *x), *Mr = malloc(9 * sizeof *Mr);
        double *Nc = malloc(3 * n * sizeof *Nc), *Md = malloc(n * n * sizeof *Md);
        double *K = malloc(n * n * sizeof *K), *K2 = malloc(n * n * sizeof *K2);
        double *M = malloc(G * G * sizeof *M), *X = malloc(G * sizeof *X);
        double *grad = malloc(n * sizeof *grad), *xs = malloc(n * sizeof *xs);
        double *v = malloc(n * sizeof *v), *gam = malloc(n * sizeof *gam);

        for (int trial = 0; trial < 5; trial++) {
            random_shape(N, x);
            ref_mass(N, x, rho0, rhof, Mr, Nc, Md, K);

            /* NULL outputs allowed; same K when only K is requested. */
            ref_mass(N, x, rho0, rhof, NULL, NULL, NULL, K2);
            for (int i = 0; i < n * n; i++)
                if (fabs(K2[i] - K[i]) > err_null) err_null = fabs(K2[i] - K[i]);
            CHECK(err_null == 0.0, "N=%d: K differs when other outputs are NULL", N);

            /* Full fluid mass matrix: [Mr Nc; Nc^T Md] minus body terms. */
            for (int r = 0; r < G; r++)
                for (int c = 0; c < G; c++) {
                    double val;
                    if (r < 3 && c < 3) val = Mr[3 * r + c];
                    else if (r < 3) val = Nc[n * r + (c - 3)];
                    else if (c < 3) val = Nc[n * c + (r - 3)];
                    else val = Md[n * (r - 3) + (c - 3)];
                    M[G * r + c] = val;
                }
            double inertia = 0.0;
            for (int p = 0; p <= N; p++) {
                int k = p == 0 ? 1 : -p;
                inertia += (x[2 * p] * x[2 * p] + x[2 * p + 1] * x[2 * p + 1]) / (abs(k) + 1);
            }
            M[0] -= rho0 * PI;
            M[G + 1] -= rho0 * PI;
            M[2 * G + 2] -= rho0 * PI * inertia;
            for (int p = 0; p <= N; p++) {
                int k = p == 0 ? 1 : -p;
                for (int s = 0; s < 2; s++) {
                    int d = 3 + 2 * p + s;
                    M[G * d + d] -= rho0 * PI / (abs(k) + 1);
                }
            }

            /* (a) (1/2) X^T M_fluid X vs complex form, random X = (q, xdot). */
            for (int rep = 0; rep < 4; rep++) {
                for (int i = 0; i < G; i++) X[i] = urand();
                double e1 = 0.0;
                for (int r = 0; r < G; r++)
                    for (int c = 0; c < G; c++) e1 += X[r] * M[G * r + c] * X[c];
                e1 *= 0.5;
                double e2 = ref_fluid_energy_complex(N, x, X, X + 3, rhof);
                double rel = fabs(e1 - e2) / fabs(e2);
                if (rel > err_a) err_a = rel;
                CHECK(rel <= 1e-13, "(a) N=%d fluid energy: closed %.17g vs complex %.17g (rel %.3g)",
                      N, e1, e2, rel);
            }

            /* Extra: K is the Schur complement -- with q = -Mr^{-1} Nc xdot (zero impulse,
             * ERRATA C4), the total kinetic energy (body terms + complex-form fluid energy)
             * equals (1/2) xdot^T K xdot.  q is solved here by Cramer's rule, not by
             * ref_mass's elimination. */
            {
                double *xd = X + 3;
                for (int i = 0; i < n; i++) xd[i] = urand();
                double rhs[3], A[9];
                memcpy(A, Mr, sizeof A);
                for (int r = 0; r < 3; r++) {
                    rhs[r] = 0.0;
                    for (int c = 0; c < n; c++) rhs[r] -= Nc[n * r + c] * xd[c];
                }
                /* Cramer's rule (different from ref_mass's elimination). */
                double det = A[0] * (A[4] * A[8] - A[5] * A[7]) - A[1] * (A[3] * A[8] - A[5] * A[6])
                           + A[2] * (A[3] * A[7] - A[4] * A[6]);
                for (int col = 0; col < 3; col++) {
                    double B[9];
                    memcpy(B, A, sizeof B);
                    for (int r = 0; r < 3; r++) B[3 * r + col] = rhs[r];
                    X[col] = (B[0] * (B[4] * B[8] - B[5] * B[7]) - B[1] * (B[3] * B[8] - B[5] * B[6])
                              + B[2] * (B[3] * B[7] - B[4] * B[6])) / det;
                }
                double body = 0.5 * rho0 * PI * (X[0] * X[0] + X[1] * X[1] + inertia * X[2] * X[2]);
                for (int p = 0; p <= N; p++) {
                    int k = p == 0 ? 1 : -p;
                    body += 0.5 * rho0 * PI / (abs(k) + 1) * (xd[2 * p] * xd[2 * p] + xd[2 * p + 1] * xd[2 * p + 1]);
                }
                double etot = body + ref_fluid_energy_complex(N, x, X, xd, rhof);
                double ek = 0.0;
                for (int i = 0; i < n; i++)
                    for (int j = 0; j < n; j++) ek += xd[i] * K[n * i + j] * xd[j];
                ek *= 0.5;
                double rel = fabs(etot - ek) / fabs(ek);
                if (rel > err_schur) err_schur = rel;
                CHECK(rel <= 1e-12, "N=%d Schur energy: %.17g vs %.17g (rel %.3g)", N, etot, ek, rel);
            }

            /* (b) symmetry of K (and Mr, Md). */
            double kscale = max_abs(K, n * n);
            for (int i = 0; i < n; i++)
                for (int j = 0; j < n; j++) {
                    double d = fabs(K[n * i + j] - K[n * j + i]) / kscale;
                    if (d > err_sym) err_sym = d;
                    CHECK(d <= 1e-14, "(b) N=%d K[%d][%d] asymmetric (rel %.3g)", N, i, j, d);
                    CHECK(Md[n * i + j] == Md[n * j + i], "N=%d Md[%d][%d] asymmetric", N, i, j);
                }
            for (int i = 0; i < 3; i++)
                for (int j = 0; j < 3; j++)
                    CHECK(Mr[3 * i + j] == Mr[3 * j + i], "N=%d Mr[%d][%d] asymmetric", N, i, j);

            /* K positive definite (Cholesky without pivoting succeeds). */
            {
                double *L = malloc(n * n * sizeof *L);
                int ok = 1;
                memcpy(L, K, n * n * sizeof *L);
                for (int j = 0; j < n && ok; j++) {
                    double d = L[n * j + j];
                    for (int k = 0; k < j; k++) d -= L[n * j + k] * L[n * j + k];
                    if (d <= 0) { ok = 0; break; }
                    L[n * j + j] = sqrt(d);
                    for (int i = j + 1; i < n; i++) {
                        double s = L[n * i + j];
                        for (int k = 0; k < j; k++) s -= L[n * i + k] * L[n * j + k];
                        L[n * i + j] = s / L[n * j + j];
                    }
                }
                CHECK(ok, "N=%d K not positive definite", N);
                free(L);
            }

            /* (d) barrier gradient vs central finite difference of W2. */
            {
                /* The random shapes (min J ~ 0.1, modes up to m = 7) make W2 steep, so the
                 * steps are small.  The 2nd-order difference error was measured to scale as
                 * h^2 (2.2e-7 at h = 1e-5, 4.5e-9 at h = 1e-6) and the 4th-order one as h^4
                 * (5.4e-8 at 2e-4, 3.4e-9 at 1e-4, 2.1e-10 at 5e-5): pure truncation, so
                 * the analytic gradient is right and only the step had to be chosen. */
                const double eps = 0.03, alpha = 0.5, h = 1e-6, h4 = 2.5e-5;
                const int Q = 256;
                ref_barrier(N, x, eps, alpha, Q, grad);
                double gscale = max_abs(grad, n);
                for (int i = 0; i < n; i++) {
                    double w[5]; /* W2 at x_i + (s-2) h4, s = 0..4 */
                    memcpy(xs, x, n * sizeof *xs);
                    xs[i] = x[i] + h;
                    double wp = ref_barrier(N, xs, eps, alpha, Q, NULL);
                    xs[i] = x[i] - h;
                    double wm = ref_barrier(N, xs, eps, alpha, Q, NULL);
                    double fd = (wp - wm) / (2 * h);
                    double d = fabs(fd - grad[i]) / gscale;
                    if (d > err_grad) err_grad = d;
                    CHECK(d <= 1e-7, "(d) N=%d dW2/dx[%d]: %.17g vs fd %.17g (rel %.3g)",
                          N, i, grad[i], fd, d);
                    for (int s = 0; s < 5; s++) {
                        xs[i] = x[i] + (s - 2) * h4;
                        w[s] = ref_barrier(N, xs, eps, alpha, Q, NULL);
                    }
                    double fd4 = (w[0] - 8 * w[1] + 8 * w[3] - w[4]) / (12 * h4);
                    double d4 = fabs(fd4 - grad[i]) / gscale;
                    if (d4 > err_grad4) err_grad4 = d4;
                    CHECK(d4 <= 1e-9, "(d) N=%d dW2/dx[%d]: %.17g vs 4th-order fd %.17g (rel %.3g)",
                          N, i, grad[i], fd4, d4);
                }
            }

            /* Extra: ref_christoffel_fd satisfies v . Gamma(v,v) = 1/2 D_v(v^T K v). */
            {
                const double h = 1e-5;
                for (int i = 0; i < n; i++) v[i] = urand();
                ref_christoffel_fd(N, x, v, rho0, rhof, h, gam);
                double lhs = 0.0;
                for (int i = 0; i < n; i++) lhs += v[i] * gam[i];
                double ep = 0.0, em = 0.0;
                for (int i = 0; i < n; i++) xs[i] = x[i] + h * v[i];
                ref_mass(N, xs, rho0, rhof, NULL, NULL, NULL, K2);
                for (int i = 0; i < n; i++)
                    for (int j = 0; j < n; j++) ep += v[i] * K2[n * i + j] * v[j];
                for (int i = 0; i < n; i++) xs[i] = x[i] - h * v[i];
                ref_mass(N, xs, rho0, rhof, NULL, NULL, NULL, K2);
                for (int i = 0; i < n; i++)
                    for (int j = 0; j < n; j++) em += v[i] * K2[n * i + j] * v[j];
                double rhs = 0.5 * (ep - em) / (2 * h);
                double scale = max_abs(gam, n) * n;
                double d = fabs(lhs - rhs) / (scale > 1e-300 ? scale : 1.0);
                if (d > err_gamma) err_gamma = d;
                CHECK(d <= 1e-7, "N=%d v.Gamma %.17g vs 1/2 D_v(v'Kv) %.17g (rel %.3g)", N, lhs, rhs, d);
            }
        }

        /* (c) unit circle: J = 1, W2 = pi eps/alpha, grad W2 = (-2 pi eps, 0, ...). */
        {
            const double eps = 0.03, alpha = 0.5;
            for (int i = 0; i < n; i++) xs[i] = 0.0;
            xs[0] = 1.0;
            for (int q = 0; q < 7; q++)
                CHECK_CLOSE(ref_jacobian_circle(N, xs, 0.9 * q), 1.0, 1e-15, "(c) J at circle");
            CHECK_CLOSE(ref_min_jacobian(N, xs, 64), 1.0, 1e-15, "(c) min J at circle");
            double w2 = ref_barrier(N, xs, eps, alpha, 256, grad);
            CHECK_CLOSE(w2, PI * eps / alpha, 1e-14, "(c) W2 at circle");
            CHECK_CLOSE(ref_barrier(N, xs, eps, alpha, 256, NULL), PI * eps / alpha, 1e-14,
                        "(c) W2 at circle, grad NULL");
            CHECK_CLOSE(w2, 0.18849555921538758, 1e-12, "(c) W2 = 0.18850 for eps=0.03, alpha=0.5");
            CHECK_CLOSE(grad[0], -2 * PI * eps, 1e-14, "(c) dW2/da1 at circle");
            for (int i = 1; i < n; i++) CHECK_CLOSE(grad[i], 0.0, 1e-15, "(c) dW2/dx_i at circle");

            /* (e) rotating unit circle: zero added inertia, no rotation coupling. */
            ref_mass(N, xs, rho0, rhof, Mr, Nc, NULL, NULL);
            CHECK_CLOSE(Mr[8] - rho0 * PI * 0.5, 0.0, 1e-15, "(e) fluid Mr[2][2] at circle");
            CHECK_CLOSE(Mr[2], 0.0, 1e-15, "(e) Mr[0][2] at circle");
            CHECK_CLOSE(Mr[5], 0.0, 1e-15, "(e) Mr[1][2] at circle");
            for (int c = 0; c < n; c++) CHECK_CLOSE(Nc[2 * n + c], 0.0, 1e-15, "(e) Nc[2][:] at circle");
            /* Translation added mass of the unit disk: pi rhof. */
            CHECK_CLOSE(Mr[0] - rho0 * PI, PI * rhof, 1e-14, "circle added mass x");
            CHECK_CLOSE(Mr[4] - rho0 * PI, PI * rhof, 1e-14, "circle added mass y");
            double qz[3] = {0, 0, 1};
            double *zero = calloc(n, sizeof *zero);
            CHECK_CLOSE(ref_fluid_energy_complex(N, xs, qz, zero, rhof), 0.0, 1e-15,
                        "(e) complex-form energy of rotating circle");
            free(zero);
        }

        /* Extra: ellipse c_1 = 1, c_-1 = e: semi-axes 1+e (x), 1-e (y). Classical added
         * masses pi rhof (1-e)^2 (along x), pi rhof (1+e)^2 (along y), added inertia
         * pi rhof (A^2 - B^2)^2 / 8 = 2 pi rhof e^2. */
        if (N >= 1) {
            const double e = 0.3;
            for (int i = 0; i < n; i++) xs[i] = 0.0;
            xs[0] = 1.0;
            xs[2] = e;
            ref_mass(N, xs, rho0, rhof, Mr, NULL, NULL, NULL);
            double I0 = 1.0 / 2 + e * e / 2;
            CHECK_CLOSE(Mr[0] - rho0 * PI, PI * rhof * (1 - e) * (1 - e), 1e-14, "ellipse added mass x");
            CHECK_CLOSE(Mr[4] - rho0 * PI, PI * rhof * (1 + e) * (1 + e), 1e-14, "ellipse added mass y");
            CHECK_CLOSE(Mr[8] - rho0 * PI * I0, 2 * PI * rhof * e * e, 1e-14, "ellipse added inertia");
            CHECK_CLOSE(Mr[1], 0.0, 1e-15, "ellipse Mr[0][1]");
            CHECK_CLOSE(Mr[2], 0.0, 1e-15, "ellipse Mr[0][2]");
            CHECK_CLOSE(Mr[5], 0.0, 1e-15, "ellipse Mr[1][2]");
        }

        free(x); free(Mr); free(Nc); free(Md); free(K); free(K2); free(M); free(X);
        free(grad); free(xs); free(v); free(gam);
    }

    printf("max rel err: (a) energy %.3g, Schur %.3g, (b) K asym %.3g, (d) grad %.3g (4th order %.3g), "
           "v.Gamma %.3g, NULL-output diff %.3g\n",
           err_a, err_schur, err_sym, err_grad, err_grad4, err_gamma, err_null);
    return check_report("test_reference");
}
