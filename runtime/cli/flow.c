/* swim flow DIR: the body and the flow at chosen times of a finished run, computed from the run's
 * own files (DIR/trajectory.csv and the scene copy DIR/scene.toml), so that `swim run` does not
 * pay for pictures nobody asked for.
 *
 * Output: a JSON list of the objects written by swim_flow_snapshot (boundary, density rho0/J,
 * fluid velocity arrows), one per requested time, in increasing time order. A time between two
 * rows gets the shape by cubic Hermite interpolation of c with its stored velocity dc (exact to
 * O(dt^4) on the row grid), dc and the position linearly; a time on a row uses that row as is. */
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "cli/args.h"
#include "cli/commands.h"
#include "io/files.h"
#include "codegen/codegen.h"
#include "model/dynamics.h"
#include "model/flow.h"
#include "scene/scene.h"
#include "io/message.h"
#include "cli/report.h"

#define MAX_TIMES 100000

typedef struct {
    int rows, cols;      /* rows kept, state columns per row (3 + 2n) */
    double *t;           /* rows */
    double *q;           /* rows x cols: x, y, theta, c, dc */
} table;

/* Index of `name` in the comma-separated header, or -1. */
static int header_index(char *const *names, int count, const char *name)
{
    for (int i = 0; i < count; i++)
        if (strcmp(names[i], name) == 0) return i;
    return -1;
}

/* Reads the columns t, x, y, theta, the coordinates and their velocities from trajectory.csv.
 * A truncated last line (a run that stopped while writing) is dropped. 0, or 2 with a message. */
static int read_trajectory(const char *path, const swim_scene *s, table *tb)
{
    FILE *f = fopen(path, "r");
    if (!f) {
        swim_message(stderr, "swim flow: cannot read %s: %s", path, strerror(errno));
        return 2;
    }
    size_t cap = 1 << 16;
    char *line = malloc(cap);
    char *names[512];
    int nnames = 0;
    if (!line || !fgets(line, (int)cap, f)) {
        swim_message(stderr, "swim flow: %s: empty file", path);
        free(line);
        fclose(f);
        return 2;
    }
    line[strcspn(line, "\r\n")] = '\0';
    char *header = strdup(line);
    for (char *tok = strtok(header, ","); tok && nnames < 512; tok = strtok(NULL, ",")) names[nnames++] = tok;
    const int n = s->n, want = 3 + 2 * n;
    int idx[1 + 3 + 2 * SWIM_NMAX];
    char name[32];
    static const char *const head[] = {"t", "x", "y", "theta"};
    for (int i = 0; i < 4; i++) idx[i] = header_index(names, nnames, head[i]);
    for (int i = 0; i < n; i++) {
        swim_coord_name(i, name, sizeof name);
        idx[4 + i] = header_index(names, nnames, name);
        char dname[34];
        snprintf(dname, sizeof dname, "d%s", name);
        idx[4 + n + i] = header_index(names, nnames, dname);
    }
    for (int i = 0; i < 1 + want; i++)
        if (idx[i] < 0) {
            swim_message(stderr, "swim flow: %s: column %d of the state is missing (header does not match %s's %d modes)",
                         path, i, s->path, s->modes);
            free(header);
            free(line);
            fclose(f);
            return 2;
        }
    int rcap = 1024;
    tb->rows = 0;
    tb->cols = want;
    tb->t = malloc(sizeof(double) * rcap);
    tb->q = malloc(sizeof(double) * rcap * want);
    double *v = malloc(sizeof(double) * nnames);
    while (tb->t && tb->q && v && fgets(line, (int)cap, f)) {
        if (!strchr(line, '\n')) break;   /* truncated last line */
        int k = 0;
        char *p = line, *end;
        for (; k < nnames; k++) {
            v[k] = strtod(p, &end);
            if (end == p && strncmp(p, "nan", 3) != 0) break;
            if (end == p) { v[k] = NAN; end = p + 3; }
            p = end;
            if (*p == ',') p++;
        }
        if (k != nnames) break;
        if (tb->rows == rcap) {
            rcap *= 2;
            double *nt = realloc(tb->t, sizeof(double) * rcap), *nq = nt ? realloc(tb->q, sizeof(double) * rcap * want) : NULL;
            if (nt) tb->t = nt;
            if (!nq) break;
            tb->q = nq;
        }
        tb->t[tb->rows] = v[idx[0]];
        for (int i = 0; i < want; i++) tb->q[(size_t)tb->rows * want + i] = v[idx[1 + i]];
        tb->rows++;
    }
    free(v);
    free(header);
    free(line);
    fclose(f);
    if (tb->rows == 0) {
        swim_message(stderr, "swim flow: %s: no complete data row", path);
        return 2;
    }
    return 0;
}

