#include "scene/scene.h"

#include <ctype.h>
#include <errno.h>
#include <stdarg.h>
#include <lapacke.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "io/message.h"
#include "io/status.h"
#include "shape/constraints.h"
#include "shape/shape.h"
#include "ode/ode.h"
#include "scene/keys.h"
#include "scene/material.h"
#include "scene/toml.h"

typedef struct {
    const char *path;
    const char *table;   /* current table name, for messages */
    const swim_scene *s; /* its overrides name the values they set (swim_scene_where) */
    swim_status *st;     /* where a refusal goes */
} ctx;

/* How an override is named in messages: "--set KEY=VALUE", or its text as it is when that names
 * the option it came from ("--param KEY=START:STOP ...", scene.h). */
static const char *set_option(const char *text) { return text[0] == '-' ? "" : "--set "; }

const char *swim_scene_where(const swim_scene *s, int line, char *buf, size_t n)
{
    if (line > 0) snprintf(buf, n, "%s:%d", s->path, line);
    else if (line < 0 && -line <= s->nover) snprintf(buf, n, "%s: %s%s", s->path, set_option(s->override_text[-line - 1]),
                                                       s->override_text[-line - 1]);
    else snprintf(buf, n, "%s", s->path);
    return buf;
}

#define WHERE_MAX 512   /* a path of any length is cut in messages, not the message itself */

/* The key an override's text names ("KEY" of "KEY=VALUE"; "" for the text of another option). */
static void override_key(const char *text, char *buf, size_t n)
{
    const char *eq = strchr(text, '=');
    snprintf(buf, n, "%.*s", text[0] == '-' || !eq ? 0 : (int)(eq - text), text);
}

/* The status of a value refused where it was given (line > 0: the file's line; line < 0: the
 * override -line; 0: the file): file, line and key, and its line as a command shows it. */
static void value_error(swim_status *st, const swim_scene *s, int line, const char *key, const char *fmt, ...)
    __attribute__((format(printf, 5, 6)));
static void value_error(swim_status *st, const swim_scene *s, int line, const char *key, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    char *msg = swim_vstrprintf(fmt, ap);
    va_end(ap);
    char where[WHERE_MAX], okey[128];
    const int from_override = line < 0 && -line <= s->nover;
    if (from_override) override_key(s->override_text[-line - 1], okey, sizeof okey);
    swim_status_fail(st, "swim", s->path, line > 0 ? line : 0, from_override && okey[0] ? okey : key, "%s: %s",
                     swim_scene_where(s, line, where, sizeof where), msg ? msg : fmt);
    free(msg);
}

/* One line "swim: FILE:LINE: TABLE.KEY: message" (user text quoted when it is shown);
 * for a value an override set, "swim: FILE: --set KEY=VALUE: TABLE.KEY: message". */
static void scene_error(const ctx *c, int line, const char *key, const char *fmt, ...)
    __attribute__((format(printf, 4, 5)));
static void scene_error(const ctx *c, int line, const char *key, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    char *msg = swim_vstrprintf(fmt, ap);
    va_end(ap);
    char full[128];
    snprintf(full, sizeof full, "%s%s%s", c->table ? c->table : "", c->table ? "." : "", key);
    value_error(c->st, c->s, line, full, "%s: %s", full, msg ? msg : fmt);
    free(msg);
}

#define ERR(c, line, key, ...)                        \
    do {                                              \
        scene_error((c), (line), (key), __VA_ARGS__); \
        return 2;                                     \
    } while (0)

/* Every |a_i| <= SWIM_MAGNITUDE_MAX (NaN fails too). */
static int bounded(const double *a, int n)
{
    for (int i = 0; i < n; i++)
        if (!(fabs(a[i]) <= SWIM_MAGNITUDE_MAX)) return 0;
    return 1;
}

/* 1 when Mr, N, Md, K (and with v, <Gamma, v, v> and v^T K v / 2) are all within bounds. */
static int model_bounded(const swim_kernel *k, const double *c, const double *v, double rho0, double rhof)
{
    const int n = k->dim;
    double Mr[9], Nc[3 * SWIM_NMAX], Md[SWIM_NMAX * SWIM_NMAX], K[SWIM_NMAX * SWIM_NMAX], g[SWIM_NMAX];
    k->mass(c, rho0, rhof, Mr, Nc, Md);
    if (!bounded(Mr, 9) || !bounded(Nc, 3 * n) || !bounded(Md, n * n)) return 0;
    if (k->reduced(c, v, rho0, rhof, K, NULL, v ? g : NULL) != 0 || !bounded(K, n * n)) return 0;
    if (!v) return 1;
    double e = 0.0;
    for (int i = 0; i < n; i++)
        for (int j = 0; j < n; j++) e += 0.5 * v[i] * K[i * n + j] * v[j];
    return bounded(g, n) && bounded(&e, 1);
}

int swim_model_overflow(const swim_kernel *k, const double *c, const double *v, double rho0, double rhof)
{
    if (!model_bounded(k, c, NULL, 1.0, 1.0)) return SWIM_INPUT_SHAPE;
    if (!model_bounded(k, c, NULL, rho0, 1.0)) return SWIM_INPUT_RHO0;
    if (!model_bounded(k, c, NULL, rho0, rhof)) return SWIM_INPUT_RHOF;
    if (v && !model_bounded(k, c, v, rho0, rhof)) return SWIM_INPUT_VELOCITY;
    return SWIM_INPUT_OK;
}

int swim_scene_check_model(const swim_scene *s, const swim_kernel *k, swim_status *st)
{
    ctx c = {.path = s->path, .table = "shape", .s = s, .st = st};
    switch (swim_model_overflow(k, s->c0, s->dc0, s->rho0, s->rhof)) {
    case SWIM_INPUT_SHAPE:
        ERR(&c, s->line_c0, "c0", "too large: the mass matrices at this shape exceed %g", SWIM_MAGNITUDE_MAX);
    case SWIM_INPUT_RHO0:
        c.table = "model";
        ERR(&c, s->line_rho0, "rho0", "%g is too large for this shape: the mass matrices exceed %g", s->rho0, SWIM_MAGNITUDE_MAX);
    case SWIM_INPUT_RHOF:
        c.table = "model";
        ERR(&c, s->line_rhof, "rhof", "%g is too large for this shape: the mass matrices exceed %g", s->rhof, SWIM_MAGNITUDE_MAX);
    case SWIM_INPUT_VELOCITY:
        ERR(&c, s->line_dc0, "dc0", "too large: the kinetic energy or the Christoffel term exceeds %g", SWIM_MAGNITUDE_MAX);
    }
    return 0;
}

/* Every key of table t must be in `allowed`. */
static int check_keys(ctx *c, const toml_value *t, const char *const *allowed)
{
    for (size_t i = 0; i < toml_table_size(t); i++) {
        const char *k = toml_table_key(t, i);
        int ok = 0;
        for (const char *const *a = allowed; *a; a++) ok |= strcmp(*a, k) == 0;
        if (!ok) {
            char list[256] = "";
            for (const char *const *a = allowed; *a; a++) {
                strncat(list, *a, sizeof list - strlen(list) - 3);
                if (a[1]) strncat(list, ", ", sizeof list - strlen(list) - 1);
            }
            ERR(c, toml_table_key_line(t, i), k, "unknown key (expected one of: %s)", list);
        }
    }
    return 0;
}

