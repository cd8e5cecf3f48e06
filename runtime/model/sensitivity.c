#include "model/sensitivity.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "io/message.h"
#include "kernel/coords.h"
#include "scene/keys.h"
#include "shape/constraints.h"

/* Central differences: truncation ~ h^2 |f'''|, rounding ~ u/h. Measured on Example 3 (c0.am1
 * over T = 10): the result moves by 1.5e-3, 1.5e-5 for h = 1e-3, 1e-4 (|f'''| ~ 1e3 along
 * that direction) and by ~2e-7 at 1e-7 (rounding); 2e-6 keeps both near 1e-8. */
#define SENS_STEP 2e-6

int swim_sens_init(swim_sens *S, swim_dynamics *d)
{
    memset(S, 0, sizeof *S);
    S->d = d;
    S->error_control = 1;
    S->dim = swim_dynamics_state_dim(d);
    size_t b = sizeof(double) * (size_t)(d->dim > S->dim ? d->dim : S->dim);
    S->yp = malloc(b);
    S->ym = malloc(b);
    S->fp = malloc(b);
    S->fm = malloc(b);
    S->J = malloc(sizeof(double) * (size_t)S->dim * (size_t)S->dim);
    if (!S->yp || !S->ym || !S->fp || !S->fm || !S->J) {
        swim_sens_free(S);
        return -1;
    }
    return 0;
}

void swim_sens_free(swim_sens *S)
{
    for (int k = 0; k < S->nkeys; k++) free(S->keys[k].s0);
    free(S->yp); free(S->ym); free(S->fp); free(S->fm); free(S->J); free(S->dp); free(S->plist);
    S->yp = S->ym = S->fp = S->fm = S->J = S->dp = NULL;
    S->plist = NULL;
    S->nkeys = 0;
}

static swim_sens_key *new_key(swim_sens *S, const char *name)
{
    if (S->nkeys == SWIM_SENS_MAX_KEYS) return NULL;
    swim_sens_key *k = &S->keys[S->nkeys];
    memset(k, 0, sizeof *k);
    snprintf(k->name, sizeof k->name, "%s", name);
    k->exact = 1;   /* an initial value until the caller says which parameter it is */
    k->param_scale = 1.0;
    const size_t nk = (size_t)S->nkeys + 1;
    swim_param *pl = realloc(S->plist, nk * sizeof *pl);
    if (pl) S->plist = pl;
    double *dp = pl ? realloc(S->dp, nk * (size_t)S->dim * sizeof *dp) : NULL;
    if (dp) S->dp = dp;
    k->s0 = dp ? calloc((size_t)S->dim, sizeof(double)) : NULL;
    if (!k->s0) return NULL;
    S->nkeys++;
    return k;
}

int swim_sens_add_state(swim_sens *S, int i, const char *name)
{
    swim_sens_key *k = new_key(S, name);
    if (!k) return -1;
    k->s0[i] = 1.0;
    return 0;
}

/* The initial velocity the loader makes of dc0 at shape c0 with project_initial (ERRATA D5). */
static void projected_velocity(const swim_scene *s, const double *c0, const double *dc0, double *v)
{
    double G[(SWIM_NMAX + 2) * SWIM_NMAX];
    memcpy(v, dc0, sizeof(double) * s->n);
    int m = swim_constraint_rows(s->n, c0, s->free_mask, G);
    swim_constraint_project(s->n, m, G, v);
}

