/* run_outputs.h -- where `swim run` writes, for dynamic scenes and prescribed strokes alike:
 * the output folder (--out, else out/<scene name>) and the paths of its files.
 */
#ifndef SWIM_CLI_RUN_OUTPUTS_H
#define SWIM_CLI_RUN_OUTPUTS_H

typedef struct {
    char *dir, *csv_path, *snap_path, *summary_path, *scene_copy_path, *events_path;   /* owned */
} swim_run_paths;

/* out/<scene file name without its extension>; NULL when out of memory. */
char *swim_run_default_out(const char *scene_path);

/* Creates the folder (out, else the default for scene_path) and fills p with it and the paths
 * DIR/trajectory.csv, snapshots.json, summary.json, scene.toml, events.csv. 0; 1 out of memory;
 * 2 the folder cannot be created (one line on stderr). p is freed by swim_run_paths_free in
 * every case. */
int swim_run_paths_open(swim_run_paths *p, const char *out, const char *scene_path);
void swim_run_paths_free(swim_run_paths *p);

#endif
