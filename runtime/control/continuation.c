/* continuation.c -- natural-parameter continuation of periodic orbits (control/continuation.h). */
#include "control/continuation.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "model/sensitivity.h"
#include "io/clock.h"
#include "io/json.h"
#include "io/message.h"
#include "kernel/coords.h"

#define MAX_HALVINGS 4

typedef struct {
    swim_dynamics *d;
    int energy;                    /* the parameter is the energy */
    double *value[2];              /* else: the scene's numbers the key is */
    int nvalue;
    double keep_energy;            /* a key of a conservative scene: the energy kept (else NAN) */
    const swim_periodic_options *po;
    const signed char *hold;       /* the invariant subspace held (n2 flags), or NULL */
    const swim_cont_options *o;
    long rhs_calls;
    swim_status *st;               /* the caller's: a point that fails is told to its note */
} problem;

/* A solved point: its integrator state and period, for the predictor. */
typedef struct {
    double param, T;
    double *ys;
} anchor;

/* The caller asked the work to stop (swim_dynamics.interrupt): its value, else 0. */
static int stop_asked(const problem *pb) { return pb->d->interrupt && *pb->d->interrupt ? *pb->d->interrupt : 0; }

static void set_param(problem *pb, double v)
{
    for (int i = 0; i < pb->nvalue; i++) *pb->value[i] = v;
}

/* The orbit at parameter v from the guess (ys, T). 0 converged, 1 not converged, -1 failed. */
static int solve_at(problem *pb, double v, const double *ys, double T, swim_periodic *p)
{
    if (!pb->energy) set_param(pb, v);
    swim_status why = {0};   /* the branch goes on past a point that fails: its cause is a notice */
    const int rc = swim_periodic_refine(pb->d, ys, T, pb->energy ? v : pb->keep_energy, pb->po, p, &why);
    pb->rhs_calls += p->rhs_calls;
    swim_status_notes_from(pb->st, &why);
    if (rc != 0) return -1;
    return p->converged ? 0 : 1;
}

/* How many of the complement's multipliers outside the unit circle belong to the directions across
 * the held subspace: those among the eigenvalues of M's block of held rows and columns (M maps the
 * subspace into itself, so that block's eigenvalues are the across directions' multipliers). The
 * block itself also holds a Jordan pair at 1 split by ~sqrt of M's error (1 +- 4e-6): matched
 * against the complement's multipliers, from which the exact 1s are out, those do not count. */
static int outside_across(const swim_periodic *p, const signed char *hold)
{
    if (!hold || !p->have_floquet) return 0;
    const int n2 = p->n2;
    int idx[SWIM_FLOQUET_MAX], n = 0, out = 0;
    for (int i = 0; i < n2; i++)
        if (hold[i]) idx[n++] = i;
    double A[SWIM_FLOQUET_MAX * SWIM_FLOQUET_MAX], re[SWIM_FLOQUET_MAX], im[SWIM_FLOQUET_MAX];
    for (int a = 0; a < n; a++)
        for (int b = 0; b < n; b++) A[a * n + b] = p->floquet.M[idx[a] * n2 + idx[b]];
    if (n == 0 || swim_floquet_eigenvalues(A, n, re, im) != 0) return 0;
    const swim_floquet *fl = &p->floquet;
    for (int k = 0; k < fl->nc; k++) {
        const double a = hypot(fl->cre[k], fl->cim[k]);
        if (!(a > 1.0 + SWIM_CONT_OUTSIDE_TOL)) continue;
        int found = 0;
        for (int i = 0; i < n && !found; i++) found = hypot(re[i] - fl->cre[k], im[i] - fl->cim[k]) <= 1e-6 * a;
        out += found;
    }
    return out;
}

