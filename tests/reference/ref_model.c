/* Independent reference implementation of the swimmer model; see ref_model.h.
 * Formulas: Munnier Section 3.2.5 (3.7), (3.8), (3.15)-(3.18), Section 4.1.1 (4.2),
 * with the corrections of shared/paper/ERRATA.md sections A and B. */
#include "ref_model.h"

#include <complex.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

static const double REF_PI = 3.14159265358979323846264338327950288;

int ref_ncoords(int N) { return 2 * (N + 1); }

/* ---- shape coefficients ------------------------------------------------------ */

/* Storage slot of mode k (k = 1, -1, ..., -N), or -1 if c_k is identically 0. */
static int slot_of_mode(int N, int k)
{
    if (k == 1) return 0;
    if (k <= -1 && k >= -N) return -k;
    return -1;
}

/* Mode of storage slot p (p = 0..N). */
static int mode_of_slot(int p) { return p == 0 ? 1 : -p; }

static double coef_a(int N, const double *x, int k)
{
    int p = slot_of_mode(N, k);
    return p < 0 ? 0.0 : x[2 * p];
}

static double coef_b(int N, const double *x, int k)
{
    int p = slot_of_mode(N, k);
    return p < 0 ? 0.0 : x[2 * p + 1];
}

static double complex coef_c(int N, const double *x, int k)
{
    return coef_a(N, x, k) + I * coef_b(N, x, k);
}

/* ---- sequences (3.7)-(3.8) --------------------------------------------------- */

/* A "pair of sequences" s = ((s1_j), (s2_j)), j = 1..L, stored as s[2*(j-1)], s[2*(j-1)+1].
 * All sequences vanish for j > N+1 (ERRATA A6); L = N+2 keeps one spare zero term. */
static int seq_len(int N) { return N + 2; }

/* mu_k and nu_k of (3.8) for k in {0, 1, -1, ..., -N}. */
static void seq_mu_nu(int N, const double *x, int k, double *mu, double *nu)
{
    int L = seq_len(N);
    for (int j = 1; j <= L; j++) {
        double kp = (double)k / (double)j + 1.0; /* (k/j + 1) */
        double km = (double)k / (double)j - 1.0; /* (k/j - 1) */
        double ap = coef_a(N, x, k + j), bp = coef_b(N, x, k + j);
        double am = coef_a(N, x, k - j), bm = coef_b(N, x, k - j);
        mu[2 * (j - 1)]     = kp * ap + km * am;
        mu[2 * (j - 1) + 1] = kp * bp - km * bm;
        nu[2 * (j - 1)]     = kp * bp + km * bm;
        nu[2 * (j - 1) + 1] = -kp * ap + km * am;
    }
}

/* alpha of ERRATA A5 (the corrected (3.7)):
 *   alpha1_j =  sum_i (a_i b_{i+j} - b_i a_{i+j}),  alpha2_j = -sum_i (a_i a_{i+j} + b_i b_{i+j}). */
static void seq_alpha(int N, const double *x, double *al)
{
    int L = seq_len(N);
    for (int j = 1; j <= L; j++) {
        double s1 = 0.0, s2 = 0.0;
        for (int i = -N; i <= 1; i++) {
            double ai = coef_a(N, x, i), bi = coef_b(N, x, i);
            double aij = coef_a(N, x, i + j), bij = coef_b(N, x, i + j);
            s1 += ai * bij - bi * aij;
            s2 -= ai * aij + bi * bij;
        }
        al[2 * (j - 1)] = s1;
        al[2 * (j - 1) + 1] = s2;
    }
}

/* Weighted dot product u . s = sum_{j>=1} j (u1_j s1_j + u2_j s2_j). */
static double seq_dot(int N, const double *u, const double *s)
{
    int L = seq_len(N);
    double r = 0.0;
    for (int j = 1; j <= L; j++)
        r += j * (u[2 * (j - 1)] * s[2 * (j - 1)] + u[2 * (j - 1) + 1] * s[2 * (j - 1) + 1]);
    return r;
}

/* ---- mass matrices (3.15)-(3.18), ERRATA A9 ----------------------------------- */

/* Solve the 3x3 system A y = b by Gaussian elimination with partial pivoting
 * (A and b are copied, not modified). */
static void solve3(const double A_in[9], const double b_in[3], double y[3])
{
    double A[3][4];
    for (int r = 0; r < 3; r++) {
        for (int c = 0; c < 3; c++) A[r][c] = A_in[3 * r + c];
        A[r][3] = b_in[r];
    }
    for (int col = 0; col < 3; col++) {
        int piv = col;
        for (int r = col + 1; r < 3; r++)
            if (fabs(A[r][col]) > fabs(A[piv][col])) piv = r;
        if (piv != col)
            for (int c = 0; c < 4; c++) {
                double t = A[col][c]; A[col][c] = A[piv][c]; A[piv][c] = t;
            }
        for (int r = col + 1; r < 3; r++) {
            double f = A[r][col] / A[col][col];
            for (int c = col; c < 4; c++) A[r][c] -= f * A[col][c];
        }
    }
    for (int r = 2; r >= 0; r--) {
        double s = A[r][3];
        for (int c = r + 1; c < 3; c++) s -= A[r][c] * y[c];
        y[r] = s / A[r][r];
    }
}

