/* folder.h -- a run written into its output folder: the sink (driver/run.h) that keeps the rows
 * of a run as DIR/trajectory.csv, the flow snapshots (snapshots.json, with --snapshots), the step
 * trace (--trace-steps FILE), and at the end events.csv, scene.toml and summary.json, for dynamic
 * scenes and prescribed strokes alike.
 *
 * DIR/scene.toml is the scene as run (the overrides applied, scene/resolve.h); the file as given
 * is kept beside it as DIR/scene.original.toml when they differ. summary.json, snapshots.json,
 * events.csv and scene.toml are written whole, atomically (swim_replace_file): a reader never sees
 * a part; each row of trajectory.csv is flushed, so a run that stops keeps every row it wrote.
 * A write that fails is remembered (the first one, with why) and fails the run; nothing here
 * prints or exits: errors are one line of text for the caller to show.
 */
#ifndef SWIM_OUTPUT_FOLDER_H
#define SWIM_OUTPUT_FOLDER_H

#include <stddef.h>
#include <stdio.h>

#include "driver/events.h"
#include "driver/run.h"

typedef struct {
    char *dir, *csv_path, *snap_path, *summary_path, *scene_copy_path, *events_path, *original_path;   /* owned */
} swim_run_paths;

typedef struct {
    const char *cmd;               /* "run", for messages ("swim run: --out: ...") */
    const char *out;               /* --out, or NULL for out/<scene name> */
    const char *scene_file;        /* the scene file as given: never overwritten */
    const char *scene_path;        /* the scene's path as the scene knows it (for the default DIR) */
    const char *resolved;          /* DIR/scene.toml: the scene as run (NULL: a copy of scene_file) */
    const char *trace;             /* --trace-steps FILE, or NULL */
    int summary_only;              /* rows computed, not written; no snapshots */
    int snapshots;                 /* snapshots.json */
    const char *const *names;      /* the columns of trajectory.csv */
    int ncol;
} swim_folder_request;

typedef struct swim_folder swim_folder;

/* out/<scene file name without its extension>; NULL when out of memory. */
char *swim_run_default_out(const char *scene_path);

/* Before any work: the folders of the outputs can be created (generating a kernel can take a
 * minute; an output that cannot be made is bad input). 0, or 2 with the line in err. */
int swim_folder_preflight(const swim_folder_request *req, char *err, size_t errlen);
/* Creates DIR, writes scene.toml (and scene.original.toml), opens trajectory.csv and the trace,
 * removes a summary, snapshots, events and rows an earlier run left in DIR that this run does not
 * replace at once. 0; 1 out of memory; 2 an output cannot be created; the line in err. */
int swim_folder_open(const swim_folder_request *req, swim_folder **out, char *err, size_t errlen);
/* The sink for swim_run_request.sink (rows, steps; notice and progress stay NULL). */
swim_run_sink swim_folder_sink(swim_folder *f);
const swim_run_paths *swim_folder_paths(const swim_folder *f);
/* Closes trajectory.csv and the trace (checking they are still the files named by their paths),
 * writes snapshots.json and events.csv (ev may be NULL). 0, or -1 when an output failed. */
int swim_folder_finish(swim_folder *f, const swim_run_events *ev);
/* The first output that could not be written, and why ("cannot write PATH: ..."); NULL if none. */
const char *swim_folder_error(const swim_folder *f);
/* summary.json written whole by fill(f, ctx). 0, or -1 with errno set. */
int swim_folder_write_summary(swim_folder *f, void (*fill)(FILE *, void *), void *ctx);
void swim_folder_free(swim_folder *f);

#endif
