/* Event location on the integrator's interpolant (see ode.h, "Events").
 *
 * After each accepted step [ta, tb] every event function is evaluated at tb and
 * its sign class (g >= 0 or g < 0) compared with the one at the previous step
 * end.  The value at the previous end is kept from the previous step rather
 * than recomputed on the new interpolant: the two interpolants differ there by
 * the local error, and a sign taken from each could make a crossing vanish or
 * count twice.  A crossing is located on the new step's interpolant by the
 * Illinois algorithm (regula falsi whose retained end value is halved when the
 * same end is kept twice in a row, which restores superlinear convergence;
 * Dowell & Jarratt, BIT 11 (1971) 168), with a bisection whenever two steps
 * in a row failed to halve the bracket.  The iteration ends when the bracket
 * is below the tolerance; the reported time is the end of the bracket on the
 * new side of the crossing. */
#include "ode/events.h"

#include <float.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#define ROOT_MAXIT 200

struct ode_events {
    size_t n, m;              /* state dimension, number of events */
    swim_ode_event *ev;       /* the events (copied) */
    void (*on_event)(const swim_ode_event_hit *hit, void *data);
    void *on_event_data;
    const volatile int *event_stop;   /* swim_ode_options.event_stop */
    double tol;               /* bracket width that ends the root finder */
    double *gprev;            /* g at the previous step end (NAN: unknown) */
    double *gnew;             /* g at this step end */
    double *y, *yp;           /* interpolant values at the current trial time */
    double *ystop;            /* state at a terminal event */
    int have_prev;            /* gprev holds values */
    long evals, found;        /* event-function evaluations, events located */
};

/* 1: g >= 0, 0: g < 0, -1: no sign (NaN). */
static int sign_class(double g) { return isnan(g) ? -1 : g >= 0.0; }

ode_events *ode_events_create(size_t n, const swim_ode_options *opt)
{
    ode_events *e = calloc(1, sizeof *e);
    if (!e)
        return NULL;
    e->n = n;
    e->m = opt->nevents;
    e->ev = malloc(e->m * sizeof *e->ev);
    e->gprev = malloc((2 * e->m + 3 * n) * sizeof(double));
    if (!e->ev || !e->gprev) {
        ode_events_free(e);
        return NULL;
    }
    memcpy(e->ev, opt->events, e->m * sizeof *e->ev);
    e->gnew = e->gprev + e->m;
    e->y = e->gnew + e->m;
    e->yp = e->y + n;
    e->ystop = e->yp + n;
    e->on_event = opt->on_event;
    e->on_event_data = opt->on_event_data;
    e->event_stop = opt->event_stop;
    e->tol = opt->event_tol > 0 ? opt->event_tol : 1e-13;
    return e;
}

void ode_events_free(ode_events *e)
{
    if (!e)
        return;
    free(e->ev);
    free(e->gprev);
    free(e);
}

/* g_i on the interpolant at t. */
static double eval_at(ode_events *e, const ode_backend *be, void *impl, size_t i, double t)
{
    if (be->dense(impl, t, e->y, e->yp))
        return NAN;
    e->evals++;
    return e->ev[i].g(t, e->y, e->yp, e->ev[i].data);
}

