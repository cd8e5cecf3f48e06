/* libswim's events, dense output and analyses (runtime/lib/swim.h), through the public API only:
 *   - every event reaches the caller's on_event with the time, column, kind and value events.csv
 *     has, and the state there; a nonzero return stops the run at that event: its last row is
 *     the event's, and the run fails "stopped by the caller";
 *   - swim_sim_state_at at a row's time gives that row's state bit for bit, elsewhere in the last
 *     step a state between its neighbours, and outside it is refused naming t;
 *   - the sensitivity dy/d model.rho0 at t_end agrees with a central difference of two runs;
 *     an unknown key is refused at swim_sim_create naming "sensitivity";
 *   - the Lyapunov pass gives its renormalizations, and the exponent is their mean growth. */
#include <math.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "lib/swim.h"

#define SCENE "models/example3.toml"

typedef struct {
    int n;
    double t[64], value[64], y_state[64];
    char column[64][16], kind[64][8];
    int nstate;
    int stop_at;          /* > 0: stop at this event (1 = the first) */
} events;

static int on_event(void *ctx, const swim_event *e)
{
    events *ev = ctx;
    if (ev->n < 64) {
        ev->t[ev->n] = e->t;
        ev->value[ev->n] = e->value;
        ev->y_state[ev->n] = e->nstate > 1 ? e->state[1] : NAN;
        snprintf(ev->column[ev->n], sizeof ev->column[0], "%s", e->column);
        snprintf(ev->kind[ev->n], sizeof ev->kind[0], "%s", e->kind);
        ev->nstate = e->nstate;
    }
    ev->n++;
    return ev->stop_at > 0 && ev->n >= ev->stop_at;
}

typedef struct {
    double t, y;   /* the last row's time and y */
    long n;
} last_row;

static int keep_last(void *ctx, double t, const double *values, int ncol)
{
    last_row *r = ctx;
    r->t = t;
    r->y = ncol > 2 ? values[2] : NAN;
    r->n++;
    return 0;
}

static swim_model *open_model(const char *const *sets, int nsets)
{
    swim_model *m = NULL;
    swim_error e = SWIM_ERROR_INIT;
    if (swim_model_from_file(SCENE, sets, nsets, &m, &e) != SWIM_OK) fprintf(stderr, "%s\n", e.message);
    return m;
}

