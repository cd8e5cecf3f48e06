"""The frame of the generated files: banner, sizes, the wrappers that hold SymPy's statements,
and the includes of the hand-written C. No numerical C lives here: the fixed assembly (Gram
products, Cholesky, Schur complement, product-rule derivatives, Gamma, the scene's right-hand
side) is in runtime/kernel/assembly.h and runtime/kernel/scene_rhs.h, which the generated file
includes after defining what they need (listed at the top of each header).
"""

from string import Template

TABLE = Template("""\
/* swim_kernel_table.c -- the kernels linked into this build.
 *
 * $banner
 */
#include <stddef.h>
#include "kernel/swim_kernel.h"

$externs

static const swim_kernel *const table[] = {$entries};

const swim_kernel *swim_kernel_find(int modes)
{
    for (size_t i = 0; i < sizeof table / sizeof table[0]; i++)
        if (table[i]->modes == modes)
            return table[i];
    return NULL;
}

int swim_kernel_list(int *modes, int cap)
{
    int count = (int)(sizeof table / sizeof table[0]);
    for (int i = 0; i < count && i < cap; i++)
        modes[i] = table[i]->modes;
    return count;
}
""")

KERNEL_HEAD = Template("""\
/* $filename -- $what
 *
 * $banner
 *
 * Velocity coordinates ($n): $columns.
 * S is the $R x $P boundary-data matrix of generator/swimgen/model.py (rows: Fourier modes j of
 * the potentials, columns: r*_1, r*_2, omega, then the velocity coordinates).
 */
#include <math.h>
#include <string.h>

#define NFULL $nfull   /* length of the shape vector x */
#define NX $n      /* velocity coordinates carried by this kernel */
#define NR $R
#define NP $P
$options
""")

SYMBOLIC_CORE = Template("""\
/* ---- symbolic pieces (SymPy) ---------------------------------------------------------- */

/* S(x): the sequences mu_0, nu_0, alpha, mu_k, nu_k of (3.7)-(3.8), ERRATA A5-A6. */
static void boundary_data(const double *x, double S[NR][NP])
{
    memset(S, 0, sizeof(double) * NR * NP);
$S_body
}

/* D_v S = sum_r v_r dS/dx_r. */
static void boundary_data_dir(const double *x, const double *v, double D[NR][NP])
{
    memset(D, 0, sizeof(double) * NR * NP);
$D_body
}

/* g_i = sum_{row,col} w_row dS[row][col]/dx_i X_col. */
static void boundary_data_bigrad(const double *x, const double *w, const double *X, double *g)
{
$G_body
}

static double inertia(const double *x, double *grad)
{
    double I;
$I_body
    return I;
}

/* Body part of Md over pi rho0: 1/(|k|+1) (ERRATA A7). */
static const double body_shape[NX] = {$bodyw};

/* The factor j of the weighted product u.s = sum_j j (u1_j s1_j + u2_j s2_j), per row of S. */
static const double weight[NR] = {$weights};

""")

SYMBOLIC_DERIV = Template("""\
/* dS[r][row][col] = dS[row][col]/dx_r (zero entries are not written: caller clears). */
static void boundary_data_deriv(const double *x, double *dS)
{
$dS_body
}

""")

SYMBOLIC_JACOBIAN = Template("""\
/* J(c) on the unit circle (2.4), ERRATA B2, and its gradient. */
static void jacobian_circle(const double *x, const double *cs, const double *sn,
                            double *J, double *dJ)
{
$J_body
    if (dJ) {
$dJ_body
    }
}

""")

SCENE_PIECES = Template("""\
/* ---- the scene's effects (SymPy) ------------------------------------------------------ */

#define SWIM_SCENE_STRUCTURE "$structure"

static const int free_index[NX] = {$free_index};

/* f = -<Gamma, v, v> - grad W1 - D v + F(t) and the power F.v - v^T D v (4.10), (4.15), (5.1),
 * ERRATA E2; the forcing law is "$law". */
static void scene_forces(double t, const double *x, const double *v, const double *g,
                         const swim_scene_params *p, double *f, double *power)
{
$force_body
}

/* G1 (2.8) and G2 (2.14) on the carried coordinates, and curv = (DG1[v]).v (ERRATA C2). */
static void scene_constraints(const double *x, const double *v, double G[2][NX], double *curv)
{
$constraint_body
}

""")

