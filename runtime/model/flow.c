#include "model/flow.h"

#include <complex.h>
#include <math.h>
#include <stdlib.h>

#include "io/json.h"
#include "kernel/coords.h"

#define NB 256          /* boundary points */
#define NRAD 12         /* density grid radii */
#define NANG 96         /* density grid angles */
#define ARROW_RINGS 4
#define ARROW_ANG 24

static double complex coef(const double *x, int k)   /* c_k for k = 1, -1..-N */
{
    const int i = swim_coord_index(k);
    return x[i] + I * x[i + 1];
}

/* phi(z) = c_1 z + sum_{k<=-1} c_k z^k and phi'(z) (2.2). */
static double complex phi(const double *x, int N, double complex z, double complex *dphi)
{
    double complex w = coef(x, 1) * z, dw = coef(x, 1);
    for (int m = 1; m <= N; m++) {
        w += coef(x, -m) * cpow(z, -m);
        dw += -m * coef(x, -m) * cpow(z, -m - 1);
    }
    if (dphi) *dphi = dw;
    return w;
}

static void write_array(FILE *f, const double *a, int n) { swim_json_vector(f, a, n); }

int swim_flow_snapshot(swim_dynamics *d, double t, const double *y, FILE *f)
{
    const swim_scene *s = d->scene;
    const int N = s->modes, n = s->n, R = n, P = n + 3;
    const double *c = y + 3, *v = y + 3 + n;
    double *S = malloc(sizeof(double) * R * P), X[3 + 2 * (SWIM_KERNEL_MAX_MODES + 1)];
    double *buf = malloc(sizeof(double) * (2 * NB + 3 * NRAD * NANG + 4 * ARROW_RINGS * ARROW_ANG));
    if (!S || !buf) { free(S); free(buf); return -1; }
    if (d->k->reduced(c, NULL, s->rho0, s->rhof, d->K, d->P, NULL) != 0) { free(S); free(buf); return -1; }
    for (int p = 0; p < 3; p++) {
        X[p] = 0.0;
        for (int k = 0; k < n; k++) X[p] += d->P[p * n + k] * v[k];
    }
    for (int k = 0; k < n; k++) X[3 + k] = v[k];
    d->k->boundary_data(c, S);
    /* xi = Re F(z), F(z) = sum_j (A_j + i B_j) z^-j with A_j = -(S X)_{2j-2}, B_j = (S X)_{2j-1}. */
    double complex AB[SWIM_KERNEL_MAX_MODES + 2];
    for (int j = 1; j <= N + 1; j++) {
        double a = 0.0, b = 0.0;
        for (int p = 0; p < P; p++) {
            a += S[(2 * j - 2) * P + p] * X[p];
            b += S[(2 * j - 1) * P + p] * X[p];
        }
        AB[j] = -a + I * b;
    }
    double *bx = buf, *by = bx + NB, *dx = by + NB, *dy = dx + NRAD * NANG, *rho = dy + NRAD * NANG;
    double *ax = rho + NRAD * NANG, *ay = ax + ARROW_RINGS * ARROW_ANG;
    double *au = ay + ARROW_RINGS * ARROW_ANG, *av = au + ARROW_RINGS * ARROW_ANG;
    /* body frame -> fixed frame (3.21) */
#define WORLD(w, X_, Y_) do { double b_[3] = {creal(w), cimag(w), 0.0}, f_[3]; \
        swim_to_fixed_frame(y[2], b_, f_); X_ = y[0] + f_[0]; Y_ = y[1] + f_[1]; } while (0)
    for (int q = 0; q < NB; q++) {
        double complex w = phi(c, N, cexp(I * 2 * M_PI * q / (NB - 1)), NULL);
        WORLD(w, bx[q], by[q]);
    }
    for (int i = 0; i < NRAD; i++)
        for (int j = 0; j < NANG; j++) {
            double r = (double)i / (NRAD - 1), th = 2 * M_PI * j / (NANG - 1);
            double complex z = r * cexp(I * th), zb = conj(z), w = coef(c, 1) * z, h = 0.0, p = 1.0;
            /* powers by products, not cpow: cpow(0, 0) is NaN, which left a hole at the centre */
            for (int k = 1; k <= N; k++) {
                h += k * coef(c, -k) * p;   /* (2.4), p = zb^(k-1) */
                p *= zb;
                w += coef(c, -k) * p;       /* chi (2.1) */
            }
            double J = creal(coef(c, 1) * conj(coef(c, 1))) - creal(h * conj(h));
            WORLD(w, dx[i * NANG + j], dy[i * NANG + j]);
            rho[i * NANG + j] = J > 0 ? s->rho0 / J : NAN;
        }
    for (int i = 0; i < ARROW_RINGS; i++)
        for (int j = 0; j < ARROW_ANG; j++) {
            double r = 1.15 + 0.45 * i, th = 2 * M_PI * (j + 0.5 * (i % 2)) / ARROW_ANG;
            double complex z = r * cexp(I * th), dphi, dF = 0.0;
            double complex w = phi(c, N, z, &dphi);
            for (int k = 1; k <= N + 1; k++) dF += -k * AB[k] * cpow(z, -k - 1);
            double complex u = conj(dF / dphi);   /* u1 + i u2 in the body frame */
            int a = i * ARROW_ANG + j;
            WORLD(w, ax[a], ay[a]);
            double ub[3] = {creal(u), cimag(u), 0.0}, uf[3];
            swim_to_fixed_frame(y[2], ub, uf);
            au[a] = uf[0];
            av[a] = uf[1];
        }
#undef WORLD
    fprintf(f, "{\"t\": %.10g, \"x\": %.10g, \"y\": %.10g, \"theta\": %.10g,\n \"boundary\": {\"X\": ", t, y[0], y[1], y[2]);
    write_array(f, bx, NB);
    fprintf(f, ", \"Y\": ");
    write_array(f, by, NB);
    fprintf(f, "},\n \"density\": {\"X\": ");
    swim_json_matrix(f, dx, NRAD, NANG, 2);
    fprintf(f, ", \"Y\": ");
    swim_json_matrix(f, dy, NRAD, NANG, 2);
    fprintf(f, ", \"rho\": ");
    swim_json_matrix(f, rho, NRAD, NANG, 2);
    fprintf(f, "},\n \"arrows\": {\"X\": ");
    write_array(f, ax, ARROW_RINGS * ARROW_ANG);
    fprintf(f, ", \"Y\": ");
    write_array(f, ay, ARROW_RINGS * ARROW_ANG);
    fprintf(f, ", \"U\": ");
    write_array(f, au, ARROW_RINGS * ARROW_ANG);
    fprintf(f, ", \"V\": ");
    write_array(f, av, ARROW_RINGS * ARROW_ANG);
    fprintf(f, "}}");
    free(S);
    free(buf);
    return ferror(f) ? -1 : 0;
}