/* The state (x, y, theta, c, dc) at time t inside the rows (see the file comment). */
static void state_at(const table *tb, int n, double t, double *y)
{
    int lo = 0, hi = tb->rows - 1;
    while (hi - lo > 1) {
        int mid = (lo + hi) / 2;
        if (tb->t[mid] <= t) lo = mid; else hi = mid;
    }
    const double *a = tb->q + (size_t)lo * tb->cols, *b = tb->q + (size_t)hi * tb->cols;
    const double h = tb->t[hi] - tb->t[lo];
    if (hi == lo || !(h > 0) || fabs(t - tb->t[lo]) <= 1e-12 * fmax(1.0, fabs(t))) {
        memcpy(y, a, sizeof(double) * tb->cols);
        return;
    }
    if (fabs(t - tb->t[hi]) <= 1e-12 * fmax(1.0, fabs(t))) {
        memcpy(y, b, sizeof(double) * tb->cols);
        return;
    }
    const double s = (t - tb->t[lo]) / h, s2 = s * s, s3 = s2 * s;
    const double h00 = 2 * s3 - 3 * s2 + 1, h10 = s3 - 2 * s2 + s, h01 = -2 * s3 + 3 * s2, h11 = s3 - s2;
    for (int i = 0; i < 3; i++) y[i] = (1 - s) * a[i] + s * b[i];
    for (int i = 0; i < n; i++) {
        y[3 + i] = h00 * a[3 + i] + h10 * h * a[3 + n + i] + h01 * b[3 + i] + h11 * h * b[3 + n + i];
        y[3 + n + i] = (1 - s) * a[3 + n + i] + s * b[3 + n + i];
    }
}

static int cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

/* Whether --out can be written at all, checked before any work: not a folder, and a folder
 * that exists and may be written when the file is new or regular (it is replaced there). */
static int output_unwritable(const char *out)
{
    struct stat st;
    if (stat(out, &st) == 0) {
        if (S_ISDIR(st.st_mode)) {
            errno = EISDIR;
            return 1;
        }
        if (!S_ISREG(st.st_mode)) return access(out, W_OK) != 0;
    }
    char *copy = strdup(out);
    if (!copy) return 1;
    char *slash = strrchr(copy, '/');
    const char *folder = slash ? (slash == copy ? "/" : (*slash = '\0', copy)) : ".";
    int bad = access(folder, W_OK) != 0;
    free(copy);
    return bad;
}

