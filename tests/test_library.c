/* libswim's contract (runtime/lib/swim.h), through the public API only:
 *   - a run gives swim run's rows: advancing in pieces gives the rows of one run, bit for bit;
 *   - a bad scene or override comes back as an error struct (file, line, key, message), nothing
 *     printed (stdout and stderr checked), and the process goes on to the next call; a notice
 *     (an initial velocity projected onto the constraints) is not printed either;
 *   - two simulations on two threads give the results of two sequential ones, bit for bit;
 *   - the row callback can stop a run, which then fails saying so;
 *   - swim_inspect's K is Md - N^T Mr^-1 N and symmetric, Gamma(v, v) is Gamma contracted twice,
 *     and an inadmissible shape is refused naming the argument;
 *   - the version macros are swim_version()'s numbers; swim_strerror names every status;
 *   - the caller's structs are filled only as far as their size field says (a bigger struct's
 *     tail untouched, a too small one refused and left as it was);
 *   - swim_model_set of a run-time key gives the rows of a model opened with that override, bit
 *     for bit; a structure key or a bad value is refused naming the key, the model unchanged. */
#include <math.h>
#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "capture.h"
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

/* The rows of model m run to its end. */
static int model_rows(const swim_model *m, rows *out, swim_result *res)
{
    swim_sim *s;
    swim_error e = SWIM_ERROR_INIT;
    memset(out, 0, sizeof *out);
    swim_sim_options o = {.size = sizeof o, .rows = keep_row, .rows_ctx = out};
    if (swim_sim_create(m, &o, &s, &e) != SWIM_OK) return -1;
    const int rc = swim_sim_run(s, &e);
    swim_sim_result(s, res);
    swim_sim_free(s);
    return rc;
}