/* dy0/dp of c0.NAME (shape) or dc0.NAME (velocity) of the free coordinate i. */
static void initial_column(const swim_sens *S, int i, int velocity, double *s0)
{
    const swim_dynamics *d = S->d;
    const swim_scene *s = d->scene;
    const int nf = d->spec->nfree, n = s->n;
    double cp[SWIM_NMAX], cm[SWIM_NMAX], vp[SWIM_NMAX], vm[SWIM_NMAX], dv[SWIM_NMAX];
    memcpy(cp, s->c0, sizeof(double) * n);
    memcpy(cm, s->c0, sizeof(double) * n);
    memcpy(vp, s->dc0, sizeof(double) * n);
    memcpy(vm, s->dc0, sizeof(double) * n);
    const double h = 1e-5;
    if (velocity) {   /* P is linear in dc0: P e_i */
        memset(dv, 0, sizeof dv);
        dv[i] = 1.0;
        projected_velocity(s, s->c0, dv, vp);
        for (int k = 0; k < n; k++) dv[k] = vp[k];
    } else {          /* d/dc0_i of P(c0) dc0, by central differences of the projection */
        cp[i] += h;
        cm[i] -= h;
        projected_velocity(s, cp, s->dc0, vp);
        projected_velocity(s, cm, s->dc0, vm);
        for (int k = 0; k < n; k++) dv[k] = (vp[k] - vm[k]) / (2 * h);
    }
    memset(s0, 0, sizeof(double) * S->dim);
    for (int f = 0; f < nf; f++) {
        const int j = d->spec->free_index[f];
        s0[3 + f] = !velocity && j == i ? 1.0 : 0.0;
        s0[3 + nf + f] = dv[j];
    }
}

static int key_error(swim_status *st, const char *cmd, const char *key, const char *fmt, const char *detail)
{
    char *msg = swim_strprintf(fmt, detail);
    /* the option that gave the key: --sensitivity, unless cmd names another (sensitivity.h) */
    char who[128];
    snprintf(who, sizeof who, "swim %s%s", cmd, strchr(cmd, ':') ? "" : ": --sensitivity");
    swim_status_fail(st, who, NULL, 0, key, "%s: %s", key, msg ? msg : fmt);
    free(msg);
    return 2;
}

/* The keys a sensitivity may be taken with respect to: the values the equations read at run
 * time and the initial conditions (scene/keys.h), for the message that lists them. */
static const char *differentiable_keys(char *buf, size_t len)
{
    int count, at = snprintf(buf, len, "not a value the equations read (keys:");
    const swim_scene_key *keys = swim_scene_keys(&count);
    for (int i = 0, first = 1; i < count && at > 0 && (size_t)at < len; i++) {
        const swim_scene_key *k = &keys[i];
        if (!(k->flags & (SWIM_KEY_RUNTIME | SWIM_KEY_INITIAL))) continue;
        const char *tail = k->kind == SWIM_KEY_VECTOR ? ".NAME" : "";
        at += snprintf(buf + at, len - (size_t)at, "%s %s.%s%s", first ? "" : ",", k->table,
                       strcmp(k->key, "*") == 0 ? "NAME" : k->key, tail);
        first = 0;
    }
    if (at > 0 && (size_t)at < len) snprintf(buf + at, len - (size_t)at, "; NAME a coordinate such as am1, or [I])");
    return buf;
}

