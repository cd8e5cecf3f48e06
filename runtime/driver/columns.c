/* columns.c -- the columns of trajectory.csv (driver/columns.h). */
#include "driver/columns.h"

#include "kernel/coords.h"

static double kinetic_fluid(const swim_run_quantities *q) { return q->g->kinetic_fluid; }
static double kinetic_shape(const swim_run_quantities *q) { return q->g->kinetic_shape; }
static double kinetic_rigid(const swim_run_quantities *q) { return q->g->kinetic_rigid; }
/* W1 + W2 and the energy law's W (0 without a law), which the energy holds too */
static double potential(const swim_run_quantities *q) { return q->g->w1 + q->g->w2 + q->g->w_law; }
static double energy(const swim_run_quantities *q) { return q->g->energy; }
static double body_x(const swim_run_quantities *q) { return q->g->impulse_body[0]; }
static double body_y(const swim_run_quantities *q) { return q->g->impulse_body[1]; }
static double body_ang(const swim_run_quantities *q) { return q->g->impulse_body[2]; }
static double rigid_x(const swim_run_quantities *q) { return q->g->impulse_fluid_rigid[0]; }
static double rigid_y(const swim_run_quantities *q) { return q->g->impulse_fluid_rigid[1]; }
static double rigid_ang(const swim_run_quantities *q) { return q->g->impulse_fluid_rigid[2]; }
static double shape_x(const swim_run_quantities *q) { return q->g->impulse_fluid_shape[0]; }
static double shape_y(const swim_run_quantities *q) { return q->g->impulse_fluid_shape[1]; }
static double shape_ang(const swim_run_quantities *q) { return q->g->impulse_fluid_shape[2]; }
static double res_volume(const swim_run_quantities *q) { return q->g->res_volume; }
static double res_volume_rate(const swim_run_quantities *q) { return q->g->res_volume_rate; }
static double res_angular(const swim_run_quantities *q) { return q->g->res_angular; }
static double res_locks(const swim_run_quantities *q) { return q->g->res_locks; }
static double jmin(const swim_run_quantities *q) { return q->g->jmin; }
static double work(const swim_run_quantities *q) { return q->g->work; }
static double w1(const swim_run_quantities *q) { return q->g->w1; }
static double w2(const swim_run_quantities *q) { return q->g->w2; }

static const swim_run_column diagnostics[] = {
    {"kinetic_fluid", kinetic_fluid}, {"kinetic_shape", kinetic_shape}, {"kinetic_rigid", kinetic_rigid},
    {"potential", potential}, {"energy", energy},
    {"impulse_body_x", body_x}, {"impulse_body_y", body_y}, {"impulse_body_ang", body_ang},
    {"impulse_fluid_rigid_x", rigid_x}, {"impulse_fluid_rigid_y", rigid_y}, {"impulse_fluid_rigid_ang", rigid_ang},
    {"impulse_fluid_shape_x", shape_x}, {"impulse_fluid_shape_y", shape_y}, {"impulse_fluid_shape_ang", shape_ang},
    {"res_volume", res_volume}, {"res_volume_rate", res_volume_rate}, {"res_angular", res_angular},
    {"res_locks", res_locks}, {"jmin", jmin}, {"work", work}, {"w1", w1}, {"w2", w2},
};

const swim_run_columns_part swim_run_diagnostics = {diagnostics, (int)(sizeof diagnostics / sizeof diagnostics[0])};

int swim_run_state_columns(int n, const char **names, char storage[][24])
{
    static const char *const head[] = {"t", "x", "y", "theta"};
    int c = 0;
    for (int i = 0; i < 4; i++) names[c++] = head[i];
    for (int i = 0; i < n; i++) {
        swim_coord_name(i, storage[i], 24);
        names[c++] = storage[i];
    }
    for (int i = 0; i < n; i++) {
        storage[n + i][0] = 'd';
        swim_coord_name(i, storage[n + i] + 1, 23);
        names[c++] = storage[n + i];
    }
    return c;
}

int swim_run_column_names(int n, const swim_run_columns_part *parts, int nparts, const char **names,
                          char storage[][24])
{
    int c = swim_run_state_columns(n, names, storage);
    for (int p = 0; p < nparts; p++)
        for (int i = 0; i < parts[p].count; i++) names[c++] = parts[p].cols[i].name;
    return c;
}

int swim_run_column_values(double t, const double *full, int n, const swim_run_quantities *q,
                           const swim_run_columns_part *parts, int nparts, double *v)
{
    int c = 0;
    v[c++] = t;
    for (int i = 0; i < 3 + 2 * n; i++) v[c++] = full[i];
    for (int p = 0; p < nparts; p++)
        for (int i = 0; i < parts[p].count; i++) v[c++] = parts[p].cols[i].value(q);
    return c;
}
