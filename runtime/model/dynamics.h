/* dynamics.h -- the ODE of sections 4-5 in first-order form, and the diagnostics of a state.
 *
 * The equations themselves are generated (runtime/codegen: a scene kernel, whose right-hand
 * side is runtime/kernel/scene_rhs.h around SymPy's expressions); this module wires them to the
 * integrator: state packing, the barrier quadrature they call back, drift control after each
 * step, and the diagnostics of an output row (energies, impulses, residuals, min J), which use
 * the kernel of N modes.
 *
 * State y (dimension 3 + 2n + 1):
 *   y[0..2]      q = (r_1, r_2, theta): centre of mass and orientation in the fixed frame
 *   y[3..3+n)    c: shape coordinates (a_1, b_1, a_-1, b_-1, ..., a_-N, b_-N)
 *   y[3+n..3+2n) cdot
 *   y[3+2n]      work = int_0^t (F . cdot - cdot^T D cdot) dt, so that E(t) - E(0) = work (5.3)
 * Equations:
 *   K c'' + <Gamma(c), c', c'> + grad W = sum_j lambda_j G_j - D c' + F(t)      (4.10), (4.15), (5.2)
 *   with lambda from the symmetric system (4.12) (ERRATA C2, C3), and
 *   q' = R(theta) q*,  q* = -Mr^-1 N c'                                         (3.20)-(3.21)
 *   W = W1 + W2 (+ W_law), W1 = 1/2 (c - cref)^T R (c - cref) (ERRATA E2), W2 of section 4.1.1,
 *   W_law = int_D U(I1, J) dz of an [elastic] energy law (ERRATA B5, the scene kernel's).
 * Units: lengths in units of the reference radius, densities rho0, rhof as given; time as in
 * the paper's scenes.
 */
#ifndef SWIM_DYNAMICS_H
#define SWIM_DYNAMICS_H

#include "io/clock.h"
#include "scene/scene.h"
#include "shape/barrier.h"
#include "shape/shape.h"

/* Values returned by the right-hand side (passed through the integrator); the first five are
 * the SWIM_RHS_* codes that scene kernels return too. They are returned positive -- the state is
 * outside the domain of the equations, so the integrator may retry with a smaller step (see
 * swim_ode_func) -- except the interrupt, returned as -SWIM_DYN_EINTERRUPT (fatal). */
enum {
    SWIM_DYN_OK = SWIM_RHS_OK,
    SWIM_DYN_ENAN = SWIM_RHS_ENAN,               /* NaN or Inf in the state or its derivative */
    SWIM_DYN_EBARRIER = SWIM_RHS_EBARRIER,       /* the shape left D: J <= 0 at a quadrature node of the
                                                    barrier, or (no barrier) min J <= 0 */
    SWIM_DYN_EMASS = SWIM_RHS_EMASS,             /* K (or Mr) not positive definite */
    SWIM_DYN_ECONSTRAINT = SWIM_RHS_ECONSTRAINT, /* multiplier system (4.12) singular */
    SWIM_DYN_EINTERRUPT                          /* an interrupt was requested (SIGINT) */
};
const char *swim_dynamics_strerror(int code);

