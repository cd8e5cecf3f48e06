/* Independent reference for the right-hand side of the equations of motion, with plain loops
 * and no code shared with the generator or runtime/kernel/ (tests compare the generated
 * kernels against it):
 *   K c'' + <Gamma(c), c', c'> + grad W1 + grad W2 = G^T lambda - D c' + F(t)   (4.10), (4.15), (5.2)
 *   G c'' = -(DG[c'])c'                                                        (4.12)
 *   q' = R(theta) q*,  q* = -Mr^-1 Nc c'                                       (3.20)-(3.21)
 * with G = (G1; G2; e_i for every locked i) (ERRATA C2), W1 of ERRATA E2, W2 of section 4.1.1
 * (ref_barrier), and the Christoffel symbol Gamma_ijl = (d_l K_ij + d_j K_il - d_i K_jl)/2 exact:
 * dK = dMd - dNc^T Y - Y^T dNc + Y^T dMr Y (Y = Mr^-1 Nc) from exact derivatives of the blocks.
 * Those come from ref_mass by a central difference with step 1/2, which is exact (up to rounding)
 * because every entry of Mr, Nc, Md is a quadratic polynomial in each single coordinate: the
 * sequences mu, nu of (3.8) are linear in c and alpha of ERRATA A5 is bilinear in distinct
 * coefficients (c_i and c_{i+j}, j >= 1). The acceleration and the multipliers come from one
 * Gaussian elimination on the whole saddle-point system [K -G^T; G 0].
 * State y (3 + 2n + 1): q = (r1, r2, theta), c, c', work; dy[3 + 2n] = F.c' - c'^T D c'. */
#ifndef SWIM_TESTS_REF_RHS_H
#define SWIM_TESTS_REF_RHS_H

typedef struct {
    int N;
    double rho0, rhof;
    const int *free_mask;                 /* n entries: 1 free, 0 locked */
    const double *stiffness, *reference;  /* W1, or NULL */
    int barrier_nodes;                    /* W2 with this many trapezoidal nodes, or 0 */
    double epsilon, alpha;
    const double *damping;                /* D (diagonal), or NULL */
    double (*law)(double t);              /* F(t) = law(t) direction, or NULL */
    const double *direction;
} ref_scene;

/* dK[r*n*n + i*n + j] = d K_ij / d x_r, exact (see above). */
void ref_reduced_deriv(int N, const double *x, double rho0, double rhof, double *dK);

/* The right-hand side at (t, y). 0, or -1 when the saddle-point system is singular. */
int ref_rhs(const ref_scene *s, double t, const double *y, double *dy);

#endif
