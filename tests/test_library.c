/* libswim's contract (runtime/lib/swim.h), through the public API only:
 *   - a run gives swim run's rows: advancing in pieces gives the rows of one run, bit for bit;
 *   - a bad scene or override comes back as an error struct (file, line, key, message), nothing
 *     printed, and the process goes on to the next call;
 *   - two simulations on two threads give the results of two sequential ones, bit for bit;
 *   - the row callback can stop a run, which then fails saying so;
 *   - swim_inspect's K is Md - N^T Mr^-1 N and symmetric, Gamma(v, v) is Gamma contracted twice,
 *     and an inadmissible shape is refused naming the argument. */
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

/* Mr^-1 N column by column (Cramer's rule on the 3 x 3 Mr). */
static void solve3(const double *A, const double *b, double *x)
{
    const double d = A[0] * (A[4] * A[8] - A[5] * A[7]) - A[1] * (A[3] * A[8] - A[5] * A[6]) +
                     A[2] * (A[3] * A[7] - A[4] * A[6]);
    for (int c = 0; c < 3; c++) {
        double M[9];
        memcpy(M, A, sizeof M);
        for (int r = 0; r < 3; r++) M[3 * r + c] = b[r];
        x[c] = (M[0] * (M[4] * M[8] - M[5] * M[7]) - M[1] * (M[3] * M[8] - M[5] * M[6]) +
                M[2] * (M[3] * M[7] - M[4] * M[6])) / d;
    }
}

static void test_inspect(void)
{
    enum { N = 2, n = 2 * (N + 1) };
    const double c[n] = {1, 0, 0.2, -0.05, 0.1, 0.04}, v[n] = {0, 0, 0.1, 0.3, -0.2, 0.1};
    double Mr[9], Nc[3 * n], Md[n * n], K[n * n], gvv[n], G[n * n * n];
    swim_inspection in = {0, Mr, Nc, Md, K, gvv, G};
    swim_error e;
    CHECK(swim_inspect(N, c, v, 1.3, 0.7, &in, &e) == SWIM_OK, "swim_inspect at an admissible shape: %s", e.message);
    double worst = 0, asym = 0, scale = 0, gerr = 0;
    for (int j = 0; j < n; j++) {
        double b[3] = {Nc[j], Nc[n + j], Nc[2 * n + j]}, y[3];
        solve3(Mr, b, y);
        for (int i = 0; i < n; i++) {
            const double want = Md[i * n + j] - (Nc[i] * y[0] + Nc[n + i] * y[1] + Nc[2 * n + i] * y[2]);
            worst = fmax(worst, fabs(K[i * n + j] - want));
            asym = fmax(asym, fabs(K[i * n + j] - K[j * n + i]));
            scale = fmax(scale, fabs(Md[i * n + j]));
        }
    }
    for (int i = 0; i < n; i++) {
        double g = 0;
        for (int j = 0; j < n; j++)
            for (int k = 0; k < n; k++) g += G[(i * n + j) * n + k] * v[j] * v[k];
        gerr = fmax(gerr, fabs(g - gvv[i]));
    }
    CHECK(worst <= 1e-13 * scale && asym <= 1e-13 * scale, "K = Md - N^T Mr^-1 N (%.2g), symmetric (%.2g)", worst, asym);
    CHECK(in.jmin > 0 && gerr <= 1e-12 * (1 + scale), "Gamma(v, v) = Gamma^i_jk v^j v^k (%.2g)", gerr);
    const double out_of_d[n] = {1, 0, 0, 0, 0.6, 0};
    int rc = swim_inspect(N, out_of_d, NULL, 1, 1, &in, &e);
    CHECK(rc == SWIM_EINPUT && strcmp(e.key, "shape") == 0 && strstr(e.message, "admissible"),
          "a shape outside D: SWIM_EINPUT, key shape (%d, %s)", rc, e.message);
    rc = swim_inspect(N, c, NULL, 1, 0, &in, &e);
    CHECK(rc == SWIM_EINPUT && strcmp(e.key, "rhof") == 0, "rhof = 0 refused, key rhof (%d, %s)", rc, e.key);
}

int main(void)
{
    CHECK(strcmp(swim_version(), "unknown") != 0 && strchr(swim_version(), '.'), "a version: %s", swim_version());
    test_pieces();
    test_errors();
    test_threads();
    test_inspect();
    return check_report("test_library");
}