int swim_sens_add_key(swim_sens *S, swim_scene *s, const char *cmd, const char *key, swim_status *st)
{
    swim_dynamics *d = S->d;
    swim_override o;
    char err[200];
    if (swim_override_key(key, &o, err, sizeof err) != 0) return key_error(st, cmd, key, "%s", err);
    /* c0.NAME, dc0.NAME as shorthands of shape.c0.NAME, shape.dc0.NAME */
    if ((strcmp(o.table, "c0") == 0 || strcmp(o.table, "dc0") == 0) && o.index < 0) {
        char full[128];
        snprintf(full, sizeof full, "shape.%s.%s", o.table, o.key);
        if (swim_override_key(full, &o, err, sizeof err) != 0) return key_error(st, cmd, key, "%s", err);
    }
    const int generic = d->generic;
    const long i = o.index;
    const int coord = i >= 0 && i < s->n, fr = coord && s->free_mask[i];
    double *v0 = NULL, *v1 = NULL;
    swim_param par = {0, 0};     /* the kernel's parameter; kind 0: differentiated by differences */
    double par_scale = 1.0;
    const char *absent = NULL;   /* why the kernel has no such term */
    if (o.index >= s->n) {
        char n[16];
        snprintf(n, sizeof n, "%d", s->n);
        return key_error(st, cmd, key, "index out of range (the scene has %s shape coordinates)", n);
    }
    if (strcmp(o.table, "shape") == 0 && (strcmp(o.key, "c0") == 0 || strcmp(o.key, "dc0") == 0) && coord) {
        const int vel = strcmp(o.key, "dc0") == 0;
        if (fr) {
            swim_sens_key *k = new_key(S, key);
            if (!k) return key_error(st, cmd, key, "%s", "too many keys or out of memory");
            initial_column(S, (int)i, vel, k->s0);
            return 0;
        }
        if (vel) return key_error(st, cmd, key, "%s", "the coordinate is locked: its velocity is 0 by definition");
        v0 = &s->c0[i];   /* a locked coordinate's value is a parameter of the right-hand side */
    } else if (strcmp(o.table, "model") == 0 && o.index < 0 && strcmp(o.key, "rho0") == 0) {
        if (s->rhof_neutral) return key_error(st, cmd, key, "%s", "rhof = \"neutral\" follows rho0: give rhof a number");
        v0 = &s->rho0;
        v1 = &d->spec_params.rho0;
        par = (swim_param){SWIM_PARAM_RHO0, 0};
    } else if (strcmp(o.table, "model") == 0 && o.index < 0 && strcmp(o.key, "rhof") == 0) {
        v0 = &s->rhof;
        v1 = &d->spec_params.rhof;
        par = (swim_param){SWIM_PARAM_RHOF, 0};
    } else if (strcmp(o.table, "elastic") == 0 && coord && strcmp(o.key, "stiffness") == 0) {
        v0 = &s->stiffness[i];
        par = (swim_param){SWIM_PARAM_STIFFNESS, (int)i};
        if (!generic && fr && !(s->elastic && s->stiffness[i] != 0)) absent = "its stiffness is 0, so the kernel has no elastic term there";
    } else if (strcmp(o.table, "elastic") == 0 && coord && strcmp(o.key, "reference") == 0) {
        v0 = &s->reference[i];   /* read only where the stiffness is nonzero; elsewhere dW1/dref = 0 */
        par = (swim_param){SWIM_PARAM_REFERENCE, (int)i};
    } else if (strcmp(o.table, "damping") == 0 && coord && strcmp(o.key, "diagonal") == 0) {
        v0 = &s->damping[i];
        par = (swim_param){SWIM_PARAM_DAMPING, (int)i};
        if (!generic && fr && !(s->damped && s->damping[i] != 0)) absent = "its damping is 0, so the kernel has no damping term there";
    } else if (strcmp(o.table, "forcing") == 0 && coord && strcmp(o.key, "direction") == 0) {
        v0 = &s->direction[i];
        par = (swim_param){SWIM_PARAM_DIRECTION, (int)i};
        if (!s->forced) absent = "the scene has no forcing law";
        else if (!generic && fr && s->direction[i] == 0) absent = "its direction is 0, so the kernel has no force there";
    } else if (strcmp(o.table, "barrier") == 0 && o.index < 0 && strcmp(o.key, "epsilon") == 0) {
        v0 = &s->epsilon;
        if (!s->barrier) absent = "epsilon is 0, so the kernel has no barrier";
        par = (swim_param){SWIM_PARAM_BARRIER_SCALE, 0};   /* eps d/d eps: W2 is linear in eps */
        par_scale = s->epsilon != 0 ? 1.0 / s->epsilon : 0.0;
    } else if (strcmp(o.table, "barrier") == 0 && o.index < 0 && strcmp(o.key, "alpha") == 0) {
        v0 = &s->alpha;
    } else if (strcmp(o.table, "parameters") == 0 && o.index < 0) {
        for (int j = 0; j < s->nparams; j++)
            if (strcmp(s->param_names[j], o.key) == 0) {
                v0 = &s->param_values[j];
                par = (swim_param){SWIM_PARAM_LAW, j};   /* the forcing and energy laws read law_params[j] */
            }
        if (!v0) return key_error(st, cmd, key, "the scene's [parameters] has no '%s'", o.key);
    } else {
        char list[600];
        return key_error(st, cmd, key, "%s", differentiable_keys(list, sizeof list));
    }
    if (absent) {
        char why[200];
        snprintf(why, sizeof why, "%s (run with --generic to differentiate with respect to it)", absent);
        return key_error(st, cmd, key, "%s", why);
    }
    swim_sens_key *k = new_key(S, key);
    if (!k) return key_error(st, cmd, key, "%s", "too many keys or out of memory");
    k->value[0] = v0;
    k->value[1] = v1;
    k->nvalue = v1 ? 2 : 1;
    k->exact = par.kind != 0 && d->spec->jacobian_params != NULL;
    k->param = par;
    k->param_scale = par_scale;
    return 0;
}