static void record(swim_cont_point *q, double v, const swim_periodic *p, const signed char *hold)
{
    memset(q, 0, sizeof *q);
    q->param = v;
    q->converged = p->converged;
    q->period = p->period;
    q->dx = p->dx;
    q->dy = p->dy;
    q->dtheta = p->dtheta;
    q->energy = p->energy;
    q->residual = p->residual;
    q->iterations = p->iterations;
    q->n2 = p->n2;
    memcpy(q->z, p->z, sizeof(double) * (size_t)p->n2);
    if (!p->have_floquet) return;
    q->outside_across = outside_across(p, hold);
    const swim_floquet *fl = &p->floquet;
    q->nt = fl->nc;   /* the complement's multipliers: the exact 1s taken out (floquet.h) */
    for (int i = 0; i < fl->nc; i++) {
        const double a = hypot(fl->cre[i], fl->cim[i]);
        q->re[i] = fl->cre[i];
        q->im[i] = fl->cim[i];
        q->max_abs = fmax(q->max_abs, a);
        if (a > 1.0 + SWIM_CONT_OUTSIDE_TOL) {
            q->outside++;
            if (fabs(fl->cim[i]) > SWIM_CONT_OUTSIDE_TOL) q->complex_outside = 1;
            else if (fl->cre[i] < 0) q->negative_real = 1;
        }
    }
    q->stable = p->converged && fl->nc == fl->nt - fl->exact_ones && q->outside == 0;
}

/* The predictor: the secant through the last two anchors (or the last one alone), at v. */
static void predict(const anchor *a, const anchor *b, int have_b, double v, int N, double *ys, double *T)
{
    const double s = have_b && b->param != a->param ? (v - a->param) / (a->param - b->param) : 0.0;
    for (int i = 0; i < N; i++) ys[i] = a->ys[i] + (have_b ? s * (a->ys[i] - b->ys[i]) : 0.0);
    *T = a->T + (have_b ? s * (a->T - b->T) : 0.0);
}

static void anchor_set(anchor *an, double v, const swim_periodic *p, int N)
{
    an->param = v;
    an->T = p->period;
    memset(an->ys, 0, sizeof(double) * N);
    for (int i = 0; i < p->n2; i++) an->ys[3 + i] = p->z[i];
}

/* One side of the branch: targets[0..n) in order away from the first point. */
static int walk(problem *pb, const anchor *first, const double *targets, int n, swim_branch *b, char *ended,
                size_t len)
{
    const int N = swim_dynamics_state_dim(pb->d);
    anchor an[2];
    double *ys = malloc(sizeof(double) * N);
    an[0].ys = malloc(sizeof(double) * N);
    an[1].ys = malloc(sizeof(double) * N);
    if (!ys || !an[0].ys || !an[1].ys) {
        free(ys); free(an[0].ys); free(an[1].ys);
        return -1;
    }
    an[0].param = first->param;
    an[0].T = first->T;
    memcpy(an[0].ys, first->ys, sizeof(double) * N);
    int have_prev = 0, rc = 0;
    for (int k = 0; k < n && !stop_asked(pb); k++) {
        /* from the last anchor to targets[k], in halved steps when a point does not converge */
        double goal = targets[k];
        int halvings = 0, reached = 0, attempts = 0;
        while (!reached) {
            if (++attempts > 64) {   /* creeping in ever smaller steps is a fold or an edge, not progress */
                snprintf(ended, len, "the branch stalled before %.10g (at %.10g after 64 solves)", targets[k], an[0].param);
                goto end;
            }
            double T;
            swim_periodic p;
            predict(&an[0], &an[1], have_prev, goal, N, ys, &T);
            const int s = solve_at(pb, goal, ys, T, &p);
            if (stop_asked(pb)) {   /* this point's Newton was cut short: the points before it stand */
                swim_periodic_free(&p);
                goto end;
            }
            if (s == 0) {
                if (goal == targets[k]) {
                    record(&b->pt[b->n++], goal, &p, pb->hold);
                    if (pb->o->progress) pb->o->progress(pb->o->progress_ctx, goal, p.period);
                }
                an[1].param = an[0].param;
                an[1].T = an[0].T;
                memcpy(an[1].ys, an[0].ys, sizeof(double) * N);
                anchor_set(&an[0], goal, &p, N);
                have_prev = 1;
                reached = goal == targets[k];
                goal = targets[k];
                halvings = 0;
            } else if (halvings < MAX_HALVINGS) {
                goal = 0.5 * (an[0].param + goal);
                halvings++;
            } else {
                snprintf(ended, len, "no periodic orbit converged near %s = %.10g (from %.10g in %d halved steps): %s",
                         pb->energy ? "energy" : "the parameter", goal, an[0].param, MAX_HALVINGS,
                         s < 0 ? "an integration failed" : p.why ? p.why : "Newton did not converge");
                swim_periodic_free(&p);
                goto end;
            }
            swim_periodic_free(&p);
        }
    }
end:
    free(ys); free(an[0].ys); free(an[1].ys);
    return rc;
}

