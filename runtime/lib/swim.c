/* swim.c -- libswim (lib/swim.h) over the run driver: a model is the scene's text with its
 * overrides and the kernels of its structure; a simulation parses its own copy of the scene (a run
 * resolves settings into it, a stroke its initial state) and runs it through driver/run.h with
 * the model's kernels, which any number of simulations share read-only.
 *
 * The layers below report a failure in a status of the call's own (io/status.h: file, line, key
 * and the line a command would show), which becomes the swim_error returned; nothing is printed,
 * and notices (a projected initial velocity) go nowhere.
 *
 * The caller's structs are read and written only as far as their size field says: every call
 * works on whole structs of its own and copies in or out what the caller's size holds. */
#include "lib/swim.h"

#include <ctype.h>
#include <math.h>
#include <stdarg.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "codegen/codegen.h"
#include "control/continuation.h"
#include "control/floquet.h"
#include "control/periodic.h"
#include "driver/analyses.h"
#include "driver/events.h"
#include "driver/run.h"
#include "driver/summary.h"
#include "driver/summary_read.h"
#include "io/files.h"
#include "io/message.h"
#include "io/version.h"
#include "kernel/coords.h"
#include "kernel/swim_kernel.h"
#include "problem/problem.h"
#include "scene/keys.h"
#include "scene/resolve.h"
#include "scene/scene.h"
#include "shape/shape.h"
#include "sweep/sweep.h"

#define MAX_SETS 64
/* runtime/lib/module.mk passes VERSION's numbers and the SONAME's (test_library checks the same
 * at run time, for a build without them) */
#if defined(SWIM_BUILD_MAJOR) && (SWIM_BUILD_MAJOR != SWIM_VERSION_MAJOR || SWIM_BUILD_MINOR != SWIM_VERSION_MINOR || \
                                  SWIM_BUILD_PATCH != SWIM_VERSION_PATCH)
#error "VERSION and swim.h's SWIM_VERSION_MAJOR/MINOR/PATCH disagree"
#endif
#if defined(SWIM_BUILD_ABI) && SWIM_BUILD_ABI != SWIM_ABI
#error "the SONAME's number (runtime/lib/module.mk) is not swim.h's SWIM_ABI"
#endif
_Static_assert(SWIM_LIB_MAX_EVENTS == SWIM_RUN_MAX_EVENTS, "the library's event bound is the driver's");

struct swim_model {
    swim_problem P;              /* the text, its overrides, the validated scene, the kernels; never
                                    moved (a loaded scene is not, scene.h) */
    const char *names[SWIM_RUN_MAX_COLUMNS];
    char storage[2 * SWIM_NMAX][24];
    int ncol;
};

struct swim_sim {
    const swim_model *m;
    swim_override *sets;         /* the model's overrides when the simulation was created */
    int nsets;
    swim_scene s;
    int loaded;
    swim_run_events *events;
    swim_run *run;
    swim_sim_options o;
    int caller_stopped;
    double t_asked;              /* the latest time swim_sim_advance was asked for */
    int bad_events;              /* sim_open refused an event */
    int bad_option;              /* sim_open refused the sensitivity keys or the Lyapunov interval */
    int analysed;                /* the analyses after the run were done (sim_analyses) */
    char *sens_keys;             /* the options' sensitivity (a copy), NULL: none */
    swim_sens_table sens;        /* its rows */
    swim_analyses an;            /* the sensitivities and the tangent vector on the run's steps */
    int an_ready;
    int sens_ok;
    swim_lyapunov lyap;          /* the Lyapunov pass (o.lyapunov > 0) */
    int lyap_done;
    char lyap_reason[160];
};

/* ---- errors ---------------------------------------------------------------------------------- */

/* A failed call's status (io/status.h, filled by the layer that found the fault) into its error:
 * the fields as they were set there, the message its line without "swim[ CMD]: "; fallback when
 * no layer said more (out of memory before anything was read). The status alone when err is
 * NULL. */
static int failed(swim_error *err, const swim_status *st, int status, const char *fallback)
{
    if (!err || !status) return status;
    memset(err, 0, sizeof *err);
    err->status = status;
    if (!st || !st->failed) {
        snprintf(err->message, sizeof err->message, "%s", fallback);
        return status;
    }
    snprintf(err->file, sizeof err->file, "%s", st->file);
    err->line = st->line;
    snprintf(err->key, sizeof err->key, "%s", st->key);
    swim_status_message(st, err->message, sizeof err->message);
    return status;
}

const char *swim_version(void) { return SWIM_VERSION; }

void swim_free(void *p) { free(p); }

const char *swim_strerror(int status)
{
    switch (status < 0 ? -status : status) {
    case SWIM_OK: return "SWIM_OK: success, nothing went wrong";
    case SWIM_EFAILED: return "SWIM_EFAILED: the run failed or stopped early (the reason is in the error and the summary)";
    case SWIM_EINPUT: return "SWIM_EINPUT: bad input (a scene value, an override, an event, an argument)";
    case SWIM_ENOMEM: return "SWIM_ENOMEM: out of memory";
    case SWIM_EKERNEL: return "SWIM_EKERNEL: no kernel could be had (generation or compilation failed)";
    default: return "unknown status";
    }
}

/* ---- the caller's structs: as much of them as their size holds ------------------------------ */

/* The first layout of a struct: up to its last field of the first version. A later version adds
 * fields after these; a caller's size below this is refused. */
#define FIRST_LAYOUT(type, last) (offsetof(type, last) + sizeof(((type *)0)->last))
#define ERROR_V1 FIRST_LAYOUT(swim_error, message)
#define OPTIONS_V1 FIRST_LAYOUT(swim_sim_options, stop)
#define RESULT_V1 FIRST_LAYOUT(swim_result, rhs_evaluations)
#define INSPECTION_V1 FIRST_LAYOUT(swim_inspection, christoffel)
#define LYAPUNOV_V1 FIRST_LAYOUT(swim_lyapunov_result, reason)
#define ORBIT_OPTIONS_V1 FIRST_LAYOUT(swim_orbit_options, points)
#define PERIODIC_V1 FIRST_LAYOUT(swim_periodic_result, seconds)
#define FLOQUET_V1 FIRST_LAYOUT(swim_floquet_result, seconds)
#define BRANCH_V1 FIRST_LAYOUT(swim_branch_result, seconds)
#define MEMBER_V1 FIRST_LAYOUT(swim_member, wall_seconds)

size_t swim_struct_size(const char *name)
{
    static const struct {
        const char *name;
        size_t size;
    } sizes[] = {{"swim_error", sizeof(swim_error)},
                 {"swim_sim_options", sizeof(swim_sim_options)},
                 {"swim_result", sizeof(swim_result)},
                 {"swim_inspection", sizeof(swim_inspection)},
                 {"swim_event", sizeof(swim_event)},
                 {"swim_lyapunov_result", sizeof(swim_lyapunov_result)},
                 {"swim_orbit_options", sizeof(swim_orbit_options)},
                 {"swim_periodic_result", sizeof(swim_periodic_result)},
                 {"swim_floquet_result", sizeof(swim_floquet_result)},
                 {"swim_branch_result", sizeof(swim_branch_result)},
                 {"swim_member", sizeof(swim_member)}};
    for (size_t i = 0; name && i < sizeof sizes / sizeof sizes[0]; i++)
        if (strcmp(name, sizes[i].name) == 0) return sizes[i].size;
    return 0;
}

