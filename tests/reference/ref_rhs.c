/* Independent reference right-hand side; see ref_rhs.h. Plain loops, straightforward, slow. */
#include "ref_rhs.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "ref_model.h"

static void *xcalloc(size_t count, size_t size)
{
    void *p = calloc(count ? count : 1, size);
    if (!p) abort();
    return p;
}

/* Y = Mr^-1 Nc by Cramer's rule (3 x 3, Mr symmetric positive definite). */
static void rigid_solve(const double *Mr, const double *Nc, int n, double *Y)
{
    const double a = Mr[0], b = Mr[1], c = Mr[2], d = Mr[4], e = Mr[5], f = Mr[8];
    const double c00 = d * f - e * e, c01 = c * e - b * f, c02 = b * e - c * d;
    const double c11 = a * f - c * c, c12 = b * c - a * e, c22 = a * d - b * b;
    const double det = a * c00 + b * c01 + c * c02;
    const double inv[9] = {c00, c01, c02, c01, c11, c12, c02, c12, c22};
    for (int r = 0; r < 3; r++)
        for (int k = 0; k < n; k++) {
            double s = 0.0;
            for (int q = 0; q < 3; q++) s += inv[3 * r + q] * Nc[n * q + k];
            Y[n * r + k] = s / det;
        }
}

void ref_reduced_deriv(int N, const double *x, double rho0, double rhof, double *dK)
{
    const int n = ref_ncoords(N);
    const double h = 0.5;
    double Mr[9], Mrp[9], Mrm[9];
    double *Nc = xcalloc(3 * n, sizeof *Nc), *Ncp = xcalloc(3 * n, sizeof *Ncp);
    double *Ncm = xcalloc(3 * n, sizeof *Ncm), *Mdp = xcalloc(n * n, sizeof *Mdp);
    double *Mdm = xcalloc(n * n, sizeof *Mdm), *Y = xcalloc(3 * n, sizeof *Y);
    double *xs = xcalloc(n, sizeof *xs), *dNc = xcalloc(3 * n, sizeof *dNc);
    ref_mass(N, x, rho0, rhof, Mr, Nc, NULL, NULL);
    rigid_solve(Mr, Nc, n, Y);
    for (int r = 0; r < n; r++) {
        memcpy(xs, x, sizeof(double) * n);
        xs[r] = x[r] + h;
        ref_mass(N, xs, rho0, rhof, Mrp, Ncp, Mdp, NULL);
        xs[r] = x[r] - h;
        ref_mass(N, xs, rho0, rhof, Mrm, Ncm, Mdm, NULL);
        double dMr[9];
        for (int i = 0; i < 9; i++) dMr[i] = (Mrp[i] - Mrm[i]) / (2 * h);
        for (int i = 0; i < 3 * n; i++) dNc[i] = (Ncp[i] - Ncm[i]) / (2 * h);
        double *out = dK + (size_t)r * n * n;
        for (int i = 0; i < n; i++)
            for (int j = 0; j < n; j++) {
                double s = (Mdp[n * i + j] - Mdm[n * i + j]) / (2 * h);
                for (int p = 0; p < 3; p++) {
                    s -= dNc[n * p + i] * Y[n * p + j] + Y[n * p + i] * dNc[n * p + j];
                    for (int q = 0; q < 3; q++) s += Y[n * p + i] * dMr[3 * p + q] * Y[n * q + j];
                }
                out[n * i + j] = s;
            }
    }
    free(Nc); free(Ncp); free(Ncm); free(Mdp); free(Mdm); free(Y); free(xs); free(dNc);
}

/* Solve A z = b (dim x dim, row-major, overwritten) by Gaussian elimination with partial
 * pivoting; -1 when a pivot vanishes. */
static int gauss_solve(double *A, double *b, int dim)
{
    for (int col = 0; col < dim; col++) {
        int piv = col;
        for (int r = col + 1; r < dim; r++)
            if (fabs(A[dim * r + col]) > fabs(A[dim * piv + col])) piv = r;
        if (A[dim * piv + col] == 0.0) return -1;
        if (piv != col) {
            for (int c = 0; c < dim; c++) {
                double t = A[dim * col + c];
                A[dim * col + c] = A[dim * piv + c];
                A[dim * piv + c] = t;
            }
            double t = b[col];
            b[col] = b[piv];
            b[piv] = t;
        }
        for (int r = col + 1; r < dim; r++) {
            double f = A[dim * r + col] / A[dim * col + col];
            for (int c = col; c < dim; c++) A[dim * r + c] -= f * A[dim * col + c];
            b[r] -= f * b[col];
        }
    }
    for (int r = dim - 1; r >= 0; r--) {
        double s = b[r];
        for (int c = r + 1; c < dim; c++) s -= A[dim * r + c] * b[c];
        b[r] = s / A[dim * r + r];
    }
    return 0;
}

