/* events.h -- events of a run: instants where a column of trajectory.csv crosses zero or has a
 * minimum or maximum, located by the integrator (ode.h, "Events"), written to DIR/events.csv
 * and summary.json, with the period and displacement per period of each event sequence.
 *
 * An event is "COLUMN:KIND[:stop]" (--event, repeatable, and the scene's [events] list):
 * KIND zero (sign change of the column), min or max (sign change of its time derivative,
 * rising for a minimum, falling for a maximum); ":stop" ends the run at the first one. */
#ifndef SWIM_DRIVER_EVENTS_H
#define SWIM_DRIVER_EVENTS_H

#include <stdio.h>

#include "ode/ode.h"
#include "scene/scene.h"

#define SWIM_RUN_MAX_EVENTS 32

typedef struct swim_run_events swim_run_events;

/* The values of the columns of trajectory.csv (names[0] = "t") at integrator state ys: all of
 * them, or with all = 0 only t and the state columns (x, y, theta, coordinates, velocities:
 * no diagnostics needed). */
typedef int (*swim_run_row_func)(void *ctx, double t, const double *ys, int all, double *row);

/* Collects the scene's [events] list and the extra specifications extra[0..nextra) (--event),
 * checks them against the columns (names[0..ncol), names[0] = "t") and the capabilities of
 * the integrators of the run's settings `set` (resolved, driver/run.h).  0 with *out (NULL when there are no events); 2 (bad input) or 1 (out of memory)
 * with the cause in st. Prints nothing. */
int swim_run_events_parse(const swim_scene *s, const swim_run_settings *set, const char *const *extra, int nextra,
                          const char *const *names, int ncol, swim_run_events **out, swim_status *st);

/* Registers the events in o (o->events, o->on_event); row(ctx, ...) gives the columns, the
 * first nstate of which (after t) are state columns; state_dim is the integrator's state
 * dimension.  0, or -1 when out of memory. */
int swim_run_events_attach(swim_run_events *ev, swim_ode_options *o, size_t state_dim, int nstate,
                           swim_run_row_func row, void *ctx);

/* A caller told of every event as it is located: its time, column, kind ("zero", "min", "max"),
 * the column's value there and the state there (trajectory.csv's columns 1 .. nstate: x, y,
 * theta, the coordinates and their velocities). Nonzero stops the integration at that event, as
 * a :stop event would (swim_run_events_caller_stopped then says so). An event found in a step
 * the stiff fallback takes back (swim_run_events_rewind) has been told already. */
typedef int (*swim_run_event_listener)(void *ctx, double t, const char *column, const char *kind, double value,
                                       const double *state, int nstate);
/* Before swim_run_events_attach. */
void swim_run_events_listen(swim_run_events *ev, swim_run_event_listener fn, void *ctx);
/* The listener asked to stop at the event that ended the run. */
int swim_run_events_caller_stopped(const swim_run_events *ev);

/* The integrator was restarted at t (stiff fallback): forget events found after t. */
void swim_run_events_rewind(swim_run_events *ev, double t);

/* The integrator's time is t - t0 from now on (swim run restarts it relative to an origin near
 * the barrier, model/dynamics.h): events are recorded and rows evaluated at t0 + its time. */
void swim_run_events_time_origin(swim_run_events *ev, double t0);

/* Which event ended the run (after SWIM_ODE_TERMINATED): "COLUMN:KIND". */
const char *swim_run_events_stop_name(const swim_run_events *ev);

struct json_t;
/* "events": [...], "event_stop": "COLUMN:KIND" or "", "periodic": [...] set into the summary
 * object (driver/summary.h). 0; -1 when out of memory. */
int swim_run_events_summary(const swim_run_events *ev, struct json_t *summary);

/* events.csv (t,column,kind,value) written whole at `path`, atomically (swim_replace_file);
 * nothing when ev is NULL.  0, or -1 with errno set (nothing printed: the caller reports it). */
int swim_run_events_write_csv(const swim_run_events *ev, const char *path);

/* The same text on f (the header alone when ev is NULL). */
void swim_run_events_csv(const swim_run_events *ev, FILE *f);

void swim_run_events_free(swim_run_events *ev);

#endif
