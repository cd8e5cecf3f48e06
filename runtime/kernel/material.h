/* material.h -- W(c) = int_D U(I1, J) dz by a product rule over the unit disk, with its
 * gradient, Hessian and parameter partials (ERRATA B5), for an energy law that is not a
 * polynomial in I1 and J (generator/swimgen/material.py; a polynomial law is in closed form).
 *
 * Included by a generated scene kernel, which defines before it:
 *   MATERIAL_NR, material_r[], material_w[]   Gauss-Legendre nodes and weights of
 *                            int_0^1 g(r) r dr;
 *   MATERIAL_NT, material_c[], material_s[]   cos and sin of the trapezoid nodes 2 pi l / NT;
 *   MATERIAL_TOP             the highest mode not locked at 0 (h has degree TOP - 1);
 *   MATERIAL_GK, material_gx[], material_gw[]   Gauss-Legendre on [-1, 1], for the graded rule;
 *   material_density(I1, J, p, u)   u = U, U_I, U_J, U_II, U_IJ, U_JJ at one point;
 *   material_density_dp(I1, J, p, k, u)   d/d law_params[k] of U, U_I, U_J (1), or 0.
 * and it defines material_energy and material_energy_dp, as the closed form does.
 *
 * At z = r e^{i theta}: A = |c_1|^2, h = sum_m m c_-m conj(z)^(m-1), H = |h|^2, and
 * I1 = 2 (A + H), J = A - H (2.4). With U as a function of (A, H):
 *   U_A = 2 U_I + U_J,  U_H = 2 U_I - U_J,
 *   U_AA = 4 U_II + 4 U_IJ + U_JJ,  U_AH = 4 U_II - U_JJ,  U_HH = 4 U_II - 4 U_IJ + U_JJ,
 * grad U = U_A grad A + U_H grad H and
 * hess U = U_AA gA gA^T + U_AH (gA gH^T + gH gA^T) + U_HH gH gH^T + U_A hess A + U_H hess H,
 * where h is linear in c: d h / d a_-m = m conj(z)^(m-1) = e_m, d h / d b_-m = i e_m, so
 * d H / d x_s = 2 Re(conj(h) dh_s) and d^2 H / d x_s d x_t = 2 Re(conj(dh_s) dh_t).
 */
#ifndef SWIM_KERNEL_MATERIAL_H
#define SWIM_KERNEL_MATERIAL_H

#define MATERIAL_MODES (NFULL / 2 - 1)

/* d h / d x_i at the node (e: e_m, m = 1..N) as (re, im); 0 for a_1, b_1. */
static inline void material_dh(int i, const double *er, const double *ei, double *re, double *im)
{
    if (i < 2) {
        *re = *im = 0.0;
        return;
    }
    const int m = i / 2;
    if (i % 2 == 0) {
        *re = er[m];
        *im = ei[m];
    } else {   /* i e_m */
        *re = -ei[m];
        *im = er[m];
    }
}

/* The point values at z = r e^{i theta} (c, sn: cos and sin of theta): A, H, gradients on the
 * carried coordinates (gA, gH) and, for the Hessian, the e_m. */
static void material_node(const double *x, double r, double c, double sn, double *A, double *H,
                          double *gA, double *gH, double *er, double *ei)
{
    /* conj(z)^(m-1) = r^(m-1) e^{-i (m-1) theta} */
    double pr = 1.0, pi_ = 0.0, hr = 0.0, hi = 0.0;
    const double zr = r * c, zi = -r * sn;
    for (int m = MATERIAL_TOP + 1; m <= MATERIAL_MODES; m++) er[m] = ei[m] = 0.0;
    for (int m = 1; m <= MATERIAL_TOP; m++) {   /* modes above MATERIAL_TOP are locked at 0 */
        er[m] = m * pr;
        ei[m] = m * pi_;
        const double a = x[2 * m], b = x[2 * m + 1];
        hr += a * er[m] - b * ei[m];
        hi += a * ei[m] + b * er[m];
        const double t = pr * zr - pi_ * zi;
        pi_ = pr * zi + pi_ * zr;
        pr = t;
    }
    *A = x[0] * x[0] + x[1] * x[1];
    *H = hr * hr + hi * hi;
    for (int f = 0; f < NX; f++) {
        const int i = free_index[f];
        gA[f] = i == 0 ? 2.0 * x[0] : i == 1 ? 2.0 * x[1] : 0.0;
        double dr, di;
        material_dh(i, er, ei, &dr, &di);
        gH[f] = 2.0 * (hr * dr + hi * di);   /* 2 Re(conj(h) dh) */
    }
}

