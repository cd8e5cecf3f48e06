/* simulate.c -- the program of a tree made by `swim export SCENE --out DIR` (docs/export.md).
 *
 *   DIR/simulate [--out OUT] [--t-end T] [--rtol R] [--atol A] [--set KEY=VALUE ...] [--quiet]
 *
 * runs the scene DIR/scene.toml (found next to the program) into OUT (default out/<scene name>)
 * exactly as `swim run SCENE` does: the same job (output/job.h), the same run driver, the same
 * kernels compiled with the same flags, so OUT/trajectory.csv and OUT/summary.json are those of
 * `swim run SCENE --out OUT` with the same options. The options are those of swim run: --t-end,
 * --rtol and --atol are checked and written into OUT/scene.toml as swim run's are, --set is
 * applied before the scene is validated. Bad input: one line on stderr, exit status 2; a run
 * that fails: exit status 1, its outputs kept.
 *
 * Not part of bin/swim: runtime/export/export.c copies it into the tree.
 */
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "export_info.h"
#include "io/message.h"
#include "output/job.h"

#define PROG "simulate"

typedef struct {
    const char *out, *value[3];   /* --t-end, --rtol, --atol as given */
    int quiet;
    swim_override sets[SWIM_JOB_MAX_SETS];
    int nsets;
} options;

static const char *const number_opt[3] = {"t-end", "rtol", "atol"};
static const char *const number_key[3] = {"run.t_end", "run.rtol", "run.atol"};
static const int number_set[3] = {SWIM_SET_T_END, SWIM_SET_RTOL, SWIM_SET_ATOL};

static void usage(FILE *f)
{
    fprintf(f, "usage: %s [--out OUT] [--t-end T] [--rtol R] [--atol A] [--set KEY=VALUE ...] [--quiet]\n"
               "  runs %s (exported by swim %s) as `swim run` does: OUT/trajectory.csv, summary.json, scene.toml\n",
            PROG, SWIM_EXPORT_SCENE_NAME, SWIM_VERSION);
}

/* "--name value" or "--name=value". 0, or 2 after one line. */
static int read_options(int argc, char **argv, options *o)
{
    for (int i = 1; i < argc; i++) {
        const char *a = argv[i];
        if (strcmp(a, "--quiet") == 0) {
            o->quiet = 1;
            continue;
        }
        if (strncmp(a, "--", 2) != 0) {
            swim_message(stderr, "%s: unexpected argument '%s' (the scene is %s; options: --out, --t-end, --rtol, --atol, "
                         "--set, --quiet)", PROG, a, SWIM_EXPORT_SCENE_NAME);
            return 2;
        }
        const char *eq = strchr(a + 2, '=');
        const size_t nlen = eq ? (size_t)(eq - a - 2) : strlen(a + 2);
        const char *names[] = {"out", "t-end", "rtol", "atol", "set"};
        int which = -1;
        for (int k = 0; k < 5; k++)
            if (strlen(names[k]) == nlen && strncmp(a + 2, names[k], nlen) == 0) which = k;
        if (which < 0) {
            swim_message(stderr, "%s: unknown option '%.*s' (options: --out, --t-end, --rtol, --atol, --set, --quiet)", PROG,
                         (int)(nlen + 2), a);
            return 2;
        }
        const char *v = eq ? eq + 1 : i + 1 < argc ? argv[++i] : NULL;
        if (!v) {
            swim_message(stderr, "%s: --%s: missing value", PROG, names[which]);
            return 2;
        }
        if (which == 0) {
            o->out = v;
        } else if (which == 4) {
            char err[256];
            if (o->nsets == SWIM_JOB_MAX_SETS) {
                swim_message(stderr, "%s: --set: more than %d overrides", PROG, SWIM_JOB_MAX_SETS);
                return 2;
            }
            if (swim_override_parse(v, &o->sets[o->nsets], err, sizeof err) != 0) {
                swim_message(stderr, "%s: --set: %s", PROG, err);
                return 2;
            }
            o->nsets++;
        } else {
            o->value[which - 1] = v;
        }
    }
    return 0;
}

