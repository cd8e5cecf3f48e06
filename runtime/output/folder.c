#include "output/folder.h"

#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "io/csv.h"
#include "io/files.h"
#include "io/message.h"
#include "model/flow.h"

static const char *const trace_columns[] = {"t", "h", "order", "accepted", "err", "erk", "growth", "energy", "work"};

struct swim_folder {
    swim_folder_request req;
    swim_run_paths paths;
    swim_csv csv;
    FILE *snap;                 /* snapshots, in memory until the end (open_memstream) */
    char *snap_buf;
    size_t snap_len;
    int nsnap;
    swim_csv trace;
    int trace_open;
    int trace_err;              /* errno of the trace's first write error */
    double *trace_full;         /* full state for the trace's energies */
    char *error;                /* the first output that could not be written, and why */
    int bad;                    /* an output failed (also when error could not be made) */
};

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

/* ---- before the run ------------------------------------------------------------------------ */

/* 1 when a and b name the same file: the same canonical path, or (both existing) the same
 * inode -- a second spelling, a symbolic link or a hard link of one file. */
static int same_file(const char *a, const char *b)
{
    struct stat sa, sb;
    if (stat(a, &sa) == 0 && stat(b, &sb) == 0)
        return sa.st_dev == sb.st_dev && sa.st_ino == sb.st_ino;
    char *ca = swim_canonical_path(a), *cb = swim_canonical_path(b);
    int same = ca && cb && strcmp(ca, cb) == 0;
    free(ca);
    free(cb);
    return same;
}

/* 1 when a file can be created at `path` (its folder exists and may be written), else 0 with
 * errno set. */
static int folder_writable(const char *path)
{
    char *copy = strdup(path);
    if (!copy) return 1;   /* out of memory: swim_folder_open will say so */
    char *slash = strrchr(copy, '/');
    const char *dir = slash == copy ? "/" : slash ? copy : ".";
    if (slash && slash != copy) *slash = '\0';
    int ok = access(dir, W_OK | X_OK) == 0, saved = errno;
    free(copy);
    errno = saved;
    return ok;
}

/* 1 when the folder `dir` exists and may be written, or can be created below the nearest folder
 * above it that exists and may be written; else 0 with errno set. */
static int folder_creatable(const char *dir)
{
    char *p = strdup(dir);
    if (!p) return 1;
    for (;;) {
        struct stat st;
        if (stat(p, &st) == 0) {
            int ok = S_ISDIR(st.st_mode) ? access(p, W_OK | X_OK) == 0 : (errno = ENOTDIR, 0);
            int saved = errno;
            free(p);
            errno = saved;
            return ok;
        }
        char *slash = strrchr(p, '/');
        if (!slash) {
            free(p);
            return access(".", W_OK | X_OK) == 0;
        }
        if (slash == p) slash[1] = '\0';
        else *slash = '\0';
    }
}

int swim_folder_preflight(const swim_folder_request *req, char *err, size_t errlen)
{
    if (req->trace && !folder_writable(req->trace)) {
        snprintf(err, errlen, "swim %s: --trace-steps: cannot write '%s': %s", req->cmd, req->trace, strerror(errno));
        return 2;
    }
    char *def = req->out ? NULL : swim_run_default_out(req->scene_path);
    const char *out = req->out ? req->out : def;
    int rc = 0;
    if (out && !folder_creatable(out)) {
        snprintf(err, errlen, "swim %s: --out: cannot create directory '%s': %s", req->cmd, out, strerror(errno));
        rc = 2;
    }
    free(def);
    return rc;
}

/* ---- opening ------------------------------------------------------------------------------ */

static int paths_open(swim_folder *f, char *err, size_t errlen)
{
    swim_run_paths *p = &f->paths;
    p->dir = f->req.out ? strdup(f->req.out) : swim_run_default_out(f->req.scene_path);
    if (!p->dir) return 1;
    if (swim_mkdirs(p->dir) != 0) {
        snprintf(err, errlen, "swim %s: --out: cannot create directory '%s': %s", f->req.cmd, p->dir, strerror(errno));
        return 2;
    }
    p->csv_path = swim_path_join(p->dir, "trajectory.csv");
    p->snap_path = swim_path_join(p->dir, "snapshots.json");
    p->summary_path = swim_path_join(p->dir, "summary.json");
    p->scene_copy_path = swim_path_join(p->dir, "scene.toml");
    p->events_path = swim_path_join(p->dir, "events.csv");
    p->original_path = swim_path_join(p->dir, "scene.original.toml");
    return p->csv_path && p->snap_path && p->summary_path && p->scene_copy_path && p->events_path && p->original_path ? 0 : 1;
}

/* --trace-steps must not name one of the run's own outputs or the scene: it would interleave
 * two files, or truncate the scene. 0, or 2. */
