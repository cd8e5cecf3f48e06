/* swim_kernel.h -- contract between the generated kernels and the runtime.
 *
 * Written by hand: the generated kernels (generated/, and the run-time cache) include it, and the
 * fixed assembly they share lives next to it (kernel/assembly.h, kernel/scene_rhs.h).
 *
 * Conventions (Munnier's model with shared/paper/ERRATA.md):
 *   x  = (a_1, b_1, a_-1, b_-1, ..., a_-N, b_-N), n = 2(N+1) real shape coordinates;
 *   generalized rigid velocity q* = (r*_1, r*_2, omega) in the body frame;
 *   matrices are row-major; rho0 = body density, rhof = fluid density (run-time values).
 *   Mr (3x3), Nc (3xn), Md (nxn) are the blocks of the mass matrix (3.14), with ERRATA A9;
 *   K = Md - Nc^T Mr^-1 Nc is the reduced mass matrix (section 4.1.2);
 *   Gamma[i][j][l] = (d_l K_ij + d_j K_il - d_i K_jl)/2, so that
 *   <Gamma(c), v, v>_i = sum_jl Gamma[i][j][l] v_j v_l = [D_v(K v)]_i - d_i(v^T K v)/2 (ERRATA C1).
 * The caller owns every array; kernels allocate nothing except reduced_deriv (freed before it returns).
 */
#ifndef SWIM_KERNEL_H
#define SWIM_KERNEL_H

#define SWIM_KERNEL_ABI 10
#define SWIM_KERNEL_MAX_MODES 32   /* largest N the runtime accepts (arrays are sized by it) */

typedef struct swim_kernel {
    int modes;  /* N */
    int dim;    /* n = 2(N+1) */
    /* Mr, Nc, Md at shape x; any output may be NULL. */
    void (*mass)(const double *x, double rho0, double rhof, double *Mr, double *Nc, double *Md);
    /* Partial derivatives with respect to x_r, stored as slice r: dMr[r*9 + ...],
     * dNc[r*3n + ...], dMd[r*n*n + ...]; any output may be NULL.
     * Returns 0, or -2 when out of memory. */
    int (*mass_deriv)(const double *x, double rho0, double rhof,
                      double *dMr, double *dNc, double *dMd);
    /* K (nxn, exactly symmetric), P = -Mr^-1 Nc (3xn, may be NULL) and, when v is not NULL,
     * gvv = <Gamma(c), v, v> (n) computed without forming the tensor.
     * Returns 0, or -1 when Mr is not positive definite. */
    int (*reduced)(const double *x, const double *v, double rho0, double rhof,
                   double *K, double *P, double *gvv);
    /* dK (slice r = d K / d x_r, n*n*n) and Gamma (n*n*n, [i][j][l]); either may be NULL.
     * Returns 0, -1 when Mr is not positive definite, -2 when out of memory. */
    int (*reduced_deriv)(const double *x, double rho0, double rhof, double *dK, double *Gamma);
    /* J(c) at z = e^{i theta} on the unit circle (2.4) and its gradient dJ (n, may be NULL);
     * cs[m] = cos(m theta), sn[m] = sin(m theta) for m = 0 .. N-1 (unused when N = 0). */
    void (*jacobian_circle)(const double *x, const double *cs, const double *sn,
                            double *J, double *dJ);
    /* sum_k |c_k|^2/(|k|+1) and its gradient (may be NULL); I(c) = pi rho0 times it (2.11). */
    double (*inertia)(const double *x, double *grad);
    /* S(x), 2(N+1) x (3+n) row-major: column p holds the Fourier data (s1_j, s2_j), j = 1..N+1,
     * of the potential of velocity component p (r*_1, r*_2, omega, x_0, ...). For a generalized
     * velocity X the fluid potential is xi = sum_j (-(S X)_{2j-2} cos j theta
     * + (S X)_{2j-1} sin j theta) r^-j (ERRATA A4). */
    void (*boundary_data)(const double *x, double *S);
    /* What the row diagnostics read, from one evaluation of the boundary data: Mr (3x3), and
     * Nc, P = -Mr^-1 Nc and Md only in the m columns (and rows) where v is not 0, their indices
     * written ascending to idx: Nc[p*m + a] = Nc_{p idx[a]}, P likewise, Md[a*m + b] =
     * Md_{idx[a] idx[b]}, each entry the same bits as mass and reduced give (products with v
     * lose only exact zeros; the cost falls with the coordinates locked). Returns m, or -1 when
     * Mr is not positive definite. */
    int (*row_blocks)(const double *x, const double *v, double rho0, double rhof, double *Mr, double *Nc,
                      double *P, int *idx, double *Md);
} swim_kernel;