/* The product rule used at shape x. Where min J on the circle (sampled at the NT angles) is at
 * least MATERIAL_GRADE_BELOW, the fixed rule: NR Gauss-Legendre nodes in r, the NT-point
 * trapezoid in theta (exact to round-off there, docs/materials.md). Below it ln J or 1/J vary on
 * the scale of min J across r and of sqrt(min J) across theta near the angle theta* of the
 * minimum, and a graded rule takes over, as the barrier's quadrature is graded (shape/barrier.c):
 * MATERIAL_GK-point Gauss-Legendre panels, geometric towards r = 1 down to a width min J / 4,
 * and geometric on both sides of theta* down to sqrt(min J) / 4. */
#define MATERIAL_GRADE_BELOW 0.15
#define MATERIAL_MAX_PANELS 40
typedef struct {
    int nr, nt;
    double r[MATERIAL_MAX_PANELS * MATERIAL_GK + MATERIAL_NR], wr[MATERIAL_MAX_PANELS * MATERIAL_GK + MATERIAL_NR];
    double c[2 * MATERIAL_MAX_PANELS * MATERIAL_GK + MATERIAL_NT], s[2 * MATERIAL_MAX_PANELS * MATERIAL_GK + MATERIAL_NT];
    double wt[2 * MATERIAL_MAX_PANELS * MATERIAL_GK + MATERIAL_NT];
} material_rule;

/* GK Gauss-Legendre nodes on [a, b] appended to x, w (weights times `scale`, nodes through f). */
static int material_panel(double a, double b, double *x, double *w, int n)
{
    for (int k = 0; k < MATERIAL_GK; k++) {
        x[n + k] = 0.5 * (b - a) * material_gx[k] + 0.5 * (a + b);
        w[n + k] = 0.5 * (b - a) * material_gw[k];
    }
    return n + MATERIAL_GK;
}

static void material_rule_at(const double *x, material_rule *q)
{
    const double twopi = 2.0 * 3.14159265358979323846;
    double jmin = INFINITY, tmin = 0.0;
    double er[MATERIAL_MODES + 1], ei[MATERIAL_MODES + 1], gA[NX], gH[NX];
    for (int l = 0; l < MATERIAL_NT; l++) {   /* J on the circle at the trapezoid's angles */
        double A, H;
        material_node(x, 1.0, material_c[l], material_s[l], &A, &H, gA, gH, er, ei);
        if (A - H < jmin) {
            jmin = A - H;
            tmin = twopi * l / MATERIAL_NT;
        }
    }
    /* near the boundary of D: the angle of the minimum to ~1e-6, zooming in by 16 three times */
    for (int z = 0, span = 1; jmin < MATERIAL_GRADE_BELOW && z < 3; z++, span *= 16) {
        const double c0 = tmin, h = twopi / MATERIAL_NT / span;
        for (int l = -16; l <= 16; l++) {
            const double th = c0 + h * l / 16.0;
            double A, H;
            material_node(x, 1.0, cos(th), sin(th), &A, &H, gA, gH, er, ei);
            if (A - H < jmin) {
                jmin = A - H;
                tmin = th;
            }
        }
    }
    if (!(jmin < MATERIAL_GRADE_BELOW) || !(jmin > 0.0)) {   /* fixed rule (J <= 0: refused later) */
        q->nr = MATERIAL_NR;
        q->nt = MATERIAL_NT;
        for (int i = 0; i < MATERIAL_NR; i++) {
            q->r[i] = material_r[i];
            q->wr[i] = material_w[i];
        }
        for (int l = 0; l < MATERIAL_NT; l++) {
            q->c[l] = material_c[l];
            q->s[l] = material_s[l];
            q->wt[l] = twopi / MATERIAL_NT;
        }
        return;
    }
    double rr[MATERIAL_MAX_PANELS * MATERIAL_GK], ww[MATERIAL_MAX_PANELS * MATERIAL_GK];
    int n = 0;
    double a = 0.0, width = 0.5;
    for (int p = 0; p < MATERIAL_MAX_PANELS - 1 && width > jmin / 64.0; p++, width *= 0.5) {
        n = material_panel(a, 1.0 - width, rr, ww, n);
        a = 1.0 - width;
    }
    n = material_panel(a, 1.0, rr, ww, n);
    q->nr = n;
    for (int i = 0; i < n; i++) {
        q->r[i] = rr[i];
        q->wr[i] = ww[i] * rr[i];   /* r dr */
    }
    /* theta = tmin + phi, phi in [-pi, pi], panels geometric towards phi = 0 on both sides */
    double pp[MATERIAL_MAX_PANELS * MATERIAL_GK], pw[MATERIAL_MAX_PANELS * MATERIAL_GK];
    int m = 0;
    const double pi = 0.5 * twopi, stop = sqrt(jmin) / 16.0;
    double hi = pi;
    for (int p = 0; p < MATERIAL_MAX_PANELS - 1 && hi > stop; p++, hi *= 0.5) m = material_panel(0.5 * hi, hi, pp, pw, m);
    m = material_panel(0.0, hi, pp, pw, m);
    q->nt = 2 * m;
    for (int i = 0; i < m; i++)
        for (int side = 0; side < 2; side++) {
            const double th = tmin + (side ? -pp[i] : pp[i]);
            q->c[2 * i + side] = cos(th);
            q->s[2 * i + side] = sin(th);
            q->wt[2 * i + side] = pw[i];
        }
}

