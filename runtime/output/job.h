/* job.h -- one scene run into its output folder: what `swim run` does once its command line is
 * read, and what a sweep member is (a request struct, not an argv).
 *
 * A job reads the scene (the overrides applied before it is validated), checks everything a run
 * needs before any output is touched (events, the output folder, the kernels -- generated and
 * cached when missing --, the model's magnitudes, the sensitivity keys, a stroke's allowability),
 * then integrates it (driver/run.h) into its folder (output/folder.h) and writes the summary
 * (driver/summary.h). Dynamic scenes and prescribed strokes alike.
 *
 * Bad input is status 2 with the cause in the caller's swim_status (io/status.h), before any
 * output; a run that fails keeps what it wrote and says why in its summary (status 1). The
 * status is filled by the layer that finds the fault (the scene reader, codegen, the driver,
 * this module) and shown by the command; nothing exits.
 */
#ifndef SWIM_OUTPUT_JOB_H
#define SWIM_OUTPUT_JOB_H

#include <signal.h>

#include "driver/run.h"
#include "output/folder.h"

struct swim_lyapunov_s;   /* model/lyapunov.h */
#include "scene/scene.h"

#define SWIM_JOB_MAX_SETS 64

typedef struct {
    const char *cmd;                    /* "run", for messages */
    const char *scene_file;
    /* The scene's name in the outputs -- summary.json's "scene" and provenance.scene_original,
     * DIR/scene.toml's header, the default out/NAME -- when it is read from another file (the
     * scene.toml of a `swim export` tree, runtime/export/). NULL: scene_file. */
    const char *scene_name;
    const swim_override *sets;          /* applied before the scene is validated (--set) */
    int nsets;
    /* The run's settings resolved: set holds the read scene's [run] (s->run, which stays as
     * read); the command puts its run options over it and checks them once, with their option's
     * name (swim_run_settings_check): 0, or 2 with the cause in st. It may add to `recorded` (at
     * most SWIM_JOB_MAX_SETS) the overrides that write its changes into DIR/scene.toml. The run
     * and its analyses read set. May be NULL: the scene's [run]. */
    int (*adjust)(const swim_scene *s, swim_run_settings *set, swim_override *recorded, int *nrecorded, void *ctx,
                  swim_status *st);
    void *adjust_ctx;
    const char *out;                    /* NULL: out/<scene name> */
    const char *trace;                  /* --trace-steps FILE (dynamic scenes) */
    int quiet;                          /* no progress of kernel generation */
    int generic;                        /* the kernel of the generic structure */
    int summary_only, snapshots;
    const char *const *events;          /* --event specifications, besides the scene's */
    int nevents;
    const char *sensitivity;            /* KEY[,KEY...]: DIR/sensitivity.csv (dynamic scenes) */
    int sens_state_steps;               /* the sensitivities without an error test of their own (the default) */
    int sens_differences;               /* every key by difference quotients (for comparison) */
    double lyapunov;                    /* > 0: DIR/lyapunov.csv, renormalized at this interval */
    const char *command;                /* the command line, for the summary (may be NULL) */
    volatile sig_atomic_t *stop;        /* a stop request (signal), or NULL */
    void (*notice)(void *ctx, const char *line);           /* lines for the user (driver/run.h) */
    void (*progress)(void *ctx, double t, double t_end);
    void (*sens_done)(void *ctx, int nkeys, const char *path, double t, double seconds, long evals);
    void (*lyapunov_done)(void *ctx, const char *path, const struct swim_lyapunov_s *l);
    void *ctx;
} swim_run_job;

typedef struct swim_job swim_job;

/* Everything before the integration. 0 with *out; 1 or 2 with the cause in st (*out is NULL). */
int swim_job_open(const swim_run_job *req, swim_job **out, swim_status *st);
/* The integration, the outputs closed, the sensitivities, the summary. The run's status: 0
 * completed, 1 failed (also when an output, or the summary itself, could not be written: that
 * cause in st). A pass skipped or failed after the trajectory is a notice to st's note. */
int swim_job_run(swim_job *j, swim_status *st);

const swim_scene *swim_job_scene(const swim_job *j);
/* The run's settings, resolved (the scene's [run] with the adjustment over it). */
const swim_run_settings *swim_job_settings(const swim_job *j);
const swim_run_result *swim_job_result(const swim_job *j);
const swim_run_paths *swim_job_paths(const swim_job *j);
swim_dynamics *swim_job_dynamics(swim_job *j);
/* After swim_job_run: the output error the run's reason does not name (NULL: none), and whether
 * the summary itself could not be written. */
const char *swim_job_output_error(const swim_job *j);
int swim_job_summary_failed(const swim_job *j);
void swim_job_free(swim_job *j);

/* The convenience of a sweep member: open, run, free. The exit status of `swim run`; a refusal
 * before the run, or a summary not written, in st. */
int swim_job_execute(const swim_run_job *req, swim_status *st);

#endif
