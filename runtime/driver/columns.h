/* columns.h -- the columns of trajectory.csv as one table {name, value} per kind of run: the
 * state (t, x, y, theta, the shape coordinates and their velocities), then the diagnostics every
 * kind writes, then the kind's own (a scene with an energy law: W_law; a stroke: power,
 * work_positive, phase_c1). The same table names the columns (the CSV header, the library's rows,
 * events) and computes every row, so a column cannot be named in one place and missing in another.
 * Internal to the driver. */
#ifndef SWIM_DRIVER_COLUMNS_H
#define SWIM_DRIVER_COLUMNS_H

#include "model/dynamics.h"

/* What a row's values are computed from. */
typedef struct {
    const swim_diag *g;        /* the row's diagnostics (model/dynamics.h) */
    const double *extra;       /* the kind's own quantities, in the order of its columns */
} swim_run_quantities;

/* A column after the state: its name and its value at a row. */
typedef struct {
    const char *name;
    double (*value)(const swim_run_quantities *q);
} swim_run_column;

/* A part of a kind's table: count columns. */
typedef struct {
    const swim_run_column *cols;
    int count;
} swim_run_columns_part;

/* The diagnostics every kind writes after the state: kinetic energies, potential, energy, the
 * three impulses (3.3), the residuals, min J (4.1), work, w1, w2. */
extern const swim_run_columns_part swim_run_diagnostics;

/* The state's columns: t, x, y, theta, the n shape coordinates and their velocities ("d" + name)
 * into names[0 .. 4 + 2n) (the coordinates' names written into storage[0 .. 2n)). The count. */
int swim_run_state_columns(int n, const char **names, char storage[][24]);
/* All the columns of a kind: the state's, then those of parts[0 .. nparts). The count. */
int swim_run_column_names(int n, const swim_run_columns_part *parts, int nparts, const char **names,
                          char storage[][24]);
/* A row: v[0] = t, then x, y, theta, c, cdot from the full state, then every part's values. The count. */
int swim_run_column_values(double t, const double *full, int n, const swim_run_quantities *q,
                           const swim_run_columns_part *parts, int nparts, double *v);

#endif
