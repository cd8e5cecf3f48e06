/* libswim under bad arguments and faults (runtime/lib/swim.h), through the public API only; also
 * built with ASan + UBSan (asan-test_library_args), so a crash or an invalid access fails it:
 *   - every public function refuses NULL or inconsistent pointers, a NULL entry of a list and
 *     counts or numbers outside their bounds with SWIM_EINPUT naming the argument;
 *   - swim_sim_advance refuses NaN, infinities and a step back, and the run goes on unharmed;
 *   - the summary of a run not started or advanced part-way says so (never "completed");
 *   - the stop flag is a flag: stop = 1 stops the run "by the caller", never "by SIGHUP";
 *   - a kernel that cannot be generated (a generator that fails; a cache and a TMPDIR that cannot
 *     be written) comes back as SWIM_EKERNEL with the cause in the error and nothing on stdout
 *     or stderr;
 *   - a process out of file descriptors gets an error, and its cache entries are not taken for
 *     damaged and rebuilt;
 *   - two threads needing the same new kernel build it one after the other (the cache entry's
 *     lock), and the program's own signal handlers are never replaced, during or after. */
#define _GNU_SOURCE
#include <fcntl.h>
#include <math.h>
#include <pthread.h>
#include <signal.h>
#include <stdatomic.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

#include "capture.h"
#include "check.h"
#include "lib/swim.h"

#define SCENE "models/example3.toml"

static void expect_input(int rc, const swim_error *e, const char *key, const char *what)
{
    CHECK(rc == SWIM_EINPUT && e->status == SWIM_EINPUT && strcmp(e->key, key) == 0 && strlen(e->message) > 8,
          "%s: want SWIM_EINPUT naming '%s', got %d key '%s' (%s)", what, key, rc, e->key, e->message);
}

static void test_model_arguments(void)
{
    swim_model *m = (swim_model *)1;
    swim_error e = SWIM_ERROR_INIT;
    const char *one[] = {"run.t_end=1"}, *holed[] = {"run.t_end=1", NULL};
    expect_input(swim_model_from_file(SCENE, NULL, 0, NULL, &e), &e, "out", "out NULL");
    expect_input(swim_model_from_file(NULL, NULL, 0, &m, &e), &e, "path", "path NULL");
    CHECK(m == NULL, "a refused call leaves *out NULL");
    expect_input(swim_model_from_file(SCENE, NULL, 1, &m, &e), &e, "sets", "sets NULL with nsets 1");
    expect_input(swim_model_from_file(SCENE, holed, 2, &m, &e), &e, "sets[1]", "a NULL entry in sets");
    expect_input(swim_model_from_file(SCENE, one, -1, &m, &e), &e, "nsets", "nsets -1");
    expect_input(swim_model_from_file(SCENE, one, 65, &m, &e), &e, "nsets", "nsets above its bound");
    expect_input(swim_model_from_text(NULL, "x", NULL, 0, &m, &e), &e, "toml", "toml NULL");
    expect_input(swim_model_from_text("", "x", NULL, 0, NULL, &e), &e, "out", "from_text out NULL");
    expect_input(swim_model_from_text("", "x", holed, 2, &m, &e), &e, "sets[1]", "from_text NULL entry");
    CHECK(swim_model_from_file(NULL, NULL, 0, &m, NULL) == SWIM_EINPUT, "a NULL error struct is allowed");
    const char *const *names = NULL;
    CHECK(swim_model_columns(NULL, &names) == -SWIM_EINPUT, "columns of a NULL model");
    CHECK(swim_model_scene_text(NULL) == NULL, "scene text of a NULL model");
    swim_model_free(NULL);
    swim_sim_free(NULL);
}

static int stop_after_rows(void *ctx, double t, const double *values, int ncol)
{
    int *flag = ctx;
    (void)t, (void)values, (void)ncol;
    if (++flag[1] >= 3) flag[0] = 1;   /* the stop flag set to 1 (SIGHUP's number) */
    return 0;
}