/* The crossing of g_i in [ta, tb], where g_i(tb) = gb has the new sign class. */
static double locate(ode_events *e, const ode_backend *be, void *impl, size_t i, double ta, double tb, double gb)
{
    const int sb = sign_class(gb);
    double a = ta, b = tb, fb = gb;
    double fa = eval_at(e, be, impl, i, a);
    if (sign_class(fa) != 1 - sb)
        return ta;   /* the new interpolant has the new sign at ta already: the crossing is at ta */
    int side = 0, slow = 0;
    double width = b - a;
    for (int it = 0; it < ROOT_MAXIT; it++) {
        double tol = fmax(e->tol, 4.0 * DBL_EPSILON * fmax(fabs(a), fabs(b)));
        if (b - a <= tol)
            break;
        double c;
        if (slow >= 2) {
            c = 0.5 * (a + b);
            slow = 0;
        } else {
            c = (a * fb - b * fa) / (fb - fa);
            if (!(c > a && c < b))
                c = 0.5 * (a + b);
        }
        double fc = eval_at(e, be, impl, i, c);
        int sc = sign_class(fc);
        if (sc < 0) {                 /* no sign: shrink towards the known side by bisection */
            c = 0.5 * (a + b);
            fc = eval_at(e, be, impl, i, c);
            sc = sign_class(fc);
            if (sc < 0)
                break;
        }
        if (sc == sb) {
            b = c;
            fb = fc;
            if (side == -1)
                fa *= 0.5;
            side = -1;
        } else {
            a = c;
            fa = fc;
            if (side == 1)
                fb *= 0.5;
            side = 1;
        }
        double w = b - a;
        slow = w > 0.5 * width ? slow + 1 : 0;
        if (!slow)
            width = w;
    }
    return b;
}

typedef struct {
    double t;
    size_t i;
    int rising;
} hit_rec;

int ode_events_step(ode_events *e, const ode_backend *be, void *impl, double ta, double tb, double *t_stop,
                    const double **y_stop)
{
    *t_stop = NAN;
    *y_stop = NULL;
    if (!e->have_prev) {
        /* g = 0 exactly at the initial point gives no sign to leave: no event there (as ode113) */
        for (size_t i = 0; i < e->m; i++) {
            double g = eval_at(e, be, impl, i, ta);
            e->gprev[i] = g == 0.0 ? NAN : g;
        }
        e->have_prev = 1;
    }
    for (size_t i = 0; i < e->m; i++)
        e->gnew[i] = eval_at(e, be, impl, i, tb);
    /* crossings of this step, in time order (few: insertion sort) */
    hit_rec stack[16], *hits = stack;
    if (e->m > 16 && !(hits = malloc(e->m * sizeof *hits)))
        return SWIM_ODE_ENOMEM;
    size_t nh = 0;
    for (size_t i = 0; i < e->m; i++) {
        int sa = sign_class(e->gprev[i]), sb = sign_class(e->gnew[i]);
        if (sa < 0 || sb < 0 || sa == sb)
            continue;
        int rising = sb == 1;
        int dir = e->ev[i].direction;
        if ((dir > 0 && !rising) || (dir < 0 && rising))
            continue;
        double t = locate(e, be, impl, i, ta, tb, e->gnew[i]);
        size_t j = nh++;
        while (j > 0 && hits[j - 1].t > t) {
            hits[j] = hits[j - 1];
            j--;
        }
        hits[j] = (hit_rec){t, i, rising};
    }
    memcpy(e->gprev, e->gnew, e->m * sizeof(double));
    int rc = SWIM_ODE_OK;
    for (size_t h = 0; h < nh; h++) {
        if (be->dense(impl, hits[h].t, e->y, e->yp)) {
            rc = SWIM_ODE_EFAIL;
            break;
        }
        const swim_ode_event *ev = &e->ev[hits[h].i];
        swim_ode_event_hit hit = {(int)hits[h].i, hits[h].t, e->y, e->yp, hits[h].rising, ev->terminal != 0};
        e->found++;
        if (e->on_event)
            e->on_event(&hit, e->on_event_data);
        if (ev->terminal || (e->event_stop && *e->event_stop)) {
            memcpy(e->ystop, e->y, e->n * sizeof(double));
            *t_stop = hits[h].t;
            *y_stop = e->ystop;
            rc = SWIM_ODE_TERMINATED;
            break;
        }
    }
    if (hits != stack)
        free(hits);
    return rc;
}

void ode_events_counts(const ode_events *e, long *evals, long *found)
{
    *evals = e ? e->evals : 0;
    *found = e ? e->found : 0;
}
