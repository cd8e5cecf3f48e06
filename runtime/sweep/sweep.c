#define _GNU_SOURCE   /* open_memstream, prctl */
#include "sweep/sweep.h"

#include <errno.h>
#include <fcntl.h>
#include <math.h>
#include <stddef.h>
#include <signal.h>
#include <stdarg.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#include <sys/file.h>
#include <sys/prctl.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>
#include <dirent.h>

#include "io/clock.h"
#include "io/files.h"
#include "io/json.h"
#include "codegen/codegen.h"
#include "ode/ode.h"
#include "io/message.h"
#include "driver/summary_read.h"
#include "output/job.h"
#include "scene/scene.h"

/* ------------------------------------------------------------------ specs */

static int parse_double(const char *s, size_t len, double *out)
{
    char buf[64];
    if (len == 0 || len >= sizeof buf) return -1;
    memcpy(buf, s, len);
    buf[len] = '\0';
    char *end;
    errno = 0;
    double v = strtod(buf, &end);
    if (*end != '\0' || errno == ERANGE || !isfinite(v)) return -1;
    *out = v;
    return 0;
}

/* START:STOP:COUNT, the endpoints exact (the last value is STOP itself, not START + (COUNT-1)h). */
static int parse_range(const char *spec, int logarithmic, double **values, long *count, char *err, size_t errlen)
{
    const char *c1 = strchr(spec, ':'), *c2 = c1 ? strchr(c1 + 1, ':') : NULL;
    double a, b;
    char *end;
    if (!c1 || !c2 || strchr(c2 + 1, ':') || parse_double(spec, (size_t)(c1 - spec), &a) ||
        parse_double(c1 + 1, (size_t)(c2 - c1 - 1), &b)) {
        snprintf(err, errlen, "expected %sSTART:STOP:COUNT with finite numbers, got '%s'", logarithmic ? "log:" : "", spec);
        return -1;
    }
    errno = 0;
    long n = strtol(c2 + 1, &end, 10);
    if (c2[1] == '\0' || *end != '\0' || errno || n < 1 || n > SWEEP_MAX_MEMBERS) {
        snprintf(err, errlen, "COUNT must be an integer 1..%ld, got '%s'", SWEEP_MAX_MEMBERS, c2 + 1);
        return -1;
    }
    if (logarithmic && !(a > 0 && b > 0)) {
        snprintf(err, errlen, "log:START:STOP:COUNT needs START > 0 and STOP > 0, got '%s'", spec);
        return -1;
    }
    double *v = malloc(sizeof(double) * (size_t)n);
    if (!v) { snprintf(err, errlen, "out of memory"); return -1; }
    for (long i = 0; i < n; i++) {
        double f = n > 1 ? (double)i / (double)(n - 1) : 0.0;
        v[i] = logarithmic ? exp(log(a) + f * (log(b) - log(a))) : a + f * (b - a);
    }
    v[0] = a;
    if (n > 1) v[n - 1] = b;
    *values = v;
    *count = n;
    return 0;
}

int sweep_parse_spec(const char *spec, double **values, long *count, char *err, size_t errlen)
{
    if (strncmp(spec, "log:", 4) == 0) return parse_range(spec + 4, 1, values, count, err, errlen);
    if (strchr(spec, ':')) return parse_range(spec, 0, values, count, err, errlen);
    long n = 1;
    for (const char *q = spec; *q; q++) n += *q == ',';
    double *v = malloc(sizeof(double) * (size_t)n);
    if (!v) { snprintf(err, errlen, "out of memory"); return -1; }
    const char *q = spec;
    for (long i = 0; i < n; i++) {
        const char *comma = strchr(q, ',');
        size_t len = comma ? (size_t)(comma - q) : strlen(q);
        if (parse_double(q, len, &v[i])) {
            snprintf(err, errlen, "item %ld ('%.*s') of '%s' is not a finite number (SPEC: START:STOP:COUNT, "
                     "log:START:STOP:COUNT or V1,V2,...)", i + 1, (int)len, q, spec);
            free(v);
            return -1;
        }
        q = comma ? comma + 1 : q + len;
    }
    *values = v;
    *count = n;
    return 0;
}

double sweep_value(const sweep_plan *p, long m, int v)
{
    if (p->zip) return p->vary[v].values[m];
    long stride = 1;
    for (int w = p->nvary - 1; w > v; w--) stride *= p->vary[w].count;
    return p->vary[v].values[(m / stride) % p->vary[v].count];
}

/* --------------------------------------------------------------- options */

void sweep_free(sweep_plan *p)
{
    for (int i = 0; i < p->nvary; i++) free(p->vary[i].values);
    free(p->finished);
    p->finished = NULL;
    free(p->scene_text);
    p->scene_text = NULL;
    if (p->lock_fd >= 0) {
        /* the lock file goes while it is held: a sweep that opened it meanwhile finds, once it has
         * the lock, that its file is no longer DIR's (lock_dir checks) and opens the path again */
        char path[SWIM_SWEEP_PATH + 64];
        snprintf(path, sizeof path, "%s/sweep.lock", p->dir);
        unlink(path);
        close(p->lock_fd);   /* releases DIR's lock */
    }
    p->lock_fd = -1;
}

/* --------------------------------------------------------- member scenes */