static void test_sim_arguments(void)
{
    swim_model *m;
    swim_sim *s = (swim_sim *)1;
    swim_error e = SWIM_ERROR_INIT;
    const char *sets[] = {"run.t_end=2"};
    if (swim_model_from_file(SCENE, sets, 1, &m, &e) != SWIM_OK) {
        CHECK(0, "Example 3 loads: %s", e.message);
        return;
    }
    const char *const *names;
    CHECK(swim_model_columns(m, NULL) == -SWIM_EINPUT && swim_model_columns(m, &names) > 4, "columns");
    swim_sim_options o = SWIM_SIM_OPTIONS_INIT;
    expect_input(swim_sim_create(m, &o, NULL, &e), &e, "out", "sim out NULL");
    expect_input(swim_sim_create(NULL, &o, &s, &e), &e, "model", "model NULL");
    CHECK(s == NULL, "a refused create leaves *out NULL");
    o.nevents = 1;
    expect_input(swim_sim_create(m, &o, &s, &e), &e, "events", "events NULL with nevents 1");
    const char *ev[] = {"y:max", NULL};
    o.events = ev;
    o.nevents = 2;
    expect_input(swim_sim_create(m, &o, &s, &e), &e, "events[1]", "a NULL entry in events");
    o.nevents = -3;
    expect_input(swim_sim_create(m, &o, &s, &e), &e, "nevents", "nevents -3");
    o.nevents = 0;
    expect_input(swim_sim_advance(NULL, 1, &e), &e, "sim", "advance NULL");
    expect_input(swim_sim_run(NULL, &e), &e, "sim", "run NULL");
    swim_result r = SWIM_RESULT_INIT;
    CHECK(swim_sim_result(NULL, &r) == SWIM_EINPUT, "result of NULL");
    CHECK(swim_sim_state(NULL, NULL, 0) == -SWIM_EINPUT, "state of NULL");
    CHECK(swim_sim_summary_json(NULL) == NULL && swim_sim_events_csv(NULL) == NULL, "summary, events of NULL");

    /* a run not started, then advanced part way, then asked for nonsense times */
    CHECK(swim_sim_create(m, &o, &s, &e) == SWIM_OK, "a simulation: %s", e.message);
    CHECK(swim_sim_result(s, NULL) == SWIM_EINPUT, "result into NULL");
    CHECK(swim_sim_state(s, NULL, 4) == -SWIM_EINPUT && swim_sim_state(s, NULL, 0) > 0, "state into NULL");
    char *json = swim_sim_summary_json(s);
    CHECK(json && strstr(json, "\"status\": \"not started\"") && !strstr(json, "completed") && !strstr(json, "out of memory"),
          "the summary of a run not started: %s", json ? strstr(json, "\"status\"") : "(none)");
    swim_free(json);
    CHECK(swim_sim_advance(s, 0.5, &e) == SWIM_OK, "advance to 0.5: %s", e.message);
    json = swim_sim_summary_json(s);
    CHECK(json && strstr(json, "\"status\": \"in progress\"") && !strstr(json, "completed") && !strstr(json, "out of memory"),
          "the summary of a run advanced part way: %.200s", json ? strstr(json, "\"status\"") : "(none)");
    swim_free(json);
    swim_result before = SWIM_RESULT_INIT;
    swim_sim_result(s, &before);
    expect_input(swim_sim_advance(s, NAN, &e), &e, "t", "advance to NaN");
    expect_input(swim_sim_advance(s, INFINITY, &e), &e, "t", "advance to +inf");
    expect_input(swim_sim_advance(s, -INFINITY, &e), &e, "t", "advance to -inf");
    expect_input(swim_sim_advance(s, 0.25, &e), &e, "t", "advance back to 0.25");
    swim_sim_result(s, &r);
    CHECK(!r.finished && r.rows == before.rows && r.t_reached == before.t_reached, "refused times ran nothing");
    CHECK(swim_sim_run(s, &e) == SWIM_OK, "then on to t_end: %s", e.message);
    swim_sim_result(s, &r);
    json = swim_sim_summary_json(s);
    CHECK(r.completed && r.t_reached == 2.0 && json && strstr(json, "\"status\": \"completed\""), "completed at t_end");
    swim_free(json);
    swim_sim_free(s);

    /* the stop flag: 1 is a request to stop, not SIGHUP */
    int flag[2] = {0, 0};
    swim_sim_options os = {.size = sizeof os, .rows = stop_after_rows, .rows_ctx = flag, .stop = (volatile int *)&flag[0]};
    CHECK(swim_sim_create(m, &os, &s, &e) == SWIM_OK, "a simulation with a stop flag");
    const int rc = swim_sim_run(s, &e);
    swim_sim_result(s, &r);
    CHECK(rc == SWIM_EFAILED && strstr(e.message, "stopped by the caller") && !strstr(e.message, "SIG") && !r.completed &&
          r.rows >= 3, "stop = 1: %d '%s' (%ld rows)", rc, e.message, r.rows);
    json = swim_sim_summary_json(s);
    CHECK(json && strstr(json, "\"status\": \"failed\"") && strstr(json, "stopped by the caller"), "its summary says so");
    swim_free(json);
    swim_sim_free(s);
    swim_model_free(m);

    /* a prescribed stroke not run yet says so too */
    const char *short_run[] = {"run.t_end=0.2"};
    if (swim_model_from_file("models/stroke_loop.toml", short_run, 1, &m, &e) != SWIM_OK) {
        CHECK(0, "the stroke scene loads: %s", e.message);
        return;
    }
    CHECK(swim_sim_create(m, NULL, &s, &e) == SWIM_OK, "a stroke simulation: %s", e.message);
    json = swim_sim_summary_json(s);
    CHECK(json && strstr(json, "\"status\": \"not started\"") && !strstr(json, "completed"),
          "the summary of a stroke not run: %s", json ? json : "(none)");
    swim_free(json);
    CHECK(swim_sim_run(s, &e) == SWIM_OK, "the stroke runs: %s", e.message);
    json = swim_sim_summary_json(s);
    CHECK(json && strstr(json, "\"status\": \"completed\""), "and then says completed");
    swim_free(json);
    swim_sim_free(s);
    swim_model_free(m);
}

