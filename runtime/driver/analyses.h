/* analyses.h -- the analyses of a run that ride on its own integration: sensitivities
 * (model/sensitivity.h) and the Lyapunov tangent vector (model/lyapunov.h), attached to a run
 * (driver/run.h, swim_run_variational) before it starts. One integration gives the trajectory,
 * the sensitivity rows (one per trajectory row) and the tangent vector's growth; by default
 * neither is in the error control, so the trajectory is bit for bit the one without them.
 * swim run (output/job.c) and libswim (lib/swim.c) both use it.
 *
 * Ownership: a swim_analyses borrows the run and the scene and owns the rest.
 */
#ifndef SWIM_DRIVER_ANALYSES_H
#define SWIM_DRIVER_ANALYSES_H

#include <stddef.h>

#include "model/lyapunov.h"
#include "model/sensitivity.h"
#include "driver/run.h"

/* Where the sensitivity rows go: once with row = NULL for the header (names, ncol), then a row per
 * trajectory row. 0, or nonzero with `why` (the run stops, failed). */
typedef int (*swim_analyses_sink)(void *ctx, const char *const *names, int ncol, const double *row, char *why,
                                  size_t len);

typedef struct {
    const char *keys;           /* --sensitivity's comma-separated keys, or NULL */
    int differences;            /* every key by difference quotients */
    int in_error_test;          /* the sensitivities in the error test (--sensitivity-steps all) */
    double lyapunov;            /* the renormalization interval, 0 = no tangent vector */
    swim_analyses_sink sink;
    void *ctx;
} swim_analyses_request;

typedef struct {
    swim_sens S;                /* the keys' columns, then the tangent vector's */
    int ready, nsens;
    double *y0, *row;
    char **names;
    int ncol;
    swim_analyses_sink sink;
    void *ctx;
    long rows;                  /* sensitivity rows kept, ... */
    double t_last;              /* ... the last at this time */
    double row_seconds;         /* time spent on the rows (denergy's diagnostics, the sink) */
} swim_analyses;

/* Whether the integrator can carry what req asks for on the run's steps: 0, or 2 with the line
 * "WHO: --OPTION: integrator NAME cannot ...; use ..." in st (before any output). */
int swim_analyses_check(const char *integrator, const swim_analyses_request *req, const char *who, swim_status *st);
/* The keys (checked before: swim_sens_add_list) resolved on the run's dynamics, the tangent vector's
 * start, the header to the sink, attached to the run. 0; 1 out of memory (or the header could not
 * be kept); 2 as swim_run_set_variational (the cause in st). cmd names the command in messages. */
int swim_analyses_attach(swim_analyses *a, swim_run *run, swim_scene *scene, const char *cmd,
                         const swim_analyses_request *req, swim_status *st);
/* After the run: the Lyapunov results from the growth the run measured (status 1 with the reason
 * when the tangent vector stopped before the run's end). 0, or -1 out of memory. */
int swim_analyses_lyapunov(swim_analyses *a, swim_run *run, double interval, double rtol, swim_lyapunov *l);
void swim_analyses_free(swim_analyses *a);

#endif