/* what bytes of our struct (whole, `ours` bytes) into the caller's `theirs` of `size` bytes,
 * keeping their size field */
static void give(void *theirs, const void *ours, size_t whole)
{
    const size_t size = *(const size_t *)theirs;
    memcpy(theirs, ours, size < whole ? size : whole);
    *(size_t *)theirs = size;
}

/* The start of a call with the caller's error err (NULL allowed): 0 when err is too small to
 * hold the first swim_error (nothing is written into it), else 1 with e, the call's own, clear. */
static int error_begin(const swim_error *err, swim_error *e)
{
    memset(e, 0, sizeof *e);
    e->size = sizeof *e;
    return !err || err->size >= ERROR_V1;
}

/* The end of the call: its error into the caller's, as far as their size goes; status. */
static int error_give(swim_error *err, const swim_error *e, int status)
{
    if (err) give(err, e, sizeof *e);
    return status;
}

/* ---- arguments: checked at the top of every function, before anything is touched ---------- */

/* status with err->key naming what was refused (err cleared first; NULL err: the status alone);
 * the message is a sentence of its own, as the error's other messages. */
static int refuse(swim_error *err, int status, const char *key, const char *fmt, ...)
    __attribute__((format(printf, 4, 5)));
static int refuse(swim_error *err, int status, const char *key, const char *fmt, ...)
{
    if (!err) return status;
    memset(err, 0, sizeof *err);
    err->status = status;
    snprintf(err->key, sizeof err->key, "%s", key);
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(err->message, sizeof err->message, fmt, ap);
    va_end(ap);
    return status;
}
#define bad_arg(err, key, ...) refuse((err), SWIM_EINPUT, (key), __VA_ARGS__)

/* A caller's struct whose size field is below its first layout (not set, or garbage). */
static int too_small(swim_error *err, const char *type, size_t size, size_t first)
{
    return bad_arg(err, type, "%s.size is %zu, below the %zu bytes of its first layout: set it to sizeof(%s) "
                   "(the SWIM_*_INIT initialisers do)", type, size, first, type);
}

/* value against the bounds of function's argument arg (scene/keys.h, the library's rows). */
static int bounded(swim_error *err, const char *function, const char *arg, double value)
{
    const swim_scene_key *k = swim_library_arg(function, arg);
    if (!k || (isfinite(value) && value >= k->lo && value < k->hi)) return SWIM_OK;
    if (k->kind == SWIM_KEY_INTEGER && value < k->hi + 1 && value >= k->lo) return SWIM_OK;   /* [lo, hi] */
    return bad_arg(err, arg, "%s must be %s (got %g)", k->doc, k->expect, value);
}

/* The lists of strings a function takes: list[0 .. n) with no NULL entry. */
static int string_list(swim_error *err, const char *function, const char *name, const char *count,
                       const char *const *list, int n)
{
    if (bounded(err, function, count, n)) return SWIM_EINPUT;
    if (n > 0 && !list) return bad_arg(err, name, "%s is NULL while %s = %d", name, count, n);
    for (int i = 0; i < n; i++)
        if (!list[i]) {
            char which[64];
            snprintf(which, sizeof which, "%s[%d]", name, i);
            return bad_arg(err, which, "%s is NULL", which);
        }
    return SWIM_OK;
}

/* ---- models --------------------------------------------------------------------------------- */

/* The model: the problem (problem/problem.h) of its text and overrides, opened as swim run opens
 * one, with the text kept with the overrides written in (swim_model_scene_text). */
static int model_open(swim_model *m, const char *text, size_t len, const char *name, const char *const *sets,
                      int nsets, swim_status *st)
{
    if (nsets > MAX_SETS) {
        swim_status_fail(st, "swim", name, 0, "nsets", "%s: more than %d overrides", name, MAX_SETS);
        return SWIM_EINPUT;
    }
    swim_override ov[MAX_SETS];
    for (int i = 0; i < nsets; i++) {
        char why[256], key[128];
        if (swim_override_parse(sets[i], &ov[i], why, sizeof why) != 0) {
            /* the key of the override that does not parse: what precedes '=' */
            const size_t n = strcspn(sets[i], "=");
            snprintf(key, sizeof key, "%.*s", (int)(n < sizeof key ? n : sizeof key - 1), sets[i]);
            swim_status_fail(st, "swim", name, 0, key, "%s: --set: %s", name, why);
            return SWIM_EINPUT;
        }
    }
    const swim_problem_source src = {.text = text, .len = len, .name = name, .sets = ov, .nsets = nsets,
                                     .flags = SWIM_PROBLEM_RESOLVE};
    int rc = swim_problem_read(&m->P, &src, st);
    if (rc) return rc == 2 ? SWIM_EINPUT : SWIM_ENOMEM;
    rc = swim_problem_kernels(&m->P, "library", 0, 0, st);
    if (rc) return rc == 2 ? SWIM_EINPUT : SWIM_EKERNEL;
    m->ncol = swim_run_columns(m->P.s, m->names, m->storage);
    return SWIM_OK;
}

static int model_new(char *text, size_t len, const char *name, const char *const *sets, int nsets, swim_model **out,
                     swim_error *err)
{
    *out = NULL;
    swim_model *m = calloc(1, sizeof *m);
    if (!m || !text) {
        free(text);
        free(m);
        return failed(err, NULL, SWIM_ENOMEM, "out of memory");
    }
    swim_status st = {0};
    const int rc = model_open(m, text, len, name, sets, nsets, &st);
    free(text);
    if (rc) {
        failed(err, &st, rc, "the scene could not be read");
        swim_model_free(m);
        return rc;
    }
    *out = m;
    return SWIM_OK;
}

static int swim_model_from_file_(const char *path, const char *const *sets, int nsets, swim_model **out, swim_error *err)
{
    if (!out) return bad_arg(err, "out", "out is NULL");
    *out = NULL;
    if (!path) return bad_arg(err, "path", "path is NULL");
    if (string_list(err, "swim_model_from_file", "sets", "nsets", sets, nsets)) return SWIM_EINPUT;
    size_t len = 0;
    swim_status st = {0};
    char *text = swim_scene_read(path, &len, &st);   /* refuses what is not a scene file */
    if (!text) {
        *out = NULL;
        return failed(err, &st, SWIM_EINPUT, "the scene file cannot be read");
    }
    return model_new(text, len, path, sets, nsets, out, err);
}

static int swim_model_from_text_(const char *toml, const char *name, const char *const *sets, int nsets, swim_model **out,
                         swim_error *err)
{
    if (!out) return bad_arg(err, "out", "out is NULL");
    *out = NULL;
    if (!toml) return bad_arg(err, "toml", "toml is NULL");
    if (string_list(err, "swim_model_from_file", "sets", "nsets", sets, nsets)) return SWIM_EINPUT;
    const size_t len = strlen(toml);
    char *text = malloc(len + 1);
    if (text) memcpy(text, toml, len + 1);
    return model_new(text, len, name ? name : "(text)", sets, nsets, out, err);
}