static int by_param(const void *a, const void *b)
{
    const double x = ((const swim_cont_point *)a)->param, y = ((const swim_cont_point *)b)->param;
    return (x > y) - (x < y);
}

/* Bisection of the bracket [p, q] of a special point: the orbit at the midpoint from the state
 * and period interpolated between the bracket's ends, kept as the end whose count of multipliers
 * outside the circle it shares. The bracket's final ends go to s. 0, or -1 out of memory. */
static int bisect(problem *pb, swim_cont_point p, swim_cont_point q, swim_cont_special *s)
{
    /* which multipliers leave, judged at the branch's own points (near the special point the
     * leaving one is too close to 1 to tell the across block's from its Jordan pair at 1) */
    const int across = p.outside_across != q.outside_across;
    const int N = swim_dynamics_state_dim(pb->d);
    double *ys = calloc((size_t)N, sizeof(double));
    if (!ys) return -1;
    s->why[0] = '\0';
    for (s->bisections = 0; s->bisections < SWIM_CONT_BISECTIONS; s->bisections++) {
        const double v = 0.5 * (p.param + q.param);
        for (int i = 0; i < p.n2; i++) ys[3 + i] = 0.5 * (p.z[i] + q.z[i]);
        swim_periodic o;
        const int rc = solve_at(pb, v, ys, 0.5 * (p.period + q.period), &o);
        if (rc != 0) {
            snprintf(s->why, sizeof s->why, "the orbit at %.10g did not converge: %s", v,
                     rc < 0 ? "an integration failed" : o.why ? o.why : "Newton did not converge");
            swim_periodic_free(&o);
            break;
        }
        swim_cont_point m;
        record(&m, v, &o, pb->hold);
        swim_periodic_free(&o);
        if (m.outside == p.outside) p = m;
        else q = m;
    }
    s->refined = s->bisections == SWIM_CONT_BISECTIONS;
    s->lo = fmin(p.param, q.param);
    s->hi = fmax(p.param, q.param);
    const swim_cont_point *out = p.outside > q.outside ? &p : &q;
    s->at = *out;
    s->kind = across
                  ? "branch point of orbits leaving the invariant subspace (multipliers across it leave the unit "
                    "circle; the branch stays in the subspace)"
              : out->complex_outside ? "Neimark-Sacker" : out->negative_real ? "period doubling" : "fold or branch point";
    free(ys);
    return 0;
}

/* Where the count of multipliers outside the unit circle changes between neighbours, refined. */
static int classify(problem *pb, swim_branch *b)
{
    for (int i = 1; i < b->n && b->nspecial < 64; i++) {
        const swim_cont_point *p = &b->pt[i - 1], *q = &b->pt[i];
        if (p->outside == q->outside) continue;
        if (bisect(pb, *p, *q, &b->special[b->nspecial++]) != 0) return -1;
    }
    if (!pb->energy)   /* bisect set the key's numbers: back to the branch's own */
        set_param(pb, b->param0);
    return 0;
}