typedef struct {
    const swim_scene *scene;     /* borrowed */
    const swim_kernel *k;        /* kernel of N modes (borrowed): diagnostics, flow pictures */
    const swim_scene_kernel *spec;   /* the right-hand side (borrowed); set before integrating */
    int generic;                 /* spec carries every coordinate, locks by multipliers */
    swim_scene_params spec_params;
    int n, dim, m;               /* shape coordinates, full state dimension, constraint rows */
    swim_barrier_quad *barrier;  /* quadrature of W2 for the right-hand side (owned; NULL without a barrier) */
    swim_barrier_quad *diag_barrier; /* the same for diagnostics: its warm start is its own, so
                                    rows and traces never change the right-hand side's rounding */
    double *gbar;                /* full gradient of W2 (owned) */
    volatile int *interrupt;     /* set asynchronously to stop (may be NULL) */
    /* workspace (owned) */
    double *K, *P, *G, *proj;
    /* statistics */
    long rhs_calls, projections;
    double max_projection;       /* largest change made by swim_dynamics_project */
    swim_clock_sample rhs_time;  /* the right-hand side's time, sampled (swim_dynamics_rhs_seconds) */
    double last_rhs_t;
    /* W2 of the barrier's last evaluation by the right-hand side, at shape w2_x (swim_dynamics_w2) */
    int w2_valid;
    double w2_last, w2_x[2 * (SWIM_KERNEL_MAX_MODES + 1)];
    long jac_calls;              /* exact Jacobians (swim_dynamics_jacobian) */
    /* Quadratures of W2 for evaluations aside from the run's own (swim_dynamics_set_aside), or NULL */
    swim_barrier_quad *aside_barrier, *aside_diag;
    double jac_seconds;
    /* Origin of the integrator state (swim_dynamics_set_origin), or NULL. */
    double *origin;              /* packed, state_dim entries (owned) */
    double *hi;                  /* workspace: origin + u as doubles (owned) */
    double x_lo[2 * (SWIM_KERNEL_MAX_MODES + 1)];   /* full shape: what origin + u lost to rounding */
    int lo_valid;                /* x_lo belongs to the evaluation under way */
    double t_origin;             /* the integrator's time is t - t_origin (0 unless the caller shifts it) */
    /* The energy balance at the state of the last successful right-hand side, which computed its
     * kinetic energy and W2 anyway (swim_dynamics_track_balance, swim_dynamics_balance). */
    int bal_track, bal_valid;
    double bal_kinetic, bal_u[4 + 4 * (SWIM_KERNEL_MAX_MODES + 1)];
    /* B at bal_u once computed from those by-products (the integrator's error test asks first,
     * the check at the step end then again): valid while bal_valid is, cleared with it */
    int bal_memo;
    double bal_memo_b;
    /* The last projection: its output and what it changed (packed), for the balance's noise. */
    int proj_valid;
    double proj_out[4 + 4 * (SWIM_KERNEL_MAX_MODES + 1)], proj_delta[4 + 4 * (SWIM_KERNEL_MAX_MODES + 1)];
    /* Fixed by the scene, for the projection at every step: mu0^2 = sum k |c0_k|^2 (2.5), the
     * free coordinates (scene->free_mask) ascending and how many there are. */
    double mu0;
    int free_at[2 * (SWIM_KERNEL_MAX_MODES + 1)], nfree;
    /* the kernel carries other coordinates than free_at (it may move locked ones), set with it */
    int carries_locked;
} swim_dynamics;

/* k: the kernel of N = scene->modes modes. 0, or -1 (out of memory). */
int swim_dynamics_init(swim_dynamics *d, const swim_scene *scene, const swim_kernel *k);
void swim_dynamics_free(swim_dynamics *d);
void swim_dynamics_initial_state(const swim_dynamics *d, double *y);

/* The right-hand side to integrate: the integrator's state is then (q, c_carried, cdot_carried,
 * work); `generic` says that it carries every coordinate and holds locks by multipliers. */
void swim_dynamics_use_scene_kernel(swim_dynamics *d, const swim_scene_kernel *spec, int generic);
int swim_dynamics_state_dim(const swim_dynamics *d);
/* Full state (dim) <-> integrator state (state_dim). With an origin the integrator state is
 * u = (packed full) - origin; unpack rounds origin + u to doubles. */
void swim_dynamics_pack(const swim_dynamics *d, const double *full, double *state);
void swim_dynamics_unpack(const swim_dynamics *d, const double *state, double *full);

/* Shifted coordinates near the boundary of D. A shape coordinate held as a double is rounded by
 * ~1e-16 at every step, which moves J = |c_1|^2 - |h|^2 by ~1e-16 and the barrier energy by
 * kappa 1e-16 / min J: at alpha = 1/2, where a bounce goes down to min J ~ 1e-11, that is 1e-6 of
 * the energy per step, a random walk no tolerance can control. Relative to an origin taken at the
 * approach, the integrator carries u = y - origin, which stays as small as the motion since the
 * origin (~1e-4 over a bounce), so its rounding is ~1e-20; the right-hand side evaluates the
 * kernel at origin + u rounded (harmless for every term but J near its zeros) and gives the
 * barrier the exact remainder (shape/barrier.h, swim_barrier_w2_carry). The projection applies
 * its corrections to u. Nothing changes without an origin.
 *
 * Time needs the same: a bounce to min J ~ 1e-14 turns in ~1e-14 of time, below the resolution
 * of t itself (4e-16 at t = 2), so the caller may start the integrator at a time relative to
 * d->t_origin, which the right-hand side adds back (forcing laws see the absolute time).
 *
 * set_origin(d, origin): from now on the integrator state is relative to origin (packed,
 * state_dim; copied); NULL: absolute again. Callers convert their state themselves
 * (swim_dynamics_rebase). 0, or -1 when out of memory. */
int swim_dynamics_set_origin(swim_dynamics *d, const double *origin);
/* Move the origin to the current state exactly: origin' + u' = origin + u with origin' = origin + u
 * rounded and u' its rounding error (TwoSum), so no bit of the state is lost. `u` is updated in
 * place. Without an origin the origin becomes u and u becomes 0. `clear`: instead drop the origin
 * and leave the rounded absolute state in u. 0 or -1 (out of memory). */
int swim_dynamics_rebase(swim_dynamics *d, double *u, int clear);
/* min J of the shape of integrator state u, at the angle *theta (may be NULL): with an origin and
 * J small, evaluated at origin + u exactly (shape.h, swim_shape_j_precise), where the rounded
 * shape would give J to 1e-16 only -- 0 or below at the bottom of a deep bounce. */