static int get_number(ctx *c, const toml_value *t, const char *key, int required, double *out)
{
    const toml_value *v = toml_get(t, key);
    int line = toml_get_key_line(t, key);
    if (!v) {
        if (required) ERR(c, toml_line(t), key, "missing (a number is required)");
        return 0;
    }
    if (!toml_is_number(v)) ERR(c, line, key, "expected a number, got a %s", toml_kind_name(toml_kind_of(v)));
    double d = toml_number(v);
    if (!isfinite(d)) ERR(c, line, key, "value %g is not a finite number", d);
    *out = d;
    return 0;
}

static int get_vector(ctx *c, const toml_value *t, const char *key, int n, int required, double *out,
                      int *present)
{
    const toml_value *v = toml_get(t, key);
    int line = toml_get_key_line(t, key);
    if (present) *present = v != NULL;
    if (!v) {
        if (required) ERR(c, toml_line(t), key, "missing (an array of %d numbers is required)", n);
        return 0;
    }
    if (toml_kind_of(v) != TOML_ARRAY) ERR(c, line, key, "expected an array of %d numbers, got a %s", n, toml_kind_name(toml_kind_of(v)));
    if ((int)toml_array_size(v) != n)
        ERR(c, line, key, "expected %d numbers (a1,b1,a-1,b-1,...) for this mode count, got %zu", n, toml_array_size(v));
    for (int i = 0; i < n; i++) {
        const toml_value *e = toml_array_at(v, (size_t)i);
        if (!toml_is_number(e)) ERR(c, line, key, "item %d is a %s, expected a number", i + 1, toml_kind_name(toml_kind_of(e)));
        out[i] = toml_number(e);
        if (!isfinite(out[i])) ERR(c, line, key, "item %d (%g) is not a finite number", i + 1, out[i]);
    }
    return 0;
}

static const toml_value *get_table(ctx *c, const toml_value *root, const char *name, int required, int *rc)
{
    const toml_value *t = toml_get(root, name);
    *rc = 0;
    if (!t && required) {
        swim_status_fail(c->st, "swim", c->path, 1, name, "%s:1: [%s]: missing table", c->path, name);
        *rc = 2;
    } else if (t && toml_kind_of(t) != TOML_TABLE) {
        value_error(c->st, c->s, toml_get_key_line(root, name), name, "%s: expected a table [%s], got a %s", name,
                    name, toml_kind_name(toml_kind_of(t)));
        *rc = 2;
        t = NULL;
    }
    return t;
}

/* An integrator name (absent: leave *out as it is). */
static int get_integrator(ctx *c, const toml_value *t, const char *key, char *out, size_t len)
{
    const toml_value *v = toml_get(t, key);
    if (!v) return 0;
    const char *name = toml_string(v);
    int line = toml_get_key_line(t, key);
    if (!name) ERR(c, line, key, "expected a string (an integrator name)");
    if (!swim_ode_method_known(name) || strlen(name) >= len)
        ERR(c, line, key, "unknown integrator \"%s\" (%s)", name, swim_ode_method_list());
    snprintf(out, len, "%s", name);
    return 0;
}

/* run.stiff_fallback (absent: leave *out as it is): "none" (out = ""), or an integrator that
 * takes over where ABM's stiffness diagnostic fires -- an implicit one: any other integrator is
 * held to the same stability limit and would crawl on, or stop, where ABM stopped. */
static int get_stiff_fallback(ctx *c, const toml_value *run, char *out, size_t len)
{
    const toml_value *v = toml_get(run, "stiff_fallback");
    if (!v) return 0;
    const char *name = toml_string(v);
    const int line = toml_get_key_line(run, "stiff_fallback");
    const char *allowed = swim_ode_method_list_with(SWIM_ODE_CAP_IMPLICIT);
    if (!name) ERR(c, line, "stiff_fallback", "expected a string (%s, or \"none\")", allowed);
    if (strcmp(name, "none") == 0) {
        out[0] = '\0';
        return 0;
    }
    if (!swim_ode_method_known(name))
        ERR(c, line, "stiff_fallback", "unknown integrator \"%s\" (%s, or \"none\")", name, allowed);
    if (!(swim_ode_capabilities(name) & SWIM_ODE_CAP_IMPLICIT) || strlen(name) >= len)
        ERR(c, line, "stiff_fallback", "integrator \"%s\" is not implicit: it has the stability limit that stops ABM (%s, or \"none\")",
            name, allowed);
    snprintf(out, len, "%s", name);
    return 0;
}

static int parse_free(ctx *c, const toml_value *shape, swim_scene *s)
{
    const toml_value *v = toml_get(shape, "free");
    int line = toml_get_key_line(shape, "free");
    if (!v) ERR(c, toml_line(shape), "free", "missing (\"all\" or an array of names such as \"am1\")");
    if (toml_kind_of(v) == TOML_STRING) {
        if (strcmp(toml_string(v), "all") != 0)
            ERR(c, line, "free", "expected \"all\" or an array of coordinate names, got \"%s\"", toml_string(v));
        for (int i = 0; i < s->n; i++) s->free_mask[i] = 1;
        return 0;
    }
    if (toml_kind_of(v) != TOML_ARRAY) ERR(c, line, "free", "expected \"all\" or an array of names, got a %s", toml_kind_name(toml_kind_of(v)));
    for (int i = 0; i < s->n; i++) s->free_mask[i] = 0;
    if (toml_array_size(v) == 0) ERR(c, line, "free", "no free coordinate: nothing can move");
    for (size_t j = 0; j < toml_array_size(v); j++) {
        const char *name = toml_string(toml_array_at(v, j));
        if (!name) ERR(c, line, "free", "item %zu is not a string", j + 1);
        int found = -1;
        char buf[16];
        for (int i = 0; i < s->n; i++) {
            swim_coord_name(i, buf, sizeof buf);
            if (strcmp(buf, name) == 0) found = i;
        }
        if (found < 0) ERR(c, line, "free", "unknown coordinate \"%s\" for modes = %d (names: a1, b1, am1, bm1, ..., bm%d)", name, s->modes, s->modes);
        if (s->free_mask[found]) ERR(c, line, "free", "coordinate \"%s\" listed twice", name);
        s->free_mask[found] = 1;
    }
    return 0;
}

