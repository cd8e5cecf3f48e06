#include "cli/run_outputs.h"

#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>

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

void swim_run_stats_json(FILE *f, const swim_ode_stats *st, const swim_run_timing *t)
{
    fprintf(f, ",\n  \"stats\": {\"steps\": %ld, \"rhs_evaluations\": %ld, \"rejected_steps\": %ld, "
            "\"jacobian_evaluations\": %ld, \"last_step\": %.6g, \"last_order\": %d, \"stiffness_suspected\": %s,\n"
            "            \"order_histogram\": [",
            st->steps, st->rhs_evals, st->rejected, st->jac_evals, st->last_h, st->last_order,
            st->stiff_suspected ? "true" : "false");
    for (int i = 0; i < 13; i++) fprintf(f, "%s%ld", i ? ", " : "", st->order_hist[i]);
    struct rusage ru;
    getrusage(RUSAGE_SELF, &ru);
    fprintf(f, "],\n            \"integrate_seconds\": %.6f, \"diagnostics_seconds\": %.6f, \"output_seconds\": %.6f,",
            t->integrate, t->diagnostics, t->output);
    fprintf(f, "\n            \"rhs_seconds\": %.6f, \"wall_seconds\": %.6f, \"ns_per_rhs\": %.1f, \"max_rss_kb\": %ld,",
            t->rhs, t->wall, t->rhs_calls ? 1e9 * t->rhs / t->rhs_calls : 0.0, ru.ru_maxrss);
    fprintf(f, "\n            \"jacobian\": \"%s\", \"exact_jacobian_calls\": %ld, \"jacobian_seconds\": %.6f}",
            t->jacobian, t->jacobian_calls, t->jacobian_seconds);
}