int swim_model_columns(const swim_model *m, const char *const **names)
{
    if (!m || !names) return -SWIM_EINPUT;
    *names = m->names;
    return m->ncol;
}

const char *swim_model_scene_text(const swim_model *m) { return !m ? NULL : m->P.resolved ? m->P.resolved : m->P.text; }

/* One run-time key set in place (swim.h): the override list with it, validated as opening the
 * model with it would validate it, then kept when the kernel's structure is what it was. */
static int model_set(swim_model *m, const char *key, const char *value, swim_error *err)
{
    if (!m) return bad_arg(err, "model", "model is NULL");
    if (!key) return bad_arg(err, "key", "key is NULL");
    if (!value) return bad_arg(err, "value", "value is NULL");
    swim_override ov;
    char text[sizeof ov.text];
    if (snprintf(text, sizeof text, "%s=%s", key, value) >= (int)sizeof text)
        return bad_arg(err, "key", "%s=%s: longer than the %zu characters of an override", key, value, sizeof text - 1);
    swim_status st = {0};
    const int rc = swim_problem_set(&m->P, key, value, &st);
    if (rc) {
        failed(err, &st, rc == 1 ? SWIM_ENOMEM : SWIM_EINPUT, rc == 1 ? "out of memory" : "the value was refused");
        if (!err->key[0]) snprintf(err->key, sizeof err->key, "%s", key);
        if (!err->file[0]) snprintf(err->file, sizeof err->file, "%s", m->P.name);
        return err->status;
    }
    return SWIM_OK;
}

void swim_model_free(swim_model *m)
{
    if (!m) return;
    swim_problem_close(&m->P);
    free(m);
}

/* ---- simulations ---------------------------------------------------------------------------- */

static int sink_row(void *ctx, const swim_run_row *row, char *why, size_t len)
{
    swim_sim *s = ctx;
    if (!s->o.rows || s->o.rows(s->o.rows_ctx, row->t, row->values, row->ncol) == 0) return 0;
    s->caller_stopped = 1;
    snprintf(why, len, "stopped by the caller");
    return SWIM_RUN_ROW_STOP;
}

/* An event of the run to the caller's on_event (driver/events.h's listener). */
static int sim_event(void *ctx, double t, const char *column, const char *kind, double value, const double *state,
                     int nstate)
{
    swim_sim *s = ctx;
    const swim_event e = {sizeof e, t, column, kind, value, state, nstate};
    return s->o.on_event(s->o.event_ctx, &e) != 0;
}

/* The options' analyses checked before anything runs, as `swim run` checks --sensitivity and
 * --lyapunov-interval (output/job.c): the keys resolved on the run's dynamics. */
static int sim_check_analyses(swim_sim *s, swim_status *st)
{
    const char *keys = s->o.sensitivity;
    if ((keys || s->o.lyapunov != 0) && s->s.stroke_count > 0) {
        swim_status_fail(st, "swim", s->m->P.name, 0, keys ? "sensitivity" : "lyapunov", "%s: --%s: not available on a "
                         "prescribed stroke: the variational equations are those of free shape dynamics only",
                         s->m->P.name, keys ? "sensitivity" : "lyapunov");
        s->bad_option = 1;
        return SWIM_EINPUT;
    }
    if (s->o.lyapunov != 0 && !(s->o.lyapunov > 0 && s->s.run.t_end / s->o.lyapunov <= SWIM_LYAPUNOV_MAX_SEGMENTS)) {
        swim_status_fail(st, "swim", s->m->P.name, 0, "lyapunov", "%s: lyapunov: the interval %g must be > 0 and give at "
                         "most %d renormalizations over t_end = %g", s->m->P.name, s->o.lyapunov,
                         SWIM_LYAPUNOV_MAX_SEGMENTS, s->s.run.t_end);
        s->bad_option = 2;
        return SWIM_EINPUT;
    }
    if (!keys) return SWIM_OK;
    if (!(s->sens_keys = strdup(keys))) return SWIM_ENOMEM;
    swim_sens S;
    if (swim_sens_init(&S, swim_run_dynamics(s->run)) != 0) return SWIM_ENOMEM;
    const int rc = swim_sens_add_list(&S, &s->s, "library", s->sens_keys, st);
    swim_sens_free(&S);
    if (rc) {   /* the option is what the caller gave: the key refused is named in the message */
        s->bad_option = 1;
        if (st) snprintf(st->key, sizeof st->key, "sensitivity");
    }
    return rc == 0 ? SWIM_OK : rc == 2 ? SWIM_EINPUT : SWIM_ENOMEM;
}

/* The sensitivity rows into the table (swim_analyses_sink). */
static int sens_table_row(void *ctx, const char *const *names, int ncol, const double *row, char *why, size_t len)
{
    swim_sim *s = ctx;
    if (swim_sens_table_add(&s->sens, names, ncol, row) == 0) return 0;
    snprintf(why, len, "out of memory keeping the sensitivities");
    return 1;
}

/* The options' analyses ride on the run's own integration, as `swim run`'s (output/job.c,
 * driver/analyses.h): attached before it starts. */
static int sim_attach_analyses(swim_sim *s, swim_status *st)
{
    if (!s->sens_keys && !(s->o.lyapunov > 0)) return SWIM_OK;
    const swim_analyses_request ar = {s->sens_keys, 0, 0, s->o.lyapunov > 0 ? s->o.lyapunov : 0.0, sens_table_row, s};
    int rc = swim_analyses_check(s->s.run.integrator, &ar, "swim", st);
    if (rc) {
        s->bad_option = s->sens_keys ? 1 : 2;
        return SWIM_EINPUT;
    }
    s->an_ready = 1;
    swim_status sst = {0};   /* the keys were checked when the simulation opened */
    rc = swim_analyses_attach(&s->an, s->run, &s->s, "library", &ar, &sst);
    return rc == 0 ? SWIM_OK : rc == 2 ? SWIM_EINPUT : SWIM_ENOMEM;
}

/* The options' analyses once the run ended, as `swim run` finishes them (output/job.c): the rows
 * came with the run's; sensitivities that stopped before the run did fail it, a Lyapunov result
 * that could not be had does not. */
