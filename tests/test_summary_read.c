/* The one summary reader (driver/summary_read.h): values at their path in the JSON tree, integers
 * exactly, null and absent as unset, whole and stopped summaries told apart, and a text that is
 * not one strict JSON object refused with its line and column; a summary's tree read directly
 * (swim_summary_take) gives what its text gives: -0 as 0, a byte of no UTF-8 text as U+FFFD. */
#include "check.h"
#include "driver/summary_read.h"
#include "io/json.h"
#include "sweep/sweep.h"

#include <errno.h>
#include <jansson.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

/* The shape of a summary of swim run (runtime/cli/run.c): "steps" first in projection. */
static const char *const RUN =
    "{\n  \"scene\": \"models/example3.toml\",\n"
    "  \"projection\": {\"enabled\": true, \"steps\": 142, \"max_change\": 5.67e-12},\n"
    "  \"status\": \"completed\",\n  \"reason\": \"reached t_end = 1\",\n"
    "  \"t_end\": 1,\n  \"t_reached\": 1,\n"
    "  \"final_state\": {\"t\": 1, \"x\": 0, \"y\": 0.057913299135342496, \"theta\": -0.25, \"c\": [1, 0]},\n"
    "  \"energy_drift_abs\": 1.8657630995733143e-11,\n  \"energy_drift_rel\": 1.90563238414292e-11,\n"
    "  \"jmin\": 0.28000000000006164,\n"
    "  \"step_checks\": {\"enabled\": true, \"steps\": 121, \"seconds\": 0.000124},\n"
    "  \"impacts\": {\"jmin_max\": null},\n"
    "  \"stats\": {\"steps\": 122, \"rhs_evaluations\": 245, \"integrate_seconds\": 0.000312,\n"
    "            \"wall_seconds\": 0.001542, \"max_rss_kb\": 5212}\n}\n";

static char *replace(const char *text, const char *from, const char *to)
{
    const char *at = strstr(text, from);
    if (!at) return NULL;
    size_t n = strlen(text) - strlen(from) + strlen(to) + 1;
    char *out = malloc(n);
    snprintf(out, n, "%.*s%s%s", (int)(at - text), text, to, at + strlen(from));
    return out;
}

static void test_run_summary(void)
{
    swim_summary s;
    char err[256];
    int rc = swim_summary_read("m/summary.json", RUN, &s, err, sizeof err);
    CHECK(rc == SWIM_SUMMARY_OK, "a run's summary reads: %d %s", rc, err);
    CHECK(strcmp(s.status, "completed") == 0 && strcmp(s.reason, "reached t_end = 1") == 0, "status, reason");
    CHECK(s.whole && !s.stopped, "whole, not stopped");
    CHECK(s.steps.set && s.steps.value == 122, "steps is stats.steps (122), not projection.steps: %lld", s.steps.value);
    CHECK(s.rhs_evaluations.set && s.rhs_evaluations.value == 245, "stats.rhs_evaluations");
    CHECK(s.energy_balance_abs.set && s.energy_balance_abs.value == 1.8657630995733143e-11, "energy_drift_abs");
    CHECK(s.energy_drift_rel.value == 1.90563238414292e-11 && s.jmin.value == 0.28000000000006164, "rel drift, jmin");
    CHECK(s.t_reached.set && s.t_reached.value == 1.0, "t_reached (an integer in the text) as a number");
    CHECK(s.x.value == 0 && s.y.value == 0.057913299135342496 && s.theta.value == -0.25, "final_state.x, y, theta");
    CHECK(s.integrate_seconds.value == 0.000312 && s.wall_seconds.value == 0.001542, "stats timings");

    char *t = replace(RUN, "\"steps\": 122", "\"steps\": 9007199254740993");
    rc = swim_summary_read(NULL, t, &s, err, sizeof err);
    CHECK(rc == 0 && s.steps.value == 9007199254740993LL, "an integer beyond 2^53 exactly: %lld", s.steps.value);
    free(t);
    t = replace(RUN, "\"jmin\": 0.28000000000006164", "\"jmin\": null");
    char *u = replace(t, "\"t_reached\": 1,", "");
    rc = swim_summary_read(NULL, u, &s, err, sizeof err);
    CHECK(rc == 0 && !s.jmin.set && !s.t_reached.set && s.steps.set, "null and absent values are unset");
    free(t);
    free(u);
}