/* G1, G2 and locks at dc0: error, or project if asked (ERRATA D5). */
static int check_initial_velocity(ctx *c, const toml_value *shape, swim_scene *s)
{
    double G[(SWIM_NMAX + 2) * SWIM_NMAX];
    int m = swim_constraint_rows(s->n, s->c0, s->free_mask, G);
    double worst = 0.0;
    int wrow = -1;
    for (int j = 0; j < m; j++) {
        double dot = 0.0, gn = 0.0, vn = 0.0;
        for (int i = 0; i < s->n; i++) {
            dot += G[j * s->n + i] * s->dc0[i];
            gn += G[j * s->n + i] * G[j * s->n + i];
            vn += s->dc0[i] * s->dc0[i];
        }
        double rel = fabs(dot) / fmax(sqrt(gn * vn), 1e-300);
        if (fabs(dot) > 1e-12 && rel > 1e-10 && fabs(dot) > worst) { worst = fabs(dot); wrow = j; }
    }
    if (wrow < 0) return 0;
    int line = toml_get_key_line(shape, "dc0");
    char what[64];
    if (wrow == 0) snprintf(what, sizeof what, "the volume constraint G1 (2.8)");
    else if (wrow == 1) snprintf(what, sizeof what, "the angular constraint G2 (2.14)");
    else {
        int idx = swim_constraint_locked_index(s->n, s->free_mask, wrow);
        char nm[16];
        swim_coord_name(idx, nm, sizeof nm);
        snprintf(what, sizeof what, "the lock of %s (it must start at rest)", nm);
    }
    if (!s->run.project_initial)
        ERR(c, line, "dc0", "violates %s by %.3g; fix the data or set [run] project_initial = true", what, worst);
    double before[SWIM_NMAX];
    memcpy(before, s->dc0, sizeof(double) * s->n);
    if (swim_constraint_project(s->n, m, G, s->dc0) != 0)
        ERR(c, line, "dc0", "cannot project onto the constraints: they are dependent at c0");
    s->projection_change = 0.0;
    for (int i = 0; i < s->n; i++) s->projection_change = fmax(s->projection_change, fabs(s->dc0[i] - before[i]));
    char where[WHERE_MAX];
    swim_status_note(c->st, "swim: %s: shape.dc0: violated %s by %.3g; projected onto the constraints "
                     "(largest change %.3g)", swim_scene_where(s, line, where, sizeof where), what, worst,
                     s->projection_change);
    return 0;
}

const char *swim_scene_stroke_where(const swim_scene *s, int coord, char *buf, size_t n)
{
    int k = 0;
    while (k < s->stroke_count - 1 && s->stroke_index[k] != coord) k++;
    char where[WHERE_MAX], name[24];
    swim_coord_name(s->stroke_index[k], name, sizeof name);
    snprintf(buf, n, "%s: stroke.%s", swim_scene_where(s, s->stroke_line[k], where, sizeof where), name);
    return buf;
}

/* The first of step, abs used in `law` (a word of the text), or NULL: neither is twice
 * differentiable where it switches, and a stroke needs c'' (its power). */
static const char *not_smooth(const char *law)
{
    static const char *const names[] = {"step", "abs"};
    for (const char *p = law; *p;) {
        if (!((*p >= 'a' && *p <= 'z') || (*p >= 'A' && *p <= 'Z'))) {
            p++;
            continue;
        }
        const char *w = p;
        while ((*p >= 'a' && *p <= 'z') || (*p >= 'A' && *p <= 'Z') || (*p >= '0' && *p <= '9') || *p == '_') p++;
        for (int i = 0; i < 2; i++)
            if ((size_t)(p - w) == strlen(names[i]) && strncmp(w, names[i], (size_t)(p - w)) == 0) return names[i];
    }
    return NULL;
}

/* [stroke] COORD = "law in t" (and period = T): a prescribed stroke. The tables of effects do
 * not apply (the shape is given, nothing acts on it) and neither do dc0 and free (the velocities
 * are the laws' derivatives; the laws say what moves): any of them is refused, naming its first
 * key. Sets free_mask to the prescribed coordinates, and to c1 when it is completed. */
static int parse_stroke(ctx *c, const toml_value *root, const toml_value *stroke, const toml_value *shape,
                        swim_scene *s)
{
    static const char *const refused[] = {"elastic", "barrier", "damping", "forcing"};
    for (size_t i = 0; i < sizeof refused / sizeof refused[0]; i++) {
        const toml_value *t = toml_get(root, refused[i]);
        if (!t) continue;
        c->table = refused[i];
        const int has_key = toml_kind_of(t) == TOML_TABLE && toml_table_size(t) > 0;
        ERR(c, has_key ? toml_table_key_line(t, 0) : toml_get_key_line(root, refused[i]),
            has_key ? toml_table_key(t, 0) : "*", "does not apply to a prescribed stroke ([stroke]): "
            "the shape is given, only (3.21) is integrated; remove [%s]", refused[i]);
    }
    c->table = "shape";
    static const char *const shape_refused[] = {"dc0", "free"};
    for (int i = 0; i < 2; i++)
        if (toml_get(shape, shape_refused[i]))
            ERR(c, toml_get_key_line(shape, shape_refused[i]), shape_refused[i], "does not apply to a prescribed "
                "stroke ([stroke]): the laws give the moving coordinates and their velocities; remove it");
    c->table = "stroke";
    s->stroke = 1;
    for (int i = 0; i < s->n; i++) s->free_mask[i] = 0;
    for (size_t j = 0; j < toml_table_size(stroke); j++) {
        const char *key = toml_table_key(stroke, j);
        const toml_value *v = toml_table_value(stroke, j);
        const int line = toml_table_key_line(stroke, j);
        if (strcmp(key, "period") == 0) {
            if (get_number(c, stroke, "period", 1, &s->stroke_period)) return 2;
            if (!(s->stroke_period > 0)) ERR(c, line, key, "must be > 0, got %g", s->stroke_period);
            s->stroke_period_line = line;
            continue;
        }
        int found = -1;
        char buf[16];
        for (int i = 0; i < s->n; i++) {
            swim_coord_name(i, buf, sizeof buf);
            if (strcmp(buf, key) == 0) found = i;
        }
        if (found < 0)
            ERR(c, line, key, "unknown key: expected period or a coordinate name for modes = %d (a1, b1, am1, bm1, ..., bm%d)",
                s->modes, s->modes);
        if (!toml_string(v)) ERR(c, line, key, "expected a string law in t, e.g. \"0.2*sin(t)\"");
        const int k = s->stroke_count++;
        char err[160];
        s->stroke_index[k] = found;
        s->stroke_line[k] = line;
        if (!(s->stroke_law[k] = strdup(toml_string(v)))) ERR(c, line, key, "out of memory");
        const char *names[SWIM_PARAMS_MAX];
        for (int i = 0; i < s->nparams; i++) names[i] = s->param_names[i];
        if (!(s->stroke_expr[k] = swim_expr_compile_params(s->stroke_law[k], names, s->nparams, s->param_values,
                                                           err, sizeof err)))
            ERR(c, line, key, "\"%s\": %s", s->stroke_law[k], err);
        const char *kink = not_smooth(s->stroke_law[k]);
        if (kink)
            ERR(c, line, key, "\"%s\": %s() is not twice differentiable where it switches; a stroke law must be "
                "(the power needs c'')", s->stroke_law[k], kink);
        s->free_mask[found] = 1;
    }
    if (s->stroke_count == 0) ERR(c, toml_line(stroke), "*", "no law: a stroke prescribes at least one coordinate");
    s->stroke_complete_c1 = !s->free_mask[0] && !s->free_mask[1];
    if (s->stroke_complete_c1) s->free_mask[0] = s->free_mask[1] = 1;
    return 0;
}

