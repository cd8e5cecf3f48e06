/* stroke.h -- a prescribed stroke: the swimmer as a shape-controlled robot (section 3.3).
 *
 * The scene's [stroke] table gives some shape coordinates as laws in t (the generated stroke
 * kernel, kernel/stroke_kernel.h, returns them with their exact first and second derivatives);
 * every other coordinate stays at its c0 value, except c1 when neither a1 nor b1 is prescribed:
 * it is then completed so that the stroke is allowable (Definition 2.2),
 *   |c1|^2 = mu^2 + sum_{m>=1} m |c_-m|^2                              the volume (2.5),
 *   c1 = |c1| e^{i psi},  psi' = -2/|c1|^2 sum_{m>=1} (b'_-m a_-m - a'_-m b_-m)/(m+1)   (2.14),
 * with psi integrated alongside the rigid motion, mu^2 and psi(0) from the shape at t = 0.
 * Only (3.21) is integrated: q' = R(theta) q*, q* = -Mr^-1 N c' (P = -Mr^-1 N from the kernel of
 * N modes, `reduced`).
 *
 * Energy: with the shape prescribed the body must exert the internal force
 * F = K c'' + <Gamma(c), c', c'> - sum_j lambda_j G_j ((4.10) without W, D, F(t)); its power on an
 * allowable stroke (G c' = 0) is P = c'.(K c'' + <Gamma, c', c'>) = dE/dt, E = 1/2 c'^T K c'.
 * The state carries work = int P dt (so that E - E0 - work checks the power). The positive work
 * int max(P, 0) dt (what the body spends if it cannot recover energy) is not integrated: its
 * integrand has a kink wherever P changes sign, which would cost an Adams code its order (and
 * its accuracy on every component). Since P = dE/dt it is the sum of the rises of E over the
 * intervals where P > 0: swim_stroke_poswork_add samples P along the run and sums E's rises
 * between the located zeros of P (an error d in a zero changes the sum by O(d^2): P = 0 there).
 *
 * State y (SWIM_STROKE_DIM): r_1, r_2, theta (fixed frame), psi (phase of c1; constant when c1
 * is not completed), work.
 */
#ifndef SWIM_STROKE_H
#define SWIM_STROKE_H

#include "kernel/stroke_kernel.h"
#include "kernel/swim_kernel.h"
#include "scene/scene.h"

enum { SWIM_STROKE_PSI = 3, SWIM_STROKE_WORK = 4, SWIM_STROKE_DIM = 5 };

/* Equal steps of the allowability check over [0, t_end] (besides the output times), and samples
 * per stroke period of the positive work (swim_stroke_poswork_add): every caller that runs a
 * stroke (swim run, swim optimize) uses the same. */
#define SWIM_STROKE_CHECK_SAMPLES 16384
#define SWIM_STROKE_POSWORK_SAMPLES 512

/* Right-hand-side codes beyond the SWIM_RHS_* ones (returned positive, see ode.h). */
enum { SWIM_STROKE_EVOLUME = 16,    /* |c1|^2 = mu^2 + sum m|c_-m|^2 <= 0: no c1 keeps the volume */
       SWIM_STROKE_EINTERRUPT };    /* a stop was requested (returned negative: fatal) */
const char *swim_stroke_strerror(int code);

typedef struct {
    const swim_scene *scene;         /* borrowed */
    const swim_kernel *k;            /* kernel of N modes (borrowed) */
    const swim_stroke_kernel *law;   /* the laws (borrowed) */
    const double *par;               /* values of the laws' parameters (law->nparams; none yet) */
    int n;
    int complete;                    /* c1 completed (scene->stroke_complete_c1) */
    double mu2;                      /* area constant (2.5) of the stroke */
    double psi0;                     /* phase of c1 at t = 0 */
    double base[SWIM_NMAX];          /* values of the coordinates that are not prescribed (c0) */
    double *K, *P, *g;               /* workspace (owned) */
    volatile int *interrupt;         /* set asynchronously to stop (may be NULL) */
    long rhs_calls;
    double rhs_seconds, last_rhs_t;
} swim_stroke;

/* mu^2 and psi(0) from the shape at t = 0 (the laws there, c0 elsewhere). 0; SWIM_RHS_ENAN when a
 * law is not finite at 0; SWIM_STROKE_EVOLUME when c1 is to be completed but is 0 in c0 (its
 * phase is undefined); -1 out of memory. */
int swim_stroke_init(swim_stroke *st, const swim_scene *s, const swim_kernel *k, const swim_stroke_kernel *law,
                     const double *par);
void swim_stroke_free(swim_stroke *st);

/* The whole shape at t (with psi, the phase of c1 when completed): c, c', c'' (full length n)
 * and psi'. 0, SWIM_RHS_ENAN or SWIM_STROKE_EVOLUME. */
int swim_stroke_shape(const swim_stroke *st, double t, double psi, double *c, double *dc, double *ddc, double *dpsi);

void swim_stroke_initial_state(const swim_stroke *st, double *y);
/* (3.21), psi' and the power, in the form of swim_ode_func (params = swim_stroke *). */
int swim_stroke_rhs(double t, const double *y, double *dydt, void *params);
/* The state of model/dynamics.h at t (r, theta, c, c', work: 3 + 2n + 1) for the diagnostics,
 * and the power P (may be NULL). 0 or an RHS code. */
int swim_stroke_full_state(swim_stroke *st, double t, const double *y, double *full, double *power);

/* E = 1/2 c'^T K c' and P = c'.(K c'' + <Gamma, c', c'>) at t with phase psi. 0 or an RHS code. */
int swim_stroke_energy_power(swim_stroke *st, double t, double psi, double *E, double *P);

/* The positive work int max(P, 0) dt accumulated over samples t_0 < t_1 < ... of a run (psi at
 * each sample from the integrator): between two samples, E's rise where P > 0, with a zero of P
 * located by bisection (psi interpolated by cubic Hermite from psi and psi' at the samples).
 * Samples must be close enough that P changes sign at most once between two of them. */
typedef struct {
    int have;                  /* a previous sample exists */
    double t, psi, dpsi, E, P; /* the previous sample */
    double total;              /* int_0^t max(P, 0) dt */
} swim_stroke_poswork;
int swim_stroke_poswork_add(swim_stroke *st, swim_stroke_poswork *w, double t, double psi);

/* Allowability over [0, t_end] at `samples` equal steps and at every output time: (2.8), (2.14)
 * and the volume (2.5) to round-off (relative 1e-10 of the terms' size), the laws finite, and the
 * shape in D (4.1) at every 8th step and at ~2048 of the output times (all when there are fewer;
 * the run checks min J on every row). 0 when it holds; otherwise 1 with the first failing time in *t_bad and what
 * failed (one phrase with the values) in why. */
int swim_stroke_check(const swim_stroke *st, double t_end, double output_step, long samples, double *t_bad,
                      char *why, size_t whylen);

/* The smallest T in (0, t_end] after which the prescribed laws repeat (c and c' as at t = 0 and
 * at 16 points of [0, T]), or 0 when there is none. Found on 4096 samples, then refined to
 * round-off by bisection on the derivative of |c(T) - c(0)|^2 + |c'(T) - c'(0)|^2. */
double swim_stroke_detect_period(const swim_stroke *st, double t_end);

#endif