static void test_inspect_arguments(void)
{
    enum { N = 1, n = 2 * (N + 1) };
    const double c[n] = {1, 0, 0.1, 0}, bad[n] = {1, NAN, 0.1, 0};
    double Mr[9];
    swim_inspection in = {sizeof in, 0, Mr, NULL, NULL, NULL, NULL, NULL};
    swim_error e = SWIM_ERROR_INIT;
    expect_input(swim_inspect(N, c, NULL, 1, 1, NULL, &e), &e, "out", "inspect out NULL");
    expect_input(swim_inspect(N, NULL, NULL, 1, 1, &in, &e), &e, "shape", "inspect shape NULL");
    expect_input(swim_inspect(N, bad, NULL, 1, 1, &in, &e), &e, "shape", "inspect shape NaN");
    expect_input(swim_inspect(N, c, bad, 1, 1, &in, &e), &e, "velocity", "inspect velocity NaN");
    expect_input(swim_inspect(-1, c, NULL, 1, 1, &in, &e), &e, "modes", "modes -1");
    expect_input(swim_inspect(33, c, NULL, 1, 1, &in, &e), &e, "modes", "modes 33");
    expect_input(swim_inspect(N, c, NULL, NAN, 1, &in, &e), &e, "rho0", "rho0 NaN");
    expect_input(swim_inspect(N, c, NULL, 1, INFINITY, &in, &e), &e, "rhof", "rhof inf");
    expect_input(swim_inspect(N, c, NULL, 1e200, 1, &in, &e), &e, "rho0", "rho0 1e200");
    CHECK(swim_inspect(N, c, NULL, 1, 1, &in, &e) == SWIM_OK && in.jmin > 0, "good arguments still work: %s", e.message);
}

/* The kernel cache folder of the scene kernel a run of SCENE uses (its summary's kernel.cache). */
static int kernel_dir(char *dir, size_t len)
{
    swim_model *m;
    swim_sim *s;
    swim_error e = SWIM_ERROR_INIT;
    const char *sets[] = {"run.t_end=0.1"};
    if (swim_model_from_file(SCENE, sets, 1, &m, &e) || swim_sim_create(m, NULL, &s, &e)) return -1;
    swim_sim_run(s, &e);
    char *json = swim_sim_summary_json(s), *at = json ? strstr(json, "\"cache\": \"") : NULL;
    int rc = -1;
    if (at) {
        at += 10;
        const size_t n = strcspn(at, "\"");
        if (n > 0 && n < len) {
            snprintf(dir, len, "%.*s", (int)n, at);
            rc = 0;
        }
    }
    swim_free(json);
    swim_sim_free(s);
    swim_model_free(m);
    return rc;
}

