/* libswim's periodic orbits, Floquet multipliers and continuation (runtime/lib/swim.h), through
 * the public API only:
 *   - Example 1's orbit converges; its struct's numbers are the ones of the JSON the library gives
 *     (the command's writer), its tangent multipliers lie on the unit circle (a conservative
 *     libration) and multiply to 1 (det M_t = 1); a result struct is filled to its size, nothing
 *     past it, and a size below its first layout is refused;
 *   - Example 3's monodromy: its trace is the sum of its multipliers, its period the time between
 *     two am1:max events of a plain simulation;
 *   - a branch of Example 1 in the energy: the table's first column is the targets, its energy
 *     column reaches them, its header is branch.csv's;
 *   - Example 3's energy minimized over elastic.reference.am1 (swim_optimize): the optimum sits at
 *     c0's 0.4 (E(T) = E(0) is smallest at cref = c0), the struct's numbers are those of the
 *     optimize.json the library gives, optimize.csv's header names the key; a bad spec, an
 *     unknown quantity and BFGS without a gradient are refused naming their key, nothing printed;
 *   - bad input (a stroke, an unknown section, a tolerance out of bounds, a small options struct,
 *     no period within t_max, no parameter) comes back as a status naming the key, with nothing
 *     printed; a stop flag set before the work gives a stopped, unconverged result. */
#include <math.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "capture.h"
#include "check.h"
#include "lib/swim.h"

static swim_model *open_model(const char *scene, const char *const *sets, int nsets)
{
    swim_model *m = NULL;
    swim_error e = SWIM_ERROR_INIT;
    if (swim_model_from_file(scene, sets, nsets, &m, &e) != SWIM_OK) fprintf(stderr, "%s\n", e.message);
    return m;
}

/* The number after "KEY": in the JSON text (the first one), NAN when absent. */
static double json_number(const char *json, const char *key)
{
    char pat[64];
    snprintf(pat, sizeof pat, "\"%s\": ", key);
    const char *at = json ? strstr(json, pat) : NULL;
    return at ? strtod(at + strlen(pat), NULL) : NAN;
}

