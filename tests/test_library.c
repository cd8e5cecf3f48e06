/* libswim's contract (runtime/lib/swim.h), through the public API only:
 *   - a run gives swim run's rows: advancing in pieces gives the rows of one run, bit for bit;
 *   - a bad scene or override comes back as an error struct (file, line, key, message), nothing
 *     printed, and the process goes on to the next call;
 *   - two simulations on two threads give the results of two sequential ones, bit for bit;
 *   - the row callback can stop a run, which then fails saying so. */
#include <math.h>
#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "check.h"
#include "lib/swim.h"

typedef struct {
    double *v;
    long n, cap;
    int ncol;
    long stop_after;   /* > 0: stop the run after this many rows */
} rows;

static int keep_row(void *ctx, double t, const double *values, int ncol)
{
    rows *r = ctx;
    if (r->n == r->cap) {
        r->cap = r->cap ? 2 * r->cap : 256;
        r->v = realloc(r->v, sizeof(double) * (size_t)r->cap * (size_t)ncol);
    }
    memcpy(r->v + r->n * ncol, values, sizeof(double) * (size_t)ncol);
    r->ncol = ncol;
    r->n++;
    (void)t;
    return r->stop_after > 0 && r->n >= r->stop_after;
}

/* The rows of scene path with overrides, run to its end (or in pieces of `piece` time units). */
static int run_rows(const char *path, const char *const *sets, int nsets, double piece, rows *out, swim_result *res)
{
    swim_model *m;
    swim_sim *s;
    swim_error e;
    memset(out, 0, sizeof *out);
    if (swim_model_from_file(path, sets, nsets, &m, &e) != SWIM_OK) return -1;
    swim_sim_options o = {keep_row, out, NULL, 0, NULL};
    if (swim_sim_create(m, &o, &s, &e) != SWIM_OK) {
        swim_model_free(m);
        return -1;
    }
    int rc = SWIM_OK;
    if (piece > 0)
        for (double t = piece; rc == SWIM_OK; t += piece) {
            rc = swim_sim_advance(s, t, &e);
            swim_sim_result(s, res);
            if (res->finished) break;
        }
    else
        rc = swim_sim_run(s, &e);
    swim_sim_result(s, res);
    swim_sim_free(s);
    swim_model_free(m);
    return rc;
}

static int same_rows(const rows *a, const rows *b)
{
    return a->n == b->n && a->ncol == b->ncol && a->n > 0 &&
           memcmp(a->v, b->v, sizeof(double) * (size_t)a->n * (size_t)a->ncol) == 0;
}

static void test_pieces(void)
{
    const char *sets[] = {"run.t_end=3"};
    rows whole, parts;
    swim_result rw, rp;
    CHECK(run_rows("models/example3.toml", sets, 1, 0, &whole, &rw) == SWIM_OK, "Example 3 runs");
    CHECK(run_rows("models/example3.toml", sets, 1, 0.37, &parts, &rp) == SWIM_OK, "Example 3 runs in pieces");
    CHECK(same_rows(&whole, &parts), "pieces of 0.37 give the rows of one run, bit for bit (%ld vs %ld rows)", whole.n,
          parts.n);
    CHECK(rw.finished && rw.completed && rw.t_reached == 3.0 && rw.rows == whole.n, "the result: completed at t = 3");
    CHECK(rw.y == rp.y && rw.x == rp.x && rw.steps == rp.steps, "the same final state and steps");
    free(whole.v);
    free(parts.v);
}