static int check_trace_path(const swim_folder *f, char *err, size_t errlen)
{
    const swim_run_paths *p = &f->paths;
    const char *const others[] = {p->csv_path, p->snap_path, p->summary_path, p->scene_copy_path, p->events_path,
                                  f->req.scene_file};
    const size_t nown = sizeof others / sizeof others[0] - 1;
    for (size_t i = 0; i < sizeof others / sizeof others[0]; i++)
        if (same_file(f->req.trace, others[i])) {
            snprintf(err, errlen, "swim %s: --trace-steps: '%s' is %s %s; choose another file", f->req.cmd, f->req.trace,
                     i < nown ? "the run's own" : "the scene file", others[i]);
            return 2;
        }
    return 0;
}

/* DIR/scene.toml: the scene as run; the file as given beside it when they differ. A scene read
 * from DIR/scene.toml itself (a rerun of an output folder) is left as it is. */
static int write_scene(swim_folder *f, char *err, size_t errlen)
{
    const swim_run_paths *p = &f->paths;
    const char *cmd = f->req.cmd;
    if (same_file(f->req.scene_file, p->scene_copy_path) && !f->req.resolved) return 0;
    if (f->req.resolved) {
        if (!same_file(f->req.scene_file, p->original_path) && swim_copy_file(f->req.scene_file, p->original_path) != 0) {
            snprintf(err, errlen, "swim %s: --out: cannot write '%s': %s", cmd, p->original_path, strerror(errno));
            return 2;
        }
        if (swim_replace_file(p->scene_copy_path, f->req.resolved, strlen(f->req.resolved)) != 0) {
            snprintf(err, errlen, "swim %s: --out: cannot write '%s': %s", cmd, p->scene_copy_path, strerror(errno));
            return 2;
        }
        return 0;
    }
    if (swim_copy_file(f->req.scene_file, p->scene_copy_path) != 0) {
        snprintf(err, errlen, "swim %s: --out: cannot write '%s': %s", cmd, p->scene_copy_path, strerror(errno));
        return 2;
    }
    /* an original left by an earlier run with overrides would describe another run */
    if (unlink(p->original_path) != 0 && errno != ENOENT) {
        snprintf(err, errlen, "swim %s: --out: cannot remove the old '%s': %s", cmd, p->original_path, strerror(errno));
        return 2;
    }
    return 0;
}

static int folder_open(swim_folder *f, char *err, size_t errlen)
{
    const int prc = paths_open(f, err, errlen);
    if (prc != 0) return prc;
    const swim_run_paths *p = &f->paths;
    const char *cmd = f->req.cmd;
    const char *const written[] = {p->csv_path, p->snap_path, p->summary_path, p->events_path};
    for (size_t i = 0; i < sizeof written / sizeof written[0]; i++)
        if (same_file(written[i], f->req.scene_file)) {
            snprintf(err, errlen, "swim %s: --out: %s would overwrite the scene file %s", cmd, written[i], f->req.scene_file);
            return 2;
        }
    if (f->req.trace) {
        if (check_trace_path(f, err, errlen)) return 2;
        if (swim_csv_open(&f->trace, f->req.trace, trace_columns, 9) != 0) {
            snprintf(err, errlen, "swim %s: --trace-steps: cannot write '%s': %s", cmd, f->req.trace, strerror(errno));
            return 2;
        }
        f->trace_open = 1;
    }
    if (write_scene(f, err, errlen)) return 2;
    if (!f->req.summary_only && swim_csv_open(&f->csv, p->csv_path, f->req.names, f->req.ncol) != 0) {
        snprintf(err, errlen, "swim %s: --out: cannot write '%s': %s", cmd, p->csv_path, strerror(errno));
        return 2;
    }
    const char *const stale[] = {p->summary_path, p->snap_path, p->events_path, f->req.summary_only ? p->csv_path : NULL};
    for (size_t i = 0; i < sizeof stale / sizeof stale[0]; i++)
        if (stale[i] && unlink(stale[i]) != 0 && errno != ENOENT) {
            snprintf(err, errlen, "swim %s: --out: cannot remove the old '%s': %s", cmd, stale[i], strerror(errno));
            return 2;
        }
    if (f->req.snapshots && !f->req.summary_only) {
        if (!(f->snap = open_memstream(&f->snap_buf, &f->snap_len))) return 1;
        fputs("[\n", f->snap);
    }
    return 0;
}

int swim_folder_open(const swim_folder_request *req, swim_folder **out, char *err, size_t errlen)
{
    *out = NULL;
    swim_folder *f = calloc(1, sizeof *f);
    if (!f) {
        snprintf(err, errlen, "swim %s: out of memory", req->cmd);
        return 1;
    }
    f->req = *req;
    const int rc = folder_open(f, err, errlen);
    if (rc == 1) snprintf(err, errlen, "swim %s: out of memory", req->cmd);
    *out = f;   /* freed by the caller in every case */
    return rc;
}