static void test_periodic(void)
{
    swim_model *m = open_model("models/example1.toml", NULL, 0);
    CHECK(m != NULL, "Example 1 opens");
    if (!m) return;
    swim_orbit_options o = SWIM_ORBIT_OPTIONS_INIT;
    swim_orbit *a = NULL;
    swim_error e = SWIM_ERROR_INIT;
    const int rc = swim_periodic_orbit(m, &o, &a, &e);
    CHECK(rc == SWIM_OK && a, "swim_periodic_orbit: %d %s", rc, e.message);
    if (!a) {
        swim_model_free(m);
        return;
    }
    swim_periodic_result r = SWIM_PERIODIC_RESULT_INIT;
    CHECK(swim_orbit_periodic(a, &r) == SWIM_OK, "the periodic result");
    swim_floquet_result wrong = SWIM_FLOQUET_RESULT_INIT;
    CHECK(swim_orbit_floquet(a, &wrong) == SWIM_EINPUT, "a periodic orbit has no floquet result");
    char *json = swim_orbit_json(a);
    CHECK(json && strstr(json, "\"status\": \"converged\""), "periodic.json says converged");
    CHECK(r.converged && r.iterations >= 0 && r.reason && r.reason[0] == '\0', "converged (%s)", r.reason);
    CHECK(r.period > 0 && r.period == json_number(json, "period"), "period %.17g is the JSON's", r.period);
    CHECK(r.residual <= 1e-11 && r.residual == json_number(json, "residual"), "residual %.3g", r.residual);
    CHECK(r.dy == json_number(json, "dy") && r.energy == json_number(json, "energy"), "dy and energy are the JSON's");
    CHECK(r.n > 0 && r.n % 2 == 0 && r.names && strcmp(r.names[0], "am1") == 0 && strcmp(r.names[r.n / 2], "dam1") == 0,
          "shape state of %d entries named %s ...", r.n, r.n > 0 && r.names ? r.names[0] : "?");
    for (int i = 0; r.names && r.phase_point && i < r.n; i++)
        CHECK(r.phase_point[i] == json_number(json, r.names[i]), "phase point %s", r.names[i]);
    CHECK(r.have_floquet && r.monodromy && r.tangent_dimension > 0 && r.tangent_dimension <= r.n,
          "Floquet data of dimension %d", r.tangent_dimension);
    double prod_re = 1, prod_im = 0, dev = 0;
    for (int k = 0; r.multipliers_re && k < r.tangent_dimension; k++) {
        const double re = r.multipliers_re[k], im = r.multipliers_im[k], t = prod_re * re - prod_im * im;
        prod_im = prod_re * im + prod_im * re;
        prod_re = t;
        dev = fmax(dev, fabs(hypot(re, im) - 1.0));
    }
    CHECK(dev < 1e-3 && fabs(prod_re - 1.0) < 1e-6 && fabs(prod_im) < 1e-6,
          "tangent multipliers on the unit circle (dev %.2g), product %.9g%+.9gi", dev, prod_re, prod_im);
    CHECK(swim_orbit_csv(a) == NULL, "no CSV for a periodic orbit");

    /* a caller built against the first fields only: nothing written past its size */
    struct {
        swim_periodic_result head;
        unsigned char guard[64];
    } small;
    memset(&small, 0xAB, sizeof small);
    small.head.size = offsetof(swim_periodic_result, period) + sizeof(double);
    const int small_rc = swim_orbit_periodic(a, &small.head);
    CHECK(small_rc == SWIM_EINPUT, "a size below the first layout is refused (%d)", small_rc);
    memset(&small, 0xAB, sizeof small);
    small.head.size = sizeof small.head;
    int untouched = 1;
    for (size_t i = 0; i < sizeof small.guard; i++) untouched &= small.guard[i] == 0xAB;
    CHECK(swim_orbit_periodic(a, &small.head) == SWIM_OK && untouched && small.head.period == r.period,
          "the whole struct filled, the bytes after it untouched");
    swim_free(json);
    swim_orbit_free(a);
    swim_model_free(m);
}

static int keep_event(void *ctx, const swim_event *ev)
{
    double *t = ctx;
    if (t[0] < 2) t[1 + (int)t[0]] = ev->t;
    t[0]++;
    return 0;
}

static void test_floquet(void)
{
    swim_model *m = open_model("models/example3.toml", NULL, 0);
    CHECK(m != NULL, "Example 3 opens");
    if (!m) return;
    swim_orbit_options o = SWIM_ORBIT_OPTIONS_INIT;
    o.section = "am1:max";
    swim_orbit *a = NULL;
    swim_error e = SWIM_ERROR_INIT;
    CHECK(swim_floquet_multipliers(m, &o, &a, &e) == SWIM_OK && a, "swim_floquet_multipliers: %s", e.message);
    if (!a) {
        swim_model_free(m);
        return;
    }
    swim_floquet_result r = SWIM_FLOQUET_RESULT_INIT;
    CHECK(swim_orbit_floquet(a, &r) == SWIM_OK, "the Floquet result");
    CHECK(r.n == 8 && r.monodromy && r.multipliers_re && r.periodic && r.stopped == 0, "M of %d entries, periodic %d",
          r.n, r.periodic);
    double trace = 0, sum = 0, sum_im = 0;
    for (int i = 0; i < r.n; i++) {
        trace += r.monodromy[i * r.n + i];
        sum += r.multipliers_re[i];
        sum_im += r.multipliers_im[i];
    }
    CHECK(fabs(trace - sum) <= 1e-9 * fmax(1, fabs(trace)) && fabs(sum_im) <= 1e-9,
          "trace of M %.15g = sum of its multipliers %.15g (imaginary %.2g)", trace, sum, sum_im);
    CHECK(r.tangent_dimension > 0 && r.tangent_dimension < r.n && r.tangent_re && r.complement_dimension >= 0,
          "tangent dimension %d, complement %d", r.tangent_dimension, r.complement_dimension);
    /* the period is the time between two am1:max events of the scene's own run */
    const char *ev[] = {"am1:max"};
    double got[3] = {0, NAN, NAN};
    swim_sim_options so = SWIM_SIM_OPTIONS_INIT;
    so.events = ev;
    so.nevents = 1;
    so.on_event = keep_event;
    so.event_ctx = got;
    swim_sim *s = NULL;
    if (swim_sim_create(m, &so, &s, &e) == SWIM_OK) swim_sim_run(s, &e);
    swim_sim_free(s);
    CHECK(got[0] >= 2 && fabs((got[2] - got[1]) - r.period) <= 1e-6 * r.period && fabs(got[1] - r.t_first) <= 1e-6,
          "period %.10g vs events at %.10g and %.10g", r.period, got[1], got[2]);
    char *json = swim_orbit_json(a);
    CHECK(json && r.period == json_number(json, "period") && r.closure == json_number(json, "closure"),
          "period and closure are floquet.json's");
    swim_free(json);
    swim_orbit_free(a);
    swim_model_free(m);
}

