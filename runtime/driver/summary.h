/* summary.h -- the one writer of summary.json: what a run found (driver/run.h), where it wrote,
 * and what it was -- swim's version, the command line, the overrides, the kernel's cache key --
 * so that an output folder says how to make it again.
 *
 * The summary is built as one JSON object (jansson) from the run's result, whatever its kind; a
 * kind adds its own entries (a prescribed stroke its "stroke" object, swim_run_kind.summary). The
 * keys are the contract users script against (docs/outputs.md); a sweep reads them back with
 * driver/summary_read.h.
 */
#ifndef SWIM_DRIVER_SUMMARY_H
#define SWIM_DRIVER_SUMMARY_H

#include <jansson.h>
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
    /* more entries of the caller's, set into the summary after the sensitivities (0, or -1 when
     * out of memory); may be NULL */
    int (*more)(json_t *summary, const void *ctx);
    const void *more_ctx;
} swim_summary_context;

/* The summary of a run (finished, advanced part of the way, or not started) as a JSON object: a
 * new reference, NULL when out of memory. */
json_t *swim_run_summary(const swim_run *run, const swim_summary_context *x);
/* The same as JSON text on f (io/json.h, swim_json_write). 0; -1 when out of memory (nothing written). */
int swim_run_summary_json(FILE *f, const swim_run *run, const swim_summary_context *x);

#endif