static void test_out_of_descriptors(void)
{
    char dir[4096], so[4200];
    if (kernel_dir(dir, sizeof dir) != 0) {
        CHECK(0, "the scene kernel's cache folder");
        return;
    }
    snprintf(so, sizeof so, "%s/kernel.so", dir);
    struct stat before, after;
    stat(so, &before);
    struct rlimit old, low;
    getrlimit(RLIMIT_NOFILE, &old);
    low = old;
    low.rlim_cur = 64;
    setrlimit(RLIMIT_NOFILE, &low);
    int fds[64], nfd = 0;
    while (nfd < 64 && (fds[nfd] = dup(0)) >= 0) nfd++;   /* every descriptor taken ... */
    if (nfd > 0) close(fds[--nfd]);                         /* ... but one: the scene file is read */
    swim_model *m = NULL;
    swim_error e = SWIM_ERROR_INIT;
    const int rc = swim_model_from_file(SCENE, NULL, 0, &m, &e);
    while (nfd > 0) close(fds[--nfd]);
    setrlimit(RLIMIT_NOFILE, &old);
    CHECK(rc != SWIM_OK && m == NULL && strstr(e.message, "cannot be opened now"),
          "out of descriptors: an error, not a rebuild: %d '%s'", rc, e.message);
    stat(so, &after);
    CHECK(before.st_ino == after.st_ino && before.st_mtime == after.st_mtime, "the cache entry was left as it was");
    CHECK(swim_model_from_file(SCENE, NULL, 0, &m, &e) == SWIM_OK, "with descriptors again, the model loads: %s", e.message);
    swim_model_free(m);
}

/* ---- kernel builds: failures, two threads, signal handlers ---------------------------------- */

static char tmpdir[] = "/tmp/swim-libargs-XXXXXX";
static char log_path[256];

static void on_program_signal(int sig) { (void)sig; }

static int handlers_are_the_programs(void)
{
    const int sigs[3] = {SIGINT, SIGTERM, SIGHUP};
    for (int i = 0; i < 3; i++) {
        struct sigaction now;
        if (sigaction(sigs[i], NULL, &now) != 0 || now.sa_handler != on_program_signal) return 0;
    }
    return 1;
}

typedef struct {
    int rc;
    swim_error e;
} build_job;

static void *inspect_n9(void *p)
{
    build_job *j = p;
    j->e.size = sizeof j->e;
    double shape[20] = {1}, Mr[9];
    swim_inspection in = {sizeof in, 0, Mr, NULL, NULL, NULL, NULL, NULL};
    j->rc = swim_inspect(9, shape, NULL, 1, 1, &in, &j->e);
    return NULL;
}

static atomic_int threads_done;

/* No cache (SWIM_CACHE a file) and no folder for a private build (TMPDIR absent): the kernel of
 * N = 9 and the scene's kernel cannot be had; the error says where, and nothing is printed. */
static void test_no_cache_no_tmpdir(void)
{
    char dir[] = "/tmp/swim-nocache-XXXXXX", cache[128], tmp[128], printed[128];
    if (!mkdtemp(dir)) {
        CHECK(0, "a temporary folder");
        return;
    }
    snprintf(cache, sizeof cache, "%s/cache-is-a-file", dir);
    snprintf(tmp, sizeof tmp, "%s/no-such-folder", dir);
    snprintf(printed, sizeof printed, "%s/printed", dir);
    FILE *f = fopen(cache, "w");
    if (f) fclose(f);
    const env_saved ca = env_set("SWIM_CACHE", cache), td = env_set("TMPDIR", tmp);
    const capture_fds q = capture_begin(printed);
    build_job one;
    inspect_n9(&one);
    swim_model *m = NULL;
    swim_error em = SWIM_ERROR_INIT;
    const int mrc = swim_model_from_file(SCENE, NULL, 0, &m, &em);
    const long long bytes = capture_end(q);
    env_restore(ca);
    env_restore(td);
    CHECK(bytes == 0, "no cache and no TMPDIR: %lld bytes printed", bytes);
    CHECK(one.rc == SWIM_EKERNEL && one.e.status == SWIM_EKERNEL && strstr(one.e.message, "no private folder") &&
          strstr(one.e.message, tmp), "swim_inspect(9) without a cache or TMPDIR: %d '%s'", one.rc, one.e.message);
    CHECK(mrc == SWIM_EKERNEL && m == NULL && strstr(em.message, "no private folder") && strstr(em.message, "scene kernel"),
          "a model without a cache or TMPDIR: %d '%s'", mrc, em.message);
    swim_model_free(m);
    char cmd[200];
    snprintf(cmd, sizeof cmd, "rm -rf '%s'", dir);
    if (system(cmd) != 0) fprintf(stderr, "cannot remove %s\n", dir);
}