int ref_rhs(const ref_scene *s, double t, const double *y, double *dy)
{
    const int N = s->N, n = ref_ncoords(N);
    const double *c = y + 3, *v = y + 3 + n;
    double Mr[9];
    double *Nc = xcalloc(3 * n, sizeof *Nc), *K = xcalloc(n * n, sizeof *K);
    double *dK = xcalloc((size_t)n * n * n, sizeof *dK), *Y = xcalloc(3 * n, sizeof *Y);
    double *f = xcalloc(n, sizeof *f), *gW = xcalloc(n, sizeof *gW);
    ref_mass(N, c, s->rho0, s->rhof, Mr, Nc, NULL, K);
    ref_reduced_deriv(N, c, s->rho0, s->rhof, dK);
    rigid_solve(Mr, Nc, n, Y);
    /* f = -<Gamma, v, v> - grad W - D v + F(t) */
    for (int i = 0; i < n; i++) {
        double g = 0.0;
        for (int j = 0; j < n; j++)
            for (int l = 0; l < n; l++) {
                double G = 0.5 * (dK[(size_t)l * n * n + n * i + j] + dK[(size_t)j * n * n + n * i + l]
                                  - dK[(size_t)i * n * n + n * j + l]);
                g += G * v[j] * v[l];
            }
        f[i] = -g;
    }
    double power = 0.0;
    if (s->stiffness)
        for (int i = 0; i < n; i++) f[i] -= s->stiffness[i] * (c[i] - s->reference[i]);
    if (s->barrier_nodes > 0) {
        ref_barrier(N, c, s->epsilon, s->alpha, s->barrier_nodes, gW);
        for (int i = 0; i < n; i++) f[i] -= gW[i];
    }
    if (s->damping)
        for (int i = 0; i < n; i++) {
            f[i] -= s->damping[i] * v[i];
            power -= s->damping[i] * v[i] * v[i];
        }
    if (s->law) {
        const double F = s->law(t);
        for (int i = 0; i < n; i++) {
            f[i] += F * s->direction[i];
            power += F * s->direction[i] * v[i];
        }
    }
    /* constraint rows: G1 = (k a_k, k b_k), G2 = (b_k, -a_k)/(|k|+1), e_i for locked i */
    int m = 2;
    for (int i = 0; i < n; i++) m += !s->free_mask[i];
    const int dim = n + m;
    double *A = xcalloc((size_t)dim * dim, sizeof *A), *b = xcalloc(dim, sizeof *b);
    for (int i = 0; i < n; i++) {
        for (int j = 0; j < n; j++) A[dim * i + j] = K[n * i + j];
        b[i] = f[i];
    }
    double curv = 0.0;
    for (int p = 0; p <= N; p++) {
        const int k = p == 0 ? 1 : -p, ak = abs(k);
        const double a = c[2 * p], bb = c[2 * p + 1];
        const double g1[2] = {k * a, k * bb}, g2[2] = {bb / (ak + 1), -a / (ak + 1)};
        for (int q = 0; q < 2; q++) {
            A[dim * n + 2 * p + q] = g1[q];
            A[dim * (n + 1) + 2 * p + q] = g2[q];
        }
        curv += k * (v[2 * p] * v[2 * p] + v[2 * p + 1] * v[2 * p + 1]);
    }
    for (int i = 0, row = n + 2; i < n; i++)
        if (!s->free_mask[i]) A[dim * row++ + i] = 1.0;
    b[n] = -curv;   /* (DG1[v]).v; (DG2[v]).v = 0 and locks give 0 (ERRATA C2) */
    for (int r = n; r < dim; r++)   /* K a - G^T lambda = f */
        for (int i = 0; i < n; i++) A[dim * i + r] = -A[dim * r + i];
    int rc = gauss_solve(A, b, dim);
    if (rc == 0) {
        double qs[3];
        for (int p = 0; p < 3; p++) {
            qs[p] = 0.0;
            for (int k = 0; k < n; k++) qs[p] -= Y[n * p + k] * v[k];
        }
        dy[0] = cos(y[2]) * qs[0] - sin(y[2]) * qs[1];
        dy[1] = sin(y[2]) * qs[0] + cos(y[2]) * qs[1];
        dy[2] = qs[2];
        for (int i = 0; i < n; i++) {
            dy[3 + i] = v[i];
            dy[3 + n + i] = b[i];
        }
        dy[3 + 2 * n] = power;
    }
    free(Nc); free(K); free(dK); free(Y); free(f); free(gW); free(A); free(b);
    return rc;
}