/* The overrides of member m: the fixed ones, then one per varied key. */
static int member_overrides(const sweep_plan *p, long m, swim_override *ov)
{
    int n = 0;
    for (int i = 0; i < p->nsets; i++) ov[n++] = p->sets[i];
    for (int v = 0; v < p->nvary; v++) {
        ov[n] = p->vary[v].tmpl;
        ov[n].value = sweep_value(p, m, v);
        snprintf(ov[n].text, sizeof ov[n].text, "%s=%.17g", p->vary[v].key, ov[n].value);
        n++;
    }
    return n;
}

static void member_label(const sweep_plan *p, long m, char *buf, size_t len)
{
    int k = snprintf(buf, len, "member %ld (", m);
    for (int v = 0; v < p->nvary && k > 0 && (size_t)k < len; v++)
        k += snprintf(buf + k, len - (size_t)k, "%s%s=%.17g", v ? ", " : "", p->vary[v].key, sweep_value(p, m, v));
    if (k > 0 && (size_t)k < len) snprintf(buf + k, len - (size_t)k, ")");
}

/* The kernels of N modes met while validating the members, one per N, open until the end of
 * sweep_prepare (the magnitude check of every member needs its N's kernel). */
typedef struct {
    swim_compiled kn[SWIM_KERNEL_MAX_MODES + 1];
    unsigned char open[SWIM_KERNEL_MAX_MODES + 1];
} mode_kernels;

static void mode_kernels_close(mode_kernels *mk)
{
    for (int n = 0; n <= SWIM_KERNEL_MAX_MODES; n++)
        if (mk->open[n]) swim_compiled_close(&mk->kn[n]);
    memset(mk->open, 0, sizeof mk->open);
}

/* A member's scene as swim run checks it: the scene reader on the text read once (the file may
 * have changed since), then, with mk, the magnitude check of its model (swim_scene_check_model:
 * a density of 1e308 passes the reader but overflows the mass matrices). 0 or 2, or 1 when no
 * kernel of its N could be had. */
static int check_member(const sweep_plan *p, long m, swim_scene *s, mode_kernels *mk, swim_status *st)
{
    swim_override ov[SWEEP_MAX_SETS + SWEEP_MAX_VARY];
    int nov = member_overrides(p, m, ov);
    int rc = swim_scene_parse_with(p->scene_text, p->scene_len, p->scene, ov, nov, s, st);
    if (rc || !mk) return rc;
    const int n = s->modes;
    if (n < 1 || n > SWIM_KERNEL_MAX_MODES) return 0;   /* the reader refuses these */
    if (!mk->open[n]) {
        if (swim_codegen_kernel(n, &mk->kn[n], 0, st) != 0) rc = 1;
        else mk->open[n] = 1;
    }
    if (!rc) rc = swim_scene_check_model(s, mk->kn[n].kernel, st);
    if (rc) swim_scene_free(s);
    return rc;
}

/* Loads member m's scene (check_member): the cause of a refusal, with the member named in front
 * of it, in st. 0, 2, or 1 (no kernel). */
static int load_member(const sweep_plan *p, long m, swim_scene *s, mode_kernels *mk, swim_status *st)
{
    swim_status own = {0};   /* notices of a member's scene are not the sweep's */
    int rc = check_member(p, m, s, mk, &own);
    if (rc != 0) {
        char label[600], msg[SWIM_MESSAGE_MAX + 8], who[64];
        member_label(p, m, label, sizeof label);
        snprintf(who, sizeof who, "swim %s", p->cmd);
        swim_status_fail(st, who, own.file, own.line, own.key, "%s: %s", label, swim_status_message(&own, msg, sizeof msg));
    }
    return rc;
}

/* ------------------------------------------------------------- sweep.json */

static uint64_t fnv1a(const unsigned char *s, size_t n)
{
    uint64_t h = 1469598103934665603ull;
    for (size_t i = 0; i < n; i++) { h ^= s[i]; h *= 1099511628211ull; }
    return h;
}

/* A file of the sweep's folder, whole (64 MiB at most: a summary, a log, sweep.json). */
static char *read_file(const char *path, size_t *len) { return swim_read_file(path, 64u << 20, len); }

/* The definition: everything that decides the members' results, nothing that does not (jobs, MPI
 * ranks, --quiet), so a sweep may be resumed with other resources. */
static char *definition(const sweep_plan *p)
{
    size_t len = 0, n = p->scene_len;
    const char *text = p->scene_text;
    char *out = NULL;
    FILE *f = open_memstream(&out, &len);
    if (!f) return NULL;
    fprintf(f, "{\n  \"scene\": ");
    swim_json_string(f, p->scene);
    fprintf(f, ",\n  \"scene_fnv1a64\": \"%016llx\",\n  \"members\": %ld,\n  \"zip\": %s,\n  \"vary\": [",
            text ? (unsigned long long)fnv1a((unsigned char *)text, n) : 0ull, p->members, p->zip ? "true" : "false");
    for (int v = 0; v < p->nvary; v++) {
        fprintf(f, "%s\n    {\"key\": ", v ? "," : "");
        swim_json_string(f, p->vary[v].key);
        fprintf(f, ", \"spec\": ");
        swim_json_string(f, p->vary[v].spec);
        fprintf(f, ", \"values\": ");
        swim_json_vector(f, p->vary[v].values, (int)p->vary[v].count);
        fputc('}', f);
    }
    fprintf(f, "\n  ],\n  \"set\": [");
    for (int i = 0; i < p->nsets; i++) {
        fprintf(f, "%s", i ? ", " : "");
        swim_json_string(f, p->sets[i].text);
    }
    fprintf(f, "],\n  \"integrator\": ");
    swim_json_string(f, p->integrator);
    fprintf(f, ",\n  \"generic\": %s,\n  \"no_projection\": %s,\n  \"keep\": \"%s\"\n}\n",
            p->generic ? "true" : "false", p->no_projection ? "true" : "false",
            p->keep_trajectories ? "trajectories" : "summaries");
    fclose(f);
    return out;
}

