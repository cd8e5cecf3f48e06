/* run_outputs.h -- where `swim run` writes, for dynamic scenes and prescribed strokes alike:
 * the output folder (--out, else out/<scene name>) and the paths of its files.
 */
#ifndef SWIM_CLI_RUN_OUTPUTS_H
#define SWIM_CLI_RUN_OUTPUTS_H

typedef struct {
    char *dir, *csv_path, *snap_path, *summary_path, *scene_copy_path, *events_path;   /* owned */
} swim_run_paths;

/* The leading columns of DIR/trajectory.csv, shared by dynamic runs and strokes: t, x, y, theta,
 * the n shape coordinates and their velocities ("d" + name), into names[0 .. 4 + 2n) (the names of
 * the coordinates written into storage[0 .. 2n)). Returns the count; the caller's own columns
 * follow. */
int swim_run_state_columns(int n, const char **names, char storage[][24]);

/* out/<scene file name without its extension>; NULL when out of memory. */
char *swim_run_default_out(const char *scene_path);

/* Creates the folder (out, else the default for scene_path) and fills p with it and the paths
 * DIR/trajectory.csv, snapshots.json, summary.json, scene.toml, events.csv. 0; 1 out of memory;
 * 2 the folder cannot be created (one line on stderr). p is freed by swim_run_paths_free in
 * every case. */
int swim_run_paths_open(swim_run_paths *p, const char *out, const char *scene_path);
void swim_run_paths_free(swim_run_paths *p);

#endif