void ref_mass(int N, const double *x, double rho0, double rhof,
              double *Mr, double *Nc, double *Md, double *K)
{
    const int n = ref_ncoords(N);
    const int L = seq_len(N);
    const int G = 3 + n; /* generalised coordinates: r*_1, r*_2, omega, x */

    /* seq[g]: the pair of sequences of generalised coordinate g:
     * g = 0: mu_0, 1: nu_0, 2: alpha, 3 + 2p: mu_k, 3 + 2p + 1: nu_k (k = mode of slot p). */
    double *seq = calloc((size_t)G * 2 * L, sizeof *seq);
    double *mr = calloc(9, sizeof *mr);
    double *nc = calloc((size_t)3 * n, sizeof *nc);
    double *md = calloc((size_t)n * n, sizeof *md);
    if (!seq || !mr || !nc || !md) abort();

    seq_mu_nu(N, x, 0, seq + 0 * 2 * L, seq + 1 * 2 * L);
    seq_alpha(N, x, seq + 2 * 2 * L);
    for (int p = 0; p <= N; p++)
        seq_mu_nu(N, x, mode_of_slot(p), seq + (3 + 2 * p) * 2 * L, seq + (3 + 2 * p + 1) * 2 * L);

    /* Fluid parts: rho_f pi s_g . s_h. */
    for (int r = 0; r < 3; r++)
        for (int c = 0; c < 3; c++)
            mr[3 * r + c] = rhof * REF_PI * seq_dot(N, seq + r * 2 * L, seq + c * 2 * L);
    for (int r = 0; r < 3; r++)
        for (int c = 0; c < n; c++)
            nc[n * r + c] = rhof * REF_PI * seq_dot(N, seq + r * 2 * L, seq + (3 + c) * 2 * L);
    for (int r = 0; r < n; r++)
        for (int c = 0; c < n; c++)
            md[n * r + c] = rhof * REF_PI * seq_dot(N, seq + (3 + r) * 2 * L, seq + (3 + c) * 2 * L);

    /* Body parts: rho0 pi diag(1, 1, sum_k |c_k|^2/(|k|+1)) and rho0 pi/(|k|+1) (ERRATA A7, A8). */
    double inertia = 0.0;
    for (int p = 0; p <= N; p++) {
        int k = mode_of_slot(p);
        double a = x[2 * p], b = x[2 * p + 1];
        inertia += (a * a + b * b) / (abs(k) + 1);
    }
    mr[0] += rho0 * REF_PI;
    mr[4] += rho0 * REF_PI;
    mr[8] += rho0 * REF_PI * inertia;
    for (int p = 0; p <= N; p++) {
        int k = mode_of_slot(p);
        md[n * (2 * p) + 2 * p] += rho0 * REF_PI / (abs(k) + 1);
        md[n * (2 * p + 1) + 2 * p + 1] += rho0 * REF_PI / (abs(k) + 1);
    }

    if (K) {
        /* K = Md - Nc^T Y with Mr Y = Nc, solved column by column. */
        double *Y = calloc((size_t)3 * n, sizeof *Y);
        if (!Y) abort();
        for (int c = 0; c < n; c++) {
            double b[3] = {nc[c], nc[n + c], nc[2 * n + c]}, y[3];
            solve3(mr, b, y);
            for (int r = 0; r < 3; r++) Y[n * r + c] = y[r];
        }
        for (int i = 0; i < n; i++)
            for (int j = 0; j < n; j++) {
                double s = 0.0;
                for (int r = 0; r < 3; r++) s += nc[n * r + i] * Y[n * r + j];
                K[n * i + j] = md[n * i + j] - s;
            }
        free(Y);
    }
    if (Mr) memcpy(Mr, mr, 9 * sizeof *mr);
    if (Nc) memcpy(Nc, nc, (size_t)3 * n * sizeof *nc);
    if (Md) memcpy(Md, md, (size_t)n * n * sizeof *md);
    free(seq); free(mr); free(nc); free(md);
}

/* ---- complex form of the fluid energy (ERRATA A9) ---------------------------- */

double ref_fluid_energy_complex(int N, const double *x, const double q[3],
                                const double *xdot, double rhof)
{
    const double omega = q[2];
    double energy = 0.0;
    /* g_n vanishes for n > N+1; loop further anyway, the extra terms are exact zeros. */
    for (int nn = 1; nn <= 2 * N + 4; nn++) {
        double complex g = 0.0;
        /* m = 0 (translation, u_0 = r*_1 + i r*_2) and m = 1, -1, ..., -N (u_m = c'_m). */
        for (int m = 1; m >= -N; m--) {
            double complex u;
            if (m == 0) {
                u = q[0] + I * q[1];
            } else {
                int p = slot_of_mode(N, m);
                u = xdot[2 * p] + I * xdot[2 * p + 1];
            }
            g += -0.5 * (u * (double)(m - nn) * conj(coef_c(N, x, m - nn))
                         + conj(u) * (double)(m + nn) * coef_c(N, x, m + nn));
        }
        double complex s = 0.0;
        for (int p = -N; p <= 1; p++) s += conj(coef_c(N, x, p)) * coef_c(N, x, p + nn);
        g += I * omega * (double)nn / 2.0 * s;
        double g2 = creal(g) * creal(g) + cimag(g) * cimag(g);
        energy += 0.5 * (4.0 * REF_PI * rhof / nn) * g2;
    }
    return energy;
}