static void test_events(void)
{
    const char *sets[] = {"run.t_end=8"};
    swim_model *m = open_model(sets, 1);
    CHECK(m != NULL, "Example 3 opens");
    if (!m) return;
    const char *spec[] = {"am1:max", "y:zero"};
    events ev = {0};
    last_row lr = {0};
    swim_sim_options o = SWIM_SIM_OPTIONS_INIT;
    o.events = spec;
    o.nevents = 2;
    o.on_event = on_event;
    o.event_ctx = &ev;
    o.rows = keep_last;
    o.rows_ctx = &lr;
    swim_sim *s;
    swim_error e = SWIM_ERROR_INIT;
    CHECK(swim_sim_create(m, &o, &s, &e) == SWIM_OK && swim_sim_run(s, &e) == SWIM_OK, "the run with events: %s",
          e.message);
    char *csv = swim_sim_events_csv(s);
    /* events.csv: t,column,kind,value, one line per event, the same order */
    int lines = 0, same = 1;
    for (char *p = csv ? strchr(csv, '\n') : NULL; p && p[1]; p = strchr(p + 1, '\n'), lines++) {
        double t, v;
        char col[32], kind[16];
        if (sscanf(p + 1, "%lf,%31[^,],%15[^,],%lf", &t, col, kind, &v) != 4 || lines >= ev.n ||
            t != ev.t[lines] || strcmp(col, ev.column[lines]) || strcmp(kind, ev.kind[lines]) || v != ev.value[lines])
            same = 0;
    }
    CHECK(ev.n >= 2 && lines == ev.n && same, "on_event saw the %d events of events.csv (%d lines), the same numbers",
          ev.n, lines);
    CHECK(ev.nstate == 3 + 2 * 16, "the state at an event has x, y, theta, the 16 coordinates and velocities (%d)",
          ev.nstate);
    int first_max = -1;
    for (int i = 0; i < ev.n && first_max < 0; i++)
        if (strcmp(ev.column[i], "am1") == 0 && strcmp(ev.kind[i], "max") == 0) first_max = i;
    CHECK(first_max >= 0, "an am1:max event");
    swim_sim_free(s);
    free(csv);

    /* stop at the first am1:max */
    events stop = {0};
    stop.stop_at = 1;
    last_row lr2 = {0};
    o.events = spec;
    o.nevents = 1;
    o.event_ctx = &stop;
    o.rows_ctx = &lr2;
    CHECK(swim_sim_create(m, &o, &s, &e) == SWIM_OK, "created");
    const int rc = swim_sim_run(s, &e);
    swim_result r = SWIM_RESULT_INIT;
    swim_sim_result(s, &r);
    CHECK(rc == SWIM_EFAILED && strstr(e.message, "stopped by the caller at event am1:max"),
          "a nonzero return stops the run, saying so: %d %s", rc, e.message);
    CHECK(first_max >= 0 && stop.n == 1 && stop.t[0] == ev.t[first_max] && r.t_reached == stop.t[0] &&
              lr2.t == stop.t[0], "it stops at the event (t = %.17g, reached %.17g, last row %.17g)", stop.t[0],
          r.t_reached, lr2.t);
    CHECK(lr2.y == stop.y_state[0], "the last row's y is the state the event gave");
    char *summary = swim_sim_summary_json(s);
    CHECK(summary && strstr(summary, "\"failed\"") && strstr(summary, "stopped by the caller"),
          "the summary says the run was stopped by the caller");
    free(summary);
    swim_sim_free(s);
    swim_model_free(m);
}

typedef struct {
    double t[2], row[2][35];
    long n;
} two_rows;

static int keep_two(void *ctx, double t, const double *values, int ncol)
{
    two_rows *r = ctx;
    r->t[0] = r->t[1];
    memcpy(r->row[0], r->row[1], sizeof r->row[0]);
    r->t[1] = t;
    for (int i = 0; i < 35 && i + 1 < ncol; i++) r->row[1][i] = values[1 + i];
    r->n++;
    return 0;
}

static void test_state_at(void)
{
    swim_model *m = open_model(NULL, 0);
    CHECK(m != NULL, "Example 3 opens");
    if (!m) return;
    two_rows tr = {{0}, {{0}}, 0};
    swim_sim_options o = SWIM_SIM_OPTIONS_INIT;
    o.rows = keep_two;
    o.rows_ctx = &tr;
    swim_sim *s;
    swim_error e = SWIM_ERROR_INIT;
    double y[40];
    CHECK(swim_sim_create(m, &o, &s, &e) == SWIM_OK, "created");
    CHECK(swim_sim_state_at(s, 0.0, y, 40, &e) == -SWIM_EFAILED, "nothing to interpolate before the run");
    CHECK(swim_sim_advance(s, 2.0, &e) == SWIM_OK && tr.t[1] == 2.0, "advanced to 2 (last row %g)", tr.t[1]);
    const int n = swim_sim_state_at(s, 2.0, y, 40, &e);
    CHECK(n == 35 && memcmp(y, tr.row[1], sizeof(double) * 35) == 0, "state_at(2) is the row at 2, bit for bit (%d)", n);
    double state[40];
    CHECK(swim_sim_state(s, state, 40) == 35 && memcmp(state, y, sizeof(double) * 35) == 0, "and swim_sim_state");
    CHECK(swim_sim_state_at(s, 1.0, y, 40, &e) == -SWIM_EINPUT && strcmp(e.key, "t") == 0 &&
              strstr(e.message, "outside the last step"), "t = 1 is before the last step: refused naming t (%s)",
          e.message);
    swim_sim_free(s);
    swim_model_free(m);
}