int swim_sens_add_initial(swim_sens *S, swim_scene *scene, const char *cmd, swim_status *st)
{
    for (int vel = 0; vel < 2; vel++)
        for (int f = 0; f < S->d->spec->nfree; f++) {
            char name[24], key[40];
            swim_coord_name(S->d->spec->free_index[f], name, sizeof name);
            snprintf(key, sizeof key, "%s.%s", vel ? "dc0" : "c0", name);
            int given = 0;
            for (int k = 0; k < S->nkeys; k++) given |= strcmp(S->keys[k].name, key) == 0;
            if (given) continue;   /* --sensitivity named it already */
            const int rc = swim_sens_add_key(S, scene, cmd, key, st);
            if (rc != 0) return rc;
        }
    return 0;
}

void swim_sens_use_differences(swim_sens *S)
{
    for (int k = 0; k < S->nkeys; k++) S->keys[k].exact = 0;
}

int swim_sens_exact(const swim_sens *S)
{
    for (int k = 0; k < S->nkeys; k++)
        if (!S->keys[k].exact) return 0;
    return 1;
}

int swim_sens_add_list(swim_sens *S, swim_scene *scene, const char *cmd, const char *list, swim_status *st)
{
    char *copy = strdup(list), *save = NULL;
    if (!copy) return 2;
    int rc = 0, any = 0;
    for (char *tok = strtok_r(copy, ",", &save); tok && rc == 0; tok = strtok_r(NULL, ",", &save)) {
        for (int k = 0; k < S->nkeys; k++)
            if (strcmp(S->keys[k].name, tok) == 0) rc = key_error(st, cmd, tok, "%s", "given twice");
        if (rc == 0) rc = strcmp(tok, "initial") == 0 ? swim_sens_add_initial(S, scene, cmd, st)
                                                      : swim_sens_add_key(S, scene, cmd, tok, st);
        any = 1;
    }
    if (rc == 0 && !any) rc = key_error(st, cmd, list, "%s", "expected KEY[,KEY...]");
    free(copy);
    return rc;
}

int swim_sens_dimension(const swim_sens *S)
{
    return (1 + S->nkeys) * S->dim;
}

void swim_sens_initial(const swim_sens *S, const double *y0, double *Y0)
{
    memcpy(Y0, y0, sizeof(double) * S->dim);
    for (int k = 0; k < S->nkeys; k++) memcpy(Y0 + (size_t)(k + 1) * S->dim, S->keys[k].s0, sizeof(double) * S->dim);
}

/* The step along (s, 1): h relative to the state and to the key's value, whichever is tighter;
 * 0 when there is no direction at all. */
static double diff_step(const swim_sens_key *key, const double *y, const double *s, int n)
{
    double w = 0.0;
    for (int i = 0; i < n; i++) w = fmax(w, fabs(s[i]) / (1.0 + fabs(y[i])));
    if (key->nvalue) {
        const double p = fabs(*key->value[0]);
        w = fmax(w, 1.0 / (p > 0 ? p : 1.0));
    }
    return w > 0 ? SENS_STEP / w : 0.0;
}

static void set_key(const swim_sens_key *key, const double *base, double delta)
{
    for (int j = 0; j < key->nvalue; j++) *key->value[j] = base[j] + delta;
}