int swim_continue(swim_dynamics *d, swim_scene *scene, const swim_floquet_section *sec, const swim_cont_options *o,
                  swim_branch *b, swim_status *st)
{
    memset(b, 0, sizeof *b);
    const double t0 = swim_clock_seconds();
    problem pb = {d, strcmp(o->key, "energy") == 0, {NULL, NULL}, 0, NAN, &o->periodic, NULL, o, 0, st};
    swim_periodic_options held;   /* the options with the invariant subspace held */
    const int conservative = swim_periodic_conservative(d);
    if (pb.energy && !conservative) {
        swim_status_fail_cmd(st, "continue", scene->path, "param", "--param energy: %s has damping or forcing, so energy "
                             "is not conserved and orbits do not come in a family by energy; continue in a scene key "
                             "instead", scene->path);
        return 2;
    }
    swim_sens S;
    int have_sens = 0;
    double saved[2] = {0, 0};
    if (!pb.energy) {   /* the key's numbers in the scene, as --sensitivity finds them */
        if (swim_sens_init(&S, d) != 0) {
            swim_status_fail_cmd(st, "continue", NULL, NULL, "out of memory");
            return 1;
        }
        have_sens = 1;
        const int krc = swim_sens_add_key(&S, scene, "continue: --param", o->key, st);
        if (krc != 0 || S.keys[0].nvalue == 0) {
            if (krc == 0)
                swim_status_fail_cmd(st, "continue", NULL, "param", "--param %s: an initial value, not a parameter of the "
                                     "equations", o->key);
            swim_sens_free(&S);
            return 2;
        }
        pb.nvalue = S.keys[0].nvalue;
        for (int i = 0; i < pb.nvalue; i++) {
            pb.value[i] = S.keys[0].value[i];
            saved[i] = *pb.value[i];
        }
    }
    int rc = 1;
    const int N = swim_dynamics_state_dim(d);
    double *targets = malloc(sizeof(double) * (size_t)o->points);
    b->pt = calloc((size_t)o->points, sizeof *b->pt);
    anchor first = {0, 0, malloc(sizeof(double) * N)};
    swim_periodic p0;
    int have_p0 = 0;
    if (!targets || !b->pt || !first.ys) {
        swim_status_fail_cmd(st, "continue", NULL, NULL, "out of memory");
        goto done;
    }
    /* the first point: the scene's own orbit */
    if (swim_periodic_solve(d, sec, &o->periodic, &p0, st) != 0) goto done;
    have_p0 = 1;
    pb.rhs_calls += p0.rhs_calls;
    if (p0.stopped) {   /* no point yet: an empty branch, said as stopped */
        b->stopped = p0.stopped;
        snprintf(b->ended[0], sizeof b->ended[0], "stopped by %s before the first orbit converged",
                 swim_floquet_signal_name(p0.stopped));
        rc = 0;
        goto done;
    }
    if (!p0.converged) {
        swim_status_fail_cmd(st, "continue", scene->path, NULL, "%s: no periodic orbit to start from: %s (residual %.2g)",
                             scene->path, p0.why, p0.residual);
        goto done;
    }
    b->param0 = pb.energy ? p0.energy : saved[0];
    /* the invariant subspace of the first orbit, held along the branch */
    b->n2 = p0.n2;
    for (int i = 0; i < p0.n2; i++) {
        char name[20];
        swim_coord_name(d->spec->free_index[i % (p0.n2 / 2)], name, sizeof name);
        snprintf(b->znames[i], sizeof b->znames[i], "%s%s", i < p0.n2 / 2 ? "" : "d", name);
    }
    b->nhold = swim_periodic_invariant_zeros(&p0, b->hold);
    if (b->nhold) {
        held = o->periodic;
        held.hold_zero = b->hold;
        pb.hold = b->hold;
        pb.po = &held;
    }
    if (!pb.energy && conservative) pb.keep_energy = p0.energy;
    anchor_set(&first, b->param0, &p0, N);
    for (int k = 0; k < o->points; k++)
        targets[k] = o->points == 1 ? o->start : o->start + (o->stop - o->start) * k / (o->points - 1);
    /* each side outwards from the first point */
    double *up = malloc(sizeof(double) * (size_t)o->points), *down = malloc(sizeof(double) * (size_t)o->points);
    int nup = 0, ndown = 0;
    if (!up || !down) {
        free(up); free(down);
        swim_status_fail_cmd(st, "continue", NULL, NULL, "out of memory");
        goto done;
    }
    for (int k = 0; k < o->points; k++)
        if (targets[k] >= b->param0) up[nup++] = targets[k];
    for (int k = o->points - 1; k >= 0; k--)
        if (targets[k] < b->param0) down[ndown++] = targets[k];
    /* up[] ascending, down[] descending: both away from param0 when the range is ordered START < STOP */
    if (o->start > o->stop) {
        for (int i = 0; i < nup / 2; i++) { double t = up[i]; up[i] = up[nup - 1 - i]; up[nup - 1 - i] = t; }
        for (int i = 0; i < ndown / 2; i++) { double t = down[i]; down[i] = down[ndown - 1 - i]; down[ndown - 1 - i] = t; }
    }
    const int w1 = walk(&pb, &first, up, nup, b, b->ended[0], sizeof b->ended[0]);
    const int w2 = w1 == 0 ? walk(&pb, &first, down, ndown, b, b->ended[1], sizeof b->ended[1]) : -1;
    free(up);
    free(down);
    if (w1 || w2) {
        swim_status_fail_cmd(st, "continue", NULL, NULL, "out of memory");
        goto done;
    }
    qsort(b->pt, (size_t)b->n, sizeof *b->pt, by_param);
    if ((b->stopped = stop_asked(&pb)) != 0) {   /* the points so far, no refinement of special points */
        snprintf(b->ended[0], sizeof b->ended[0], "stopped by %s after %d of %d points",
                 swim_floquet_signal_name(b->stopped), b->n, o->points);
        b->ended[1][0] = '\0';
        rc = 0;
        goto done;
    }
    if (classify(&pb, b) != 0) {
        swim_status_fail_cmd(st, "continue", NULL, NULL, "out of memory");
        goto done;
    }
    rc = 0;
done:
    if (have_p0) swim_periodic_free(&p0);
    for (int i = 0; i < pb.nvalue; i++) *pb.value[i] = saved[i];   /* the scene as it was */
    if (have_sens) swim_sens_free(&S);
    free(targets);
    free(first.ys);
    b->rhs_calls = pb.rhs_calls;
    b->seconds = swim_clock_seconds() - t0;
    return rc;
}