/* [parameters]: NAME = number, NAME an identifier that the law grammar does not already take. */
static int parse_parameters(ctx *c, const toml_value *root, swim_scene *s)
{
    int rc;
    const toml_value *pa = get_table(c, root, "parameters", 0, &rc);
    if (rc || !pa) return rc;
    c->table = "parameters";
    s->params_line = toml_line(pa);
    for (size_t i = 0; i < toml_table_size(pa); i++) {
        const char *k = toml_table_key(pa, i);
        const int line = toml_table_key_line(pa, i);
        int ident = isalpha((unsigned char)k[0]) && strlen(k) < sizeof s->param_names[0];
        for (const char *q = k; ident && *q; q++) ident = isalnum((unsigned char)*q) || *q == '_';
        if (!ident) ERR(c, line, k, "a parameter name is a letter followed by letters, digits or _ (at most %zu characters)", sizeof s->param_names[0] - 1);
        if (swim_expr_reserved(k)) ERR(c, line, k, "'%s' is taken by the law grammar (t, pi, e, sin, cos, ...): choose another parameter name", k);
        if (s->nparams == SWIM_PARAMS_MAX) ERR(c, line, k, "more than %d parameters", SWIM_PARAMS_MAX);
        double v;
        if (get_number(c, pa, k, 1, &v)) return 2;
        snprintf(s->param_names[s->nparams], sizeof s->param_names[0], "%s", k);
        s->param_values[s->nparams++] = v;
    }
    return 0;
}

/* The plain keys of table t (named `table`, scene/keys.h): each read, bounded and defaulted from
 * its row, in the table's order. */
static int read_plain(ctx *c, const toml_value *t, const char *table, swim_scene *s)
{
    int count;
    const swim_scene_key *keys = swim_scene_keys(&count);
    for (int i = 0; i < count; i++) {
        const swim_scene_key *k = &keys[i];
        if (!(k->flags & SWIM_KEY_PLAIN) || strcmp(k->table, table) != 0) continue;
        void *field = (char *)s + k->offset;
        const toml_value *v = toml_get(t, k->key);
        const int line = toml_get_key_line(t, k->key);
        switch (k->kind) {
        case SWIM_KEY_BOOL:
            *(int *)field = (int)k->dflt;
            if (v && toml_kind_of(v) != TOML_BOOL) ERR(c, line, k->key, "expected %s", k->expect);
            if (v) *(int *)field = toml_bool(v);
            break;
        case SWIM_KEY_INTEGER:
            *(int *)field = (int)k->dflt;
            if (v && (toml_kind_of(v) != TOML_INT || toml_int(v) < k->lo || toml_int(v) > k->hi))
                ERR(c, line, k->key, "expected %s", k->expect);
            if (v) *(int *)field = (int)toml_int(v);
            break;
        case SWIM_KEY_NUMBER:
            *(double *)field = k->dflt;
            if (get_number(c, t, k->key, 0, (double *)field)) return 2;
            if (!(*(double *)field >= k->lo && *(double *)field < k->hi))
                ERR(c, line, k->key, "value %g must be %s", *(double *)field, k->expect);
            break;
        case SWIM_KEY_CHOICE: {
            *(int *)field = (int)k->dflt;
            if (!v) break;
            const char *w = toml_string(v);
            int found = -1;
            for (int j = 0; w && k->words[j]; j++)
                if (strcmp(w, k->words[j]) == 0) found = j;
            if (found < 0) ERR(c, line, k->key, "expected %s", k->expect);
            *(int *)field = found;
            break;
        }
        default:
            break;
        }
    }
    return 0;
}

/* check_keys with the keys scene/keys.h lists for `table`. */
static int check_table_keys(ctx *c, const toml_value *t, const char *table)
{
    const char *names[64];
    swim_scene_table_keys(table, names, 64);
    return check_keys(c, t, names);
}