static void test_branch(void)
{
    swim_model *m = open_model("models/example1.toml", NULL, 0);
    CHECK(m != NULL, "Example 1 opens");
    if (!m) return;
    swim_orbit_options o = SWIM_ORBIT_OPTIONS_INIT;
    o.param = "energy";
    o.start = 0.1;
    o.end = 0.15;
    o.points = 2;
    swim_orbit *a = NULL;
    swim_error e = SWIM_ERROR_INIT;
    CHECK(swim_continuation(m, &o, &a, &e) == SWIM_OK && a, "swim_continuation: %s", e.message);
    if (!a) {
        swim_model_free(m);
        return;
    }
    swim_branch_result b = SWIM_BRANCH_RESULT_INIT;
    CHECK(swim_orbit_branch(a, &b) == SWIM_OK, "the branch result");
    CHECK(b.points == 2 && b.columns > 12 && b.names && strcmp(b.names[0], "energy_target") == 0 &&
          strcmp(b.names[5], "energy") == 0 && strcmp(b.names[12], "am1") == 0 &&
          b.ended && b.ended[0] == '\0' && b.stopped == 0, "2 points of %d columns (%s)", b.columns, b.ended);
    for (int i = 0; b.table && i < b.points; i++) {
        const double *row = b.table + (size_t)i * b.columns;
        CHECK(row[0] == (i ? 0.15 : 0.1) && fabs(row[5] - row[0]) <= 1e-9 && row[1] > 0,
              "point %d: target %.17g, energy %.17g, period %.10g", i, row[0], row[5], row[1]);
    }
    char *csv = swim_orbit_csv(a), header[1024] = "";
    for (int j = 0; b.names && j < b.columns; j++) {
        strcat(header, j ? "," : "");
        strcat(header, b.names[j]);
    }
    CHECK(csv && strncmp(csv, header, strlen(header)) == 0 && csv[strlen(header)] == '\n', "branch.csv's header is %s",
          header);
    swim_free(csv);
    swim_orbit_free(a);
    swim_model_free(m);
}