int swim_cmd_flow(int argc, char **argv)
{
    swim_opt opts[] = {
        {"times", 1, NULL, "T1,T2,...", "the times (within the run) at which to compute the body and the flow"},
        {"frames", 1, NULL, "K", "K times evenly spaced over the run, 1..100000 (default 10; not with --times)"},
        {"out", 1, NULL, "FILE|-", "where the JSON goes, - for stdout (default: DIR/snapshots.json)"}};
    const int nopts = (int)(sizeof opts / sizeof opts[0]);
    const char *pos[1];
    int npos = 0;
    const int prc = swim_args_parse("flow", argc, argv, 2, opts, nopts, pos, 1, &npos);
    if (prc) return prc;
    if (npos != 1) {
        swim_message(stderr, "swim flow: expected one run directory, e.g. swim flow out/example3 --frames 10");
        return 2;
    }
    const char *dir = pos[0], *v;
    if (swim_args_get(opts, nopts, "times") && swim_args_get(opts, nopts, "frames")) {
        swim_message(stderr, "swim flow: give either --times or --frames, not both");
        return 2;
    }
    static double times[MAX_TIMES];
    int ntimes = 0;
    long frames = 10;
    if ((v = swim_args_get(opts, nopts, "times"))) {
        if (swim_args_list("flow", "times", v, times, MAX_TIMES, &ntimes)) return 2;
        if (ntimes > MAX_TIMES) {
            swim_message(stderr, "swim flow: --times: at most %d times, got %d", MAX_TIMES, ntimes);
            return 2;
        }
    } else if ((v = swim_args_get(opts, nopts, "frames"))) {
        double f;
        if (swim_args_bounded("flow", opts, nopts, "frames", &f)) return 2;
        frames = (long)f;
    }
    char path[4200], out[4200];
    const char *given = swim_args_get(opts, nopts, "out");
    if (strlen(dir) + 32 >= sizeof path || (given && strlen(given) >= sizeof out)) {
        swim_message(stderr, "swim flow: %s: a path of %zu characters is longer than the system's limit of 4095",
                     strlen(dir) + 32 >= sizeof path ? "the run directory" : "--out",
                     strlen(dir) + 32 >= sizeof path ? strlen(dir) : strlen(given));
        return 2;
    }
    snprintf(path, sizeof path, "%s/scene.toml", dir);
    static swim_scene s;
    FILE *probe = fopen(path, "r");
    if (!probe) {
        swim_message(stderr, "swim flow: %s: %s (a run directory written by swim run has it)", path, strerror(errno));
        return 2;
    }
    fclose(probe);
    swim_status st = SWIM_STATUS_STDERR;
    if (swim_status_shown(&st, swim_scene_load(path, &s, &st))) return 2;
    table tb = {0, 0, NULL, NULL};
    snprintf(path, sizeof path, "%s/trajectory.csv", dir);
    if (read_trajectory(path, &s, &tb)) {
        free(tb.t);
        free(tb.q);
        swim_scene_free(&s);
        return 2;
    }
    const double t0 = tb.t[0], t1 = tb.t[tb.rows - 1];
    if (ntimes > 0) {
        for (int i = 0; i < ntimes; i++)
            if (times[i] < t0 - 1e-9 || times[i] > t1 + 1e-9) {
                swim_message(stderr, "swim flow: --times: %.10g is outside the run's rows [%.10g, %.10g]", times[i], t0, t1);
                free(tb.t);
                free(tb.q);
                swim_scene_free(&s);
                return 2;
            }
        qsort(times, (size_t)ntimes, sizeof(double), cmp_double);
    } else {
        ntimes = (int)frames;
        for (int i = 0; i < ntimes; i++) times[i] = ntimes > 1 ? t0 + (t1 - t0) * i / (ntimes - 1) : t0;
    }
    if ((v = swim_args_get(opts, nopts, "out"))) snprintf(out, sizeof out, "%s", v);
    else snprintf(out, sizeof out, "%s/snapshots.json", dir);
    if (strcmp(out, "-") != 0 && output_unwritable(out)) {
        swim_message(stderr, "swim flow: --out: cannot write '%s': %s", out, strerror(errno));
        free(tb.t);
        free(tb.q);
        swim_scene_free(&s);
        return 2;
    }
    /* The kernel of N modes (boundary data and K): linked in, cached, or generated now. */
    swim_compiled kn;
    if (swim_codegen_kernel(s.modes, &kn, 1, &st) != 0) {
        swim_status_print(&st, stderr);
        swim_message(stderr, "swim flow: %s: no kernel for N = %d, nothing computed", dir, s.modes);
        free(tb.t);
        free(tb.q);
        swim_scene_free(&s);
        return 1;
    }
    const int to_stdout = strcmp(out, "-") == 0;
    /* Formatted in memory and written whole (swim_replace_file): a reader never sees half a
     * file, and a device named by --out (/dev/null) stays a device. */
    char *text = NULL;
    size_t len = 0;
    FILE *f = open_memstream(&text, &len);
    swim_dynamics d;
    int rc = 0;
    if (!f) {
        swim_message(stderr, "swim flow: out of memory");
        rc = 1;
    } else if (swim_dynamics_init(&d, &s, kn.kernel) != 0) {
        swim_message(stderr, "swim flow: out of memory");
        fclose(f);
        rc = 1;
    } else {
        double *y = calloc((size_t)d.dim, sizeof(double));
        fputs("[\n", f);
        for (int i = 0; i < ntimes && y && rc == 0; i++) {
            double t = fmin(fmax(times[i], t0), t1);
            state_at(&tb, s.n, t, y);
            if (i) fputs(",\n", f);
            if (swim_flow_snapshot(&d, t, y, f) != 0) {
                swim_message(stderr, "swim flow: cannot compute the flow at t = %.10g (K not positive definite?)", t);
                rc = 1;
            }
        }
        fputs("\n]\n", f);
        free(y);
        swim_dynamics_free(&d);
        if (fclose(f) != 0 && rc == 0) {
            swim_message(stderr, "swim flow: out of memory");
            rc = 1;
        }
        if (rc == 0 && to_stdout) {
            fwrite(text, 1, len, stdout);
            if (swim_stdout_check("flow") != 0) rc = 1;
        } else if (rc == 0 && swim_replace_file(out, text, len) != 0) {
            swim_message(stderr, "swim flow: --out: cannot write '%s': %s", out, strerror(errno));
            rc = 1;
        }
    }
    free(text);
    swim_compiled_close(&kn);
    free(tb.t);
    free(tb.q);
    swim_scene_free(&s);
    return rc;
}