/* ---- Jacobian and barrier (ERRATA B2, B3) ------------------------------------ */

/* h(z) = sum_{m=1}^N m c_-m conj(z)^(m-1) at z = e^{i theta}. */
static double complex h_circle(int N, const double *x, double theta)
{
    double complex h = 0.0;
    for (int m = 1; m <= N; m++) {
        double complex zbar_pow = cexp(-I * (double)(m - 1) * theta); /* conj(z)^(m-1) */
        h += (double)m * coef_c(N, x, -m) * zbar_pow;
    }
    return h;
}

double ref_jacobian_circle(int N, const double *x, double theta)
{
    double a1 = x[0], b1 = x[1];
    double complex h = h_circle(N, x, theta);
    double h2 = creal(h) * creal(h) + cimag(h) * cimag(h);
    return a1 * a1 + b1 * b1 - h2;
}

double ref_min_jacobian(int N, const double *x, int Q)
{
    double mn = INFINITY;
    for (int q = 0; q < Q; q++) {
        double J = ref_jacobian_circle(N, x, 2.0 * REF_PI * q / Q);
        if (J < mn) mn = J;
    }
    return mn;
}

double ref_barrier(int N, const double *x, double eps, double alpha, int Q,
                   double *grad)
{
    const int n = ref_ncoords(N);
    const double w = 2.0 * REF_PI / Q; /* trapezoidal weight on a periodic grid */
    double integral = 0.0;             /* int J^-alpha */
    if (grad)
        for (int i = 0; i < n; i++) grad[i] = 0.0;
    double int_pow1 = 0.0;             /* int J^(-1-alpha) */
    for (int q = 0; q < Q; q++) {
        double theta = 2.0 * REF_PI * q / Q;
        double J = ref_jacobian_circle(N, x, theta);
        integral += w * pow(J, -alpha);
        if (!grad) continue;
        double Jp = pow(J, -1.0 - alpha);
        int_pow1 += w * Jp;
        double complex h = h_circle(N, x, theta);
        for (int m = 1; m <= N; m++) {
            double complex t = cexp(I * (double)(m - 1) * theta) * h; /* z^(m-1) h(z) */
            grad[2 * m]     += eps * m * w * creal(t) * Jp;
            grad[2 * m + 1] += eps * m * w * cimag(t) * Jp;
        }
    }
    if (grad) {
        grad[0] = -eps * x[0] * int_pow1;
        grad[1] = -eps * x[1] * int_pow1;
    }
    return eps / (2.0 * alpha) * integral;
}

/* ---- Christoffel vector by finite differences (ERRATA C1) -------------------- */

void ref_christoffel_fd(int N, const double *x, const double *v, double rho0,
                        double rhof, double h, double *gamma)
{
    const int n = ref_ncoords(N);
    double *Kp = malloc((size_t)n * n * sizeof *Kp);
    double *Km = malloc((size_t)n * n * sizeof *Km);
    double *xs = calloc((size_t)n, sizeof *xs);
    if (!Kp || !Km || !xs) abort();

    /* [D_v(K v)]_i = sum_j (K(x + h v) - K(x - h v))_ij v_j / (2h) */
    for (int j = 0; j < n; j++) xs[j] = x[j] + h * v[j];
    ref_mass(N, xs, rho0, rhof, NULL, NULL, NULL, Kp);
    for (int j = 0; j < n; j++) xs[j] = x[j] - h * v[j];
    ref_mass(N, xs, rho0, rhof, NULL, NULL, NULL, Km);
    for (int i = 0; i < n; i++) {
        double s = 0.0;
        for (int j = 0; j < n; j++) s += (Kp[n * i + j] - Km[n * i + j]) * v[j];
        gamma[i] = s / (2.0 * h);
    }

    /* - 1/2 d_i (v^T K v) */
    for (int i = 0; i < n; i++) {
        memcpy(xs, x, (size_t)n * sizeof *xs);
        xs[i] = x[i] + h;
        ref_mass(N, xs, rho0, rhof, NULL, NULL, NULL, Kp);
        xs[i] = x[i] - h;
        ref_mass(N, xs, rho0, rhof, NULL, NULL, NULL, Km);
        double ep = 0.0, em = 0.0;
        for (int j = 0; j < n; j++)
            for (int l = 0; l < n; l++) {
                ep += v[j] * Kp[n * j + l] * v[l];
                em += v[j] * Km[n * j + l] * v[l];
            }
        gamma[i] -= 0.5 * (ep - em) / (2.0 * h);
    }
    free(Kp); free(Km); free(xs);
}