/* y at t_end of Example 3 run to 2 with the overrides, and with the sensitivity of key. */
static double y_end(const char *rho0, const char *key, double *dy)
{
    const char *sets[] = {"run.t_end=2", rho0};
    swim_model *m = open_model(sets, 2);
    if (!m) return NAN;
    swim_sim_options o = SWIM_SIM_OPTIONS_INIT;
    o.sensitivity = key;
    swim_sim *s;
    swim_error e = SWIM_ERROR_INIT;
    swim_result r = SWIM_RESULT_INIT;
    double y = NAN;
    if (swim_sim_create(m, &o, &s, &e) == SWIM_OK && swim_sim_run(s, &e) == SWIM_OK && swim_sim_result(s, &r) == SWIM_OK)
        y = r.y;
    else
        fprintf(stderr, "%s\n", e.message);
    const char *const *names;
    const double *v;
    int ncol = 0;
    long nrows = 0;
    if (key && dy && swim_sim_sensitivity(s, &names, &ncol, &v, &nrows) == SWIM_OK) {
        CHECK(ncol > 3 && strcmp(names[0], "t") == 0 && strcmp(names[2], "dy/dmodel.rho0") == 0,
              "the columns of sensitivity.csv (%s)", ncol > 2 ? names[2] : "");
        CHECK(nrows == r.rows && v[(nrows - 1) * ncol] == 2.0, "a row per output row, the last at t_end");
        *dy = v[(nrows - 1) * ncol + 2];
    }
    swim_sim_free(s);
    swim_model_free(m);
    return y;
}

static void test_sensitivity(void)
{
    double dy = NAN;
    const double h = 1e-4;
    y_end("model.rho0=1", "model.rho0", &dy);
    const double yp = y_end("model.rho0=1.0001", NULL, NULL), ym = y_end("model.rho0=0.9999", NULL, NULL);
    const double fd = (yp - ym) / (2 * h);
    CHECK(isfinite(dy) && fabs(dy - fd) <= 1e-5 * fmax(1.0, fabs(fd)),
          "dy/drho0 at t = 2 (%.10g) is the central difference of two runs (%.10g)", dy, fd);

    swim_model *m = open_model(NULL, 0);
    swim_sim_options o = SWIM_SIM_OPTIONS_INIT;
    o.sensitivity = "model.nothing";
    swim_sim *s = NULL;
    swim_error e = SWIM_ERROR_INIT;
    CHECK(swim_sim_create(m, &o, &s, &e) == SWIM_EINPUT && s == NULL && strcmp(e.key, "sensitivity") == 0,
          "an unknown key is refused at create naming sensitivity: %s (%s)", e.message, e.key);
    swim_model_free(m);
}

static void test_lyapunov(void)
{
    const char *sets[] = {"run.t_end=4"};
    swim_model *m = open_model(sets, 1);
    if (!m) return;
    swim_sim_options o = SWIM_SIM_OPTIONS_INIT;
    o.lyapunov = 0.5;
    swim_sim *s;
    swim_error e = SWIM_ERROR_INIT;
    swim_lyapunov_result l = SWIM_LYAPUNOV_RESULT_INIT;
    CHECK(swim_sim_create(m, &o, &s, &e) == SWIM_OK && swim_sim_run(s, &e) == SWIM_OK, "the run: %s", e.message);
    CHECK(swim_sim_lyapunov(s, &l) == SWIM_OK && l.computed && l.segments == 8 && l.t_end == 4.0,
          "the pass: %d renormalizations to %g (%s)", l.segments, l.t_end, l.reason);
    double sum = 0;
    for (int i = 0; i < l.segments; i++) sum += l.log_growth[i];
    CHECK(l.segments > 0 && fabs(l.exponent - sum / l.t_end) <= 1e-12 * fmax(1, fabs(l.exponent)),
          "the exponent (%g) is the mean growth (%g)", l.exponent, sum / l.t_end);
    CHECK(l.verdict && (!strcmp(l.verdict, "converged") || !strcmp(l.verdict, "regular") ||
                        !strcmp(l.verdict, "not_converged")), "a verdict: %s", l.verdict ? l.verdict : "(null)");
    CHECK(l.horizon > 0, "a horizon: %g", l.horizon);
    swim_sim_free(s);
    o.lyapunov = 0;
    CHECK(swim_sim_create(m, &o, &s, &e) == SWIM_OK && swim_sim_lyapunov(s, &l) == SWIM_EINPUT,
          "no pass asked for: SWIM_EINPUT");
    swim_sim_free(s);
    swim_model_free(m);
}