/* The exact keys' columns: s' = J s + d f/d p, one Jacobian for all of them. */
static int exact_columns(swim_sens *S, double t, const double *Y, double *dY)
{
    const int n = S->dim;
    int np = 0, any = 0;
    for (int k = 0; k < S->nkeys; k++) {
        any |= S->keys[k].exact;
        if (S->keys[k].exact && S->keys[k].param.kind != 0) S->plist[np++] = S->keys[k].param;
    }
    if (!any) return 0;
    const int rc = swim_dynamics_jacobian_params(S->d, t, Y, S->J, np, S->plist, S->dp);
    S->jac_calls++;
    if (rc != 0) return rc;
    for (int k = 0, p = 0; k < S->nkeys; k++) {
        const swim_sens_key *key = &S->keys[k];
        if (!key->exact) continue;
        const double *s = Y + (size_t)(k + 1) * n;
        double *ds = dY + (size_t)(k + 1) * n;
        const double *dp = key->param.kind != 0 ? S->dp + (size_t)(p++) * n : NULL;
        for (int i = 0; i < n; i++) {
            const double *Ji = S->J + (size_t)i * n;
            double acc = dp ? key->param_scale * dp[i] : 0.0;
            for (int j = 0; j < n; j++) acc += Ji[j] * s[j];
            ds[i] = acc;
        }
    }
    return 0;
}

/* A difference key's column: the central difference of f along (s, 1) in (y, p). */
static int difference_column(swim_sens *S, int k, double t, const double *Y, double *dY)
{
    const int n = S->dim;
    const swim_sens_key *key = &S->keys[k];
    const double *s = Y + (size_t)(k + 1) * n;
    double *ds = dY + (size_t)(k + 1) * n;
    const double h = diff_step(key, Y, s, n);
    if (h == 0.0) {
        memset(ds, 0, sizeof(double) * n);
        return 0;
    }
    double base[2] = {0, 0};
    for (int j = 0; j < key->nvalue; j++) base[j] = *key->value[j];
    for (int i = 0; i < n; i++) {
        S->yp[i] = Y[i] + h * s[i];
        S->ym[i] = Y[i] - h * s[i];
    }
    set_key(key, base, h);
    int rc = swim_dynamics_rhs(t, S->yp, S->fp, S->d);
    set_key(key, base, -h);
    if (rc == 0) rc = swim_dynamics_rhs(t, S->ym, S->fm, S->d);
    for (int j = 0; j < key->nvalue; j++) *key->value[j] = base[j];   /* bit for bit */
    S->rhs_calls += 2;
    if (rc != 0) return rc;
    for (int i = 0; i < n; i++) ds[i] = (S->fp[i] - S->fm[i]) / (2 * h);
    return 0;
}

int swim_sens_rhs(double t, const double *Y, double *dY, void *params)
{
    swim_sens *S = params;
    /* the columns first, the state's own right-hand side last: what that call leaves in the
     * dynamics (the balance test's by-products) is then the state's, as in a run without them */
    int rc = exact_columns(S, t, Y, dY);
    for (int k = 0; k < S->nkeys && rc == 0; k++)
        if (!S->keys[k].exact) rc = difference_column(S, k, t, Y, dY);
    const int rs = swim_dynamics_rhs(t, Y, dY, S->d);
    return rs != 0 ? rs : rc;
}

