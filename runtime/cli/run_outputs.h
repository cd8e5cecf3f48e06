/* run_outputs.h -- where `swim run` writes, for dynamic scenes and prescribed strokes alike:
 * the output folder (--out, else out/<scene name>) and the paths of its files.
 */
#ifndef SWIM_CLI_RUN_OUTPUTS_H
#define SWIM_CLI_RUN_OUTPUTS_H

#include <stdio.h>

#include "ode/ode.h"

typedef struct {
    char *dir, *csv_path, *snap_path, *summary_path, *scene_copy_path, *events_path;   /* owned */
} swim_run_paths;

/* The leading columns of DIR/trajectory.csv, shared by dynamic runs and strokes: t, x, y, theta,
 * the n shape coordinates and their velocities ("d" + name), into names[0 .. 4 + 2n) (the names of
 * the coordinates written into storage[0 .. 2n)). Returns the count; the caller's own columns
 * follow. */
int swim_run_state_columns(int n, const char **names, char storage[][24]);

/* Where the time of a run went and which Jacobian it used, for the "stats" of summary.json. */
typedef struct {
    double integrate, diagnostics, output;   /* seconds: in the integrator, row diagnostics, writing */
    double rhs, wall;                         /* seconds in the right-hand side; of the whole run */
    long rhs_calls;
    const char *jacobian;                     /* "exact", "differences" or "none" */
    long jacobian_calls;
    double jacobian_seconds;
} swim_run_timing;

/* ",\n  "stats": {...}" of summary.json, the same keys for dynamic runs and strokes: the
 * integrator's counters and order histogram, the timing, the peak memory (getrusage). */
void swim_run_stats_json(FILE *f, const swim_ode_stats *st, const swim_run_timing *t);

/* out/<scene file name without its extension>; NULL when out of memory. */
char *swim_run_default_out(const char *scene_path);

/* Creates the folder (out, else the default for scene_path) and fills p with it and the paths
 * DIR/trajectory.csv, snapshots.json, summary.json, scene.toml, events.csv. 0; 1 out of memory;
 * 2 the folder cannot be created (one line on stderr). p is freed by swim_run_paths_free in
 * every case. */
int swim_run_paths_open(swim_run_paths *p, const char *out, const char *scene_path);
void swim_run_paths_free(swim_run_paths *p);

#endif
