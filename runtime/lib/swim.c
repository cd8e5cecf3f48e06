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
#include "driver/analyses.h"
#include "driver/events.h"
#include "driver/run.h"
#include "driver/summary.h"
#include "io/files.h"
#include "io/message.h"
#include "io/version.h"
#include "kernel/swim_kernel.h"
#include "scene/keys.h"
#include "scene/resolve.h"
#include "scene/scene.h"
#include "shape/shape.h"

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
    char *text, *name, *resolved;
    size_t len;
    swim_override sets[MAX_SETS];
    int nsets;
    swim_scene *s;               /* as validated, for the columns, the kernels and swim_model_set;
                                    on the heap: a loaded scene is never moved (scene.h) */
    swim_compiled kn, sys;
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
                 {"swim_lyapunov_result", sizeof(swim_lyapunov_result)}};
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

static void scene_drop(swim_scene *s)
{
    if (!s) return;
    swim_scene_free(s);
    free(s);
}

static int model_open(swim_model *m, const char *const *sets, int nsets, swim_status *st)
{
    if (nsets > MAX_SETS) {
        swim_status_fail(st, "swim", m->name, 0, "nsets", "%s: more than %d overrides", m->name, MAX_SETS);
        return SWIM_EINPUT;
    }
    for (int i = 0; i < nsets; i++) {
        char why[256], key[128];
        if (swim_override_parse(sets[i], &m->sets[i], why, sizeof why) != 0) {
            /* the key of the override that does not parse: what precedes '=' */
            const size_t n = strcspn(sets[i], "=");
            snprintf(key, sizeof key, "%.*s", (int)(n < sizeof key ? n : sizeof key - 1), sets[i]);
            swim_status_fail(st, "swim", m->name, 0, key, "%s: --set: %s", m->name, why);
            return SWIM_EINPUT;
        }
    }
    m->nsets = nsets;
    if (!(m->s = calloc(1, sizeof *m->s))) return SWIM_ENOMEM;
    if (swim_scene_parse_with(m->text, m->len, m->name, m->sets, m->nsets, m->s, st) != 0) {
        free(m->s);
        m->s = NULL;
        return SWIM_EINPUT;
    }
    if (swim_run_settings_check(m->s, NULL, st) != 0) return SWIM_EINPUT;
    size_t outlen;
    char why[512];
    if (nsets > 0 && swim_scene_resolve(m->text, m->len, m->name, m->sets, m->nsets, &m->resolved, &outlen, why, sizeof why) != 0) {
        swim_status_fail(st, "swim", m->name, 0, NULL, "%s: %s", m->name, why);
        return SWIM_EINPUT;
    }
    const int rc = swim_codegen_for_scene("library", m->s, 0, 0, &m->kn, &m->sys, st);
    if (rc) return rc == 2 ? SWIM_EINPUT : SWIM_EKERNEL;
    m->ncol = swim_run_columns(m->s, m->names, m->storage);
    return SWIM_OK;
}

