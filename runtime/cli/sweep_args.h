/* sweep_args.h -- `swim sweep SCENE --out DIR --vary KEY=SPEC ... [--zip] [--jobs J] [--keep WHAT]
 * [--set KEY=VALUE ...] [run options]` into a sweep plan (sweep/sweep.h). */
#ifndef SWIM_CLI_SWEEP_ARGS_H
#define SWIM_CLI_SWEEP_ARGS_H

#include "sweep/sweep.h"

/* Parses argv[first..argc). Keys are compared by the value they set (swim_override_same_target):
 * a value varied twice, varied and set, or set twice to two values (in any spelling) is refused.
 * 0, or 2 after one line on stderr. */
int sweep_parse(sweep_plan *p, const char *cmd, int argc, char **argv, int first);

#endif