static int load_tree(ctx *c, const toml_value *root, swim_scene *s)
{
    int rc;
    c->table = NULL;
    if (check_keys(c, root, swim_scene_tables())) return 2;
    const toml_value *title = toml_get(root, "title");
    if (title) {
        if (!toml_string(title)) ERR(c, toml_get_key_line(root, "title"), "title", "expected a string");
        free(s->title);
        if (!(s->title = strdup(toml_string(title)))) ERR(c, toml_get_key_line(root, "title"), "title", "out of memory");
    }

    const toml_value *model = get_table(c, root, "model", 1, &rc);
    if (rc) return rc;
    c->table = "model";
    if (check_table_keys(c, model, "model")) return 2;
    const toml_value *mv = toml_get(model, "modes");
    if (!mv) ERR(c, toml_line(model), "modes", "missing (an integer 0..%d is required)", SWIM_KERNEL_MAX_MODES);
    if (toml_kind_of(mv) != TOML_INT) ERR(c, toml_get_key_line(model, "modes"), "modes", "expected an integer, got a %s", toml_kind_name(toml_kind_of(mv)));
    long long N = toml_int(mv);
    if (N < 0 || N > SWIM_KERNEL_MAX_MODES) ERR(c, toml_get_key_line(model, "modes"), "modes", "%lld is out of range 0..%d", N, SWIM_KERNEL_MAX_MODES);
    s->modes = (int)N;
    s->n = 2 * (s->modes + 1);
    if (get_number(c, model, "rho0", 1, &s->rho0)) return 2;
    if (!(s->rho0 > 0)) ERR(c, toml_get_key_line(model, "rho0"), "rho0", "density must be > 0, got %g", s->rho0);
    const toml_value *rf = toml_get(model, "rhof");
    if (!rf) ERR(c, toml_line(model), "rhof", "missing (a number, or \"neutral\" for (2.10))");
    if (toml_kind_of(rf) == TOML_STRING) {
        if (strcmp(toml_string(rf), "neutral") != 0) ERR(c, toml_get_key_line(model, "rhof"), "rhof", "expected a number or \"neutral\", got \"%s\"", toml_string(rf));
        s->rhof_neutral = 1;
    } else {
        if (get_number(c, model, "rhof", 1, &s->rhof)) return 2;
        if (!(s->rhof > 0)) ERR(c, toml_get_key_line(model, "rhof"), "rhof", "density must be > 0, got %g", s->rhof);
    }

    const toml_value *run = get_table(c, root, "run", 1, &rc);
    if (rc) return rc;
    c->table = "run";
    if (check_table_keys(c, run, "run")) return 2;
    /* Bounds and the row cap: swim_run_settings_check, once the forcing law is read too. */
    if (get_number(c, run, "t_end", 1, &s->run.t_end)) return 2;
    if (get_number(c, run, "output_step", 1, &s->run.output_step)) return 2;
    s->run.rtol = 1e-8;
    s->run.atol = 1e-10;
    if (get_number(c, run, "rtol", 0, &s->run.rtol)) return 2;
    if (get_number(c, run, "atol", 0, &s->run.atol)) return 2;
    static const char *const setting_keys[] = {"t_end", "output_step", "rtol", "atol"};
    for (int i = 0; i < 4; i++) s->setting_line[i] = toml_get_key_line(run, setting_keys[i]);
    snprintf(s->run.integrator, sizeof s->run.integrator, "abm");
    if (get_integrator(c, run, "integrator", s->run.integrator, sizeof s->run.integrator)) return 2;
    /* BDF by default: where ABM's stiffness diagnostic fires, a stiff code goes on at a fraction
     * of the cost; "none" keeps the stop with the message naming the remedy */
    snprintf(s->run.stiff_fallback, sizeof s->run.stiff_fallback, "cvode-bdf");
    if (get_stiff_fallback(c, run, s->run.stiff_fallback, sizeof s->run.stiff_fallback)) return 2;
    /* projection, origin_shift, energy_control, impact_depth, step_lookahead, jacobian,
     * project_initial: plain keys (scene/keys.h). Turning points below the resolution of
     * J = |c_1|^2 - |h|^2 in double precision (u |c_1|^2) are impacts by default: the shifted
     * coordinates follow some deeper bounces, at a cost that explodes (one to 3e-19 took > 200 s
     * at rtol 1e-8, and one to 5e-23 never finished) -- model/bounce.h */
    if (read_plain(c, run, "run", s)) return 2;

    const toml_value *shape = get_table(c, root, "shape", 1, &rc);
    if (rc) return rc;
    c->table = "shape";
    if (check_table_keys(c, shape, "shape")) return 2;
    if (get_vector(c, shape, "c0", s->n, 1, s->c0, NULL)) return 2;
    if (parse_parameters(c, root, s)) return 2;   /* before the laws that may use them */
    c->table = "shape";
    const toml_value *stroke = get_table(c, root, "stroke", 0, &rc);
    if (rc) return rc;
    if (stroke) {
        if (parse_stroke(c, root, stroke, shape, s)) return 2;
        c->table = "shape";
    } else {
        if (get_vector(c, shape, "dc0", s->n, 1, s->dc0, NULL)) return 2;
        if (parse_free(c, shape, s)) return 2;
    }
    double jmin = swim_shape_jmin(s->modes, s->c0);
    if (!(jmin > 0)) ERR(c, toml_get_key_line(shape, "c0"), "c0", "shape outside the admissible set D: min J = %.4g <= 0 on the unit circle (4.1)", jmin);
    double mu2 = swim_area_constant(s->n, s->c0);
    if (s->rhof_neutral) s->rhof = s->rho0 / mu2;
    /* The magnitude check needs the kernel of N modes, which may have to be generated: the
     * lines are kept for swim_scene_check_model, called once the kernel is at hand. */
    s->line_c0 = toml_get_key_line(shape, "c0");
    s->line_dc0 = toml_get_key_line(shape, "dc0");
    s->line_rho0 = toml_get_key_line(model, "rho0");
    s->line_rhof = toml_get_key_line(model, "rhof");

    const toml_value *el = get_table(c, root, "elastic", 0, &rc);
    if (rc) return rc;
    if (el) {
        c->table = "elastic";
        if (check_table_keys(c, el, "elastic")) return 2;
        /* with an energy law, W1 is optional (stiffness and reference then default to 0) */
        const int need_w1 = toml_get(el, "energy") == NULL;
        if (get_vector(c, el, "stiffness", s->n, need_w1, s->stiffness, NULL)) return 2;
        if (get_vector(c, el, "reference", s->n, need_w1, s->reference, NULL)) return 2;
        for (int i = 0; i < s->n; i++) {
            if (s->stiffness[i] < 0) ERR(c, toml_get_key_line(el, "stiffness"), "stiffness", "item %d is %g; R must be >= 0", i + 1, s->stiffness[i]);
            if (s->stiffness[i] > 0) s->elastic = 1;
        }
        const toml_value *en = toml_get(el, "energy");
        if (en) {
            const int line = toml_get_key_line(el, "energy");
            char why[256];
            if (!toml_string(en)) ERR(c, line, "energy", "expected a string law in I1, J, I1bar, e.g. \"0.5*(I1 - 2)\"");
            s->energy_line = line;
            if (!(s->energy_text = strdup(toml_string(en)))) ERR(c, line, "energy", "out of memory");
            if (swim_material_compile(s, why, sizeof why) != 0 || swim_material_check(s, s->c0, why, sizeof why) != 0)
                ERR(c, line, "energy", "\"%s\": %s", s->energy_text, why);
        }
    }
    const toml_value *ba = get_table(c, root, "barrier", 0, &rc);
    if (rc) return rc;
    if (ba) {
        c->table = "barrier";
        if (check_table_keys(c, ba, "barrier")) return 2;
        if (get_number(c, ba, "epsilon", 1, &s->epsilon)) return 2;
        if (get_number(c, ba, "alpha", 1, &s->alpha)) return 2;
        if (s->epsilon < 0) ERR(c, toml_get_key_line(ba, "epsilon"), "epsilon", "must be >= 0, got %g", s->epsilon);
        if (!(s->alpha > 0)) ERR(c, toml_get_key_line(ba, "alpha"), "alpha", "must be > 0 (>= 0.5 for Prop. 4.2), got %g", s->alpha);
        s->barrier = s->epsilon > 0;
    }
    const toml_value *da = get_table(c, root, "damping", 0, &rc);
    if (rc) return rc;
    if (da) {
        c->table = "damping";
        if (check_table_keys(c, da, "damping")) return 2;
        if (get_vector(c, da, "diagonal", s->n, 1, s->damping, NULL)) return 2;
        for (int i = 0; i < s->n; i++) {
            if (s->damping[i] < 0) ERR(c, toml_get_key_line(da, "diagonal"), "diagonal", "item %d is %g; D must be >= 0 (4.15)", i + 1, s->damping[i]);
            if (s->damping[i] > 0) s->damped = 1;
        }
    }
    const toml_value *fo = get_table(c, root, "forcing", 0, &rc);
    if (rc) return rc;
    if (fo) {
        c->table = "forcing";
        if (check_table_keys(c, fo, "forcing")) return 2;
        const toml_value *law = toml_get(fo, "law");
        if (!law || !toml_string(law)) ERR(c, law ? toml_get_key_line(fo, "law") : toml_line(fo), "law", "expected a string expression in t, e.g. \"sin(t)\"");
        char err[160];
        s->setting_line[SWIM_SET_LAW] = toml_get_key_line(fo, "law");
        if (!(s->forcing_text = strdup(toml_string(law)))) ERR(c, toml_get_key_line(fo, "law"), "law", "out of memory");
        const char *names[SWIM_PARAMS_MAX];
        for (int i = 0; i < s->nparams; i++) names[i] = s->param_names[i];
        s->forcing = swim_expr_compile_params(s->forcing_text, names, s->nparams, s->param_values, err, sizeof err);
        if (!s->forcing) ERR(c, toml_get_key_line(fo, "law"), "law", "\"%s\": %s", s->forcing_text, err);
        if (get_vector(c, fo, "direction", s->n, 1, s->direction, NULL)) return 2;
        for (int i = 0; i < s->n; i++) s->forced |= s->direction[i] != 0.0;
    }
    const toml_value *evt = get_table(c, root, "events", 0, &rc);
    if (rc) return rc;
    if (evt) {
        c->table = "events";
        if (check_table_keys(c, evt, "events")) return 2;
        const toml_value *list = toml_get(evt, "list");
        int line = list ? toml_get_key_line(evt, "list") : toml_line(evt);
        if (!list || toml_kind_of(list) != TOML_ARRAY)
            ERR(c, line, "list", "expected an array of \"COLUMN:KIND[:stop]\" strings, e.g. [\"energy:max\"]");
        if (toml_array_size(list) > sizeof s->events / sizeof s->events[0])
            ERR(c, line, "list", "more than %zu events", sizeof s->events / sizeof s->events[0]);
        for (size_t j = 0; j < toml_array_size(list); j++) {
            const char *e = toml_string(toml_array_at(list, j));
            if (!e || strlen(e) >= sizeof s->events[0]) ERR(c, line, "list", "item %zu is not a string of at most %zu characters", j + 1, sizeof s->events[0] - 1);
            snprintf(s->events[s->nevents++], sizeof s->events[0], "%s", e);
        }
        s->events_line = line;
    }
    if (swim_run_settings_check(s, NULL, c->st)) return 2;
    c->table = "shape";
    return check_initial_velocity(c, shape, s);
}