static int model_new(char *text, size_t len, const char *name, const char *const *sets, int nsets, swim_model **out,
                     swim_error *err)
{
    *out = NULL;
    swim_model *m = calloc(1, sizeof *m);
    if (!m || !text || !(m->name = strdup(name))) {
        free(text);
        if (m) free(m);
        return failed(err, NULL, SWIM_ENOMEM, "out of memory");
    }
    m->text = text;
    m->len = len;
    swim_status st = {0};
    const int rc = model_open(m, sets, nsets, &st);
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

const char *swim_model_scene_text(const swim_model *m) { return !m ? NULL : m->resolved ? m->resolved : m->text; }

/* One run-time key set in place (swim.h): the override list with it, validated as opening the
 * model with it would validate it, then kept when the kernel's structure is what it was. */
static int model_set(swim_model *m, const char *key, const char *value, swim_error *err)
{
    if (!m) return bad_arg(err, "model", "model is NULL");
    if (!key) return bad_arg(err, "key", "key is NULL");
    if (!value) return bad_arg(err, "value", "value is NULL");
    swim_override ov;
    char text[sizeof ov.text], why[256];
    if (snprintf(text, sizeof text, "%s=%s", key, value) >= (int)sizeof text)
        return bad_arg(err, "key", "%s=%s: longer than the %zu characters of an override", key, value, sizeof text - 1);
    if (swim_override_parse(text, &ov, why, sizeof why) != 0) {
        bad_arg(err, key, "%s: --set: %s", m->name, why);
        snprintf(err->file, sizeof err->file, "%s", m->name);
        return SWIM_EINPUT;
    }
    const swim_scene_key *row = swim_scene_key_find(ov.table, ov.key);
    if (row && (row->flags & SWIM_KEY_STRUCTURE) && !(row->flags & SWIM_KEY_RUNTIME)) {
        bad_arg(err, key, "%s: --set %s: %s.%s is a structure key (%s): it is given when the model is opened, "
                "not set in place", m->name, text, ov.table, ov.key, row->doc);
        snprintf(err->file, sizeof err->file, "%s", m->name);
        return SWIM_EINPUT;
    }
    /* the model's overrides with this one in place of any that set the same value */
    swim_override sets[MAX_SETS];
    int nsets = 0;
    for (int i = 0; i < m->nsets; i++)
        if (!(swim_override_same_target(&m->sets[i], &ov) && m->sets[i].index == ov.index)) sets[nsets++] = m->sets[i];
    if (nsets == MAX_SETS) return bad_arg(err, key, "%s: more than %d overrides", m->name, MAX_SETS);
    sets[nsets++] = ov;

    swim_status st = {0};
    swim_scene *s = calloc(1, sizeof *s);
    if (!s) return failed(err, NULL, SWIM_ENOMEM, "out of memory");
    if (swim_scene_parse_with(m->text, m->len, m->name, sets, nsets, s, &st) != 0) {
        free(s);
        return failed(err, &st, SWIM_EINPUT, "the value was refused");
    }
    int rc = swim_run_settings_check(s, NULL, &st) != 0 ? SWIM_EINPUT : SWIM_OK;
    if (!rc) {
        char *was = swim_codegen_scene_key(m->s, 0), *now = swim_codegen_scene_key(s, 0);
        if (!was || !now) rc = SWIM_ENOMEM;
        else if (strcmp(was, now) != 0) {
            swim_status_fail(&st, "swim", m->name, 0, key, "%s: --set %s: the value changes the kernel's structure%s%s%s: "
                             "it is given when the model is opened, not set in place", m->name, text,
                             row ? " (" : "", row ? row->doc : "", row ? ")" : "");
            rc = SWIM_EINPUT;
        }
        free(was);
        free(now);
    }
    /* the magnitude check opening the model makes with the kernel (codegen_for_scene's) */
    if (!rc && s->stroke_count == 0 && swim_scene_check_model(s, m->kn.kernel, &st) != 0) rc = SWIM_EINPUT;
    char *resolved = NULL;
    size_t outlen;
    if (!rc && swim_scene_resolve(m->text, m->len, m->name, sets, nsets, &resolved, &outlen, why, sizeof why) != 0) {
        swim_status_fail(&st, "swim", m->name, 0, key, "%s: %s", m->name, why);
        rc = SWIM_EINPUT;
    }
    if (rc) {
        scene_drop(s);
        failed(err, &st, rc, rc == SWIM_ENOMEM ? "out of memory" : "the value was refused");
        if (!err->key[0]) snprintf(err->key, sizeof err->key, "%s", key);
        if (!err->file[0]) snprintf(err->file, sizeof err->file, "%s", m->name);
        return rc;
    }
    scene_drop(m->s);
    m->s = s;
    memcpy(m->sets, sets, sizeof sets[0] * (size_t)nsets);
    m->nsets = nsets;
    free(m->resolved);
    m->resolved = resolved;
    return SWIM_OK;
}

void swim_model_free(swim_model *m)
{
    if (!m) return;
    swim_compiled_close(&m->sys);
    swim_compiled_close(&m->kn);
    scene_drop(m->s);
    free(m->text);
    free(m->name);
    free(m->resolved);
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
        swim_status_fail(st, "swim", s->m->name, 0, keys ? "sensitivity" : "lyapunov", "%s: --%s: not available on a "
                         "prescribed stroke: the variational equations are those of free shape dynamics only",
                         s->m->name, keys ? "sensitivity" : "lyapunov");
        s->bad_option = 1;
        return SWIM_EINPUT;
    }
    if (s->o.lyapunov != 0 && !(s->o.lyapunov > 0 && s->s.t_end / s->o.lyapunov <= SWIM_LYAPUNOV_MAX_SEGMENTS)) {
        swim_status_fail(st, "swim", s->m->name, 0, "lyapunov", "%s: lyapunov: the interval %g must be > 0 and give at "
                         "most %d renormalizations over t_end = %g", s->m->name, s->o.lyapunov,
                         SWIM_LYAPUNOV_MAX_SEGMENTS, s->s.t_end);
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
    int rc = swim_analyses_check(s->s.integrator, &ar, "swim", st);
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
        else if (swim_analyses_lyapunov(&s->an, s->run, s->o.lyapunov, s->s.rtol, &s->lyap) != 0)
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
    if (swim_scene_parse_with(m->text, m->len, m->name, s->sets, s->nsets, &s->s, st) != 0) return SWIM_EINPUT;
    s->loaded = 1;
    if (swim_run_settings_check(&s->s, NULL, st) != 0) return SWIM_EINPUT;
    int rc = swim_run_events_parse(&s->s, s->o.events, s->o.nevents, m->names, m->ncol, &s->events, st);
    if (rc) {
        s->bad_events = rc == 2;
        return rc == 2 ? SWIM_EINPUT : SWIM_ENOMEM;
    }
    if (s->o.on_event && s->events) swim_run_events_listen(s->events, sim_event, s);
    /* the caller's stop flag is a flag, not a signal number (any nonzero value stops the run) */
    const swim_run_request req = {&s->s, &m->kn, &m->sys, 0, s->events, (volatile sig_atomic_t *)s->o.stop,
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
    if (!s || !(s->sets = malloc(sizeof *s->sets * (size_t)(m->nsets > 0 ? m->nsets : 1)))) {
        free(s);
        return failed(err, NULL, SWIM_ENOMEM, "out of memory");
    }
    s->m = m;
    s->o = opts;
    s->nsets = m->nsets;
    memcpy(s->sets, m->sets, sizeof *s->sets * (size_t)m->nsets);
    swim_status st = {0};
    const int rc = sim_open(s, &st);
    if (rc) {
        failed(err, &st, rc, "the simulation could not be set up");
        if (err && s->bad_events) {   /* an event of the options or of the scene: the model's file */
            if (!err->key[0]) snprintf(err->key, sizeof err->key, "events");
            if (!err->file[0]) snprintf(err->file, sizeof err->file, "%s", m->name);
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

char *swim_sim_summary_json(const swim_sim *s)
{
    if (!s) return NULL;
    char *buf = NULL;
    size_t len = 0;
    FILE *f = open_memstream(&buf, &len);
    if (!f) return NULL;
    const swim_summary_context x = {NULL, NULL, s->m->name, s->sets, s->nsets, 0, NULL, 0.0, 0, 0.0, NULL, 0, 0, 0.0, NULL, NULL};
    swim_run_summary_json(f, s->run, &x);
    if (fclose(f) != 0) {
        free(buf);
        return NULL;
    }
    return buf;
}

char *swim_sim_events_csv(const swim_sim *s)
{
    if (!s) return NULL;
    char *buf = NULL;
    size_t len = 0;
    FILE *f = open_memstream(&buf, &len);
    if (!f) return NULL;
    swim_run_events_csv(s->events, f);
    if (fclose(f) != 0) {
        free(buf);
        return NULL;
    }
    return buf;
}

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