static void *watch_handlers(void *p)
{
    int *bad = p;
    while (!atomic_load(&threads_done)) {
        if (!handlers_are_the_programs()) (*bad)++;
        const struct timespec ms = {0, 2000000};
        nanosleep(&ms, NULL);
    }
    return NULL;
}

static void test_kernel_builds(void)
{
    /* a generator that takes 0.3 s and fails, logging when it runs */
    if (!mkdtemp(tmpdir)) {
        CHECK(0, "a temporary folder");
        return;
    }
    char script[256], cache[256];
    snprintf(log_path, sizeof log_path, "%s/runs.log", tmpdir);
    snprintf(script, sizeof script, "%s/fake-python", tmpdir);
    snprintf(cache, sizeof cache, "%s/cache", tmpdir);
    FILE *f = fopen(script, "w");
    fprintf(f, "#!/bin/sh\necho start >> '%s'\nsleep 0.3\necho generator exploded\necho end >> '%s'\nexit 1\n",
            log_path, log_path);
    fclose(f);
    chmod(script, 0755);
    setenv("SWIM_PYTHON", script, 1);
    setenv("SWIM_CACHE", cache, 1);

    struct sigaction sa;
    memset(&sa, 0, sizeof sa);
    sa.sa_handler = on_program_signal;
    sigaction(SIGINT, &sa, NULL);
    sigaction(SIGTERM, &sa, NULL);
    sigaction(SIGHUP, &sa, NULL);

    /* one thread: the cause in the error, nothing printed */
    char out_path[300];
    snprintf(out_path, sizeof out_path, "%s/printed", tmpdir);
    const capture_fds q = capture_begin(out_path);
    build_job one;
    inspect_n9(&one);
    swim_model *m = NULL;
    swim_error em = SWIM_ERROR_INIT;
    const int mrc = swim_model_from_file(SCENE, NULL, 0, &m, &em);   /* its scene kernel: a new cache */
    const long long printed = capture_end(q);
    CHECK(printed == 0, "a failed kernel build printed %lld bytes", printed);
    CHECK(one.rc == SWIM_EKERNEL && one.e.status == SWIM_EKERNEL && strstr(one.e.message, "generating"),
          "swim_inspect without a kernel: %d '%s'", one.rc, one.e.message);
    CHECK(mrc == SWIM_EKERNEL && m == NULL && strstr(em.message, "generating"), "a model without a kernel: %d '%s'", mrc,
          em.message);
    CHECK(handlers_are_the_programs(), "the program's handlers after one build");

    /* two threads at once: one builds, the other waits; the handlers stay the program's */
    unlink(log_path);
    build_job a, b;
    int swapped = 0;
    pthread_t ta, tb, tw;
    atomic_store(&threads_done, 0);
    pthread_create(&tw, NULL, watch_handlers, &swapped);
    pthread_create(&ta, NULL, inspect_n9, &a);
    pthread_create(&tb, NULL, inspect_n9, &b);
    pthread_join(ta, NULL);
    pthread_join(tb, NULL);
    atomic_store(&threads_done, 1);
    pthread_join(tw, NULL);
    CHECK(a.rc == SWIM_EKERNEL && b.rc == SWIM_EKERNEL, "both threads: no kernel (%d, %d)", a.rc, b.rc);
    CHECK(swapped == 0, "a signal handler was replaced %d times while kernels were built", swapped);
    CHECK(handlers_are_the_programs(), "the program's handlers after two threads built at once");
    char runs[64] = "";
    f = fopen(log_path, "r");
    size_t got = f ? fread(runs, 1, sizeof runs - 1, f) : 0;
    if (f) fclose(f);
    runs[got] = '\0';
    CHECK(strcmp(runs, "start\nend\nstart\nend\n") == 0, "the two builds ran one after the other: %s", runs);
    char cmd[300];
    snprintf(cmd, sizeof cmd, "rm -rf '%s'", tmpdir);
    if (system(cmd) != 0) fprintf(stderr, "cannot remove %s\n", tmpdir);
}

int main(void)
{
    test_model_arguments();
    test_sim_arguments();
    test_inspect_arguments();
    test_out_of_descriptors();
    test_no_cache_no_tmpdir();
    test_kernel_builds();   /* last: it points SWIM_PYTHON and SWIM_CACHE elsewhere */
    return check_report("test_library_args");
}