double swim_dynamics_jmin(const swim_dynamics *d, const double *u, double *theta);
/* The same with u already unpacked into full (swim_dynamics_unpack): the checks at every step
 * have it at hand. */
double swim_dynamics_jmin_unpacked(const swim_dynamics *d, const double *u, const double *full, double *theta);

/* Drift control: (2.8) is enforced by (4.12) only at the acceleration level, so the
 * volume and the velocity constraints drift with the integration error. After each accepted
 * step the integrator calls this (swim_ode_options.project): it restores the locks exactly, puts
 * c back on the volume manifold sum_k k|c_k|^2 = mu0^2 by Newton steps along its gradient 2 G1,
 * and removes the components of cdot along G1 and G2 (l2-orthogonal projection, as for the initial
 * data in ERRATA D5). The corrections are of the size of the local error. */
int swim_dynamics_project(double t, double *y, void *params);

/* The right-hand side on the integrator's state, in the form of swim_ode_func
 * (params = swim_dynamics *); needs swim_dynamics_use_scene_kernel first. */
int swim_dynamics_rhs(double t, const double *y, double *dydt, void *params);
/* Seconds spent in swim_dynamics_rhs so far (estimated from a sample of the calls, io/clock.h). */
double swim_dynamics_rhs_seconds(const swim_dynamics *d);

/* The exact Jacobian of swim_dynamics_rhs (the scene kernel's, kernel/scene_rhs.h), in the form
 * of swim_ode_jacobian; the barrier's Hessian comes from shape/barrier.h on the nodes of its
 * gradient. */
/* The energy balance B = E - work at the packed state u (E = kinetic + W1 + W2, the energy of
 * the rows; work = the state's last component, the integral of the power of damping and
 * forcing): constant along exact solutions, so abm controls its local error too
 * (swim_ode_options.invariant). With tracking on, the right-hand side keeps its kinetic energy and
 * W2, and B at the state it has just evaluated costs O(n) instead of a mass matrix and a barrier
 * quadrature; at any other state it is computed in full. noise (may be NULL) receives an estimate
 * of what rounding leaves of B there. NAN where the state is outside the domain. */
void swim_dynamics_track_balance(swim_dynamics *d, int on);
double swim_dynamics_balance(double t, const double *u, double *noise, void *params);
int swim_dynamics_jacobian(double t, const double *y, double *J, void *params);
/* The same Jacobian (J may be NULL) and the exact partials of the right-hand side with respect
 * to np run-time parameters (kernel/swim_kernel.h, swim_param): dp[k * dim + i], dim the state
 * dimension. Same return values as swim_dynamics_jacobian. */
int swim_dynamics_jacobian_params(swim_dynamics *d, double t, const double *y, double *J, int np,
                                  const swim_param *param, double *dp);
/* The barrier's quadrature keeps the roots of its last call as the start of the next (a warm
 * start), so the right-hand side's and the diagnostics' last bits depend on what was evaluated
 * before them. Evaluations aside from a run's own -- the variational equations' Jacobians between
 * its right-hand sides, the sensitivities' energy diagnostics between its rows -- get quadratures
 * of their own: after this call swim_dynamics_jacobian_params and swim_dynamics_diagnostics_aside
 * use them, and the run's evaluations are bit for bit those without the others. 0, or -1 out of
 * memory. Nothing changes without a barrier. */
int swim_dynamics_set_aside(swim_dynamics *d);

typedef struct {
    double kinetic_fluid, kinetic_shape, kinetic_rigid, w1, w2, energy, work;
    double impulse_body[3], impulse_fluid_rigid[3], impulse_fluid_shape[3];  /* fixed frame, (3.19) */
    double res_volume, res_volume_rate, res_angular, res_locks;
    double jmin;
    double rigid_velocity[3];   /* q* in the body frame */
    double w_law;               /* the energy law's W = int_D U dz ([elastic] energy), else 0 */
} swim_diag;

/* The energy law's W at the full shape c: 0 without one, NAN where it is not finite. */
double swim_dynamics_w_law(const swim_dynamics *d, const double *c);

/* W2 at the full shape c (0 without a barrier; INFINITY outside D). The right-hand side computes
 * W2 with its gradient: when its last barrier evaluation was at this very shape (ABM's final
 * evaluation at an accepted state) that value is returned instead of a second quadrature. */
double swim_dynamics_w2(swim_dynamics *d, const double *c);

/* Diagnostics at state y; c0 is the initial shape (for the lock and volume residuals). */
int swim_dynamics_diagnostics(swim_dynamics *d, const double *y, swim_diag *out);
/* The same, on the quadrature aside (swim_dynamics_set_aside) when there is one. */
int swim_dynamics_diagnostics_aside(swim_dynamics *d, const double *y, swim_diag *out);

#endif
