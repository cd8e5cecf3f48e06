#include "cli/run_outputs.h"

#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "io/files.h"
#include "kernel/coords.h"
#include "io/message.h"

char *swim_run_default_out(const char *scene_path)
{
    const char *base = strrchr(scene_path, '/');
    base = base ? base + 1 : scene_path;
    char *out = swim_path_join("out", base);
    if (!out) return NULL;
    char *dot = strrchr(out, '.');
    if (dot && dot > out + 4) *dot = '\0';
    return out;
}

int swim_run_paths_open(swim_run_paths *p, const char *out, const char *scene_path)
{
    p->dir = out ? strdup(out) : swim_run_default_out(scene_path);
    if (!p->dir) return 1;
    if (swim_mkdirs(p->dir) != 0) {
        swim_message(stderr, "swim run: --out: cannot create directory '%s': %s", p->dir, strerror(errno));
        return 2;
    }
    p->csv_path = swim_path_join(p->dir, "trajectory.csv");
    p->snap_path = swim_path_join(p->dir, "snapshots.json");
    p->summary_path = swim_path_join(p->dir, "summary.json");
    p->scene_copy_path = swim_path_join(p->dir, "scene.toml");
    p->events_path = swim_path_join(p->dir, "events.csv");
    return p->csv_path && p->snap_path && p->summary_path && p->scene_copy_path && p->events_path ? 0 : 1;
}

void swim_run_paths_free(swim_run_paths *p)
{
    free(p->dir);
    free(p->csv_path);
    free(p->snap_path);
    free(p->summary_path);
    free(p->scene_copy_path);
    free(p->events_path);
    memset(p, 0, sizeof *p);
}

int swim_run_state_columns(int n, const char **names, char storage[][24])
{
    static const char *const head[] = {"t", "x", "y", "theta"};
    int c = 0;
    for (int i = 0; i < 4; i++) names[c++] = head[i];
    for (int i = 0; i < n; i++) {
        swim_coord_name(i, storage[i], 24);
        names[c++] = storage[i];
    }
    for (int i = 0; i < n; i++) {
        storage[n + i][0] = 'd';
        swim_coord_name(i, storage[n + i] + 1, 23);
        names[c++] = storage[n + i];
    }
    return c;
}