static void sim_analyses(swim_sim *s)
{
    const swim_run_result *r = swim_run_get_result(s->run);
    if (s->analysed || !r->finished) return;
    s->analysed = 1;
    const swim_run_var_result *v = s->an_ready ? swim_run_get_var_result(s->run) : NULL;
    if (s->sens_keys && r->status == 0 && v) {
        char why[512];
        if (r->impacts) {   /* the variational equations would need the impact's jump (a saltation matrix) */
            snprintf(why, sizeof why, "no sensitivities: the run took %ld bounce(s) off the barrier as impacts, "
                     "across which sensitivities are not computed; set run.impact_depth = 0 to follow them", r->impacts);
            swim_run_fail(s->run, why);
        } else if (!v->carried) {
            snprintf(why, sizeof why, "the sensitivities stopped at t = %.6g: %s", v->t_stop, v->reason);
            swim_run_fail(s->run, why);
        } else {
            s->sens_ok = !(s->o.stop && *s->o.stop);
        }
    }
    if (s->o.lyapunov > 0) {
        r = swim_run_get_result(s->run);
        if (r->status != 0 || r->impacts || !(r->t_reached > 0) || !v)
            snprintf(s->lyap_reason, sizeof s->lyap_reason, "%s", r->status != 0 ? "the run did not complete"
                     : r->impacts ? "the run took impacts, across which the variational equations do not hold"
                                  : "the run has no time span");
        else if (swim_analyses_lyapunov(&s->an, s->run, s->o.lyapunov, s->s.run.rtol, &s->lyap) != 0)
            snprintf(s->lyap_reason, sizeof s->lyap_reason, "out of memory");
        else if (s->lyap.status != 0)
            snprintf(s->lyap_reason, sizeof s->lyap_reason, "%s", s->lyap.reason);
        else
            s->lyap_done = 1;
    }
}

static int sim_open(swim_sim *s, swim_status *st)
{
    const swim_model *m = s->m;
    if (swim_scene_parse_with(m->P.text, m->P.len, m->P.name, s->sets, s->nsets, &s->s, st) != 0) return SWIM_EINPUT;
    s->loaded = 1;   /* the reader checked the run settings (swim_run_settings_check) */
    int rc = swim_run_events_parse(&s->s, s->o.events, s->o.nevents, m->names, m->ncol, &s->events, st);
    if (rc) {
        s->bad_events = rc == 2;
        return rc == 2 ? SWIM_EINPUT : SWIM_ENOMEM;
    }
    if (s->o.on_event && s->events) swim_run_events_listen(s->events, sim_event, s);
    /* the caller's stop flag is a flag, not a signal number (any nonzero value stops the run) */
    const swim_run_request req = {&s->s, &m->P.kn, &m->P.spz, 0, s->events, (volatile sig_atomic_t *)s->o.stop,
                                  {sink_row, NULL, NULL, NULL, s}, 1};
    rc = swim_run_open(&req, &s->run, st);
    if (rc) return rc == 2 ? SWIM_EINPUT : SWIM_ENOMEM;
    rc = sim_check_analyses(s, st);
    return rc == SWIM_OK ? sim_attach_analyses(s, st) : rc;
}

static int swim_sim_create_(const swim_model *m, const swim_sim_options *o, swim_sim **out, swim_error *err)
{
    if (!out) return bad_arg(err, "out", "out is NULL");
    *out = NULL;
    if (!m) return bad_arg(err, "model", "model is NULL");
    swim_sim_options opts = {0};   /* what the caller's size does not hold keeps its default */
    if (o) {
        if (o->size < OPTIONS_V1) return too_small(err, "swim_sim_options", o->size, OPTIONS_V1);
        memcpy(&opts, o, o->size < sizeof opts ? o->size : sizeof opts);
    }
    if (string_list(err, "swim_sim_create", "events", "nevents", opts.events, opts.nevents)) return SWIM_EINPUT;
    *out = NULL;
    swim_sim *s = calloc(1, sizeof *s);
    if (!s || !(s->sets = malloc(sizeof *s->sets * (size_t)(m->P.nsets > 0 ? m->P.nsets : 1)))) {
        free(s);
        return failed(err, NULL, SWIM_ENOMEM, "out of memory");
    }
    s->m = m;
    s->o = opts;
    s->nsets = m->P.nsets;
    memcpy(s->sets, m->P.sets, sizeof *s->sets * (size_t)m->P.nsets);
    swim_status st = {0};
    const int rc = sim_open(s, &st);
    if (rc) {
        failed(err, &st, rc, "the simulation could not be set up");
        if (err && s->bad_events) {   /* an event of the options or of the scene: the model's file */
            if (!err->key[0]) snprintf(err->key, sizeof err->key, "events");
            if (!err->file[0]) snprintf(err->file, sizeof err->file, "%s", m->P.name);
        }
        if (err && s->bad_option && !err->key[0])
            snprintf(err->key, sizeof err->key, "%s", s->bad_option == 1 ? "sensitivity" : "lyapunov");
        swim_sim_free(s);
        return rc;
    }
    *out = s;
    return SWIM_OK;
}

static int sim_advance(swim_sim *s, double t, swim_error *err)
{
    if (t > s->t_asked) s->t_asked = t;
    swim_run_advance(s->run, t);
    sim_analyses(s);
    const int status = swim_run_get_result(s->run)->status;
    const swim_run_result *r = swim_run_get_result(s->run);
    return failed(err, NULL, status ? SWIM_EFAILED : SWIM_OK, r->reason ? r->reason : "out of memory");
}

static int swim_sim_advance_(swim_sim *s, double t, swim_error *err)
{
    if (!s) return bad_arg(err, "sim", "sim is NULL");
    if (bounded(err, "swim_sim_advance", "t", t)) return SWIM_EINPUT;
    if (t < s->t_asked)
        return bad_arg(err, "t", "the time to advance to, %.17g, is before %.17g, the time an earlier call advanced to",
                       t, s->t_asked);
    return sim_advance(s, t, err);
}

static int swim_sim_run_(swim_sim *s, swim_error *err)
{
    if (!s) return bad_arg(err, "sim", "sim is NULL");
    return sim_advance(s, INFINITY, err);
}

int swim_sim_result(const swim_sim *s, swim_result *theirs)
{
    if (!s || !theirs || theirs->size < RESULT_V1) return SWIM_EINPUT;
    const swim_run_result *r = swim_run_get_result(s->run);
    swim_result ours = {0}, *out = &ours;
    out->finished = r->finished;
    out->completed = r->finished && r->status == 0;
    out->t_reached = r->t_reached;
    out->rows = r->rows;
    if (r->final_state) {
        out->x = r->final_state[0];
        out->y = r->final_state[1];
        out->theta = r->final_state[2];
    }
    out->energy_initial = r->e0;
    out->energy_drift_abs = r->drift_abs;
    out->energy_drift_rel = r->emax > 0 ? r->drift_abs / r->emax : 0.0;
    out->jmin = r->jmin;
    out->steps = r->stats.steps;
    out->rhs_evaluations = r->stats.rhs_evals;
    give(theirs, out, sizeof *out);
    return SWIM_OK;
}

int swim_sim_state(const swim_sim *s, double *y, int len)
{
    if (!s || len < 0 || (!y && len > 0)) return -SWIM_EINPUT;
    const swim_run_result *r = swim_run_get_result(s->run);
    const int n = 3 + 2 * s->s.n;
    for (int i = 0; i < n && i < len && r->final_state; i++) y[i] = r->final_state[i];
    return n;
}

/* What fill writes, as a malloc'd string (NULL out of memory). */
static char *text_of(int (*fill)(FILE *f, const void *ctx), const void *ctx)
{
    char *buf = NULL;
    size_t len = 0;
    FILE *f = open_memstream(&buf, &len);
    if (!f) return NULL;
    const int bad = fill(f, ctx);
    if (fclose(f) != 0 || bad) {
        free(buf);
        return NULL;
    }
    return buf;
}