/* text replaces path atomically; 0, or -1 with errno set (the reason a message names). */
/* A failure of the sweep's preparation: "swim CMD: message" in st. */
static void fail(swim_status *st, const sweep_plan *p, const char *fmt, ...) __attribute__((format(printf, 3, 4)));
static void fail(swim_status *st, const sweep_plan *p, const char *fmt, ...)
{
    char who[64];
    snprintf(who, sizeof who, "swim %s", p->cmd);
    va_list ap;
    va_start(ap, fmt);
    swim_status_vfail(st, who, NULL, 0, NULL, fmt, ap);
    va_end(ap);
}

static int write_atomic(const char *path, const char *text)
{
    return swim_replace_file(path, text, strlen(text));
}

/* DIR/sweep.lock, flock-ed for the whole sweep (until sweep_free): two sweeps into one DIR would
 * run members twice, rebuild members.csv under each other's appends (rows into a file already
 * renamed away) and take each other's running members for crashed ones. The lock is the kernel's,
 * so a sweep killed by any signal releases it; the pid written into the file only names the
 * holder in the refusal. 0, or 2 (DIR in use) or 1 (the lock file cannot be had). */
static int lock_dir(sweep_plan *p, swim_status *st)
{
    char path[SWIM_SWEEP_PATH + 64], holder[128] = "";
    snprintf(path, sizeof path, "%s/sweep.lock", p->dir);
    int fd = -1;
    for (int attempt = 0;; attempt++) {
        fd = open(path, O_RDWR | O_CREAT | O_CLOEXEC, 0644);
        if (fd < 0) {
            fail(st, p, "cannot open %s: %s", path, strerror(errno));
            return 1;
        }
        if (flock(fd, LOCK_EX | LOCK_NB) != 0) break;
        /* held: still DIR's lock file, or one a finished sweep removed before it let go? */
        struct stat a, b;
        if (attempt >= 8 || (fstat(fd, &a) == 0 && stat(path, &b) == 0 && a.st_dev == b.st_dev && a.st_ino == b.st_ino))
            break;
        close(fd);
    }
    if (flock(fd, LOCK_EX | LOCK_NB) != 0) {
        const int busy = errno == EWOULDBLOCK;
        ssize_t n = busy ? pread(fd, holder, sizeof holder - 1, 0) : -1;
        holder[n > 0 ? n : 0] = '\0';
        holder[strcspn(holder, "\n")] = '\0';
        if (busy)
            fail(st, p, "--out: '%s' is in use by another sweep (%s%s); wait for it to end or "
                         "use another --out", p->dir, holder[0] ? "pid " : "its pid unknown", holder);
        else
            fail(st, p, "cannot lock %s: %s", path, strerror(errno));
        close(fd);
        return busy ? 2 : 1;
    }
    /* Who holds it, for a second sweep's message only: a failed write here (a full disk) costs
     * nothing but that name, and the writes of the sweep proper report it. */
    char host[64] = "";
    gethostname(host, sizeof host - 1);
    int len = snprintf(holder, sizeof holder, "%ld on %s\n", (long)getpid(), host[0] ? host : "this host");
    if (ftruncate(fd, 0) != 0 || pwrite(fd, holder, (size_t)len, 0) != len) {
        /* not reported: see above */
    }
    p->lock_fd = fd;
    return 0;
}

/* DIR/scene.toml: the scene text every member runs. A new sweep writes it; a resumed one must
 * find there the text it read from the scene file now (an edited scene file would mix two
 * scenes in one family); a sweep directory from before this copy gets it. 0, 1 or 2. */
static int setup_scene_copy(const sweep_plan *p, int resumed, swim_status *st)
{
    char path[SWIM_SWEEP_PATH + 64];
    snprintf(path, sizeof path, "%s/scene.toml", p->dir);
    size_t n = 0;
    char *old = resumed ? read_file(path, &n) : NULL;
    if (old) {
        const int same = n == p->scene_len && memcmp(old, p->scene_text, n) == 0;
        free(old);
        if (!same) {
            fail(st, p, "%s: the scene file changed since the sweep in %s began (%s holds the "
                         "text its members ran); restore it or use another --out", p->scene, p->dir, path);
            return 2;
        }
        return 0;
    }
    if (swim_replace_file(path, p->scene_text, p->scene_len) != 0) {
        fail(st, p, "cannot write %s: %s", path, strerror(errno));
        return 1;
    }
    return 0;
}