const swim_run_paths *swim_folder_paths(const swim_folder *f) { return &f->paths; }

/* ---- the sink ----------------------------------------------------------------------------- */

/* Record the first output error ("cannot write PATH: why"); later ones are consequences. */
static void output_failed(swim_folder *f, const char *path, int err)
{
    f->bad = 1;
    if (!f->error)   /* NULL when out of memory: bad still fails the run */
        f->error = swim_strprintf("cannot write %s: %s", path, strerror(err ? err : EIO));
}

static int sink_row(void *ctx, const swim_run_row *row, char *why, size_t len)
{
    swim_folder *f = ctx;
    int rc = 0;
    if (!f->req.summary_only && swim_csv_row(&f->csv, row->values) != 0) {
        output_failed(f, f->paths.csv_path, errno);
        rc = -1;
    }
    if (rc == 0 && f->snap && row->snapshot) {
        if (f->nsnap++) fputs(",\n", f->snap);
        if (swim_flow_snapshot(row->d, row->t, row->full, f->snap) != 0) {
            output_failed(f, f->paths.snap_path, ENOMEM);
            rc = -1;
        }
    }
    if (rc == 0 && f->trace_err) {
        output_failed(f, f->req.trace, f->trace_err);
        rc = -1;
    }
    if (rc) snprintf(why, len, "%s", f->error ? f->error : "an output could not be written");
    return rc;
}

/* One row per step attempt, with the energy of each accepted state. */
static void sink_step(void *ctx, const swim_ode_step *st, swim_dynamics *d)
{
    swim_folder *f = ctx;
    if (f->trace_err || !f->trace_open) return;
    if (!f->trace_full && !(f->trace_full = calloc((size_t)d->dim, sizeof(double)))) {
        f->trace_err = ENOMEM;
        return;
    }
    double v[9] = {st->t, st->h, st->order, st->accepted, st->err, st->erk, st->growth, NAN, NAN};
    swim_diag g;
    if (st->y) {
        swim_dynamics_unpack(d, st->y, f->trace_full);
        if (swim_dynamics_diagnostics(d, f->trace_full, &g) == 0) {
            v[7] = g.energy;
            v[8] = g.work;
        }
    }
    if (swim_csv_row(&f->trace, v) != 0) f->trace_err = errno ? errno : EIO;
}

swim_run_sink swim_folder_sink(swim_folder *f)
{
    return (swim_run_sink){sink_row, f->trace_open ? sink_step : NULL, NULL, NULL, f};
}

/* ---- the end ------------------------------------------------------------------------------ */

int swim_folder_finish(swim_folder *f, const swim_run_events *ev)
{
    const char *paths[2] = {f->paths.csv_path, f->req.trace};
    swim_csv *files[2] = {&f->csv, f->trace_open ? &f->trace : NULL};
    for (int i = 0; i < 2; i++) {
        if (!files[i] || !files[i]->line) continue;
        struct stat st = files[i]->st;
        errno = 0;
        if (swim_csv_close(files[i]) != 0) output_failed(f, paths[i], errno);
        else if (!swim_still_names(paths[i], &st) && !f->bad) {
            f->bad = 1;
            f->error = swim_strprintf("%s was removed or replaced during the run: its rows are lost", paths[i]);
        }
    }
    if (f->snap) {
        fputs("\n]\n", f->snap);
        int bad = ferror(f->snap);
        if (fclose(f->snap) != 0 || bad) output_failed(f, f->paths.snap_path, ENOMEM);
        else if (swim_replace_file(f->paths.snap_path, f->snap_buf, f->snap_len) != 0) output_failed(f, f->paths.snap_path, errno);
        f->snap = NULL;
    }
    if (ev && swim_run_events_write_csv(ev, f->paths.events_path) != 0) output_failed(f, f->paths.events_path, errno);
    return f->bad ? -1 : 0;
}

const char *swim_folder_error(const swim_folder *f)
{
    return f->bad ? (f->error ? f->error : "an output could not be written") : NULL;
}

int swim_folder_write_summary(swim_folder *f, void (*fill)(FILE *, void *), void *ctx)
{
    return swim_replace_file_with(f->paths.summary_path, fill, ctx);
}

void swim_folder_free(swim_folder *f)
{
    if (!f) return;
    swim_csv_close(&f->csv);
    if (f->trace_open) swim_csv_close(&f->trace);
    if (f->snap) fclose(f->snap);
    free(f->snap_buf);
    free(f->trace_full);
    free(f->error);
    swim_run_paths *p = &f->paths;
    free(p->dir);
    free(p->csv_path);
    free(p->snap_path);
    free(p->summary_path);
    free(p->scene_copy_path);
    free(p->events_path);
    free(p->original_path);
    free(f);
}