void swim_branch_free(swim_branch *b)
{
    free(b->pt);
    b->pt = NULL;
}

void swim_branch_csv(FILE *f, const swim_branch *b, const char *key)
{
    /* the parameter's column is named by its key (energy_target when it is the energy, beside the
     * energy reached) */
    /* displacement = |(dx, dy)|: dx and dy are in the body frame at the phase point, which may
     * slide along the orbit from point to point; their length does not */
    /* then the phase point (the shape state each orbit was solved at, by coordinate name), so that
     * anyone can rerun an orbit and see whether the branch stays on its invariant subspace */
    const int ncol = swim_branch_columns(b);
    for (int j = 0; j < ncol; j++) fprintf(f, "%s%s", j ? "," : "", swim_branch_column(b, key, j));
    fprintf(f, "\n");
    double v[SWIM_BRANCH_FIXED_COLUMNS + SWIM_FLOQUET_MAX];
    for (int i = 0; i < b->n; i++) {
        swim_branch_row(b, i, v);
        for (int c = 0; c < ncol; c++) {
            if (c) fputc(',', f);
            if (c == 8) fputs(v[c] != 0 ? "yes" : "no", f);
            else if (c == 10) fprintf(f, "%d", (int)v[c]);
            else swim_number_print(f, v[c]);
        }
        fputc('\n', f);
    }
}

int swim_branch_columns(const swim_branch *b) { return SWIM_BRANCH_FIXED_COLUMNS + b->n2; }

const char *swim_branch_column(const swim_branch *b, const char *key, int j)
{
    static const char *const fixed[SWIM_BRANCH_FIXED_COLUMNS] = {
        NULL, "period", "dx", "dy", "dtheta", "energy", "dy_per_time", "max_abs_multiplier", "stable", "residual",
        "iterations", "displacement"};
    if (j == 0) return strcmp(key, "energy") == 0 ? "energy_target" : key;
    return j < SWIM_BRANCH_FIXED_COLUMNS ? fixed[j] : b->znames[j - SWIM_BRANCH_FIXED_COLUMNS];
}

void swim_branch_row(const swim_branch *b, int i, double *v)
{
    const swim_cont_point *q = &b->pt[i];
    const double fixed[SWIM_BRANCH_FIXED_COLUMNS] = {
        q->param, q->period, q->dx, q->dy, q->dtheta, q->energy, q->dy / q->period, q->max_abs, q->stable ? 1 : 0,
        q->residual, q->iterations, hypot(q->dx, q->dy)};
    memcpy(v, fixed, sizeof fixed);
    for (int j = 0; j < b->n2; j++) v[SWIM_BRANCH_FIXED_COLUMNS + j] = j < q->n2 ? q->z[j] : NAN;
}