int swim_scene_parse_with(const char *text, size_t len, const char *path, const swim_override *ov,
                          int nov, swim_scene *s, swim_status *st)
{
    memset(s, 0, sizeof *s);
    s->run.forcing_finite_until = INFINITY;
    s->path = strdup(path);
    s->title = strdup("");
    if (!s->path || !s->title) {
        swim_status_fail(st, "swim", path, 0, NULL, "%s: out of memory", path);
        swim_scene_free(s);
        return 2;
    }
    /* A UTF-8 byte order mark (some editors write one) is not part of the TOML text. */
    if (len >= 3 && memcmp(text, "\xEF\xBB\xBF", 3) == 0) {
        text += 3;
        len -= 3;
    }
    char err[512];
    toml_value *root = toml_parse(text, len, err, sizeof err);
    if (!root) {
        int line = 0;
        const char *msg = err;
        if (sscanf(err, "line %d:", &line) == 1 && strchr(err, ':')) msg = strchr(err, ':') + 2;
        swim_status_fail(st, "swim", path, line, NULL, "%s:%d: %s", path, line, msg);
        swim_scene_free(s);
        return 2;
    }
    int earlier, j = swim_override_conflict(ov, nov, &earlier);
    if (j >= 0) {
        char target[100];
        swim_override_target(&ov[j], target, sizeof target);
        swim_status_fail(st, "swim", path, 0, target, "%s: %s%s: sets %s, which %s%s already sets to another value "
                         "(give each value once)", path, set_option(ov[j].text), ov[j].text, target,
                         set_option(ov[earlier].text), ov[earlier].text);
        toml_free(root);
        swim_scene_free(s);
        return 2;
    }
    if (nov > 0 && !(s->override_text = calloc((size_t)nov, sizeof *s->override_text))) {
        swim_status_fail(st, "swim", path, 0, NULL, "%s: out of memory", path);
        toml_free(root);
        swim_scene_free(s);
        return 2;
    }
    for (int i = 0; i < nov; i++) {
        if (!(s->override_text[i] = strdup(ov[i].text))) {
            swim_status_fail(st, "swim", path, 0, NULL, "%s: out of memory", path);
            toml_free(root);
            swim_scene_free(s);
            return 2;
        }
        s->nover = i + 1;
        int bad;
        if (!ov[i].word[0])
            bad = toml_set_number(root, ov[i].table, ov[i].key, ov[i].index, ov[i].value, err, sizeof err);
        else if (ov[i].index >= 0)
            bad = snprintf(err, sizeof err, "value '%s' is not a finite number", ov[i].word) > 0;
        else if (!strcmp(ov[i].word, "true") || !strcmp(ov[i].word, "false"))
            bad = toml_set_bool(root, ov[i].table, ov[i].key, ov[i].word[0] == 't', err, sizeof err);
        else
            bad = toml_set_string(root, ov[i].table, ov[i].key, ov[i].word, err, sizeof err);
        if (bad) {
            char okey[128];
            override_key(ov[i].text, okey, sizeof okey);
            swim_status_fail(st, "swim", path, 0, okey, "%s: %s%s: %s", path, set_option(ov[i].text), ov[i].text, err);
            toml_free(root);
            swim_scene_free(s);
            return 2;
        }
        toml_set_origin(root, ov[i].table, ov[i].key, ov[i].index, -(i + 1));
    }
    ctx c = {path, NULL, s, st};
    int rc = load_tree(&c, root, s);
    toml_free(root);
    if (rc) swim_scene_free(s);
    return rc;
}

/* The whole file in a new buffer, refused before reading when it is not a regular file of at
 * most SWIM_SCENE_MAX_BYTES (a pipe is read up to that size). NULL with the reason in status. */
char *swim_scene_read(const char *path, size_t *len, swim_status *status)
{
    FILE *f = fopen(path, "rb");
    if (!f) {
        swim_status_fail(status, "swim", path, 0, NULL, "%s: cannot open scene file: %s", path, strerror(errno));
        return NULL;
    }
    struct stat st = {0};
    const char *refusal = NULL;
    if (fstat(fileno(f), &st) != 0) refusal = strerror(errno);
    else if (S_ISDIR(st.st_mode)) refusal = "is a directory, not a scene file";
    else if (S_ISREG(st.st_mode) && st.st_size > SWIM_SCENE_MAX_BYTES) refusal = "too large for a scene file";
    if (refusal) {
        if (S_ISREG(st.st_mode))
            swim_status_fail(status, "swim", path, 0, NULL, "%s: %s (%lld bytes; the limit is %ld)", path, refusal,
                             (long long)st.st_size, SWIM_SCENE_MAX_BYTES);
        else
            swim_status_fail(status, "swim", path, 0, NULL, "%s: %s", path, refusal);
        fclose(f);
        return NULL;
    }
    char *buf = malloc(SWIM_SCENE_MAX_BYTES + 1);
    size_t got = buf ? fread(buf, 1, SWIM_SCENE_MAX_BYTES + 1, f) : 0;
    int bad = buf && ferror(f);
    fclose(f);
    if (!buf || bad || got > SWIM_SCENE_MAX_BYTES) {
        swim_status_fail(status, "swim", path, 0, NULL, "%s: %s", path, !buf ? "out of memory" : bad ? "read error"
                         : "too large for a scene file (the limit is 1 MiB)");
        free(buf);
        return NULL;
    }
    buf[got] = '\0';
    *len = got;
    return buf;
}

int swim_scene_parse(const char *text, size_t len, const char *path, swim_scene *s, swim_status *st)
{
    return swim_scene_parse_with(text, len, path, NULL, 0, s, st);
}

int swim_scene_load(const char *path, swim_scene *s, swim_status *st)
{
    return swim_scene_load_with(path, NULL, 0, s, st);
}