static void test_refused(void)
{
    char dir[] = "/tmp/swim-lib-orbits-XXXXXX", path[64];
    if (!mkdtemp(dir)) {
        CHECK(0, "a temporary folder");
        return;
    }
    snprintf(path, sizeof path, "%s/printed", dir);
    swim_model *ex1 = open_model("models/example1.toml", NULL, 0), *stroke = open_model("models/stroke_loop.toml", NULL, 0);
    CHECK(ex1 && stroke, "the scenes open");
    if (!ex1 || !stroke) return;
    const capture_fds q = capture_begin(path);
    swim_orbit *a = NULL;
    swim_error e_stroke = SWIM_ERROR_INIT, e_section = SWIM_ERROR_INIT, e_tol = SWIM_ERROR_INIT,
               e_size = SWIM_ERROR_INIT, e_tmax = SWIM_ERROR_INIT, e_param = SWIM_ERROR_INIT;
    swim_orbit_options o = SWIM_ORBIT_OPTIONS_INIT;
    const int rc_stroke = swim_periodic_orbit(stroke, &o, &a, &e_stroke);
    o.section = "zz:max";
    const int rc_section = swim_floquet_multipliers(ex1, &o, &a, &e_section);
    o.section = NULL;
    o.tol = 2;
    const int rc_tol = swim_periodic_orbit(ex1, &o, &a, &e_tol);
    o.tol = 0;
    o.t_max = 0.5;
    const int rc_tmax = swim_periodic_orbit(ex1, &o, &a, &e_tmax);
    o.t_max = 0;
    const int rc_param = swim_continuation(ex1, &o, &a, &e_param);
    swim_orbit_options small = o;
    small.size = offsetof(swim_orbit_options, tol);
    const int rc_size = swim_periodic_orbit(ex1, &small, &a, &e_size);
    /* stopped before it began: the guess is not found, and that is said as stopped */
    volatile int stop = 1;
    o.stop = &stop;
    swim_orbit *stopped = NULL;
    swim_error e_stop = SWIM_ERROR_INIT;
    const int rc_stop = swim_periodic_orbit(ex1, &o, &stopped, &e_stop);
    const long long printed = capture_end(q);
    CHECK(printed == 0, "the refusals printed %lld bytes", printed);
    CHECK(a == NULL, "no result for a refusal");
    CHECK(rc_stroke == SWIM_EINPUT && strcmp(e_stroke.key, "stroke") == 0 && strstr(e_stroke.file, "stroke_loop") &&
          strstr(e_stroke.message, "prescribed stroke"), "a stroke: %d key '%s' (%s)", rc_stroke, e_stroke.key,
          e_stroke.message);
    CHECK(rc_section == SWIM_EINPUT && strcmp(e_section.key, "event") == 0 && strstr(e_section.message, "'zz'"),
          "an unknown section: %d key '%s' (%s)", rc_section, e_section.key, e_section.message);
    CHECK(rc_tol == SWIM_EINPUT && strcmp(e_tol.key, "tol") == 0, "tol 2: %d key '%s' (%s)", rc_tol, e_tol.key,
          e_tol.message);
    CHECK(rc_tmax == SWIM_EFAILED && strstr(e_tmax.message, "fewer than two events"), "t_max 0.5: %d (%s)", rc_tmax,
          e_tmax.message);
    CHECK(rc_param == SWIM_EINPUT && strcmp(e_param.key, "param") == 0, "no parameter: %d key '%s'", rc_param,
          e_param.key);
    CHECK(rc_size == SWIM_EINPUT && strcmp(e_size.key, "swim_orbit_options") == 0, "a small options struct: key '%s'",
          e_size.key);
    swim_periodic_result r = SWIM_PERIODIC_RESULT_INIT;
    CHECK(rc_stop == SWIM_OK && stopped && swim_orbit_periodic(stopped, &r) == SWIM_OK && r.stopped == 1 &&
          !r.converged && r.reason && strstr(r.reason, "stopped"), "stopped: %d, stopped %d (%s)", rc_stop, r.stopped,
          r.reason ? r.reason : "");
    swim_orbit_free(stopped);
    swim_model_free(ex1);
    swim_model_free(stroke);
    remove(path);
    remove(dir);
}