SCENE_JACOBIAN_PIECES = Template("""\
/* ---- derivatives for the exact Jacobian (SymPy) ---------------------------------------- */

/* First partials of S, sparse: entry k (dS_start[r] <= k < dS_start[r + 1]) is
 * d S[dS_row[k]][dS_col[k]] / d x_r = val[k]. */
#define NDS $nds
static const int dS_row[NDS > 0 ? NDS : 1] = {$ds_row};
static const int dS_col[NDS > 0 ? NDS : 1] = {$ds_col};
static const int dS_start[NX + 1] = {$ds_start};
static void boundary_data_partials(const double *x, double *val)
{
$ds_body
}

/* Second partials of S: only the alpha column (col 2) is not linear in x, and it is quadratic, so
 * d^2 S[a2_row[k]][2] / d x_r d x_s = a2_val[k] (r = a2_r[k], s = a2_s[k]) are constants. */
#define NA2 $na2
static const int a2_row[NA2 > 0 ? NA2 : 1] = {$a2_row};
static const int a2_r[NA2 > 0 ? NA2 : 1] = {$a2_r};
static const int a2_s[NA2 > 0 ? NA2 : 1] = {$a2_s};
static const double a2_val[NA2 > 0 ? NA2 : 1] = {$a2_val};

/* Hessian of the inertia sum (constant: the sum is quadratic), non-zeros. */
#define NIH $nih
static const int ih_r[NIH > 0 ? NIH : 1] = {$ih_r};
static const int ih_s[NIH > 0 ? NIH : 1] = {$ih_s};
static const double ih_val[NIH > 0 ? NIH : 1] = {$ih_val};

/* Partials of scene_forces at fixed <Gamma, v, v>: Fx[k][s] = d f_k / d x_s, Fv[k][s] = d f_k / d v_s,
 * px, pv those of the power. Only non-zeros are written: the caller clears. */
static void scene_forces_jac(double t, const double *x, const double *v, const swim_scene_params *p,
                             double Fx[NX][NX], double Fv[NX][NX], double *px, double *pv)
{
$force_jac_body
}

/* Partials of scene_forces with respect to the run-time parameter (kind, index) of
 * kernel/swim_kernel.h (swim_param), at fixed x, v and <Gamma, v, v>: dF[k] = d f_k / d p and
 * *dpow = d power / d p. Only non-zeros are written: the caller clears. 1 when the forces read
 * the parameter, 0 when they do not (all partials 0). */
static int scene_forces_dp(double t, const double *x, const double *v, const swim_scene_params *p,
                           int kind, int index, double *dF, double *dpow)
{
$force_dp_body
}

/* Partials of scene_constraints: Gx[j][k][s] = d G[j][k] / d x_s, cv[s] = d curv / d v_s (curv
 * does not depend on x). Only non-zeros are written: the caller clears. */
static void scene_constraints_jac(const double *x, const double *v, double Gx[2][NX][NX], double *cv)
{
$constraint_jac_body
}

""")

INCLUDE_ASSEMBLY = '#include "kernel/assembly.h"\n'
INCLUDE_SCENE_RHS = '#include "kernel/scene_rhs.h"\n'
INCLUDE_SPARSE_DATA = '#include "kernel/sparse_data.h"\n'
INCLUDE_LAW_FUNCTIONS = '#include "kernel/law_functions.h"\n'

# Straight-line SymPy code of large kernels: GCC's -O3 spends most of its time on it for no gain
# (measured at N = 20: compile 10.4 s -> 6.3 s of CPU, K + Gamma no slower); the hand-written
# loops of kernel/assembly.h keep the command line's optimization.
QUICK_OPTIMIZATION_BEGIN = """\
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC push_options
#pragma GCC optimize ("O1")
#endif
"""
QUICK_OPTIMIZATION_END = """\
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC pop_options
#endif
"""