static void test_whole_and_stopped(void)
{
    swim_summary s;
    char err[256];
    char *t = replace(RUN, ", \"max_rss_kb\": 5212", "");
    CHECK(swim_summary_read(NULL, t, &s, err, sizeof err) == 0 && !s.whole, "without stats.max_rss_kb: not whole");
    free(t);
    t = replace(RUN, "\"reached t_end = 1\"", "\"interrupted by SIGINT at t = 0.5\"");
    CHECK(swim_summary_read(NULL, t, &s, err, sizeof err) == 0 && s.whole && s.stopped, "interrupted: stopped");
    free(t);
    t = replace(RUN, "\"reached t_end = 1\"", "\"terminated by SIGTERM at t = 0.5\"");
    CHECK(swim_summary_read(NULL, t, &s, err, sizeof err) == 0 && s.whole && s.stopped, "terminated by: stopped");
    free(t);
    t = replace(RUN, "\"reached t_end = 1\"", "\"left D at t = 0.5 (interrupted)\"");
    CHECK(swim_summary_read(NULL, t, &s, err, sizeof err) == 0 && s.whole && !s.stopped, "a reason that only holds the word");
    free(t);
    const char *crashed = "{\n  \"scene\": \"a.toml\",\n  \"status\": \"crashed\",\n"
                          "  \"reason\": \"member process killed by signal 11 (Segmentation fault)\"\n}\n";
    CHECK(swim_summary_read(NULL, crashed, &s, err, sizeof err) == 0 && s.whole && !s.stopped && !s.steps.set &&
          !s.t_reached.set, "a crashed summary: whole, no numbers");
    CHECK(swim_summary_read(NULL, "{\"stats\": {\"max_rss_kb\": 1}}", &s, err, sizeof err) == 0 && !s.whole,
          "no status: not whole");
}

static void test_refused(void)
{
    swim_summary s;
    char err[256];
    size_t n = strlen(RUN);
    char *cut = strndup(RUN, n / 2);
    int rc = swim_summary_read("m/summary.json", cut, &s, err, sizeof err);
    CHECK(rc == SWIM_SUMMARY_INVALID && !s.whole && strncmp(err, "m/summary.json:", 15) == 0,
          "a truncated summary: invalid, named: %d %s", rc, err);
    free(cut);
    char *t = malloc(n + 8), where[64];
    snprintf(t, n + 8, "%s{}\n", RUN);
    int line = 1;
    for (const char *c = RUN; *c; c++) line += *c == '\n';
    snprintf(where, sizeof where, "m/summary.json:%d:1: ", line);   /* the line after the object */
    rc = swim_summary_read("m/summary.json", t, &s, err, sizeof err);
    CHECK(rc == SWIM_SUMMARY_INVALID && strstr(err, where) == err, "text after the object, at %s: %s", where, err);
    free(t);
    t = replace(RUN, "\"t_end\": 1,", "\"status\": \"failed\",");
    rc = swim_summary_read("s.json", t, &s, err, sizeof err);
    CHECK(rc == SWIM_SUMMARY_INVALID && strstr(err, "s.json:6:") == err, "a key twice: refused at its line: %s", err);
    free(t);
    t = replace(RUN, "\"steps\": 122", "\"steps\": \"122\"");
    rc = swim_summary_read("s.json", t, &s, err, sizeof err);
    CHECK(rc == SWIM_SUMMARY_INVALID && strstr(err, "stats.steps"), "a string for stats.steps: %s", err);
    free(t);
    t = replace(RUN, "\"steps\": 122", "\"steps\": 122.5");
    rc = swim_summary_read("s.json", t, &s, err, sizeof err);
    CHECK(rc == SWIM_SUMMARY_INVALID && strstr(err, "stats.steps"), "a real for stats.steps: %s", err);
    free(t);
    rc = swim_summary_read("s.json", "[1, 2]", &s, err, sizeof err);
    CHECK(rc == SWIM_SUMMARY_INVALID, "an array: %s", err);
    rc = swim_summary_read("s.json", "{\"jmin\": NaN}", &s, err, sizeof err);
    CHECK(rc == SWIM_SUMMARY_INVALID && strstr(err, "s.json:1:"), "NaN is not JSON: %s", err);
    rc = swim_summary_read("/nonexistent/summary.json", NULL, &s, err, sizeof err);
    CHECK(rc == SWIM_SUMMARY_UNREADABLE && errno == ENOENT && strstr(err, "/nonexistent/summary.json: "),
          "a missing file: %d %s", rc, err);
    CHECK(swim_summary_read(NULL, "{", &s, NULL, 0) == SWIM_SUMMARY_INVALID, "err may be NULL");
}