/* A new sweep needs an empty (or absent) directory; an existing one must hold the same definition
 * and scene text. DIR is locked first. */
static int setup_dir(sweep_plan *p, swim_status *st)
{
    char path[SWIM_SWEEP_PATH + 64];
    if (swim_mkdirs(p->dir) != 0) {
        fail(st, p, "--out: cannot create directory '%s': %s", p->dir, strerror(errno));
        return 2;
    }
    int rc = lock_dir(p, st);
    if (rc) return rc;
    char *def = definition(p);
    if (!def) { fail(st, p, "out of memory"); return 1; }
    snprintf(path, sizeof path, "%s/sweep.json", p->dir);
    char *old = read_file(path, NULL);
    if (old) {
        if ((rc = setup_scene_copy(p, 1, st))) { free(old); free(def); return rc; }
        int same = strcmp(old, def) == 0;
        free(old);
        if (!same) {
            fail(st, p, "%s holds a different sweep (its sweep.json differs from this command's "
                         "definition); use another --out", p->dir);
            free(def);
            return 2;
        }
        free(def);
        return 0;
    }
    DIR *dh = opendir(p->dir);
    struct dirent *e;
    while (dh && (e = readdir(dh)))
        if (strcmp(e->d_name, ".") && strcmp(e->d_name, "..") && strncmp(e->d_name, "sweep.json.tmp", 14) &&
            strcmp(e->d_name, "sweep.lock") && strncmp(e->d_name, "scene.toml", 10)) {
            fail(st, p, "--out: '%s' is not empty and holds no sweep.json (not a sweep directory)", p->dir);
            closedir(dh);
            free(def);
            return 2;
        }
    if (dh) closedir(dh);
    /* the scene copy first: a DIR with a sweep.json always has the text its members run */
    if ((rc = setup_scene_copy(p, 0, st))) { free(def); return rc; }
    rc = write_atomic(path, def);
    free(def);
    if (rc) {
        fail(st, p, "cannot write %s: %s", path, strerror(errno));
        return 1;
    }
    return 0;
}

/* ---------------------------------------------------------- summary.json */

static void member_dir(const sweep_plan *p, long m, char *buf, size_t len)
{
    snprintf(buf, len, "%s/members/%05ld", p->dir, m);
}

/* Member m's summary, read by the one summary reader (runtime/driver/summary_read.h). A summary
 * that is absent, unreadable or not JSON is not whole: the member is not finished. */
static void read_summary(const sweep_plan *p, long m, const char *text, swim_summary *s)
{
    char path[SWIM_SWEEP_PATH + 64], err[SWIM_SWEEP_PATH + 256];
    member_dir(p, m, path, sizeof path);
    strncat(path, "/summary.json", sizeof path - strlen(path) - 1);
    swim_summary_read(path, text, s, err, sizeof err);   /* on failure *s is cleared: not whole */
}

/* Finished: a whole summary (written by swim run to the end, or by the sweep for a crashed
 * member) of a run that was not stopped by a signal (a stopped one reruns). */
static int summary_finished(const swim_summary *s)
{
    return s->whole && !s->stopped;
}

int sweep_member_summary(const sweep_plan *p, long m, swim_summary *s)
{
    read_summary(p, m, NULL, s);
    return summary_finished(s);
}

void sweep_member_dir(const sweep_plan *p, long m, char *buf, size_t len) { member_dir(p, m, buf, len); }

/* A signal someone sends to stop a process -- a user (^C, kill), a batch scheduler at the end of
 * a job (SIGTERM, then SIGKILL), a closed terminal, a stopping sweep -- rather than one its own
 * fault raises (SIGSEGV, SIGBUS, SIGFPE, SIGILL, SIGABRT, ...): the member did not fail, it was
 * interrupted, and a resume reruns it. */
static int stop_request(int sig)
{
    return sig == SIGINT || sig == SIGTERM || sig == SIGHUP || sig == SIGKILL;
}

/* The columns of a member's row after id, the varied values, status and reason (members.csv,
 * family.h5), each a number of its summary: one list for every writer of the family table. */
static const sweep_column columns[] = {
    {"t_reached", offsetof(swim_summary, t_reached), 0, "t_reached"},
    {"x", offsetof(swim_summary, x), 0, "final_state.x"},
    {"y", offsetof(swim_summary, y), 0, "final_state.y"},
    {"theta", offsetof(swim_summary, theta), 0, "final_state.theta"},
    {"energy_drift_rel", offsetof(swim_summary, energy_drift_rel), 0, "energy_drift_rel"},
    {"energy_balance_abs", offsetof(swim_summary, energy_balance_abs), 0, "energy_drift_abs"},
    {"jmin", offsetof(swim_summary, jmin), 0, "jmin"},
    {"steps", offsetof(swim_summary, steps), 1, "stats.steps"},
    {"rhs_evaluations", offsetof(swim_summary, rhs_evaluations), 1, "stats.rhs_evaluations"},
    {"integrate_seconds", offsetof(swim_summary, integrate_seconds), 0, "stats.integrate_seconds"},
    {"wall_seconds", offsetof(swim_summary, wall_seconds), 0, "stats.wall_seconds"},
};

const sweep_column *sweep_columns(int *count)
{
    *count = (int)(sizeof columns / sizeof columns[0]);
    return columns;
}