static void test_optimize(void)
{
    const char *sets[] = {"run.t_end=1"};
    swim_model *m = open_model("models/example3.toml", sets, 1);
    CHECK(m != NULL, "Example 3 opens");
    if (!m) return;
    const char *vary[] = {"elastic.reference.am1=0:1"};
    swim_optimize_options o = SWIM_OPTIMIZE_OPTIONS_INIT;
    o.vary = vary;
    o.nvary = 1;
    o.quantity = "energy";
    swim_orbit *a = NULL;
    swim_error e = SWIM_ERROR_INIT;
    CHECK(swim_optimize(m, &o, &a, &e) == SWIM_OK && a, "swim_optimize: %s", e.message);
    if (a) {
        swim_optimize_result r = SWIM_OPTIMIZE_RESULT_INIT;
        CHECK(swim_orbit_optimize(a, &r) == SWIM_OK && r.nkeys == 1 && r.keys && r.best &&
              strcmp(r.keys[0], "elastic.reference.am1") == 0, "the optimize result");
        swim_periodic_result wrong = SWIM_PERIODIC_RESULT_INIT;
        CHECK(swim_orbit_periodic(a, &wrong) == SWIM_EINPUT, "a search has no periodic result");
        char *json = swim_orbit_json(a), *csv = swim_orbit_csv(a);
        CHECK(r.best && fabs(r.best[0] - 0.4) < 1e-3 && r.converged && r.holds && r.best_start == 1,
              "the optimum at c0's 0.4: %.10g (converged %d)", r.best ? r.best[0] : NAN, r.converged);
        CHECK(json && r.value == json_number(json, "value") && r.energy == json_number(json, "energy") &&
              r.best && r.best[0] == json_number(json, "elastic.reference.am1") &&
              (double)r.evaluations == json_number(strstr(json, "\n  \"evaluations\""), "evaluations") &&
              strstr(json, "\"best_scene\": null"),
              "the struct's numbers are optimize.json's: value %.17g", r.value);
        CHECK(csv && strncmp(csv, "iteration,evaluations,elastic.reference.am1,energy,size,start\n", 61) == 0,
              "optimize.csv's header");
        swim_free(json);
        swim_free(csv);
        swim_orbit_free(a);
    }
    char dir[] = "/tmp/swim-lib-optimize-XXXXXX", path[64];
    if (!mkdtemp(dir)) {
        CHECK(0, "a temporary folder");
        swim_model_free(m);
        return;
    }
    snprintf(path, sizeof path, "%s/printed", dir);
    const capture_fds q = capture_begin(path);
    swim_error e_spec = SWIM_ERROR_INIT, e_q = SWIM_ERROR_INIT, e_bfgs = SWIM_ERROR_INIT;
    const char *bad[] = {"elastic.reference.am1=1:0"};
    o.vary = bad;
    const int rc_spec = swim_optimize(m, &o, &a, &e_spec);
    o.vary = vary;
    o.quantity = "speed";
    const int rc_q = swim_optimize(m, &o, &a, &e_q);
    o.quantity = "displacement_per_work";
    o.method = "bfgs";
    const int rc_bfgs = swim_optimize(m, &o, &a, &e_bfgs);
    const long long printed = capture_end(q);
    CHECK(printed == 0, "the refusals printed %lld bytes", printed);
    CHECK(rc_spec == SWIM_EINPUT && strcmp(e_spec.key, "elastic.reference.am1") == 0 && strstr(e_spec.message, "LO < HI"),
          "LO > HI: %d key '%s' (%s)", rc_spec, e_spec.key, e_spec.message);
    CHECK(rc_q == SWIM_EINPUT && strcmp(e_q.key, "quantity") == 0, "an unknown quantity: key '%s'", e_q.key);
    CHECK(rc_bfgs == SWIM_EINPUT && strcmp(e_bfgs.key, "method") == 0 && strstr(e_bfgs.message, "no gradient"),
          "BFGS without a gradient: %d key '%s' (%s)", rc_bfgs, e_bfgs.key, e_bfgs.message);
    remove(path);
    remove(dir);
    swim_model_free(m);
}

int main(void)
{
    test_periodic();
    test_floquet();
    test_branch();
    test_refused();
    test_optimize();
    return check_report("test_library_orbits");
}