const char *swim_family_column(int i, const char **summary_path)
{
    int n;
    const sweep_column *cols = sweep_columns(&n);
    if (i < 0 || i >= n) return NULL;
    if (summary_path) *summary_path = cols[i].path;
    return cols[i].name;
}

static int fill_summary(FILE *f, const void *ctx)
{
    const swim_sim *s = ctx;
    const swim_summary_context x = {NULL, NULL, s->m->P.name, s->sets, s->nsets, 0, NULL, 0.0, 0, 0.0, NULL, 0, 0, 0.0, NULL, NULL};
    return swim_run_summary_json(f, s->run, &x);
}

static int fill_events(FILE *f, const void *ctx)
{
    swim_run_events_csv(((const swim_sim *)ctx)->events, f);
    return 0;
}

char *swim_sim_summary_json(const swim_sim *s) { return s ? text_of(fill_summary, s) : NULL; }

char *swim_sim_events_csv(const swim_sim *s) { return s ? text_of(fill_events, s) : NULL; }

int swim_sim_sensitivity(const swim_sim *s, const char *const **names, int *ncol, const double **values, long *nrows)
{
    if (!s || !names || !ncol || !values || !nrows || !s->sens_keys) return SWIM_EINPUT;
    *names = (const char *const *)s->sens.names;
    *ncol = s->sens.ncol;
    *values = s->sens.values;
    *nrows = s->sens.nrows;
    return s->sens_ok ? SWIM_OK : SWIM_EFAILED;
}

int swim_sim_lyapunov(const swim_sim *s, swim_lyapunov_result *theirs)
{
    if (!s || !theirs || theirs->size < LYAPUNOV_V1 || !(s->o.lyapunov > 0)) return SWIM_EINPUT;
    const swim_lyapunov *l = &s->lyap;
    const int have = l->n > 0;
    swim_lyapunov_result ours = {sizeof ours, s->lyap_done, have ? l->exponent : NAN,
                                 have ? l->exponent_half : NAN, swim_lyapunov_verdict_name(l->verdict),
                                 have && isfinite(l->horizon) ? l->horizon : INFINITY,
                                 have && isfinite(l->horizon_mean) ? l->horizon_mean : INFINITY,
                                 s->o.lyapunov, l->t_end, l->rtol, l->n, l->t, l->log_growth, s->lyap_reason};
    give(theirs, &ours, sizeof ours);
    return SWIM_OK;
}

static int swim_sim_state_at_(swim_sim *s, double t, double *y, int len, swim_error *err)
{
    if (!s) return -bad_arg(err, "sim", "sim is NULL");
    if (len < 0 || (!y && len > 0)) return -bad_arg(err, "y", "y is NULL or len < 0");
    const int n = 3 + 2 * s->s.n;
    double state[3 + 2 * SWIM_NMAX], ta = NAN, tb = NAN;
    const int rc = s->run ? swim_run_state_at(s->run, t, state, &ta, &tb) : -1;
    if (rc == 1)
        return -bad_arg(err, "t", "t = %.17g is outside the last step of the integrator, [%.17g, %.17g]", t, ta, tb);
    if (rc)
        return -refuse(err, SWIM_EFAILED, "", "no step to interpolate: nothing run yet, a restart since, a prescribed "
                       "stroke or an integrator without dense output");
    for (int i = 0; i < n && i < len; i++) y[i] = state[i];
    return n;
}

int swim_sim_state_at(swim_sim *s, double t, double *y, int len, swim_error *err)
{
    swim_error e;
    if (!error_begin(err, &e)) return -SWIM_EINPUT;
    const int rc = swim_sim_state_at_(s, t, y, len, &e);
    return error_give(err, &e, rc);
}

void swim_sim_free(swim_sim *s)
{
    if (!s) return;
    if (s->an_ready) swim_analyses_free(&s->an);
    swim_sens_table_free(&s->sens);
    swim_lyapunov_free(&s->lyap);
    free(s->sens_keys);
    swim_run_free(s->run);
    swim_run_events_free(s->events);
    if (s->loaded) swim_scene_free(&s->s);
    free(s->sets);
    free(s);
}

/* ---- a member of a family ---------------------------------------------------------------------- */

static double real_of(const swim_summary_real *r) { return r->set ? r->value : NAN; }

static long long count_of(const swim_summary_count *c) { return c->set ? c->value : -1; }

static int run_member(swim_model *m, const char *const *sets, int nsets, const char *const *events, int nevents,
                      swim_member *theirs, swim_error *err)
{
    if (!m) return bad_arg(err, "model", "model is NULL");
    if (!theirs) return bad_arg(err, "out", "out is NULL");
    if (theirs->size < MEMBER_V1) return too_small(err, "swim_member", theirs->size, MEMBER_V1);
    if (string_list(err, "swim_model_from_file", "sets", "nsets", sets, nsets)) return SWIM_EINPUT;
    for (int i = 0; i < nsets; i++) {
        char key[256];
        const char *eq = strchr(sets[i], '=');
        if (!eq || (size_t)(eq - sets[i]) >= sizeof key)
            return bad_arg(err, "sets", "sets[%d] = '%s' is not KEY=VALUE", i, sets[i]);
        snprintf(key, sizeof key, "%.*s", (int)(eq - sets[i]), sets[i]);
        const int rc = model_set(m, key, eq + 1, err);
        if (rc) return rc;
    }
    swim_sim_options o = SWIM_SIM_OPTIONS_INIT;
    o.events = events;
    o.nevents = nevents;
    swim_sim *s = NULL;
    int rc = swim_sim_create_(m, &o, &s, err);
    if (rc) return rc;
    swim_error ran = SWIM_ERROR_INIT;   /* a failed run is a member's row, not the call's failure */
    sim_advance(s, INFINITY, &ran);
    char *json = text_of(fill_summary, s), why[256];
    swim_summary sum;
    memset(&sum, 0, sizeof sum);
    rc = json && swim_summary_read(m->P.name, json, &sum, why, sizeof why) == SWIM_SUMMARY_OK ? SWIM_OK : SWIM_ENOMEM;
    const swim_run_result *r = swim_run_get_result(s->run);
    swim_member out = {sizeof out, r->finished && r->status == 0, "", "", real_of(&sum.t_reached), real_of(&sum.x),
                       real_of(&sum.y), real_of(&sum.theta), real_of(&sum.energy_drift_rel),
                       real_of(&sum.energy_balance_abs), real_of(&sum.jmin), count_of(&sum.steps),
                       count_of(&sum.rhs_evaluations), real_of(&sum.integrate_seconds), real_of(&sum.wall_seconds)};
    free(json);
    swim_sim_free(s);
    if (rc) return failed(err, NULL, rc, "out of memory");
    snprintf(out.status, sizeof out.status, "%s", sum.status);
    snprintf(out.reason, sizeof out.reason, "%s", sum.reason);
    give(theirs, &out, sizeof out);
    return SWIM_OK;
}