static void csv_header(const sweep_plan *p, FILE *f)
{
    fprintf(f, "id");
    for (int v = 0; v < p->nvary; v++) fprintf(f, ",%s", p->vary[v].key);
    fprintf(f, ",status,reason");
    for (size_t i = 0; i < sizeof columns / sizeof columns[0]; i++) fprintf(f, ",%s", columns[i].name);
    fprintf(f, "\n");
}

/* A number of the summary as the field of a row: the shortest digits that read back as the same
 * double (%.17g at most); "" when null or absent. */
static void real_field(const swim_summary_real *r, char *out, size_t len)
{
    out[0] = '\0';
    if (!r->set) return;
    swim_number_text(out, len, r->value);
}

static void count_field(const swim_summary_count *c, char *out, size_t len)
{
    out[0] = '\0';
    if (c->set) snprintf(out, len, "%lld", c->value);
}

/* The reason as members.csv quotes it: between double quotes, a double quote as ', a newline as a
 * space, other control characters and U+FFFD (what the summary writer makes of bytes that are not
 * UTF-8) as ?, at most 399 bytes cut at a character boundary. */
static void reason_field(const char *reason, char *out, size_t len)
{
    size_t k = 0;
    for (const unsigned char *c = (const unsigned char *)reason; *c && k + 4 < len && k < 399;) {
        if (c[0] == 0xEF && c[1] == 0xBF && c[2] == 0xBD) { out[k++] = '?'; c += 3; continue; }
        if (*c == '"') out[k++] = '\'';
        else if (*c == '\n') out[k++] = ' ';
        else if (*c < 0x20 || *c == 0x7F) out[k++] = '?';
        else {
            size_t n = *c < 0x80 ? 1 : *c >= 0xF0 ? 4 : *c >= 0xE0 ? 3 : 2;   /* the reader gives UTF-8 */
            if (k + n > 399) break;
            while (n-- && *c) out[k++] = (char)*c++;
            continue;
        }
        c++;
    }
    out[k] = '\0';
}

static void format_row(const sweep_plan *p, long m, const swim_summary *s, char *row, size_t len)
{
    char reason[404];
    reason_field(s->reason, reason, sizeof reason);
    int k = snprintf(row, len, "%ld", m);
    char num[32];
    for (int v = 0; v < p->nvary && (size_t)k < len; v++) {
        swim_number_text(num, sizeof num, sweep_value(p, m, v));
        k += snprintf(row + k, len - (size_t)k, ",%s", num);
    }
    if ((size_t)k < len) k += snprintf(row + k, len - (size_t)k, ",%s,\"%s\"", s->status, reason);
    char tok[64];
    for (size_t i = 0; i < sizeof columns / sizeof columns[0] && (size_t)k < len; i++) {
        const char *field = (const char *)s + columns[i].offset;
        if (columns[i].integer) count_field((const swim_summary_count *)field, tok, sizeof tok);
        else real_field((const swim_summary_real *)field, tok, sizeof tok);
        k += snprintf(row + k, len - (size_t)k, ",%s", tok);
    }
    if ((size_t)k < len) snprintf(row + k, len - (size_t)k, "\n");
}

/* members.csv from the summaries of the finished members, in member order; with counts, the
 * plan's tally of members found finished is redone. */
static int write_rows(const sweep_plan *p, long *already, long *already_failed, unsigned char *finished,
                      swim_status *st)
{
    char path[SWIM_SWEEP_PATH + 64], row[2048];
    snprintf(path, sizeof path, "%s/members.csv.tmp", p->dir);
    FILE *f = fopen(path, "w");
    if (!f) { fail(st, p, "cannot write %s: %s", path, strerror(errno)); return 1; }
    csv_header(p, f);
    long done = 0, failed = 0;
    for (long m = 0; m < p->members; m++) {
        swim_summary s;
        read_summary(p, m, NULL, &s);
        const int is_finished = summary_finished(&s);
        if (finished) finished[m] = (unsigned char)is_finished;
        if (is_finished) {
            format_row(p, m, &s, row, sizeof row);
            fputs(row, f);
            done++;
            failed += strcmp(s.status, "completed") != 0;
        }
    }
    if (already) *already = done;
    if (already_failed) *already_failed = failed;
    int bad = fflush(f) != 0;
    bad |= fclose(f) != 0;
    char final[SWIM_SWEEP_PATH + 64];
    snprintf(final, sizeof final, "%s/members.csv", p->dir);
    if (bad || rename(path, final) != 0) {
        fail(st, p, "cannot write %s: %s", final, strerror(errno));
        return 1;
    }
    return 0;
}

static int rebuild_rows(sweep_plan *p, swim_status *st)
{
    return write_rows(p, &p->already, &p->already_failed, p->finished, st);
}

int sweep_sort_rows(const sweep_plan *p, swim_status *st) { return write_rows(p, NULL, NULL, NULL, st); }

/* "1 h 05 min", "3 min 20 s", "12 s": what a reader takes in at a glance. */
static void duration_text(double s, char *out, size_t len)
{
    const long t = (long)(s + 0.5);
    if (t >= 3600) snprintf(out, len, "%ld h %02ld min", t / 3600, (t % 3600) / 60);
    else if (t >= 60) snprintf(out, len, "%ld min %02ld s", t / 60, t % 60);
    else snprintf(out, len, "%ld s", t);
}