/* A caller built before on_event and the analyses: a struct that ends at `stop`, followed by
 * bytes that are not fields; the library reads none of them. */
static void test_old_options(void)
{
    swim_model *m = open_model(NULL, 0);
    if (!m) return;
    union { swim_sim_options o; unsigned char b[sizeof(swim_sim_options)]; } u;
    memset(u.b, 0xAB, sizeof u.b);
    u.o.size = offsetof(swim_sim_options, stop) + sizeof u.o.stop;
    u.o.rows = NULL;
    u.o.rows_ctx = NULL;
    u.o.events = NULL;
    u.o.nevents = 0;
    u.o.stop = NULL;
    swim_sim *s;
    swim_error e = SWIM_ERROR_INIT;
    CHECK(swim_sim_create(m, &u.o, &s, &e) == SWIM_OK && swim_sim_advance(s, 0.5, &e) == SWIM_OK,
          "options of the first layout: the fields after it are not read: %s", e.message);
    swim_lyapunov_result l = SWIM_LYAPUNOV_RESULT_INIT;
    CHECK(swim_sim_lyapunov(s, &l) == SWIM_EINPUT, "no Lyapunov pass was asked for");
    swim_sim_free(s);
    swim_model_free(m);
}

/* A member in one call equals the same keys set, a simulation and its run, bit for bit; a
 * structure key is refused naming it (a member that fails to run is a row: python/tests). */
static void test_run_member(void)
{
    const char *sets[] = {"run.t_end=1"};
    swim_model *a = open_model(sets, 1), *b = open_model(sets, 1);
    CHECK(a && b, "Example 3 opens twice");
    if (!a || !b) return;
    const char *keys[] = {"model.rho0=1.4", "elastic.stiffness[2]=3"}, *ev[] = {"am1:max"};
    swim_member row = SWIM_MEMBER_INIT;
    swim_error e = SWIM_ERROR_INIT;
    const int rc = swim_model_run_member(a, keys, 2, ev, 1, &row, &e);
    swim_model_set(b, "model.rho0", "1.4", &e);
    swim_model_set(b, "elastic.stiffness[2]", "3", &e);
    swim_sim_options o = SWIM_SIM_OPTIONS_INIT;
    o.events = ev;
    o.nevents = 1;
    swim_sim *s = NULL;
    swim_result r = SWIM_RESULT_INIT;
    if (swim_sim_create(b, &o, &s, &e) == SWIM_OK && swim_sim_run(s, &e) == SWIM_OK) swim_sim_result(s, &r);
    swim_sim_free(s);
    CHECK(rc == SWIM_OK && row.completed && strcmp(row.status, "completed") == 0 && row.y == r.y && row.x == r.x &&
          row.t_reached == r.t_reached && row.steps == r.steps && row.rhs_evaluations == r.rhs_evaluations &&
          row.jmin == r.jmin && strstr(row.reason, "t_end"), "the member is the run: y %.17g vs %.17g, steps %lld vs %ld (%s)",
          row.y, r.y, row.steps, r.steps, row.reason);
    const char *structure[] = {"model.modes=3"};
    swim_error bad = SWIM_ERROR_INIT;
    CHECK(swim_model_run_member(a, structure, 1, NULL, 0, &row, &bad) == SWIM_EINPUT &&
          strcmp(bad.key, "model.modes") == 0, "a structure key: key '%s' (%s)", bad.key, bad.message);
    swim_model_free(a);
    swim_model_free(b);
}

int main(void)
{
    test_old_options();
    test_run_member();
    test_events();
    test_state_at();
    test_sensitivity();
    test_lyapunov();
    return check_report("test_library_analyses");
}