static void test_errors(void)
{
    swim_model *m = NULL;
    swim_error e;
    const char *bad[] = {"model.rho0=-1"};
    int rc = swim_model_from_file("models/example3.toml", bad, 1, &m, &e);
    CHECK(rc == SWIM_EINPUT && m == NULL && e.status == SWIM_EINPUT, "a refused override is SWIM_EINPUT (%d)", rc);
    CHECK(strstr(e.file, "example3.toml") != NULL && strcmp(e.key, "model.rho0") == 0 && strstr(e.message, "rho0"),
          "the error names the file, the key and says why: file '%s' key '%s' message '%s'", e.file, e.key, e.message);
    const char *text = "[model]\nmodes = 1\nrho0 = 1.0\nrhof = 1.0\n[shape]\nc0 = [1, 0, 0.2, 0]\ndc0 = [0, 0, 0, 0]\n"
                       "free = \"all\"\n[run]\nt_end = 1\noutput_step = 0.1\nrtol = 7\n";
    rc = swim_model_from_text(text, "inline.toml", NULL, 0, &m, &e);
    CHECK(rc == SWIM_EINPUT && strcmp(e.file, "inline.toml") == 0 && e.line == 12 && strcmp(e.key, "run.rtol") == 0,
          "a bad value in a text scene: file '%s' line %d key '%s' (%s)", e.file, e.line, e.key, e.message);
    rc = swim_model_from_file("/nonexistent/scene.toml", NULL, 0, &m, &e);
    CHECK(rc == SWIM_EINPUT && e.message[0], "a missing file: %s", e.message);
    /* the process goes on: a good scene after the bad ones */
    const char *fine[] = {"run.t_end=0.5"};
    rc = swim_model_from_file("models/example3.toml", fine, 1, &m, &e);
    CHECK(rc == SWIM_OK && m, "a good scene after the errors loads");
    swim_sim *s = NULL;
    const char *ev[] = {"nosuchcolumn:max"};
    swim_sim_options o = {NULL, NULL, ev, 1, NULL};
    rc = swim_sim_create(m, &o, &s, &e);
    CHECK(rc == SWIM_EINPUT && s == NULL && strstr(e.message, "nosuchcolumn"), "a bad event: %s", e.message);
    /* the caller's callback stops the run */
    rows r = {0};
    r.stop_after = 3;
    swim_sim_options o2 = {keep_row, &r, NULL, 0, NULL};
    CHECK(swim_sim_create(m, &o2, &s, &e) == SWIM_OK, "a simulation");
    rc = swim_sim_run(s, &e);
    swim_result res;
    swim_sim_result(s, &res);
    CHECK(rc == SWIM_EFAILED && strstr(e.message, "stopped by the caller") && res.rows == 3 && !res.completed,
          "stopped by the row callback after 3 rows: %s (%ld rows)", e.message, res.rows);
    char *json = swim_sim_summary_json(s);
    CHECK(json && strstr(json, "\"status\": \"failed\"") && strstr(json, "stopped by the caller"), "its summary says so");
    swim_free(json);
    swim_sim_free(s);
    swim_model_free(m);
    free(r.v);
}

typedef struct {
    const char *path;
    const char *set;
    rows r;
    swim_result res;
    int rc;
} job;

static void *run_job(void *p)
{
    job *j = p;
    const char *sets[] = {j->set};
    j->rc = run_rows(j->path, sets, 1, 0, &j->r, &j->res);
    return NULL;
}

static void test_threads(void)
{
    job seq[2] = {{"models/example3.toml", "run.t_end=4", {0}, {0}, 0},
                  {"models/hard/near_boundary_a05.toml", "run.t_end=0.5", {0}, {0}, 0}};
    job par[2] = {seq[0], seq[1]};
    for (int i = 0; i < 2; i++) run_job(&seq[i]);
    pthread_t th[2];
    for (int i = 0; i < 2; i++) CHECK(pthread_create(&th[i], NULL, run_job, &par[i]) == 0, "thread %d", i);
    for (int i = 0; i < 2; i++) pthread_join(th[i], NULL);
    for (int i = 0; i < 2; i++) {
        CHECK(seq[i].rc == SWIM_OK && par[i].rc == SWIM_OK, "%s runs (%d, %d)", seq[i].path, seq[i].rc, par[i].rc);
        CHECK(same_rows(&seq[i].r, &par[i].r), "%s on a thread beside another run: the sequential rows, bit for bit",
              seq[i].path);
        free(seq[i].r.v);
        free(par[i].r.v);
    }
}

int main(void)
{
    CHECK(strcmp(swim_version(), "unknown") != 0 && strchr(swim_version(), '.'), "a version: %s", swim_version());
    test_pieces();
    test_errors();
    test_threads();
    return check_report("test_library");
}