void sweep_progress_line(const sweep_plan *p, long ran, long failed, double seconds, char *line, size_t len)
{
    const long done = p->already + ran, left = p->members - done;
    int k = snprintf(line, len, "swim %s: %ld / %ld members (%ld failed)", p->cmd, done, p->members,
                     p->already_failed + failed);
    if (ran > 0 && seconds > 0 && k >= 0 && (size_t)k < len) {
        const double rate = ran / seconds;
        char eta[32];
        duration_text(left / rate, eta, sizeof eta);
        snprintf(line + k, len - (size_t)k, ", %.3g members/s, about %s left", rate, eta);
    }
}

int sweep_progress(const sweep_plan *p, long ran, long failed, double t0, sweep_progress_state *st, char *line,
                   size_t len)
{
    if (p->quiet) return 0;
    const double t = swim_clock_seconds();
    const int on_terminal = isatty(STDERR_FILENO);
    const long decile = p->members > 0 ? 10 * (p->already + ran) / p->members : 10;
    if (on_terminal ? t - st->last < 0.5 : t - st->last < p->progress_every && decile == st->decile) return 0;
    sweep_progress_line(p, ran, failed, t - t0, line, len);
    st->last = t;
    st->decile = decile;
    st->drawn |= on_terminal;
    return on_terminal ? 2 : 1;
}

/* ---------------------------------------------------------------- prepare */

/* One kernel per distinct structure (and the kernel of its N modes, for the diagnostics),
 * generated before any member starts: members then only load them from the cache and none of
 * them races to generate one. rep[k] is a member of structure k. A structure without a kernel
 * stops the sweep before any member runs: each of its members would fail the same way. */
static int generate_kernels(const sweep_plan *p, const long *rep, int nkeys, swim_status *st)
{
    const int verbose = p->quiet ? 0 : 1;
    for (int k = 0; k < nkeys; k++) {
        swim_scene s;
        if (load_member(p, rep[k], &s, NULL, st)) return 2;
        swim_compiled kn, sc;
        int bad = swim_codegen_kernel(s.modes, &kn, verbose, st) != 0;
        if (!bad) {
            /* a prescribed stroke's members run on its laws' kernel (runtime/stroke) */
            bad = s.stroke ? swim_codegen_stroke(&s, &sc, verbose, st) : swim_codegen_scene(&s, p->generic, &sc, verbose, st);
            if (!bad) swim_compiled_close(&sc);
            swim_compiled_close(&kn);
        }
        if (bad == -2) {   /* a stroke law the generator refuses: bad input */
            char where[640];
            swim_status_fail(st, "swim", s.path, 0, NULL, "%s: %s (member %ld)",
                             swim_scene_stroke_where(&s, sc.refused_index, where, sizeof where), sc.refused, rep[k]);
            swim_scene_free(&s);
            return 2;
        }
        swim_scene_free(&s);
        if (bad) {
            fail(st, p, "no kernel for the structure of member %ld, no member run", rep[k]);
            return 1;
        }
    }
    return 0;
}

int sweep_prepare(sweep_plan *p, swim_status *st)
{
    char **keys = NULL;
    long *rep = NULL;
    int nkeys = 0, cap = 0, rc = 0;
    free(p->scene_text);
    if (!(p->scene_text = swim_scene_read(p->scene, &p->scene_len, st))) return 2;
    mode_kernels mk;
    memset(mk.open, 0, sizeof mk.open);
    for (long m = 0; m < p->members && !rc; m++) {
        swim_scene s;
        if ((rc = load_member(p, m, &s, &mk, st))) break;
        char *key = swim_codegen_scene_key(&s, p->generic);
        swim_scene_free(&s);
        if (!key) {
            fail(st, p, "out of memory");
            rc = 1;
            break;
        }
        int found = 0;
        for (int k = 0; k < nkeys && !found; k++) found = strcmp(keys[k], key) == 0;
        if (found) {
            free(key);
            continue;
        }
        if (nkeys == cap) {
            cap = cap ? 2 * cap : 8;
            char **nk = realloc(keys, (size_t)cap * sizeof *keys);
            long *nr = nk ? realloc(rep, (size_t)cap * sizeof *rep) : NULL;
            if (nk) keys = nk;
            if (nr) rep = nr;
            if (!nk || !nr) {
                fail(st, p, "out of memory");
                free(key);
                rc = 1;
                break;
            }
        }
        keys[nkeys] = key;
        rep[nkeys++] = m;
    }
    mode_kernels_close(&mk);
    /* kernels before DIR: a law the generator refuses is bad input, refused before anything is written */
    if (!rc) rc = generate_kernels(p, rep, nkeys, st);
    if (!rc) rc = setup_dir(p, st);
    char path[SWIM_SWEEP_PATH + 64];
    snprintf(path, sizeof path, "%s/members", p->dir);
    if (!rc && swim_mkdirs(path) != 0) {
        fail(st, p, "cannot create %s: %s", path, strerror(errno));
        rc = 1;
    }
    if (!rc && !(p->finished = calloc((size_t)p->members, 1))) {
        fail(st, p, "out of memory");
        rc = 1;
    }
    if (!rc) rc = rebuild_rows(p, st);
    for (int k = 0; k < nkeys; k++) free(keys[k]);
    free(keys);
    free(rep);
    return rc;
}

