/* simulate.c -- the program of a tree made by `swim export SCENE --out DIR` (docs/export.md).
 *
 *   DIR/simulate [--out OUT] [--t-end T] [--output-step H] [--rtol R] [--atol A]
 *                [--event COLUMN:KIND[:stop] ...] [--set KEY=VALUE ...] [--quiet]
 *
 * runs the scene DIR/scene.toml (found next to the program) into OUT (default out/<scene name>)
 * exactly as `swim run SCENE` does: the same job (output/job.h), the same run driver, the same
 * kernels compiled with the same flags, so OUT/trajectory.csv and OUT/summary.json are those of
 * `swim run SCENE --out OUT` with the same options. The options are those of swim run, read by
 * its code (cli/args.c, cli/run_settings.c, copied into the tree): --t-end, --output-step,
 * --rtol and --atol are checked and written into OUT/scene.toml as swim run's are, --event adds
 * to the scene's [events] list, --set is applied before the scene is validated, an option other
 * than --event and --set given twice is refused. Bad input: one line on stderr, exit status 2; a run
 * that fails: exit status 1, its outputs kept.
 *
 * Not part of bin/swim: runtime/export/export.c copies it into the tree.
 */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "cli/args.h"
#include "cli/run_settings.h"
#include "driver/events.h"
#include "export_info.h"
#include "io/message.h"
#include "cli/report.h"
#include "output/job.h"

#define PROG "simulate"

/* swim run's own option rows for what simulate takes (cli/run.c spells the same help) */
enum { OPT_OUT, OPT_T_END, OPT_OUTPUT_STEP, OPT_RTOL, OPT_ATOL, OPT_QUIET, NOPTS };

typedef struct {
    swim_opt opts[NOPTS];
    swim_override sets[SWIM_JOB_MAX_SETS];
    int nsets;
    const char *events[SWIM_RUN_MAX_EVENTS + 1];
    int nevents;
} options;

static void init_options(options *o)
{
    const swim_opt opts[NOPTS] = {
        {"out", 1, NULL, "OUT", "output folder (default out/<scene name>)"},
        {"t-end", 1, NULL, "T", "end time (default: the scene's run.t_end)"},
        {"output-step", 1, NULL, "H", "time between output rows (default: the scene's run.output_step)"},
        {"rtol", 1, NULL, "R", "relative tolerance (default: the scene's run.rtol)"},
        {"atol", 1, NULL, "A", "absolute tolerance (default: the scene's run.atol)"},
        {"quiet", 0, NULL, NULL, "no line on stdout"},
    };
    memcpy(o->opts, opts, sizeof opts);
}

static void usage(FILE *f, const options *o)
{
    fprintf(f, "usage: %s [--out OUT] [--t-end T] [--output-step H] [--rtol R] [--atol A] [--event COLUMN:KIND[:stop] ...]\n"
               "       [--set KEY=VALUE ...] [--quiet]\n"
               "  runs %s (exported by swim %s) as `swim run` does: OUT/trajectory.csv, summary.json, scene.toml,\n"
               "  events.csv with --event (COLUMN: a header of trajectory.csv; KIND: zero, min or max; :stop ends the run)\n",
            PROG, SWIM_EXPORT_SCENE_NAME, SWIM_VERSION);
    swim_args_help(f, o->opts, NOPTS);
}

/* swim run's parsing (cli/args.h): --event and --set may repeat, every other option is given
 * once (a second one is refused). 0, SWIM_ARGS_HELP, or 2 after one line. */
static int read_options(int argc, char **argv, options *o)
{
    if ((o->nsets = swim_args_take_sets(PROG, &argc, argv, 1, o->sets, SWIM_JOB_MAX_SETS)) < 0) return 2;
    o->nevents = swim_args_take_all(PROG, &argc, argv, 1, "event", o->events, SWIM_RUN_MAX_EVENTS + 1);
    if (o->nevents < 0) return 2;
    for (int i = 1; i < argc; i++)
        if (strcmp(argv[i], "--help") == 0 || strcmp(argv[i], "-h") == 0) {
            usage(stdout, o);
            return SWIM_ARGS_HELP;
        }
    return swim_args_parse(PROG, argc, argv, 1, o->opts, NOPTS, NULL, 0, NULL);
}

/* The job's adjustment: the run options over the scene, read, bounded and recorded into
 * OUT/scene.toml by swim run's own code (cli/run_settings.h). */
static int adjust(const swim_scene *s, swim_run_settings *set, swim_override *recorded, int *nrecorded, void *ctx,
                  swim_status *st)
{
    (void)st;   /* the options' refusals are this program's own lines */
    const options *o = ctx;
    if (swim_run_settings_options(o->opts, NOPTS, s, set) != 0) return 2;
    *nrecorded = swim_run_settings_record(o->opts, NOPTS, set, recorded);
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
    options *o = calloc(1, sizeof *o);
    char *scene = scene_file(), *command = swim_shell_words(argc, (const char *const *)argv);
    if (!o || !scene || !command) {
        swim_message(stderr, "%s: out of memory", PROG);
        return 1;
    }
    init_options(o);
    int rc = read_options(argc, argv, o);
    swim_job *job = NULL;
    if (rc == 0) {
        const swim_run_job req = {.cmd = PROG, .scene_file = scene, .scene_name = SWIM_EXPORT_SCENE_NAME, .sets = o->sets,
                                  .nsets = o->nsets, .events = o->events, .nevents = o->nevents, .adjust = adjust,
                                  .adjust_ctx = o, .out = o->opts[OPT_OUT].value, .quiet = 1, .command = command,
                                  .notice = on_notice, .ctx = o};
        swim_status st = SWIM_STATUS_STDERR;
        rc = swim_job_open(&req, &job, &st);
        swim_status_print(&st, stderr);
    }
    if (rc == 0) {
        swim_status st = SWIM_STATUS_STDERR;
        const int status = swim_job_run(job, &st);
        swim_status_print(&st, stderr);
        const swim_run_result *r = swim_job_result(job);
        const char *oerr = swim_job_output_error(job);
        if (oerr) swim_message(stderr, "%s: %s", PROG, oerr);
        if (!o->opts[OPT_QUIET].value)
            swim_message(stdout, "%s: %s (%s); %ld rows in %s", swim_job_scene(job)->path, status ? "FAILED" : "completed",
                         r->reason ? r->reason : "out of memory", r->rows, swim_job_paths(job)->csv_path);
        rc = status ? 1 : 0;
    }
    swim_job_free(job);
    free(command);
    free(scene);
    free(o);
    /* a line lost to a full stdout is a failure, said on stderr (cli/report.h) */
    return swim_stdout_finish(PROG, rc == SWIM_ARGS_HELP ? 0 : rc);
}