static void test_file_and_long_reason(void)
{
    char path[] = "/tmp/swim-summary-XXXXXX";
    int fd = mkstemp(path);
    CHECK(fd >= 0, "a temporary file");
    if (fd < 0) return;
    /* a reason longer than the struct holds, whose cut falls inside a 2-byte character */
    char reason[SWIM_SUMMARY_REASON + 16];
    memset(reason, 'a', sizeof reason);
    for (size_t i = SWIM_SUMMARY_REASON - 3; i + 1 < sizeof reason - 1; i += 2) memcpy(reason + i, "\xc3\xa9", 2);
    reason[sizeof reason - 1] = '\0';
    char *t = replace(RUN, "reached t_end = 1", reason);
    FILE *f = fdopen(fd, "w");
    fputs(t, f);
    fclose(f);
    swim_summary s;
    char err[256];
    int rc = swim_summary_read(path, NULL, &s, err, sizeof err);
    size_t len = strlen(s.reason);
    CHECK(rc == 0 && s.whole && s.steps.value == 122, "read from the file: %d %s", rc, err);
    CHECK(len < SWIM_SUMMARY_REASON && len >= SWIM_SUMMARY_REASON - 3 && ((unsigned char)s.reason[len - 1] == 0xA9 ||
          s.reason[len - 1] == 'a'), "a long reason cut at a character boundary (%zu bytes)", len);
    unlink(path);
    free(t);
}

/* The family table's columns (members.csv, family.h5, libswim's swim_family_column, Python's sweep
 * rows) name where summary.json holds each value: that path gives what the reader put at the
 * column's place in swim_summary, for every column, so the two cannot drift apart. */
static void test_family_columns_paths(void)
{
    swim_summary s;
    char err[256];
    CHECK(swim_summary_read(NULL, RUN, &s, err, sizeof err) == 0, "the run's summary reads: %s", err);
    json_t *root = json_loads(RUN, 0, NULL);
    int n = 0;
    const sweep_column *cols = sweep_columns(&n);
    CHECK(root && n == 11, "the summary parses, and the table has its 11 columns (%d)", n);
    for (int i = 0; root && i < n; i++) {
        char path[64];
        snprintf(path, sizeof path, "%s", cols[i].path);
        json_t *v = root;
        for (char *key = strtok(path, "."); key && v; key = strtok(NULL, ".")) v = json_object_get(v, key);
        const char *at = (const char *)&s + cols[i].offset;
        const double read = cols[i].integer ? (double)((const swim_summary_count *)at)->value
                                            : ((const swim_summary_real *)at)->value;
        CHECK(v && json_is_number(v) && json_number_value(v) == read, "%s at %s: %.17g, the reader's %.17g", cols[i].name,
              cols[i].path, v ? json_number_value(v) : -1.0, read);
    }
    json_decref(root);
}

/* A tree and the text swim_json_write makes of it read alike. */
static void test_tree_is_its_text(void)
{
    json_t *root = json_object(), *fs = json_object(), *stats = json_object();
    json_object_set_new(root, "status", json_string("failed"));
    json_object_set_new(root, "reason", json_string_nocheck("scene a\xff" "b.toml: \xc3\xa9 bad"));
    json_object_set_new(root, "t_reached", json_real(0.5));
    json_object_set_new(fs, "x", json_real(-0.0));
    json_object_set_new(fs, "y", json_real(0.1 + 0.2));
    json_object_set_new(fs, "theta", json_real(-1e-300));
    json_object_set_new(root, "final_state", fs);
    json_object_set_new(stats, "steps", json_integer(12));
    json_object_set_new(root, "stats", stats);
    char *text = NULL;
    size_t len = 0;
    FILE *f = open_memstream(&text, &len);
    if (f) {
        swim_json_write(f, root);
        fclose(f);
    }
    swim_summary a, b;
    char err[256];
    const int rc_tree = swim_summary_take(root, NULL, &a, err, sizeof err);
    const int rc_text = text ? swim_summary_read(NULL, text, &b, err, sizeof err) : -9;
    CHECK(rc_tree == SWIM_SUMMARY_OK && rc_text == SWIM_SUMMARY_OK, "both read: %d %d %s", rc_tree, rc_text, err);
    CHECK(strcmp(a.reason, b.reason) == 0 && strstr(a.reason, "a\xEF\xBF\xBD" "b") && strstr(a.reason, "\xc3\xa9"),
          "the reason alike, U+FFFD for the stray byte: '%s' / '%s'", a.reason, b.reason);
    CHECK(memcmp(&a.x.value, &b.x.value, sizeof(double)) == 0 && a.x.value == 0 && !signbit(a.x.value) &&
          a.y.value == b.y.value && a.theta.value == b.theta.value && a.t_reached.value == b.t_reached.value &&
          a.steps.value == b.steps.value && strcmp(a.status, b.status) == 0, "the numbers alike, -0 as 0");
    free(text);
    json_decref(root);
}

int main(void)
{
    test_run_summary();
    test_family_columns_paths();
    test_whole_and_stopped();
    test_refused();
    test_file_and_long_reason();
    test_tree_is_its_text();
    return check_report("test_summary_read");
}