/* ------------------------------------------------------------- members */

/* The sweep's run options over a member's scene (as swim run's --integrator and --no-projection),
 * recorded for its DIR/scene.toml. */
static int member_adjust(swim_scene *s, swim_override *recorded, int *nrecorded, void *ctx, swim_status *st)
{
    const sweep_plan *p = ctx;
    char text[64];
    *nrecorded = 0;
    if (p->integrator[0]) {
        snprintf(s->run.integrator, sizeof s->run.integrator, "%s", p->integrator);
        snprintf(text, sizeof text, "run.integrator=%s", p->integrator);
        if (swim_override_parse(text, &recorded[*nrecorded], NULL, 0) == 0) (*nrecorded)++;
    }
    if (p->no_projection && s->stroke_count == 0) {
        s->run.projection = 0;
        if (swim_override_parse("run.projection=false", &recorded[*nrecorded], NULL, 0) == 0) (*nrecorded)++;
    }
    if (p->no_projection && s->stroke_count > 0) {
        swim_status_fail(st, "swim run", s->path, 0, NULL, "--no-projection: does not apply to a prescribed stroke (%s has "
                         "[stroke]: only (3.21) is integrated)", s->path);
        return 2;
    }
    return swim_run_settings_check(s, NULL, st) != 0 ? 2 : 0;
}

/* Member m in this process (the forked child): a job of the run layer (output/job.h), with the
 * command line it stands for in its summary. The exit status of `swim run`. */
static int run_member(const sweep_plan *p, const char *scene, const char *dir, const swim_override *ov, int nov,
                      int argc, const char **argv)
{
    char *command = swim_shell_words(argc, argv);
    const swim_run_job job = {.cmd = "run", .scene_file = scene, .sets = ov, .nsets = nov, .adjust = member_adjust,
                              .adjust_ctx = (void *)p, .out = dir, .quiet = 1, .generic = p->generic,
                              .summary_only = !p->keep_trajectories, .command = command};
    swim_status st = {0};
    const int rc = swim_job_execute(&job, &st);
    if (st.failed) {   /* the member's refusal: its log's line (the log is the child's stderr) */
        FILE *log = fdopen(dup(STDERR_FILENO), "w");
        if (log) {
            swim_status_print(&st, log);
            fclose(log);
        }
    }
    free(command);
    return rc;
}

pid_t sweep_spawn(const sweep_plan *p, long m)
{
    char dir[SWIM_SWEEP_PATH + 64], path[SWIM_SWEEP_PATH + 128];
    member_dir(p, m, dir, sizeof dir);
    if (swim_mkdirs(dir) != 0) return -1;
    snprintf(path, sizeof path, "%s/summary.json", dir);
    remove(path);   /* a partial summary of an interrupted attempt must not outlive it */
    swim_override ov[SWEEP_MAX_SETS + SWEEP_MAX_VARY];
    int nov = member_overrides(p, m, ov);
    const char *args[16 + 2 * (SWEEP_MAX_SETS + SWEEP_MAX_VARY)];
    char scene[SWIM_SWEEP_PATH + 64];
    snprintf(scene, sizeof scene, "%s/scene.toml", p->dir);   /* the text validated, not the file now */
    int a = 0;
    args[a++] = p->exe;
    args[a++] = "run";
    args[a++] = scene;
    args[a++] = "--out";
    args[a++] = dir;
    args[a++] = "--quiet";
    if (!p->keep_trajectories) args[a++] = "--summary-only";
    if (p->generic) args[a++] = "--generic";
    if (p->no_projection) args[a++] = "--no-projection";
    if (p->integrator[0]) { args[a++] = "--integrator"; args[a++] = p->integrator; }
    for (int i = 0; i < nov; i++) { args[a++] = "--set"; args[a++] = ov[i].text; }
    args[a] = NULL;
    snprintf(path, sizeof path, "%s/log.txt", dir);
    const pid_t parent = getpid();
    fflush(NULL);
    /* The stop signals wait across the fork: a child that took one with the sweep's handler
     * (inherited until it sets its own) would lose it and run on. The child gets them once its
     * handlers are the defaults; the parent once the fork is done. */
    sigset_t stops, old;
    sigemptyset(&stops);
    sigaddset(&stops, SIGINT);
    sigaddset(&stops, SIGTERM);
    sigaddset(&stops, SIGHUP);
    sigprocmask(SIG_BLOCK, &stops, &old);
    pid_t pid = fork();
    if (pid != 0) {
        const int saved = errno;
        sigprocmask(SIG_SETMASK, &old, NULL);
        errno = saved;
        return pid;
    }
    /* child */
    prctl(PR_SET_PDEATHSIG, SIGKILL);
    if (getppid() != parent) _exit(127);
    if (p->lock_fd >= 0) close(p->lock_fd);   /* DIR's lock is the sweep's: a member dying late must not hold it */
    signal(SIGINT, SIG_DFL);
    signal(SIGTERM, SIG_DFL);
    signal(SIGHUP, SIG_DFL);
    sigset_t none;
    sigemptyset(&none);
    sigprocmask(SIG_SETMASK, &none, NULL);
    int fd = open(path, O_WRONLY | O_CREAT | O_TRUNC, 0644);
    if (fd >= 0) { dup2(fd, 1); dup2(fd, 2); close(fd); }
    if (p->in_process) {
        /* _exit, not exit: the parent's atexit handlers and stdio buffers are not the member's */
        int rc = run_member(p, scene, dir, ov, nov, a, args);
        fflush(NULL);
        _exit(rc);
    }
    execv(p->exe, (char *const *)args);
    const int why = errno;
    FILE *log = fdopen(dup(STDERR_FILENO), "w");   /* the member's log.txt */
    if (log) {
        swim_message(log, "swim %s: cannot start %s: %s", p->cmd, p->exe, strerror(why));
        fclose(log);
    }
    _exit(127);
}