/* A point's multipliers as [[re, im], ...] (the caller writes the brackets around). */
static void multipliers_json(FILE *f, const swim_cont_point *q)
{
    for (int k = 0; k < q->nt; k++) {
        fprintf(f, "%s[", k ? ", " : "");
        swim_json_number(f, q->re[k]);
        fprintf(f, ", ");
        swim_json_number(f, q->im[k]);
        fprintf(f, "]");
    }
}

void swim_branch_json(FILE *f, const swim_branch *b, const char *scene, const char *key)
{
    fprintf(f, "{\n  \"scene\": ");
    swim_json_string(f, scene);
    fprintf(f, ",\n  \"parameter\": ");
    swim_json_string(f, key);
    fprintf(f, ",\n  \"method\": \"natural-parameter continuation, secant predictor, Newton shooting corrector\"");
    fprintf(f, ",\n  \"status\": \"%s\"", b->stopped ? "stopped" : b->ended[0][0] || b->ended[1][0] ? "ended early"
                                                                   : "completed");
    if (b->stopped) {
        fprintf(f, ",\n  \"signal\": ");
        swim_json_string(f, swim_floquet_signal_name(b->stopped));
    }
    fprintf(f, ",\n  \"start_orbit_parameter\": ");
    swim_json_number(f, b->param0);
    /* the entries held at 0 along the branch (the start orbit's invariant subspace), [] when none */
    fprintf(f, ",\n  \"invariant_subspace\": {\"held_zero\": [");
    for (int j = 0, k = 0; j < b->n2; j++)
        if (b->hold[j]) fprintf(f, "%s\"%s\"", k++ ? ", " : "", b->znames[j]);
    fprintf(f, "]}");
    fprintf(f, ",\n  \"points\": [");
    for (int i = 0; i < b->n; i++) {
        const swim_cont_point *q = &b->pt[i];
        fprintf(f, "%s\n    {\"parameter\": ", i ? "," : "");
        swim_json_number(f, q->param);
        fprintf(f, ", \"period\": ");
        swim_json_number(f, q->period);
        fprintf(f, ", \"dy\": ");
        swim_json_number(f, q->dy);
        fprintf(f, ", \"energy\": ");
        swim_json_number(f, q->energy);
        fprintf(f, ", \"residual\": ");
        swim_json_number(f, q->residual);
        fprintf(f, ", \"stable\": %s, \"multipliers\": [", q->stable ? "true" : "false");
        multipliers_json(f, q);
        fprintf(f, "]}");
    }
    fprintf(f, "\n  ],\n  \"special_points\": [");
    for (int i = 0; i < b->nspecial; i++) {
        fprintf(f, "%s\n    {\"kind\": \"%s\", \"between\": [", i ? "," : "", b->special[i].kind);
        swim_json_number(f, b->special[i].lo);
        fprintf(f, ", ");
        swim_json_number(f, b->special[i].hi);
        fprintf(f, "], \"refined\": %s, \"bisections\": %d", b->special[i].refined ? "true" : "false",
                b->special[i].bisections);
        if (b->special[i].why[0]) {
            fprintf(f, ", \"why_not_refined\": ");
            swim_json_string(f, b->special[i].why);
        }
        const swim_cont_point *q = &b->special[i].at;
        fprintf(f, ", \"at\": {\"parameter\": ");
        swim_json_number(f, q->param);
        fprintf(f, ", \"period\": ");
        swim_json_number(f, q->period);
        fprintf(f, ", \"multipliers\": [");
        multipliers_json(f, q);
        fprintf(f, "]}}");
    }
    fprintf(f, "\n  ],\n  \"ended_early\": [");
    int first = 1;
    for (int s = 0; s < 2; s++)
        if (b->ended[s][0]) {
            fprintf(f, "%s", first ? "" : ", ");
            swim_json_string(f, b->ended[s]);
            first = 0;
        }
    fprintf(f, "],\n  \"rhs_evaluations\": %ld,\n  \"seconds\": ", b->rhs_calls);
    swim_json_number(f, b->seconds);
    fprintf(f, "\n}\n");
}
