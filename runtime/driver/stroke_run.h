/* stroke_run.h -- the prescribed-stroke kind of run behind driver/run.h: swim_run_open hands a
 * scene with a [stroke] table here. Not called by commands directly. */
#ifndef SWIM_DRIVER_STROKE_RUN_H
#define SWIM_DRIVER_STROKE_RUN_H

#include <stdio.h>

#include "driver/run.h"
#include "driver/summary.h"
#include "stroke/stroke.h"

typedef struct swim_stroke_run swim_stroke_run;

int swim_stroke_run_columns(const swim_scene *s, const char **names, char storage[][24]);
/* The stroke model, its check over [0, t_end], the period: 0, 1 (out of memory) or 2 (not
 * allowable; the cause in st). */
int swim_stroke_run_open(const swim_run_request *req, swim_stroke_run **out, swim_status *st);
int swim_stroke_run_integrate(swim_stroke_run *c);
void swim_stroke_run_fail(swim_stroke_run *c, const char *reason);
const swim_run_result *swim_stroke_run_result(const swim_stroke_run *c);
swim_dynamics *swim_stroke_run_dynamics(swim_stroke_run *c);
void swim_stroke_summary_json(FILE *f, const swim_stroke_run *c, const swim_summary_context *x);
void swim_stroke_run_free(swim_stroke_run *c);

#endif