int swim_model_run_member(swim_model *m, const char *const *sets, int nsets, const char *const *events, int nevents,
                          swim_member *out, swim_error *err)
{
    swim_error e;
    if (!error_begin(err, &e)) return SWIM_EINPUT;
    return error_give(err, &e, run_member(m, sets, nsets, events, nevents, out, &e));
}

/* ---- orbits: periodic, floquet, continuation ------------------------------------------------ */

/* The scene of a model made ready for an orbit analysis, as swim periodic / floquet / continue
 * make it (control/periodic.c, floquet.c): its own copy of the scene (continuation sets its key
 * in place), the model's kernels, the dynamics and the section. */
typedef struct {
    swim_scene s;
    swim_dynamics d;
    int loaded, dyn;
    swim_floquet_section sec;
    char section[64];
} orbit_problem;

struct swim_orbit {
    char kind;                       /* 'p' periodic, 'f' floquet, 'b' branch */
    char *json, *csv;                /* the command's files */
    swim_periodic p;
    swim_floquet fl;
    swim_branch b;
    int n;                           /* shape state entries, and their names */
    char name_store[SWIM_FLOQUET_MAX][24];
    const char *names[SWIM_BRANCH_FIXED_COLUMNS + SWIM_FLOQUET_MAX];
    double *re, *im;                 /* periodic: the tangent multipliers */
    double *table;                   /* branch.csv's numbers */
    double special_lo[64], special_hi[64];
    const char *special_kind[64];
    char *key;                       /* the branch's parameter */
};

/* An option of command cmd within the bounds of its command-line option (scene/keys.c's rows of
 * the commands): 0 is the default and passes. */
static int option_bounded(swim_error *err, const char *cmd, const char *option, const char *arg, double v)
{
    const swim_scene_key *k = swim_command_option(cmd, option);
    if (v == 0 || !k || (isfinite(v) && v >= k->lo && (v < k->hi || (k->kind == SWIM_KEY_INTEGER && v == k->hi))))
        return SWIM_OK;
    return bad_arg(err, arg, "%s must be %s (got %g)", arg, k->expect, v);
}

static void orbit_close(orbit_problem *op)
{
    if (op->dyn) swim_dynamics_free(&op->d);
    if (op->loaded) swim_scene_free(&op->s);
    op->dyn = op->loaded = 0;
}

/* cmd "periodic", "floquet" or "continue": the scene checked as that command checks it. */
static int orbit_open(const swim_model *m, const swim_orbit_options *o, const char *cmd, orbit_problem *op,
                      swim_status *st)
{
    memset(op, 0, sizeof *op);
    if (swim_scene_parse_with(m->P.text, m->P.len, m->P.name, m->P.sets, m->P.nsets, &op->s, st) != 0) return SWIM_EINPUT;
    op->loaded = 1;
    const int floquet = strcmp(cmd, "floquet") == 0;
    if (floquet ? swim_floquet_check(&op->s, m->P.name, SWIM_FLOQUET_NO_STROKE | SWIM_FLOQUET_EVENTS, st)
                : swim_periodic_check(&op->s, cmd, m->P.name, st))
        return SWIM_EINPUT;
    if (swim_dynamics_init(&op->d, &op->s, m->P.kn.kernel) != 0) return SWIM_ENOMEM;
    op->dyn = 1;
    swim_dynamics_use_scene_kernel(&op->d, m->P.spz.scene, 0);
    op->d.interrupt = o->stop;
    return swim_floquet_parse_section(&op->d, cmd, floquet ? "event" : "guess-event", o->section, &op->sec,
                                      op->section, sizeof op->section, st) ? SWIM_EINPUT : SWIM_OK;
}

static void orbit_names(swim_orbit *a, const swim_dynamics *d, int n2)
{
    a->n = n2;
    for (int i = 0; i < n2; i++) {
        char name[20];
        swim_coord_name(d->spec->free_index[i % (n2 / 2)], name, sizeof name);
        snprintf(a->name_store[i], sizeof a->name_store[i], "%s%s", i < n2 / 2 ? "" : "d", name);
        a->names[i] = a->name_store[i];
    }
}

typedef struct {
    const swim_orbit *a;
    const swim_dynamics *d;
    const char *scene, *section;
} orbit_files;

static int fill_orbit_json(FILE *f, const void *ctx)
{
    const orbit_files *x = ctx;
    const swim_orbit *a = x->a;
    if (a->kind == 'p') swim_periodic_json(f, &a->p, x->d, x->scene, x->section);
    else if (a->kind == 'f') swim_floquet_json(f, &a->fl, x->scene, x->section);
    else swim_branch_json(f, &a->b, x->scene, a->key);
    return 0;
}

static int fill_orbit_csv(FILE *f, const void *ctx)
{
    const swim_orbit *a = ((const orbit_files *)ctx)->a;
    swim_branch_csv(f, &a->b, a->key);
    return 0;
}