/* The last line of the member's log, for the reason of a member that died without a summary. */
static void last_log_line(const char *dir, char *out, size_t len)
{
    char path[SWIM_SWEEP_PATH + 128];
    snprintf(path, sizeof path, "%s/log.txt", dir);
    char *text = read_file(path, NULL);
    out[0] = '\0';
    if (!text) return;
    size_t n = strlen(text);
    while (n && text[n - 1] == '\n') text[--n] = '\0';
    char *nl = strrchr(text, '\n');
    snprintf(out, len, "%s", nl ? nl + 1 : text);
    for (char *c = out; *c; c++) if (*c == '"' || *c == '\\' || (unsigned char)*c < 0x20) *c = '\'';
    free(text);
}

int sweep_collect(const sweep_plan *p, long m, int status, int interrupted, char *row, size_t len, int *failed,
                  swim_status *st)
{
    char dir[SWIM_SWEEP_PATH + 64], path[SWIM_SWEEP_PATH + 128];
    member_dir(p, m, dir, sizeof dir);
    snprintf(path, sizeof path, "%s/summary.json", dir);
    swim_summary s;
    read_summary(p, m, NULL, &s);
    int done = summary_finished(&s);
    int exited_normally = WIFEXITED(status) && (WEXITSTATUS(status) == 0 || WEXITSTATUS(status) == 1);
    if (!done && (interrupted || s.stopped || (WIFSIGNALED(status) && stop_request(WTERMSIG(status)))))
        return 0;
    if (!done || !exited_normally) {
        /* Died without a (whole) summary: say so in one, so the row and a resume agree. */
        char reason[600], last[400];
        last_log_line(dir, last, sizeof last);
        if (WIFSIGNALED(status))
            snprintf(reason, sizeof reason, "member process killed by signal %d (%s)", WTERMSIG(status), strsignal(WTERMSIG(status)));
        else
            snprintf(reason, sizeof reason, "member process exited with status %d: %s", WEXITSTATUS(status), last);
        if (done && !exited_normally) {
            /* a whole summary but an abnormal exit: keep the summary, it says what happened */
        } else {
            char *text = NULL;
            json_t *o = json_object();
            int bad = !o;
            if (o) {
                bad |= swim_json_set(o, "scene", swim_json_str(p->scene));
                bad |= swim_json_set(o, "status", swim_json_str("crashed"));
                bad |= swim_json_set(o, "reason", swim_json_str(reason));
            }
            FILE *f = bad ? NULL : open_memstream(&text, &(size_t){0});
            if (f) {
                swim_json_write(f, o);
                fclose(f);
            }
            json_decref(o);
            if (!f) {
                swim_status_fail_cmd(st, p->cmd, NULL, NULL, "member %ld: out of memory", m);
                return -1;
            }
            if (write_atomic(path, text) != 0) {
                /* the sweep's stderr, not the member's log: the disk that refused this may hold the log */
                swim_status_fail_cmd(st, p->cmd, NULL, NULL, "member %ld (%s): cannot write %s: %s", m, reason, path, strerror(errno));
                free(text);
                return -1;
            }
            read_summary(p, m, text, &s);   /* the row from the summary as written */
            free(text);
        }
    }
    *failed = strcmp(s.status, "completed") != 0;
    format_row(p, m, &s, row, len);
    return 1;
}

FILE *sweep_open_rows(const sweep_plan *p, swim_status *st)
{
    char path[SWIM_SWEEP_PATH + 64];
    snprintf(path, sizeof path, "%s/members.csv", p->dir);
    FILE *f = fopen(path, "a");
    if (!f) swim_status_fail_cmd(st, p->cmd, NULL, NULL, "cannot append to %s: %s", path, strerror(errno));
    return f;
}

int sweep_append_row(FILE *f, const char *row)
{
    if (fputs(row, f) < 0 || fflush(f) != 0) return -1;
    return 0;
}

int sweep_finish_stdout(const sweep_plan *p, int close_it, swim_status *st)
{
    int bad = fflush(stdout) != 0 || ferror(stdout);
    int err = bad ? errno : 0;
    if (close_it && fclose(stdout) != 0 && !bad) {
        bad = 1;
        err = errno;
    }
    if (!bad) return 0;
    swim_status_fail_cmd(st, p->cmd, NULL, NULL, "cannot write the report to stdout: %s", err ? strerror(err) : "write error");
    return -1;
}