/* The rows of scene path with overrides, run to its end (or in pieces of `piece` time units). */
static int run_rows(const char *path, const char *const *sets, int nsets, double piece, rows *out, swim_result *res)
{
    swim_model *m;
    swim_sim *s;
    swim_error e = SWIM_ERROR_INIT;
    memset(out, 0, sizeof *out);
    if (swim_model_from_file(path, sets, nsets, &m, &e) != SWIM_OK) return -1;
    swim_sim_options o = {.size = sizeof o, .rows = keep_row, .rows_ctx = out};
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
    swim_result rw = SWIM_RESULT_INIT, rp = SWIM_RESULT_INIT;
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
    swim_error e = SWIM_ERROR_INIT;
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
    swim_sim_options o = {.size = sizeof o, .events = ev, .nevents = 1};
    rc = swim_sim_create(m, &o, &s, &e);
    CHECK(rc == SWIM_EINPUT && s == NULL && strstr(e.message, "nosuchcolumn"), "a bad event: %s", e.message);
    /* the caller's callback stops the run */
    rows r = {0};
    r.stop_after = 3;
    swim_sim_options o2 = {.size = sizeof o2, .rows = keep_row, .rows_ctx = &r};
    CHECK(swim_sim_create(m, &o2, &s, &e) == SWIM_OK, "a simulation");
    rc = swim_sim_run(s, &e);
    swim_result res = SWIM_RESULT_INIT;
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

/* Bad values with stdout and stderr going to a file: the causes come back in the error, the file
 * stays empty. */
static void test_nothing_printed(void)
{
    char dir[] = "/tmp/swim-lib-quiet-XXXXXX", path[64];
    if (!mkdtemp(dir)) {
        CHECK(0, "a temporary folder");
        return;
    }
    snprintf(path, sizeof path, "%s/printed", dir);
    const capture_fds q = capture_begin(path);
    swim_model *m = NULL;
    swim_error bad_file = SWIM_ERROR_INIT, bad_text = SWIM_ERROR_INIT, bad_word = SWIM_ERROR_INIT,
               bad_set = SWIM_ERROR_INIT, projected = SWIM_ERROR_INIT;
    const char *bad[] = {"model.rho0=-1"}, *word[] = {"model.rho0=x1"};
    const int rc_file = swim_model_from_file("models/example3.toml", bad, 1, &m, &bad_file);
    const char *text = "[model]\nmodes = 1\nrho0 = 1.0\nrhof = 1.0\n[shape]\nc0 = [1, 0, 0.2, 0]\ndc0 = [0, 0, 0, 0]\n"
                       "free = \"all\"\n[run]\nt_end = 1\noutput_step = 0.1\nrtol = 7\n";
    const int rc_text = swim_model_from_text(text, "inline.toml", NULL, 0, &m, &bad_text);
    const int rc_word = swim_model_from_file("models/example3.toml", word, 1, &m, &bad_word);
    /* projected: a notice on swim run's stderr, nothing here */
    const char *proj[] = {"run.t_end=0.01", "run.project_initial=true", "shape.dc0[0]=0.1"};
    const int rc_proj = swim_model_from_file("models/example3.toml", proj, 3, &m, &projected);
    int rc_set = -1;
    if (rc_proj == SWIM_OK) {
        rc_set = swim_model_set(m, "run.rtol", "-2", &bad_set);
        swim_model_free(m);
    }
    const long long printed = capture_end(q);
    CHECK(printed == 0, "bad values printed %lld bytes", printed);
    CHECK(rc_file == SWIM_EINPUT && strstr(bad_file.file, "example3.toml") && bad_file.line == 0 &&
          strcmp(bad_file.key, "model.rho0") == 0 && strstr(bad_file.message, "--set model.rho0=-1"),
          "an override's bad value: file '%s' line %d key '%s' (%s)", bad_file.file, bad_file.line, bad_file.key,
          bad_file.message);
    CHECK(rc_text == SWIM_EINPUT && strcmp(bad_text.file, "inline.toml") == 0 && bad_text.line == 12 &&
          strcmp(bad_text.key, "run.rtol") == 0 && strncmp(bad_text.message, "inline.toml:12: run.rtol: ", 26) == 0,
          "a bad value in the text: file '%s' line %d key '%s' (%s)", bad_text.file, bad_text.line, bad_text.key,
          bad_text.message);
    CHECK(rc_word == SWIM_EINPUT && strcmp(bad_word.key, "model.rho0") == 0 && strstr(bad_word.message, "not a string"),
          "a word for a number: key '%s' (%s)", bad_word.key, bad_word.message);
    CHECK(rc_proj == SWIM_OK, "a velocity projected onto the constraints loads: %s", projected.message);
    CHECK(rc_set == SWIM_EINPUT && strcmp(bad_set.key, "run.rtol") == 0 && strstr(bad_set.message, "must be > 0"),
          "swim_model_set of a bad value: %d key '%s' (%s)", rc_set, bad_set.key, bad_set.message);
    unlink(path);
    rmdir(dir);
}

static void *run_job(void *p)
{
    job *j = p;
    const char *sets[] = {j->set};
    j->rc = run_rows(j->path, sets, 1, 0, &j->r, &j->res);
    return NULL;
}

static void test_threads(void)
{
    job seq[2] = {{"models/example3.toml", "run.t_end=4", {0}, SWIM_RESULT_INIT, 0},
                  {"models/hard/near_boundary_a05.toml", "run.t_end=0.5", {0}, SWIM_RESULT_INIT, 0}};
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
    swim_inspection in = {sizeof in, 0, Mr, Nc, Md, K, gvv, G};
    swim_error e = SWIM_ERROR_INIT;
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

static void test_versions(void)
{
    char want[64];
    snprintf(want, sizeof want, "%d.%d.%d", SWIM_VERSION_MAJOR, SWIM_VERSION_MINOR, SWIM_VERSION_PATCH);
    CHECK(strcmp(swim_version(), want) == 0, "swim.h's version macros %s are the library's %s", want, swim_version());
    const char *names[] = {"SWIM_OK", "SWIM_EFAILED", "SWIM_EINPUT", "SWIM_ENOMEM", "SWIM_EKERNEL"};
    const int statuses[] = {SWIM_OK, SWIM_EFAILED, SWIM_EINPUT, SWIM_ENOMEM, SWIM_EKERNEL};
    for (int i = 0; i < 5; i++) {
        const char *t = swim_strerror(statuses[i]);
        CHECK(t && strncmp(t, names[i], strlen(names[i])) == 0 && t[strlen(names[i])] == ':' && strlen(t) > 20,
              "swim_strerror(%d) names %s: %s", statuses[i], names[i], t ? t : "(NULL)");
    }
    CHECK(strcmp(swim_strerror(-SWIM_EINPUT), swim_strerror(SWIM_EINPUT)) == 0, "a negated status is named too");
    CHECK(strcmp(swim_strerror(99), "unknown status") == 0, "an unknown status: %s", swim_strerror(99));
    CHECK(swim_struct_size("swim_error") == sizeof(swim_error) && swim_struct_size("swim_result") == sizeof(swim_result) &&
          swim_struct_size("swim_sim_options") == sizeof(swim_sim_options) &&
          swim_struct_size("swim_inspection") == sizeof(swim_inspection) && swim_struct_size("swim_x") == 0 &&
          swim_struct_size(NULL) == 0, "swim_struct_size gives the header's sizes");
}

/* A caller's struct of `size` bytes inside a buffer of 0xAB: the bytes from `size` on stay 0xAB. */
static int tail_untouched(const unsigned char *buf, size_t from, size_t len)
{
    for (size_t i = from; i < len; i++)
        if (buf[i] != 0xAB) return 0;
    return 1;
}

static void test_sizes(void)
{
    enum { PAD = 64 };
    const char *sets[] = {"run.t_end=0.2"};
    swim_model *m = NULL;
    swim_sim *s = NULL;
    swim_error e = SWIM_ERROR_INIT;
    if (swim_model_from_file("models/example3.toml", sets, 1, &m, &e) != SWIM_OK ||
        swim_sim_create(m, NULL, &s, &e) != SWIM_OK || swim_sim_run(s, &e) != SWIM_OK) {
        CHECK(0, "Example 3 runs: %s", e.message);
        return;
    }
    /* a newer caller's bigger struct: the library fills its own part, the rest stays */
    union { swim_result r; unsigned char b[sizeof(swim_result) + PAD]; } big;
    memset(big.b, 0xAB, sizeof big.b);
    big.r.size = sizeof big.b;
    CHECK(swim_sim_result(s, &big.r) == SWIM_OK && big.r.completed && big.r.t_reached == 0.2 &&
          big.r.size == sizeof big.b && tail_untouched(big.b, sizeof(swim_result), sizeof big.b),
          "a bigger swim_result: filled up to sizeof(swim_result), its tail and size untouched");
    /* a size below the first layout: refused, nothing written */
    memset(big.b, 0xAB, sizeof big.b);
    big.r.size = sizeof(swim_result) - sizeof(long);
    CHECK(swim_sim_result(s, &big.r) == SWIM_EINPUT && tail_untouched(big.b, sizeof(size_t), sizeof big.b),
          "a swim_result smaller than its first layout: SWIM_EINPUT, not written");
    big.r.size = 0;
    CHECK(swim_sim_result(s, &big.r) == SWIM_EINPUT, "a swim_result of size 0 (never set): SWIM_EINPUT");

    /* the error struct: a bigger one filled up to its size; one of size 0 left as it was */
    union { swim_error e; unsigned char b[sizeof(swim_error) + PAD]; } berr;
    memset(berr.b, 0xAB, sizeof berr.b);
    berr.e.size = sizeof berr.b;
    CHECK(swim_sim_advance(s, NAN, &berr.e) == SWIM_EINPUT && strcmp(berr.e.key, "t") == 0 &&
          berr.e.size == sizeof berr.b && tail_untouched(berr.b, sizeof(swim_error), sizeof berr.b),
          "a bigger swim_error: the error in it (key '%s'), its tail untouched", berr.e.key);
    memset(berr.b, 0xAB, sizeof berr.b);
    berr.e.size = 0;
    CHECK(swim_sim_advance(s, NAN, &berr.e) == SWIM_EINPUT && tail_untouched(berr.b, sizeof(size_t), sizeof berr.b),
          "a swim_error of size 0: SWIM_EINPUT, nothing written into it");

    /* options and inspection: too small is SWIM_EINPUT naming the struct */
    swim_sim *s2 = NULL;
    swim_sim_options o = {0};
    int rc = swim_sim_create(m, &o, &s2, &e);
    CHECK(rc == SWIM_EINPUT && s2 == NULL && strcmp(e.key, "swim_sim_options") == 0 && strstr(e.message, "size"),
          "swim_sim_options without its size: %d key '%s' (%s)", rc, e.key, e.message);
    union { swim_sim_options o; unsigned char b[sizeof(swim_sim_options) + PAD]; } bo;
    memset(bo.b, 0xAB, sizeof bo.b);   /* a newer caller's fields: not read (they would be garbage) */
    bo.o = (swim_sim_options)SWIM_SIM_OPTIONS_INIT;
    bo.o.size = sizeof bo.b;
    CHECK(swim_sim_create(m, &bo.o, &s2, &e) == SWIM_OK && swim_sim_run(s2, &e) == SWIM_OK,
          "a bigger swim_sim_options: its own fields read, the run goes: %s", e.message);
    swim_sim_free(s2);
    const double c[4] = {1, 0, 0.1, 0};
    double Mr[9];
    swim_inspection in = {0};
    in.mass_rigid = Mr;
    rc = swim_inspect(1, c, NULL, 1, 1, &in, &e);
    CHECK(rc == SWIM_EINPUT && strcmp(e.key, "swim_inspection") == 0, "swim_inspection without its size: %d key '%s'",
          rc, e.key);
    swim_sim_free(s);
    swim_model_free(m);
}

static void test_model_set(void)
{
    const char *sets[] = {"run.t_end=2"}, *with[] = {"run.t_end=2", "model.rho0=2"};
    swim_model *m = NULL, *ref = NULL;
    swim_error e = SWIM_ERROR_INIT;
    if (swim_model_from_file("models/example3.toml", sets, 1, &m, &e) != SWIM_OK ||
        swim_model_from_file("models/example3.toml", with, 2, &ref, &e) != SWIM_OK) {
        CHECK(0, "Example 3 loads: %s", e.message);
        return;
    }
    rows before, after, want;
    swim_result rb = SWIM_RESULT_INIT, ra = SWIM_RESULT_INIT, rw = SWIM_RESULT_INIT;
    model_rows(m, &before, &rb);
    /* a simulation created before the set keeps rho0 = 1 */
    swim_sim *old = NULL;
    rows old_rows = {0};
    swim_sim_options o = {.size = sizeof o, .rows = keep_row, .rows_ctx = &old_rows};
    CHECK(swim_sim_create(m, &o, &old, &e) == SWIM_OK, "a simulation before the set");
    CHECK(swim_model_set(m, "model.rho0", "2", &e) == SWIM_OK, "model.rho0 set to 2: %s", e.message);
    model_rows(m, &after, &ra);
    model_rows(ref, &want, &rw);
    CHECK(same_rows(&after, &want) && ra.x == rw.x && ra.y == rw.y && ra.steps == rw.steps,
          "set model.rho0=2, then a run: the rows of a model opened with it, bit for bit (%ld, %ld rows)", after.n, want.n);
    CHECK(!same_rows(&before, &after), "and not the rows of rho0 = 1");
    CHECK(strstr(swim_model_scene_text(m), "rho0 = 2") != NULL, "the scene text has the new value");
    swim_sim_run(old, &e);
    CHECK(same_rows(&old_rows, &before), "a simulation created before the set runs with rho0 = 1");
    char *json = swim_sim_summary_json(old);
    CHECK(json && !strstr(json, "model.rho0=2"), "and its summary lists the overrides it was made with");
    swim_free(json);
    swim_sim_free(old);
    /* the same key again replaces it: back to 1 gives the first rows */
    rows back;
    swim_result rbk = SWIM_RESULT_INIT;
    CHECK(swim_model_set(m, "model.rho0", "1.0", &e) == SWIM_OK, "model.rho0 set back to 1: %s", e.message);
    model_rows(m, &back, &rbk);
    CHECK(same_rows(&back, &before), "set back, the rows are the first ones, bit for bit");
    /* refused: structure keys, a value that changes the structure, bad values; the model as it was */
    int rc = swim_model_set(m, "model.modes", "3", &e);
    CHECK(rc == SWIM_EINPUT && strcmp(e.key, "model.modes") == 0 && strstr(e.message, "structure"),
          "model.modes refused: %d key '%s' (%s)", rc, e.key, e.message);
    rc = swim_model_set(m, "elastic.stiffness.am1", "0", &e);
    CHECK(rc == SWIM_EINPUT && strcmp(e.key, "elastic.stiffness.am1") == 0 && strstr(e.message, "structure"),
          "a stiffness made zero changes the structure, refused: %d key '%s' (%s)", rc, e.key, e.message);
    rc = swim_model_set(m, "model.rho0", "-1", &e);
    CHECK(rc == SWIM_EINPUT && strcmp(e.key, "model.rho0") == 0 && strstr(e.file, "example3.toml"),
          "rho0 = -1 refused as --set refuses it: %d file '%s' key '%s' (%s)", rc, e.file, e.key, e.message);
    rc = swim_model_set(m, "model.rho0", "abc(", &e);
    CHECK(rc == SWIM_EINPUT && strcmp(e.key, "model.rho0") == 0, "a value that does not parse: %d key '%s' (%s)", rc,
          e.key, e.message);
    rc = swim_model_set(m, "model.nosuch", "1", &e);
    CHECK(rc == SWIM_EINPUT && e.message[0], "an unknown key: %d (%s)", rc, e.message);
    rc = swim_model_set(NULL, "model.rho0", "1", &e);
    CHECK(rc == SWIM_EINPUT && strcmp(e.key, "model") == 0, "a NULL model");
    rc = swim_model_set(m, NULL, "1", &e);
    CHECK(rc == SWIM_EINPUT && strcmp(e.key, "key") == 0, "a NULL key");
    rc = swim_model_set(m, "model.rho0", NULL, &e);
    CHECK(rc == SWIM_EINPUT && strcmp(e.key, "value") == 0, "a NULL value");
    rows last;
    swim_result rl = SWIM_RESULT_INIT;
    model_rows(m, &last, &rl);
    CHECK(same_rows(&last, &before), "after the refusals the model runs as before, bit for bit");
    free(last.v);
    /* a stiffness value that keeps the zeros, a parameter-free run key */
    CHECK(swim_model_set(m, "elastic.stiffness.am1", "3", &e) == SWIM_OK && swim_model_set(m, "run.t_end", "1", &e) == SWIM_OK,
          "a nonzero stiffness and run.t_end are run-time keys: %s", e.message);
    model_rows(m, &last, &rl);
    CHECK(rl.completed && rl.t_reached == 1.0, "run.t_end set to 1: the run ends at %g", rl.t_reached);
    free(last.v);
    free(before.v);
    free(after.v);
    free(want.v);
    free(old_rows.v);
    free(back.v);
    swim_model_free(m);
    swim_model_free(ref);
}

int main(void)
{
    CHECK(strcmp(swim_version(), "unknown") != 0 && strchr(swim_version(), '.'), "a version: %s", swim_version());
    test_pieces();
    test_errors();
    test_nothing_printed();
    test_threads();
    test_inspect();
    test_versions();
    test_sizes();
    test_model_set();
    return check_report("test_library");
}