/* The analysis of kind (periodic, floquet, continue) on m into *out. */
static int orbit_run(const swim_model *m, const swim_orbit_options *theirs, char kind, swim_orbit **out,
                     swim_error *err)
{
    if (!out) return bad_arg(err, "out", "out is NULL");
    *out = NULL;
    if (!m) return bad_arg(err, "model", "model is NULL");
    if (!theirs) return bad_arg(err, "options", "options is NULL");
    if (theirs->size < ORBIT_OPTIONS_V1)
        return too_small(err, "swim_orbit_options", theirs->size, ORBIT_OPTIONS_V1);
    swim_orbit_options o = {0};
    memcpy(&o, theirs, theirs->size < sizeof o ? theirs->size : sizeof o);
    const char *cmd = kind == 'p' ? "periodic" : kind == 'f' ? "floquet" : "continue";
    if (option_bounded(err, cmd, "tol", "tol", o.tol) || option_bounded(err, "periodic", "max-iter", "max_iter", o.max_iter) ||
        option_bounded(err, kind == 'f' ? "floquet" : "periodic", "t-max", "t_max", o.t_max))
        return SWIM_EINPUT;
    if (kind == 'b') {
        if (!o.param || !o.param[0]) return bad_arg(err, "param", "param is NULL or empty: give \"energy\" or a run-time key");
        if (!isfinite(o.start) || !isfinite(o.end) || o.start == o.end)
            return bad_arg(err, "start", "start and end must be finite numbers, start != end (got %g and %g)", o.start, o.end);
        if (option_bounded(err, "continue", "max-points", "points", o.points)) return SWIM_EINPUT;
    }
    swim_orbit *a = calloc(1, sizeof *a);
    if (!a || (kind == 'b' && !(a->key = strdup(o.param)))) {
        free(a);
        return refuse(err, SWIM_ENOMEM, "", "out of memory");
    }
    a->kind = kind;
    swim_status st = {0};
    orbit_problem op;
    int rc = orbit_open(m, &o, cmd, &op, &st);
    if (rc == SWIM_OK && kind == 'b' && strcmp(o.param, "energy") != 0) {
        /* both ends as overrides of the scene, refused as swim continue refuses them before any work */
        for (int e = 0; e < 2 && rc == SWIM_OK; e++) {
            swim_override ov[MAX_SETS + 1];
            char text[200], why[256];
            memcpy(ov, m->P.sets, sizeof ov[0] * (size_t)m->P.nsets);
            snprintf(text, sizeof text, "%s=%.17g", o.param, e ? o.end : o.start);
            swim_scene check;
            if (swim_override_parse(text, &ov[m->P.nsets], why, sizeof why) != 0) {
                swim_status_fail_cmd(&st, "continue", m->P.name, "param", "--param %s: %s", o.param, why);
                rc = SWIM_EINPUT;
            } else if (swim_scene_parse_with(m->P.text, m->P.len, m->P.name, ov, m->P.nsets + 1, &check, &st) != 0) {
                rc = SWIM_EINPUT;
            } else {
                swim_scene_free(&check);
            }
        }
    }
    int arc = 0;
    if (rc == SWIM_OK) {
        const double t_max = o.t_max > 0 ? o.t_max : op.s.run.t_end;
        swim_periodic_options po = {o.tol > 0 ? o.tol : 1e-11, o.max_iter > 0 ? o.max_iter : 20, 1e-12, 1e-14, t_max,
                                    cmd, "swim_orbit_options.t_max", NULL, NULL, NULL};
        if (kind == 'p') {
            arc = swim_periodic_solve(&op.d, &op.sec, &po, &a->p, &st);
        } else if (kind == 'f') {
            arc = swim_floquet_compute(&op.d, &op.sec, t_max, NULL, NULL, &a->fl, &st);
        } else {
            po.t_max = op.s.run.t_end;
            po.t_max_from = "run.t_end";
            const swim_cont_options co = {a->key, o.start, o.end, o.points > 0 ? o.points : 11, po, NULL, NULL};
            arc = swim_continue(&op.d, &op.s, &op.sec, &co, &a->b, &st);
        }
        rc = arc == 0 ? SWIM_OK : arc == 2 ? SWIM_EINPUT : SWIM_EFAILED;
    }
    if (rc == SWIM_OK) {
        const int n2 = 2 * op.d.spec->nfree;
        orbit_names(a, &op.d, n2);
        const orbit_files x = {a, &op.d, m->P.name, op.section};
        a->json = text_of(fill_orbit_json, &x);
        if (kind == 'b') a->csv = text_of(fill_orbit_csv, &x);
        if (kind == 'p' && a->p.have_floquet) {
            a->re = malloc(sizeof(double) * SWIM_FLOQUET_MAX);
            a->im = malloc(sizeof(double) * SWIM_FLOQUET_MAX);
            if (a->re && a->im) {
                memcpy(a->re, a->p.floquet.tre, sizeof a->p.floquet.tre);
                memcpy(a->im, a->p.floquet.tim, sizeof a->p.floquet.tim);
            }
        }
        if (kind == 'b') {
            const int ncol = swim_branch_columns(&a->b);
            a->table = malloc(sizeof(double) * (size_t)ncol * (size_t)(a->b.n > 0 ? a->b.n : 1));
            for (int i = 0; a->table && i < a->b.n; i++) swim_branch_row(&a->b, i, a->table + (size_t)i * ncol);
            for (int j = 0; j < ncol; j++) a->names[j] = swim_branch_column(&a->b, a->key, j);
            for (int i = 0; i < a->b.nspecial; i++) {
                a->special_lo[i] = a->b.special[i].lo;
                a->special_hi[i] = a->b.special[i].hi;
                a->special_kind[i] = a->b.special[i].kind;
            }
        }
        if (!a->json || (kind == 'b' && (!a->csv || !a->table)) || (kind == 'p' && a->p.have_floquet && (!a->re || !a->im)))
            rc = SWIM_ENOMEM;
    }
    orbit_close(&op);
    if (rc != SWIM_OK) {
        swim_orbit_free(a);
        return failed(err, &st, rc, rc == SWIM_ENOMEM ? "out of memory" : "the analysis failed");
    }
    *out = a;
    return SWIM_OK;
}

int swim_orbit_periodic(const swim_orbit *a, swim_periodic_result *theirs)
{
    if (!a || !theirs || a->kind != 'p' || theirs->size < PERIODIC_V1) return SWIM_EINPUT;
    const swim_periodic *p = &a->p;
    const swim_floquet *fl = &p->floquet;
    const int have = p->have_floquet;
    const swim_periodic_result r = {
        sizeof r, p->converged, p->stopped, p->why ? p->why : "", p->iterations, p->period, p->residual, p->scale,
        p->dx, p->dy, p->dtheta, p->energy, p->energy_target, p->t_guess, p->period_guess, a->n, a->names, p->z,
        have, have ? fl->M : NULL, have ? fl->nt : 0, have ? a->re : NULL, have ? a->im : NULL, have && fl->stable,
        p->rhs_calls, p->seconds};
    give(theirs, &r, sizeof r);
    return SWIM_OK;
}

int swim_orbit_floquet(const swim_orbit *a, swim_floquet_result *theirs)
{
    if (!a || !theirs || a->kind != 'f' || theirs->size < FLOQUET_V1) return SWIM_EINPUT;
    const swim_floquet *fl = &a->fl;
    const swim_floquet_result r = {
        sizeof r, fl->stopped, fl->period, fl->t_first, fl->closure, fl->closure_rel, fl->periodic,
        fl->periodic && fl->stable, fl->n2, fl->M, fl->re, fl->im, fl->nt, fl->tre, fl->tim, fl->nc, fl->cre, fl->cim,
        fl->rhs_calls, fl->seconds};
    give(theirs, &r, sizeof r);
    return SWIM_OK;
}

int swim_orbit_branch(const swim_orbit *a, swim_branch_result *theirs)
{
    if (!a || !theirs || a->kind != 'b' || theirs->size < BRANCH_V1) return SWIM_EINPUT;
    const swim_branch *b = &a->b;
    const char *ended = b->ended[0][0] ? b->ended[0] : b->ended[1];
    const swim_branch_result r = {
        sizeof r, b->stopped, b->n, swim_branch_columns(b), a->names, a->table, b->param0, ended, b->nspecial,
        a->special_lo, a->special_hi, a->special_kind, b->rhs_calls, b->seconds};
    give(theirs, &r, sizeof r);
    return SWIM_OK;
}

static char *copy_text(const char *t)
{
    return t ? strdup(t) : NULL;
}

char *swim_orbit_json(const swim_orbit *a) { return a ? copy_text(a->json) : NULL; }

char *swim_orbit_csv(const swim_orbit *a) { return a ? copy_text(a->csv) : NULL; }

void swim_orbit_free(swim_orbit *a)
{
    if (!a) return;
    if (a->kind == 'p') swim_periodic_free(&a->p);
    else if (a->kind == 'f') swim_floquet_free(&a->fl);
    else swim_branch_free(&a->b);
    free(a->json);
    free(a->csv);
    free(a->re);
    free(a->im);
    free(a->table);
    free(a->key);
    free(a);
}

/* ---- inspection ----------------------------------------------------------------------------- */

static int all_finite(const double *a, size_t count)
{
    for (size_t i = 0; a && i < count; i++)
        if (!isfinite(a[i])) return 0;
    return 1;
}

