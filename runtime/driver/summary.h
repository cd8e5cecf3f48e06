/* summary.h -- the one writer of summary.json: what a run found (driver/run.h), where it wrote,
 * and what it was -- swim's version, the command line, the overrides, the kernel's cache key --
 * so that an output folder says how to make it again.
 *
 * The keys are the contract users script against (docs/outputs.md); a sweep reads them back with
 * driver/summary_read.h.
 */
#ifndef SWIM_DRIVER_SUMMARY_H
#define SWIM_DRIVER_SUMMARY_H

#include <stdio.h>

#include "driver/run.h"
#include "scene/scene.h"

#include "io/version.h"

/* What the caller adds to a run's summary. Every pointer may be NULL. */
typedef struct {
    const char *out;                 /* the output folder */
    const char *command;             /* the command line, quoted for a shell */
    const char *scene_original;      /* the scene file as given (DIR/scene.toml is the resolved copy) */
    const swim_override *sets;       /* --set overrides applied, in order */
    int nsets;
    /* the sensitivities (an entry only when asked for) */
    int sensitivity;
    const char *sens_status;         /* written, failed, interrupted or skipped */
    double sens_t;                   /* where they were meant to end */
    long sens_rows;                  /* rows of sensitivity.csv, the last at sens_t_last */
    double sens_t_last;
    const char *sens_method;         /* exact, or differences (some key had no exact partial) */
    long sens_jacobians, sens_rhs;   /* exact Jacobians and right-hand sides the augmented system took */
    double sens_seconds;             /* wall time of the sensitivity pass */
    /* more entries of the caller's (one or more lines "  \"key\": value,\n"), after the
     * sensitivities; may be NULL */
    void (*more)(FILE *f, const void *ctx);
    const void *more_ctx;
} swim_summary_context;

/* The summary of a finished run (swim_run_integrate) as JSON text on f. */
void swim_run_summary_json(FILE *f, const swim_run *run, const swim_summary_context *x);

/* Where the time went and which Jacobian was used (the "stats" object, every kind of run). */
typedef struct {
    double integrate, diagnostics, output;   /* seconds: in the integrator, row diagnostics, the sink */
    double rhs, wall;                         /* seconds in the right-hand side; of the whole run */
    long rhs_calls;
    const char *jacobian;                     /* "exact", "differences" or "none" */
    long jacobian_calls;
    double jacobian_seconds;
} swim_run_timing;

/* The parts every kind of run shares, for the writers of other kinds (strokes). */
void swim_summary_provenance_json(FILE *f, const swim_summary_context *x, const swim_compiled *kernel);
void swim_run_stats_json(FILE *f, const swim_ode_stats *st, const swim_run_timing *t);

#endif