int swim_scene_load_with(const char *path, const swim_override *ov, int nov, swim_scene *s, swim_status *st)
{
    memset(s, 0, sizeof *s);
    size_t len;
    char *buf = swim_scene_read(path, &len, st);
    if (!buf) return 2;
    int rc = swim_scene_parse_with(buf, len, path, ov, nov, s, st);
    free(buf);
    return rc;
}

/* a1 -> 0, b1 -> 1, amK -> 2K, bmK -> 2K + 1 (the storage order of models/README.md). */
static long coord_index(const char *name)
{
    if (name[0] != 'a' && name[0] != 'b') return -1;
    long odd = name[0] == 'b';
    if (strcmp(name + 1, "1") == 0) return odd;
    if (name[1] != 'm' || name[2] < '1' || name[2] > '9') return -1;
    char *end;
    long k = strtol(name + 2, &end, 10);
    if (*end != '\0' || k < 1 || k > SWIM_KERNEL_MAX_MODES) return -1;
    return 2 * k + odd;
}

static int word_ok(const char *w, size_t len)
{
    if (len == 0 || len >= 32) return 0;
    for (size_t i = 0; i < len; i++)
        if (!(w[i] == '_' || (w[i] >= 'a' && w[i] <= 'z') || (w[i] >= 'A' && w[i] <= 'Z') || (w[i] >= '0' && w[i] <= '9')))
            return 0;
    return 1;
}

int swim_override_key(const char *key, swim_override *o, char *err, size_t errlen)
{
    const char *dot = strchr(key, '.');
    if (!dot || !word_ok(key, (size_t)(dot - key))) {
        snprintf(err, errlen, "expected TABLE.KEY, TABLE.KEY[I] or TABLE.KEY.COORD (e.g. run.t_end, "
                 "elastic.stiffness[4], shape.dc0.bm2), got '%s'", key);
        return -1;
    }
    snprintf(o->table, sizeof o->table, "%.*s", (int)(dot - key), key);
    o->word[0] = '\0';   /* a number unless swim_override_parse finds a word */
    const char *k = dot + 1, *br = strchr(k, '['), *dot2 = strchr(k, '.');
    size_t klen = br ? (size_t)(br - k) : dot2 ? (size_t)(dot2 - k) : strlen(k);
    if (!word_ok(k, klen)) {
        snprintf(err, errlen, "bad key name in '%s'", key);
        return -1;
    }
    snprintf(o->key, sizeof o->key, "%.*s", (int)klen, k);
    o->index = -1;
    if (br) {
        char *end;
        long i = strtol(br + 1, &end, 10);
        if (end == br + 1 || *end != ']' || end[1] != '\0' || i < 0) {
            snprintf(err, errlen, "bad index in '%s' (expected [I], I >= 0)", key);
            return -1;
        }
        o->index = i;
    } else if (dot2) {
        o->index = coord_index(dot2 + 1);
        if (o->index < 0) {
            snprintf(err, errlen, "unknown coordinate '%s' in '%s' (names: a1, b1, am1, bm1, am2, ...)", dot2 + 1, key);
            return -1;
        }
    }
    return 0;
}

int swim_override_parse(const char *text, swim_override *o, char *err, size_t errlen)
{
    memset(o, 0, sizeof *o);
    if (strlen(text) >= sizeof o->text) {   /* o->text is passed on whole (sweep members) */
        snprintf(err, errlen, "'%.40s...' is longer than %zu characters", text, sizeof o->text - 1);
        return -1;
    }
    snprintf(o->text, sizeof o->text, "%s", text);
    const char *eq = strchr(text, '=');
    if (!eq) {
        snprintf(err, errlen, "expected KEY=VALUE, got '%s'", text);
        return -1;
    }
    char key[128];
    if ((size_t)(eq - text) >= sizeof key) {
        snprintf(err, errlen, "key too long in '%s'", text);
        return -1;
    }
    snprintf(key, sizeof key, "%.*s", (int)(eq - text), text);
    if (swim_override_key(key, o, err, errlen) != 0) return -1;
    char *end;
    const char *val = eq + 1;
    const size_t wl = strspn(val, "abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ0123456789-_");
    o->value = strtod(val, &end);
    if (end == val && val[wl] == '\0' && wl > 0 && wl < sizeof o->word &&
        strchr("abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ", val[0])) {
        snprintf(o->word, sizeof o->word, "%s", val);   /* a word (not nan, inf): a string */
        return 0;
    }
    if (end == eq + 1 || *end != '\0' || !isfinite(o->value)) {
        snprintf(err, errlen, "value '%s' of %s is not a finite number", eq + 1, key);
        return -1;
    }
    return 0;
}

void swim_override_target(const swim_override *o, char *buf, size_t len)
{
    if (o->index < 0) snprintf(buf, len, "%s.%s", o->table, o->key);
    else snprintf(buf, len, "%s.%s[%ld]", o->table, o->key, o->index);
}

int swim_override_same_target(const swim_override *a, const swim_override *b)
{
    return strcmp(a->table, b->table) == 0 && strcmp(a->key, b->key) == 0 &&
           (a->index == b->index || a->index < 0 || b->index < 0);
}

int swim_override_conflict(const swim_override *ov, int n, int *earlier)
{
    for (int j = 1; j < n; j++)
        for (int i = 0; i < j; i++) {
            if (!swim_override_same_target(&ov[i], &ov[j])) continue;
            const int same = ov[i].index == ov[j].index && strcmp(ov[i].word, ov[j].word) == 0 &&
                             (ov[i].word[0] || ov[i].value == ov[j].value);
            if (!same) {
                *earlier = i;
                return j;
            }
        }
    return -1;
}

static int same_text(const char *a, const char *b) { return (!a && !b) || (a && b && strcmp(a, b) == 0); }

int swim_scene_take_values(swim_scene *s, swim_scene *from)
{
    /* the laws compiled for s read s's own arrays (param_values, energy_vars): they stay with s */
    int same = s->stroke_count == from->stroke_count && s->nparams == from->nparams &&
               same_text(s->forcing_text, from->forcing_text) && same_text(s->energy_text, from->energy_text);
    for (int k = 0; same && k < s->stroke_count; k++)
        same = s->stroke_index[k] == from->stroke_index[k] && same_text(s->stroke_law[k], from->stroke_law[k]);
    for (int i = 0; same && i < s->nparams; i++) same = strcmp(s->param_names[i], from->param_names[i]) == 0;
    if (!same) return -1;
    const swim_scene was = *s;
    *s = *from;
    *from = was;
    swim_expr *e = s->forcing;   /* each scene its own compiled laws back */
    s->forcing = from->forcing;
    from->forcing = e;
    e = s->energy;
    s->energy = from->energy;
    from->energy = e;
    for (int k = 0; k < s->stroke_count; k++) {
        e = s->stroke_expr[k];
        s->stroke_expr[k] = from->stroke_expr[k];
        from->stroke_expr[k] = e;
    }
    return 0;
}