static int swim_inspect_(int modes, const double *shape, const double *velocity, double rho0, double rhof,
                         swim_inspection *theirs, swim_error *err)
{
    if (!theirs) return bad_arg(err, "out", "out is NULL");
    if (theirs->size < INSPECTION_V1) return too_small(err, "swim_inspection", theirs->size, INSPECTION_V1);
    swim_inspection in = {0}, *out = &in;   /* the caller's arrays, as far as its size holds */
    memcpy(&in, theirs, theirs->size < sizeof in ? theirs->size : sizeof in);
    if (bounded(err, "swim_inspect", "modes", modes) || bounded(err, "swim_inspect", "rho0", rho0) ||
        bounded(err, "swim_inspect", "rhof", rhof))
        return SWIM_EINPUT;
    const size_t nc = 2 * ((size_t)modes + 1);
    if (!shape) return bad_arg(err, "shape", "shape is NULL");
    if (!all_finite(shape, nc)) return bad_arg(err, "shape", "the shape has a value that is not a finite number");
    if (velocity && !all_finite(velocity, nc))
        return bad_arg(err, "velocity", "the velocity has a value that is not a finite number");
    theirs->jmin = out->jmin = swim_shape_jmin(modes, shape);   /* jmin: in the first layout */
    if (!(out->jmin > 0.0))
        return refuse(err, SWIM_EINPUT, "shape", "the shape is outside the admissible set D "
                      "(min J = %.6g <= 0 on the unit circle, (4.1))", out->jmin);
    swim_status st = {0};
    swim_compiled kc;   /* linked in, cached, or generated now */
    if (swim_codegen_kernel(modes, &kc, 0, &st) != 0) return failed(err, &st, SWIM_EKERNEL, "no kernel could be had");
    const swim_kernel *k = kc.kernel;
    static const char *const culprit[] = {"", "shape", "rho0", "rhof", "velocity"};
    const int over = swim_model_overflow(k, shape, velocity, rho0, rhof);
    if (over != SWIM_INPUT_OK) {
        swim_compiled_close(&kc);
        return refuse(err, SWIM_EINPUT, culprit[over], "too large: the mass matrices, K or the Christoffel term "
                      "exceed %g at these values", SWIM_MAGNITUDE_MAX);
    }
    const int n = 2 * (modes + 1);
    double *work = malloc(sizeof(double) * (size_t)(9 + 3 * n + 2 * n * n + n));
    if (!work) {
        swim_compiled_close(&kc);
        return refuse(err, SWIM_ENOMEM, "", "out of memory");
    }
    double *Mr = work, *Nc = Mr + 9, *Md = Nc + 3 * n, *K = Md + n * n, *gvv = K + n * n;
    k->mass(shape, rho0, rhof, Mr, Nc, Md);
    int rc = k->reduced(shape, velocity, rho0, rhof, K, NULL, velocity ? gvv : NULL);
    if (rc == 0 && out->christoffel) rc = k->reduced_deriv(shape, rho0, rhof, NULL, out->christoffel);
    swim_compiled_close(&kc);
    if (rc != 0) {
        free(work);
        return refuse(err, SWIM_EFAILED, "shape", "Mr is not positive definite at this shape");
    }
    const size_t nn = (size_t)n * (size_t)n;
    if (!all_finite(work, 9 + 3 * (size_t)n + 2 * nn) || (velocity && !all_finite(gvv, (size_t)n)) ||
        (out->christoffel && !all_finite(out->christoffel, nn * (size_t)n))) {
        free(work);   /* within bounds but a derivative still overflowed */
        return refuse(err, SWIM_EINPUT, "shape", "the results are not finite at this shape");
    }
    if (out->mass_rigid) memcpy(out->mass_rigid, Mr, sizeof(double) * 9);
    if (out->mass_coupling) memcpy(out->mass_coupling, Nc, sizeof(double) * 3 * (size_t)n);
    if (out->mass_shape) memcpy(out->mass_shape, Md, sizeof(double) * nn);
    if (out->mass_reduced) memcpy(out->mass_reduced, K, sizeof(double) * nn);
    if (out->christoffel_vv && velocity) memcpy(out->christoffel_vv, gvv, sizeof(double) * (size_t)n);
    free(work);
    return SWIM_OK;
}

/* ---- the functions with an error: the call on an error of its own, given to the caller's ----- */

int swim_model_from_file(const char *path, const char *const *sets, int nsets, swim_model **out, swim_error *err)
{
    swim_error e;
    if (!error_begin(err, &e)) return SWIM_EINPUT;
    return error_give(err, &e, swim_model_from_file_(path, sets, nsets, out, &e));
}

int swim_model_from_text(const char *toml, const char *name, const char *const *sets, int nsets, swim_model **out,
                         swim_error *err)
{
    swim_error e;
    if (!error_begin(err, &e)) return SWIM_EINPUT;
    return error_give(err, &e, swim_model_from_text_(toml, name, sets, nsets, out, &e));
}

int swim_model_set(swim_model *model, const char *key, const char *value, swim_error *err)
{
    swim_error e;
    if (!error_begin(err, &e)) return SWIM_EINPUT;
    return error_give(err, &e, model_set(model, key, value, &e));
}

int swim_sim_create(const swim_model *m, const swim_sim_options *o, swim_sim **out, swim_error *err)
{
    swim_error e;
    if (!error_begin(err, &e)) return SWIM_EINPUT;
    return error_give(err, &e, swim_sim_create_(m, o, out, &e));
}

int swim_sim_advance(swim_sim *s, double t, swim_error *err)
{
    swim_error e;
    if (!error_begin(err, &e)) return SWIM_EINPUT;
    return error_give(err, &e, swim_sim_advance_(s, t, &e));
}

int swim_sim_run(swim_sim *s, swim_error *err)
{
    swim_error e;
    if (!error_begin(err, &e)) return SWIM_EINPUT;
    return error_give(err, &e, swim_sim_run_(s, &e));
}

int swim_inspect(int modes, const double *shape, const double *velocity, double rho0, double rhof,
                 swim_inspection *out, swim_error *err)
{
    swim_error e;
    if (!error_begin(err, &e)) return SWIM_EINPUT;
    return error_give(err, &e, swim_inspect_(modes, shape, velocity, rho0, rhof, out, &e));
}

int swim_periodic_orbit(const swim_model *m, const swim_orbit_options *o, swim_orbit **out, swim_error *err)
{
    swim_error e;
    if (!error_begin(err, &e)) return SWIM_EINPUT;
    return error_give(err, &e, orbit_run(m, o, 'p', out, &e));
}

int swim_floquet_multipliers(const swim_model *m, const swim_orbit_options *o, swim_orbit **out, swim_error *err)
{
    swim_error e;
    if (!error_begin(err, &e)) return SWIM_EINPUT;
    return error_give(err, &e, orbit_run(m, o, 'f', out, &e));
}

int swim_continuation(const swim_model *m, const swim_orbit_options *o, swim_orbit **out, swim_error *err)
{
    swim_error e;
    if (!error_begin(err, &e)) return SWIM_EINPUT;
    return error_give(err, &e, orbit_run(m, o, 'b', out, &e));
}
