/* constraints.h -- the constraints (G_j(c), cdot) = 0 of section 4.1.3 in real form (ERRATA C2):
 *   row 0: G1 = (k a_k, k b_k)_k             volume (2.8)
 *   row 1: G2 = (b_k, -a_k)/(|k|+1)          angular momentum of the deformation (2.14)
 *   rows 2..: e_i for each locked coordinate i (section 4.2.2), in increasing i.
 * G is row-major m x n with m = 2 + number of locked coordinates. */
#ifndef SWIM_CONSTRAINTS_H
#define SWIM_CONSTRAINTS_H

int swim_constraint_rows(int n, const double *x, const int *free_mask, double *G);
/* The coordinate locked by constraint row `row` (>= 2). */
int swim_constraint_locked_index(int n, const int *free_mask, int row);

/* How far a state (c, v) is from the constraints, with c0 the initial shape: the volume
 * mu^2(c) - mu^2(c0) (2.5), G1.v (2.8) and G2.v (2.14) (signed), and the largest
 * |c_i - c0_i| + |v_i| of a locked coordinate. The one computation of the residuals of the diagnostics and of the checks at every step. */
typedef struct {
    double volume, volume_rate, angular, locks;
} swim_constraint_residuals;
/* swim_area_constant (kernel/coords.h) to the bit, leaving out the modes at exactly 0 (the
 * locked ones, mostly): each adds a signed zero to a sum that started at +0 and so is never -0,
 * which changes no bit; off the chain of additions they cost nothing (every step asks). */
double swim_area_constant_moving(int n, const double *c);
/* mu0 = mu^2(c0) (swim_area_constant), kept by the caller: the checks at every step ask. */
void swim_constraint_residuals_at(int n, const double *c, const double *v, const double *c0, double mu0,
                                  const int *free_mask, swim_constraint_residuals *r);
/* v <- v - G^T (G G^T)^-1 G v, the l2-orthogonal projection onto {G v = 0} (ERRATA D5).
 * 0, or -1 when G G^T is singular. */
int swim_constraint_project(int n, int m, const double *G, double *v);

#endif