static int material_energy(const double *x, const swim_scene_params *p, double *W, double *grad,
                           double *hess)
{
    double gA[NX], gH[NX], er[MATERIAL_MODES + 1], ei[MATERIAL_MODES + 1], u[6];
    double sum = 0.0;
    material_rule q;
    material_rule_at(x, &q);
    for (int f = 0; f < NX; f++) grad[f] = 0.0;
    if (hess) memset(hess, 0, sizeof(double) * NX * NX);
    for (int iq = 0; iq < q.nr; iq++) {
        for (int l = 0; l < q.nt; l++) {
            const double w = q.wr[iq] * q.wt[l];
            double A, H;
            material_node(x, q.r[iq], q.c[l], q.s[l], &A, &H, gA, gH, er, ei);
            const double I1 = 2.0 * (A + H), J = A - H;
            if (!(J > 0.0)) return 1;   /* the law is defined for J > 0 only: outside D */
            material_density(I1, J, p, u);
            const double UA = 2.0 * u[1] + u[2], UH = 2.0 * u[1] - u[2];
            sum += w * u[0];
            for (int f = 0; f < NX; f++) grad[f] += w * (UA * gA[f] + UH * gH[f]);
            if (!hess) continue;
            const double UAA = 4.0 * u[3] + 4.0 * u[4] + u[5], UAH = 4.0 * u[3] - u[5];
            const double UHH = 4.0 * u[3] - 4.0 * u[4] + u[5];
            for (int f = 0; f < NX; f++) {
                const int i = free_index[f];
                double dfr, dfi;
                material_dh(i, er, ei, &dfr, &dfi);
                for (int g = 0; g <= f; g++) {
                    const int j = free_index[g];
                    double dgr, dgi;
                    material_dh(j, er, ei, &dgr, &dgi);
                    double v = UAA * gA[f] * gA[g] + UAH * (gA[f] * gH[g] + gH[f] * gA[g])
                             + UHH * gH[f] * gH[g] + UH * 2.0 * (dfr * dgr + dfi * dgi);
                    if (i == j && i < 2) v += 2.0 * UA;
                    hess[NX * f + g] += w * v;
                }
            }
        }
    }
    if (hess)
        for (int f = 0; f < NX; f++)
            for (int g = 0; g < f; g++) hess[NX * g + f] = hess[NX * f + g];
    *W = sum;
    if (!isfinite(sum)) return 1;
    for (int f = 0; f < NX; f++)
        if (!isfinite(grad[f])) return 1;
    return 0;
}

static int material_energy_dp(const double *x, const swim_scene_params *p, int k, double *dgrad)
{
    double gA[NX], gH[NX], er[MATERIAL_MODES + 1], ei[MATERIAL_MODES + 1], u[3];
    int any = 0;
    material_rule q;
    material_rule_at(x, &q);
    for (int f = 0; f < NX; f++) dgrad[f] = 0.0;
    for (int iq = 0; iq < q.nr; iq++)
        for (int l = 0; l < q.nt; l++) {
            double A, H;
            material_node(x, q.r[iq], q.c[l], q.s[l], &A, &H, gA, gH, er, ei);
            if (!material_density_dp(2.0 * (A + H), A - H, p, k, u)) return 0;
            any = 1;
            const double w = q.wr[iq] * q.wt[l], UA = 2.0 * u[1] + u[2], UH = 2.0 * u[1] - u[2];
            for (int f = 0; f < NX; f++) dgrad[f] += w * (UA * gA[f] + UH * gH[f]);
        }
    return any;
}

#endif
