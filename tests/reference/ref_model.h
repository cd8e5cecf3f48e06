/* Independent reference implementation of the swimmer model's closed forms
 * (Munnier, Section 3 and 4, as corrected by shared/paper/ERRATA.md A and B).
 *
 * Written with plain loops and no code shared with the symbolic generator, so the
 * tests can compare generated kernels against it.  Straightforward, not fast.
 *
 * Conventions:
 *   N >= 0 modes; n = 2(N+1) real shape coordinates in storage order
 *     x = (a_1, b_1, a_-1, b_-1, ..., a_-N, b_-N),   c_k = a_k + i b_k,
 *   c_k = 0 for k = 0, k >= 2, k < -N.
 *   Generalised rigid velocity order (r*_1, r*_2, omega).
 *   All matrices row-major.  rho0 = body density, rhof = fluid density.
 */
#ifndef SWIM_TESTS_REF_MODEL_H
#define SWIM_TESTS_REF_MODEL_H

/* Number of real shape coordinates, 2(N+1). */
int ref_ncoords(int N);

/* Mass matrices from the closed forms (3.15)-(3.18) with ERRATA A5-A9:
 *   Mr (3x3), Nc (3 x n), Md (n x n) and K = Md - Nc^T Mr^{-1} Nc (n x n).
 * Any output pointer may be NULL. */
void ref_mass(int N, const double *x, double rho0, double rhof,
              double *Mr, double *Nc, double *Md, double *K);

/* Fluid kinetic energy from the complex form of ERRATA A9,
 * (1/2) sum_{n>=1} (4 pi rhof / n) |g_n|^2, for the generalised velocity
 * q = (r*_1, r*_2, omega), xdot (length n). */
double ref_fluid_energy_complex(int N, const double *x, const double q[3],
                                const double *xdot, double rhof);

/* J(c) on the unit circle at angle theta (ERRATA B2):
 * J = |c_1|^2 - |h(z)|^2, h(z) = sum_{m=1}^N m c_-m conj(z)^(m-1), z = e^{i theta}. */
double ref_jacobian_circle(int N, const double *x, double theta);

/* Minimum of J over Q equally spaced angles 2 pi q / Q, q = 0..Q-1. */
double ref_min_jacobian(int N, const double *x, int Q);

/* W2 = eps/(2 alpha) * int_0^{2 pi} J^-alpha dtheta (trapezoidal rule, Q nodes).
 * grad (length n, may be NULL) from ERRATA B3 with the same rule.  Returns W2. */
double ref_barrier(int N, const double *x, double eps, double alpha, int Q,
                   double *grad);

/* Contracted Christoffel vector by finite differences of ref_mass's K (ERRATA C1):
 *   Gamma_i(v,v) = [D_v(K v)]_i - 1/2 d_i (v^T K v),
 * D_v K by a central difference along v with step h, d_i (v^T K v) by central
 * differences in each coordinate with step h.  gamma has length n. */
void ref_christoffel_fd(int N, const double *x, const double *v, double rho0,
                        double rhof, double h, double *gamma);

#endif
