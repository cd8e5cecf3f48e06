/* periodic.h -- a periodic orbit of the shape dynamics by Newton shooting (swim periodic).
 *
 * Unknowns: the shape state z = (c_carried, cdot_carried) at a phase point and the period T.
 * Equations: the orbit closes, phi_T(z) - z = 0, with phi the flow of the scene's equations
 * (its integrator and drift control, at a tight tolerance); a phase condition that fixes the
 * point along the orbit, f(z_k) . (z - z_k) = 0 (the correction orthogonal to the flow); and,
 * for a conservative scene (no damping, no forcing), the energy held at a target, E(z) - E* = 0
 * with E* the guess's energy (swim periodic) or the branch's value (swim continue), as the
 * bordered row grad E(z_k) . dz = E* - E(z_k) -- a conservative system has a family of orbits by
 * energy, so closing alone does not pick one, and the linearized row alone (dE = 0 at each step)
 * lets the iterates drift along the family (a libration from rest at E = 0.3 ended as a rotation
 * at 0.544). A step is taken when it lowers the larger of the closing residual and the energy's
 * relative miss; an orbit that cannot be closed at E* is refused, saying that it left the
 * energy. The corrections stay on the constraint manifold
 * {mu^2(c) = mu^2(c0), G1 cdot = 0, G2 cdot = 0}: dz = B u with B an orthonormal basis of its
 * tangent space (control/floquet.h), and z is put back on the manifold after each step
 * (model/dynamics.h, swim_dynamics_project). The Newton matrix [(M - I) B, f; f^T B, 0;
 * grad E^T B, 0] uses the monodromy M of the variational equations (swim_floquet_at); it is
 * solved in the least-squares sense (LAPACK dgelsd), which also copes with the rank a symmetry
 * takes away. A step that does not lower the residual is halved (at most 8 times).
 *
 * The guess: the state at the first event of the section (e.g. am1:max) of a plain run from the
 * scene's initial state, and the time to the section's count-th event after it (am1:max:2: a
 * libration beyond 90 degrees passes the maximum of a coordinate that goes as the sine of its
 * angle twice per period).
 *
 * Converged when max |phi_T(z) - z| <= tol * max(max |z|, atol). Then the displacement and
 * rotation per period (Delta x, Delta y, Delta theta: the rigid motion over [0, T] from
 * q = 0, i.e. in the body frame at the phase point), the energy and the Floquet multipliers at
 * the phase point (swim_floquet_at, based there) are computed.
 */
#ifndef SWIM_CONTROL_PERIODIC_H
#define SWIM_CONTROL_PERIODIC_H

#include <stdio.h>

#include "control/floquet.h"
#include "problem/problem.h"
#include "model/dynamics.h"

#define SWIM_PERIODIC_MAX_ITER 40

typedef struct {
    double tol;                    /* on the residual relative to the state's scale (1e-11) */
    int max_iter;                  /* Newton iterations (20) */
    double rtol, atol;             /* of the flow map phi_T (1e-12, 1e-14) */
    double t_max;                  /* how long the guess run looks for two events */
    const char *cmd;               /* messages "swim CMD: ..." (NULL: periodic) */
    const char *t_max_from;        /* what the user sets t_max with, for the remedy when the guess
                                    * finds no period (NULL: --t-max) */
    void (*progress)(void *ctx, int iteration, double residual, double period);   /* after each Newton
                                    * iterate's residual (NULL: none) */
    void *progress_ctx;
    const signed char *hold_zero;  /* n2 flags: entries of the shape state held at 0 -- an invariant
                                    * subspace the orbit stays in (swim_periodic_invariant_zeros) --
                                    * or NULL */
} swim_periodic_options;

typedef struct {
    double residual;               /* max |phi_T(z) - z| / scale before this iteration's step */
    double merit;                  /* the residual, or with a target energy the larger of it and
                                    * |E - E_target| / |E_target| */
    double period;
    double step;                   /* max |dz| of the step taken (after halving) */
    double energy;
    int halvings;
} swim_periodic_iteration;