void swim_scene_free(swim_scene *s)
{
    for (int k = 0; k < s->stroke_count; k++) {
        swim_expr_free(s->stroke_expr[k]);
        free(s->stroke_law[k]);
        s->stroke_expr[k] = NULL;
        s->stroke_law[k] = NULL;
    }
    s->stroke_count = 0;
    for (int i = 0; i < s->nover; i++) free(s->override_text[i]);
    free(s->override_text);
    s->override_text = NULL;
    s->nover = 0;
    swim_expr_free(s->forcing);
    swim_expr_free(s->energy);
    free(s->energy_text);
    s->energy = NULL;
    s->energy_text = NULL;
    free(s->path);
    free(s->title);
    free(s->forcing_text);
    s->forcing = NULL;
    s->path = s->title = s->forcing_text = NULL;
}

/* ---- run settings ---------------------------------------------------------------------------- */

static const char *const setting_key[SWIM_SET_COUNT] = {"run.t_end", "run.output_step", "run.rtol", "run.atol", "forcing.law"};
static const char *const setting_option[SWIM_SET_COUNT] = {"t-end", "output-step", "rtol", "atol", NULL};

/* One line naming setting i where it came from: the option, or FILE:LINE: key. */
static int setting_error(const swim_scene *s, const swim_run_overrides *cli, swim_status *st, int i, const char *fmt,
                         ...) __attribute__((format(printf, 5, 6)));
static int setting_error(const swim_scene *s, const swim_run_overrides *cli, swim_status *st, int i, const char *fmt,
                         ...)
{
    va_list ap;
    va_start(ap, fmt);
    char *msg = swim_vstrprintf(fmt, ap);
    va_end(ap);
    if (cli && cli->given[i] && setting_option[i])
        swim_status_fail(st, "swim run", NULL, 0, setting_key[i], "--%s: %s", setting_option[i], msg ? msg : fmt);
    else
        value_error(st, s, s->setting_line[i], setting_key[i], "%s: %s", setting_key[i], msg ? msg : fmt);
    free(msg);
    return 2;
}

/* The first time in (0, t_end] where the law is not defined (swim_expr_defined: a part of it
 * is not finite) among the samples t_k = k*step (k = 1..count, and t_end), located to within a
 * relative 1e-12 after the last sample where it is; inf when it is defined at every sample. */
static double first_nonfinite(const swim_expr *e, double step, long count, double t_end)
{
    double prev = 0.0;
    for (long k = 1; k <= count + 1; k++) {
        double t = k <= count ? fmin(k * step, t_end) : t_end;
        if (!swim_expr_defined(e, t, NULL, 0)) {
            double lo = prev, hi = t;   /* defined at lo, not at hi */
            while (hi - lo > 1e-12 * fmax(1.0, hi)) {
                double mid = 0.5 * (lo + hi);
                if (swim_expr_defined(e, mid, NULL, 0)) lo = mid;
                else hi = mid;
            }
            return hi;
        }
        prev = t;
    }
    return INFINITY;
}

/* Samples of a law on the run's interval: 2^16 equal steps, and the output times (the rows; at
 * most 10^6 of them), where an isolated singularity such as 1/(t-1) typically sits. */
#define LAW_SAMPLES 65536
#define LAW_ROW_SAMPLES 1000000L
static double law_finite_until(const swim_scene *s, const swim_expr *e)
{
    long rows = (long)fmin(floor(s->run.t_end / s->run.output_step), (double)LAW_ROW_SAMPLES);
    return fmin(first_nonfinite(e, s->run.t_end / LAW_SAMPLES, LAW_SAMPLES, s->run.t_end),
                first_nonfinite(e, s->run.output_step, rows, s->run.t_end));
}

/* A stroke law must be defined on the whole run (its kernel has no other law to follow, and
 * the generator refuses a part that is never finite): at t = 0 and at every sample. 0, or 2
 * after one line naming the file, the key and the law. */
static int check_stroke_laws(const swim_scene *s, swim_status *st)
{
    for (int k = 0; k < s->stroke_count; k++) {
        char key[24], why[160];
        swim_coord_name(s->stroke_index[k], key, sizeof key);
        double t = swim_expr_defined(s->stroke_expr[k], 0.0, NULL, 0) ? law_finite_until(s, s->stroke_expr[k]) : 0.0;
        if (isfinite(t)) {
            swim_expr_defined(s->stroke_expr[k], t, why, sizeof why);
            char full[32];
            snprintf(full, sizeof full, "stroke.%s", key);
            swim_status_fail(st, "swim", s->path, s->stroke_line[k], full, "%s:%d: %s: \"%s\" is not finite at t = %.9g: %s",
                             s->path, s->stroke_line[k], full, s->stroke_law[k], t, why);
            return 2;
        }
    }
    return 0;
}

int swim_run_settings_check(swim_scene *s, const swim_run_overrides *cli, swim_status *st)
{
    /* With both t_end and output_step from the scene, a row-count problem is output_step's
     * (its line is the one to change); with one from the command line, it is that option's. */
    int rows_key = cli && cli->given[SWIM_SET_T_END] && !cli->given[SWIM_SET_OUTPUT_STEP] ? SWIM_SET_T_END
                                                                                        : SWIM_SET_OUTPUT_STEP;
    if (!(s->run.t_end > 0)) return setting_error(s, cli, st, SWIM_SET_T_END, "must be > 0, got %g", s->run.t_end);
    if (!(s->run.output_step > 0)) return setting_error(s, cli, st, SWIM_SET_OUTPUT_STEP, "must be > 0, got %g", s->run.output_step);
    if (!(s->run.t_end / s->run.output_step <= SWIM_ROWS_MAX))
        return setting_error(s, cli, st, rows_key, "output_step %g gives more than 10^7 rows for t_end = %g",
                             s->run.output_step, s->run.t_end);
    if (!(s->run.rtol > 0)) return setting_error(s, cli, st, SWIM_SET_RTOL, "must be > 0, got %g", s->run.rtol);
    if (!(s->run.rtol >= SWIM_RTOL_MIN && s->run.rtol <= SWIM_RTOL_MAX))
        return setting_error(s, cli, st, SWIM_SET_RTOL, "%g is outside [%.2g, %g]: below 100 unit roundoffs the error "
                             "test cannot be met in double precision, above %g it bounds nothing",
                             s->run.rtol, SWIM_RTOL_MIN, SWIM_RTOL_MAX, SWIM_RTOL_MAX);
    if (!(s->run.atol > 0)) return setting_error(s, cli, st, SWIM_SET_ATOL, "must be > 0, got %g", s->run.atol);
    if (!(s->run.atol <= SWIM_ATOL_MAX))
        return setting_error(s, cli, st, SWIM_SET_ATOL, "%g is above %g: the states are of order 1", s->run.atol, SWIM_ATOL_MAX);
    s->run.forcing_finite_until = INFINITY;
    if (s->forcing) {
        char why[160];
        if (!swim_expr_defined(s->forcing, 0.0, why, sizeof why))
            return setting_error(s, NULL, st, SWIM_SET_LAW, "\"%s\" is not finite at t = 0, the start of the run: %s",
                                 s->forcing_text, why);
        s->run.forcing_finite_until = law_finite_until(s, s->forcing);
    }
    return s->stroke ? check_stroke_laws(s, st) : 0;
}