/* A finite number, as swim run reads its number options. */
static int number(const char *opt, const char *v, double *out)
{
    char *end;
    errno = 0;
    const double x = strtod(v, &end);
    if (*v == '\0' || *end != '\0' || end == v || errno == ERANGE || !isfinite(x)) {
        swim_message(stderr, "%s: --%s: '%s' is not a finite number", PROG, opt, v);
        return 2;
    }
    *out = x;
    return 0;
}

/* The job's adjustment: the run options over the scene, checked and recorded as swim run's are
 * (cli/run_settings.c): the bounds name the option, OUT/scene.toml gets "run.t_end=%.17g". */
static int adjust(swim_scene *s, swim_override *recorded, int *nrecorded, void *ctx)
{
    const options *o = ctx;
    swim_run_overrides cli = {{0}};
    double *field[3] = {&s->t_end, &s->rtol, &s->atol};
    for (int k = 0; k < 3; k++) {
        if (!o->value[k]) continue;
        if (number(number_opt[k], o->value[k], field[k])) return 2;
        cli.given[number_set[k]] = 1;
    }
    if (swim_run_settings_check(s, &cli) != 0) return 2;
    *nrecorded = 0;
    for (int k = 0; k < 3; k++) {
        if (!o->value[k]) continue;
        char text[160];
        snprintf(text, sizeof text, "%s=%.17g", number_key[k], *field[k]);
        if (swim_override_parse(text, &recorded[*nrecorded], NULL, 0) == 0) ++*nrecorded;
    }
    return 0;
}

/* DIR/scene.toml: next to this program. */
static char *scene_file(void)
{
    char exe[4096];
    const ssize_t n = readlink("/proc/self/exe", exe, sizeof exe - 1);
    if (n <= 0 || (size_t)n >= sizeof exe - 1) return strdup("scene.toml");
    exe[n] = '\0';
    char *slash = strrchr(exe, '/');
    if (slash) *slash = '\0';
    return swim_strprintf("%s/scene.toml", slash ? exe : ".");
}

static void on_notice(void *ctx, const char *line) { swim_message(stderr, "%s", line); }

int main(int argc, char **argv)
{
    for (int i = 1; i < argc; i++)
        if (strcmp(argv[i], "--help") == 0 || strcmp(argv[i], "-h") == 0) {
            usage(stdout);
            return 0;
        }
    options *o = calloc(1, sizeof *o);
    char *scene = scene_file(), *command = swim_shell_words(argc, (const char *const *)argv);
    if (!o || !scene || !command) {
        swim_message(stderr, "%s: out of memory", PROG);
        return 1;
    }
    int rc = read_options(argc, argv, o);
    swim_job *job = NULL;
    if (rc == 0) {
        const swim_run_job req = {.cmd = PROG, .scene_file = scene, .scene_name = SWIM_EXPORT_SCENE_NAME, .sets = o->sets, .nsets = o->nsets, .adjust = adjust,
                                  .adjust_ctx = o, .out = o->out, .quiet = 1, .command = command,
                                  .notice = on_notice, .ctx = o};
        rc = swim_job_open(&req, &job);
    }
    if (rc == 0) {
        const int status = swim_job_run(job);
        const swim_run_result *r = swim_job_result(job);
        const char *oerr = swim_job_output_error(job);
        if (oerr) swim_message(stderr, "%s: %s", PROG, oerr);
        if (!o->quiet)
            swim_message(stdout, "%s: %s (%s); %ld rows in %s", swim_job_scene(job)->path, status ? "FAILED" : "completed",
                         r->reason ? r->reason : "out of memory", r->rows, swim_job_paths(job)->csv_path);
        rc = status ? 1 : 0;
        if (fflush(stdout) != 0 && rc == 0) rc = 1;
    }
    swim_job_free(job);
    free(command);
    free(scene);
    free(o);
    return rc;
}