/* Codes returned by right-hand sides (generic: runtime/model/dynamics.c; scene kernels). */
enum { SWIM_RHS_OK = 0, SWIM_RHS_ENAN, SWIM_RHS_EBARRIER, SWIM_RHS_EMASS, SWIM_RHS_ECONSTRAINT };

/* Run-time parameters of a scene kernel. Vectors have the full length 2(N+1). */
typedef struct swim_scene_params {
    double rho0, rhof;
    const double *x_locked;     /* values of the locked coordinates (free entries ignored) */
    const double *stiffness, *reference, *damping, *direction;
    /* 1 = free, 0 = locked, full length; read only by kernels that lock by multipliers */
    const int *free_mask;
    /* grad W2 on the kernel's coordinates at the full shape x (the quadrature is the runtime's,
     * shape/barrier.h); 0, or nonzero when the shape is outside D (J <= 0 on the circle). */
    int (*barrier)(const double *x, double *grad, void *ctx);
    void *barrier_ctx;
    /* values of the scene's [parameters], in their order; the generated law reads them as
     * p->law_params[i] (the names are fixed by the structure, the values are not) */
    const double *law_params;
    /* grad W2 and its Hessian (NX x NX, row-major) on the kernel's coordinates at the full shape
     * x, for the exact Jacobian (same context and return values as barrier). */
    int (*barrier_hessian)(const double *x, double *grad, double *hess, void *ctx);
    /* NULL, or where rhs writes the kinetic energy (1/2) v^T K v of the state it evaluated (a by-
     * product: the energy balance that abm's error test reads, runtime/model/dynamics.h) */
    double *kinetic;
} swim_scene_params;

/* A run-time parameter of a scene kernel's right-hand side, for its partial derivatives: the
 * vector entries of swim_scene_params (index = full coordinate index), a forcing law's
 * [parameters] (index into law_params), the densities, and the barrier's scale eps (the partial
 * is eps d/d eps: W2 is linear in eps, shape/barrier.h; the kernel does not see eps itself). */
enum {
    SWIM_PARAM_STIFFNESS = 1, SWIM_PARAM_REFERENCE, SWIM_PARAM_DAMPING, SWIM_PARAM_DIRECTION,
    SWIM_PARAM_LAW, SWIM_PARAM_RHO0, SWIM_PARAM_RHOF, SWIM_PARAM_BARRIER_SCALE
};
typedef struct {
    int kind;    /* SWIM_PARAM_... */
    int index;
} swim_param;

/* A kernel specialized to one scene structure: it carries only the free coordinates (or all of
 * them, locks then held by multipliers of (4.12)).
 * State y = (r_1, r_2, theta, c_free, cdot_free, work), as in runtime/model/dynamics.h. */
typedef struct swim_scene_kernel {
    int abi;                    /* SWIM_KERNEL_ABI */
    int modes, nfull, nfree;
    const int *free_index;      /* nfree indices into the full shape vector */
    const char *structure;      /* the structure key it was generated for */
    int (*rhs)(double t, const double *y, double *dydt, const swim_scene_params *p);
    /* The exact Jacobian d rhs / d y at (t, y): J dense, row-major, dim x dim with
     * dim = 4 + 2 nfree, the state layout of rhs; fills J completely. Same return values as rhs
     * (positive: (t, y) outside the domain), and negative when out of memory. */
    int (*jacobian)(double t, const double *y, double *J, const swim_scene_params *p);
    /* The same Jacobian (J may be NULL) and, exactly, the partials of rhs with respect to np
     * run-time parameters: dp[k * dim + i] = d rhs_i / d param[k] at fixed (t, y) -- the
     * inhomogeneous terms of the variational equations s' = J s + d rhs / d p. A parameter the
     * right-hand side does not read gets zeros. Same return values as jacobian. */
    int (*jacobian_params)(double t, const double *y, double *J, int np, const swim_param *param,
                           double *dp, const swim_scene_params *p);
    /* NULL, or (a scene with [elastic] energy) the energy law's W = int_D U(I1, J) dz at the full
     * shape x, its gradient and Hessian (nfree x nfree, row-major) on the carried coordinates
     * (grad, hess may be NULL); 0, or nonzero where it is not finite (ERRATA B5,
     * generator/swimgen/material.py). */
    int (*material)(const double *x, const swim_scene_params *p, double *W, double *grad, double *hess);
} swim_scene_kernel;

/* Exported names: "swim_kernel_n<N>" (a swim_kernel) and "swim_scene_kernel_entry". */

/* The kernel for N modes among those linked in (generated/, N = 0..7), or NULL; any other N is
 * generated at run time (runtime/codegen/codegen.h). */
const swim_kernel *swim_kernel_find(int modes);
/* Mode counts linked in, ascending; returns how many (at most cap written). */
int swim_kernel_list(int *modes, int cap);

#endif