typedef struct {
    int converged;
    int stopped;                   /* the value of d->interrupt when the caller stopped the work (a
                                    * signal number for swim periodic/continue), else 0: the last
                                    * iterate and its residual are kept, never called converged */
    const char *why;               /* why not (static text or why_text), NULL when converged */
    char why_text[512];
    int iterations;
    swim_periodic_iteration history[SWIM_PERIODIC_MAX_ITER + 1];
    double t_guess, period_guess;  /* the guess: first event and time to the section's count-th after it */
    int section_events;            /* the count: events of the section per period (0: no section, a refine) */
    double period;
    double residual;               /* relative, as in the history */
    double scale;
    int n2;                        /* shape state dimension */
    double z[SWIM_FLOQUET_MAX];    /* the shape state at the phase point */
    double dx, dy, dtheta;         /* rigid motion per period, from q = 0 */
    double energy;
    double energy_target;          /* the energy held (NAN: none) */
    int conservative;              /* the energy row was used */
    swim_floquet floquet;          /* at the phase point (converged only; free with swim_periodic_free) */
    int have_floquet;
    long rhs_calls;
    double seconds;
} swim_periodic;

/* The orbit of d's scene from the guess of section sec. 0 (converged or not: see converged and
 * why), or 1 with the cause in st, "swim CMD: ..." (no guess: fewer than two events; an
 * integration or allocation failure). */
int swim_periodic_solve(swim_dynamics *d, const swim_floquet_section *sec, const swim_periodic_options *o,
                        swim_periodic *out, swim_status *st);
/* A scene made ready for orbits (swim periodic, swim continue): read with its overrides, refused
 * in one line when it has no free autonomous shape dynamics (a [stroke], a [forcing] law) or an
 * integrator that cannot locate the guess's events, its kernels, and the guess's section
 * (guess: COLUMN:KIND or NULL, as swim_floquet_parse_section; its text into text). 0, or 1 / 2
 * with the cause in st ("swim CMD: ..."), with m closed; kernel notices go to st's note. */
int swim_periodic_setup(swim_problem *m, const char *cmd, const char *path, const swim_override *sets, int nsets,
                        int generic, int quiet, const char *guess, swim_floquet_section *sec, char *text, size_t len,
                        swim_status *st);
/* The scene s (of file path) has free autonomous shape dynamics whose events its integrator
 * locates: 0, or 2 with the cause in st (a [stroke], a [forcing] law, an integrator without
 * events). */
int swim_periodic_check(const swim_scene *s, const char *cmd, const char *path, swim_status *st);
/* No forcing and no damping on a moving coordinate: energy is conserved (1) or not (0). */
int swim_periodic_conservative(const swim_dynamics *d);
/* Newton from the integrator state ys0 (its shape part; the rest is set to 0) and period T0:
 * with energy_target finite (a conservative scene) the orbit of that energy, otherwise the one
 * through ys0's energy. Same results and status as swim_periodic_solve (t_guess is 0). */
int swim_periodic_refine(swim_dynamics *d, const double *ys0, double T0, double energy_target,
                         const swim_periodic_options *o, swim_periodic *out, swim_status *st);
/* The invariant subspace a converged orbit p lies in, as the entries of the shape state that are 0
 * on it: each such entry is 0 at the phase point (to 1e-10 of the state's scale), so is its rate
 * there (the flow f), and the monodromy does not feed the other entries into it (|M_ij| <= 1e-7
 * max |M| for i held, j not): a mirror symmetry's fixed set, e.g. b_-1 = a_-2 = 0 for Example 3.
 * Flags into hold (n2 entries); the number held (0 when none or no Floquet data). */
int swim_periodic_invariant_zeros(const swim_periodic *p, signed char *hold);
void swim_periodic_free(swim_periodic *p);
/* DIR/periodic.json: names are the carried coordinates (d's spec). */
void swim_periodic_json(FILE *f, const swim_periodic *p, const swim_dynamics *d, const char *scene,
                        const char *section);

#endif
