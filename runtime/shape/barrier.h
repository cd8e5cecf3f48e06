/* barrier.h -- the barrier W2 of section 4.1.1 and its gradient, accurate at any distance from the
 * boundary of D.
 *
 *   W2(c)   = eps/(2 alpha) int_0^{2 pi} J(c)(e^{i theta})^{-alpha} d theta         (ERRATA B2)
 *   grad W2 = -eps/2 int_0^{2 pi} J^{-1-alpha} grad J d theta                       (ERRATA B3)
 *   J(theta) = |c_1|^2 - |h|^2,  h = sum_{j=0}^{N-1} (j+1) c_{-(j+1)} e^{-i j theta}
 *
 * J is a trigonometric polynomial of degree N-1, so J^{-alpha} is analytic and periodic; its only
 * singularities are the complex zeros of J. Near the boundary of D a pair of zeros a +- i d comes
 * close to the real axis (d ~ sqrt(2 min J / J'')), the integrand has a peak of width d, and the
 * trapezoidal rule needs O(1/d) nodes. Two rules, chosen per call:
 *
 *  1. Nested trapezoidal rule (far from the boundary, the common case). Its error decays like
 *     A Q^s e^{-Q d} (Trefethen & Weideman, SIAM Review 56 (2014), Thm 3.2; the power s from the
 *     algebraic branch points of J^-alpha), so one doubling of Q multiplies the error by about
 *     e^{-Qd} and the next by its square. The rule doubles Q from max(16, 2N), each level reusing
 *     the nodes of the last, and stops at Q >= 36/d + N - 1 (the gradient's factor e^{ik theta},
 *     |k| <= N - 1, aliases as from Q - N + 1 nodes) once the error predicted from the last two
 *     changes (value and gradient) is below 1e-14 relative, or both changes are (rounding).
 *  2. Composite Gauss-Legendre with a priori error control (near the boundary, when Q would exceed
 *     max(512, 16N)). The zeros of J are computed as the roots of z^{N-1} J(z) (eigenvalues of the companion
 *     matrix, LAPACK zhseqr). A panel [u, v] is accepted with q Gauss nodes when every zero lies
 *     outside the Bernstein ellipse of parameter rho = tol^{-1/(2q)} of the panel (Trefethen,
 *     Approximation Theory and Approximation Practice, Thm 19.3), otherwise it is halved; the
 *     gradient's factor e^{ik theta}, |k| <= N - 1, which grows on the ellipse, counts in the
 *     bound too (on long panels far from the zeros it decides). Panels
 *     start at the real parts of the close zeros, so the halving grades them geometrically toward
 *     each peak: the node count grows like log(1/d), i.e. like log(1 / min J) (the graded meshes of
 *     nearly singular boundary-element quadrature, cf. Johnston & Elliott, IJNME 62 (2005)).
 *     Near such a zero, J - J(a) cancels catastrophically in double precision (J = 1e-10 from terms
 *     of size 1), so J(a) and J'(a) are computed in extended precision and J(a + s) = J(a) + J'(a) s +
 *     2 Re sum_p J_p e^{ipa} (e^{ips} - 1 - ips), whose terms are all of the size of the result.
 *
 * Both rules are smooth in c for a fixed node layout; when the layout changes (Q doubles, a panel
 * splits, the rule switches) W2 moves by at most the two rules' errors added: test_barrier bounds
 * each by 1e-12 and measures at most 2.5e-14 relative.
 * alpha = 1/2 and alpha = 1 avoid pow(). Node arrays for 4096 graded nodes are allocated up front;
 * a rule needing more grows them (SWIM_BARRIER_ENOMEM if that fails).
 */
#ifndef SWIM_BARRIER_H
#define SWIM_BARRIER_H

enum {
    SWIM_BARRIER_OK = 0,
    SWIM_BARRIER_OUTSIDE = 1,    /* J <= 0 somewhere on the circle: the shape is not in D (4.1) */
    SWIM_BARRIER_ENOMEM = -1
};

typedef struct {
    int graded;      /* 0: nested trapezoidal rule; 1: graded Gauss-Legendre panels */
    int nodes;       /* nodes used */
    int panels;      /* Gauss panels (graded rule) */
    double dist;     /* graded rule: distance of the closest zero of J from the real axis */
} swim_barrier_info;

typedef struct swim_barrier_quad swim_barrier_quad;   /* tables and workspace for one mode count; owned */

swim_barrier_quad *swim_barrier_quad_new(int modes);   /* NULL when out of memory */
void swim_barrier_quad_free(swim_barrier_quad *b);

/* W2 and (grad != NULL) its gradient, n = 2(N+1) entries in the order of x, at shape x.
 * eps > 0, alpha > 0. Returns SWIM_BARRIER_OK, SWIM_BARRIER_OUTSIDE (then *W = +inf, grad
 * untouched) or SWIM_BARRIER_ENOMEM. info may be NULL. */
int swim_barrier_w2(swim_barrier_quad *b, const double *x, double eps, double alpha, double *W,
                      double *grad, swim_barrier_info *info);

/* The same at the shape x + lo, where lo holds what x lost to rounding (|lo_i| <= ulp(x_i)/2; the
 * integrator carries the shape relative to an origin near the boundary of D, so x = origin + u
 * rounds). Only the extended-precision values of J at the feet of the graded rule read lo: J there is
 * |c_1|^2 - |h|^2 ~ 1e-10 from terms of size 1, and the rounding of x alone would move it by
 * 1e-16 -- W2 by kappa 1e-16 / min J, more than rtol of the energy in a deep bounce at
 * alpha = 1/2. Elsewhere the rounding of x is harmless (relative 1e-16 of J). */
int swim_barrier_w2_carry(swim_barrier_quad *b, const double *x, const double *lo, double eps, double alpha,
                          double *W, double *grad, swim_barrier_info *info);

/* How deep into the barrier an approach must go to be stopped: the minimum of J at which W2 has
 * risen by `energy` above its value at x, when J keeps its shape near its minimum and only moves
 * down (J - s: exactly what scaling c_1 does, J = |c_1|^2 - |h|^2). Near the minimum j0 the
 * integral behaves like s^(1/2 - alpha), a logarithm for alpha = 1/2, so with
 * kappa = -dW2/d ln j0 = j0 (eps/2) int J^(-1-alpha) (from the gradient, ERRATA B3)
 *     s = j0 (1 + energy (alpha - 1/2) / kappa)^(-1/(alpha - 1/2)),   s = j0 e^(-energy/kappa) at 1/2.
 * For alpha = 1/2 the barrier rises only by kappa per e-fold of min J: an approach carrying more
 * than about 36 kappa of energy needs min J below double-precision resolution. An asymptotic
 * estimate, good when j0 is small (test_barrier checks it against W2 along the exact path).
 * kappa may be NULL. Returns NAN when x is outside D or out of memory. */
double swim_barrier_reach(swim_barrier_quad *b, const double *x, double eps, double alpha,
                          double energy, double *kappa);

/* W2, its gradient and its Hessian (n x n, row-major, exactly symmetric) at shape x, on the node
 * layout swim_barrier_w2 chooses there (the exact Jacobian of the equations of motion):
 *   hess W2 = eps/2 int [(alpha+1) J^{-alpha-2} grad J grad J^T - J^{-alpha-1} hess J] d theta,
 * hess J constant per node. grad may not be NULL. Returns as swim_barrier_w2 (hess untouched
 * unless SWIM_BARRIER_OK). */
int swim_barrier_hessian(swim_barrier_quad *b, const double *x, double eps, double alpha,
                         double *W, double *grad, double *hess, swim_barrier_info *info);

#endif