double swim_sens_energy(swim_sens *S, const double *Y, int k)
{
    const swim_sens_key *key = &S->keys[k];
    const int n = S->dim;
    const double *s = Y + (size_t)(k + 1) * n;
    const double h = diff_step(key, Y, s, n);
    if (h == 0.0) return 0.0;
    double base[2] = {0, 0}, E[2];
    for (int j = 0; j < key->nvalue; j++) base[j] = *key->value[j];
    int rc = 0;
    for (int side = 0; side < 2 && rc == 0; side++) {
        const double sg = side ? -h : h;
        for (int i = 0; i < n; i++) S->yp[i] = Y[i] + sg * s[i];
        set_key(key, base, sg);
        double *fullbuf = malloc(sizeof(double) * S->d->dim);
        swim_diag g;
        if (!fullbuf) { rc = -1; break; }
        swim_dynamics_unpack(S->d, S->yp, fullbuf);
        rc = swim_dynamics_diagnostics_aside(S->d, fullbuf, &g);   /* the run's own rows keep their warm starts */
        E[side] = g.energy;
        free(fullbuf);
    }
    for (int j = 0; j < key->nvalue; j++) *key->value[j] = base[j];
    return rc == 0 ? (E[0] - E[1]) / (2 * h) : NAN;
}


void swim_sens_names_free(char **names, int ncol)
{
    if (names)
        for (int c = 0; c < ncol; c++) free(names[c]);
    free(names);
}

int swim_sens_names(const swim_sens *S, int nkeys, char ***out, int *ncol_out)
{
    static const char *const what[] = {"dx", "dy", "dtheta", "denergy", "dwork"};
    const int n = S->dim, nf = (n - 4) / 2, nhead = 1 + 5 * nkeys;
    const int ncol = nhead + 2 * nf * nkeys;
    char **names = calloc((size_t)ncol, sizeof *names);
    *out = NULL;
    *ncol_out = ncol;
    if (!names) return -1;
    names[0] = strdup("t");
    for (int k = 0; k < nkeys; k++)
        for (int w = 0; w < 5; w++)
            names[1 + 5 * k + w] = swim_strprintf("%s/d%s", what[w], S->keys[k].name);
    for (int k = 0; k < nkeys; k++)   /* the full state: carried coordinates, then velocities */
        for (int c = 0; c < 2 * nf; c++) {
            char name[24];
            swim_coord_name(S->d->spec->free_index[c % nf], name, sizeof name);
            names[nhead + 2 * nf * k + c] = swim_strprintf("d%s%s/d%s", c < nf ? "" : "d", name, S->keys[k].name);
        }
    for (int c = 0; c < ncol; c++)
        if (!names[c]) {
            swim_sens_names_free(names, ncol);
            return -1;
        }
    *out = names;
    return 0;
}

void swim_sens_row(swim_sens *S, int nkeys, double t, const double *Y, double *row)
{
    const int n = S->dim, nf = (n - 4) / 2, nhead = 1 + 5 * nkeys;
    row[0] = t;
    for (int j = 0; j < nkeys; j++) {
        const double *sj = Y + (size_t)(j + 1) * n;
        row[1 + 5 * j] = sj[0];
        row[2 + 5 * j] = sj[1];
        row[3 + 5 * j] = sj[2];
        row[4 + 5 * j] = swim_sens_energy(S, Y, j);
        row[5 + 5 * j] = sj[n - 1];
        for (int c = 0; c < 2 * nf; c++) row[nhead + 2 * nf * j + c] = sj[3 + c];
    }
}

int swim_sens_table_add(swim_sens_table *T, const char *const *names, int ncol, const double *row)
{
    if (!row) {
        if (!(T->names = calloc((size_t)ncol, sizeof *T->names))) return -1;
        T->ncol = ncol;
        for (int c = 0; c < ncol; c++)
            if (!(T->names[c] = strdup(names[c]))) return -1;
        return 0;
    }
    if (T->nrows == T->cap) {
        const long cap = T->cap ? 2 * T->cap : 64;
        double *v = realloc(T->values, sizeof(double) * (size_t)cap * (size_t)ncol);
        if (!v) return -1;
        T->values = v;
        T->cap = cap;
    }
    memcpy(T->values + (size_t)T->nrows * (size_t)ncol, row, sizeof(double) * (size_t)ncol);
    T->nrows++;
    return 0;
}

void swim_sens_table_free(swim_sens_table *T)
{
    if (!T) return;
    for (int c = 0; T->names && c < T->ncol; c++) free(T->names[c]);
    free(T->names);
    free(T->values);
    memset(T, 0, sizeof *T);
}
