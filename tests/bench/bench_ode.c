/* Work-precision benchmark of the ODE integrators: ABM against GSL msadams,
 * GSL rk8pd and CVODE-Adams on four problems, tolerances 1e-4 .. 1e-15
 * (1e-14 and 1e-15 added so that the multistep codes reach errors near 1e-12:
 * an Adams code with per-step error control ends about 1e3 x tol from the
 * solution on Kepler/Arenstorf).  "abm-step" is ABM with STEP's step-size rule
 * (lookahead = 0), run side by side to show what the look-ahead changes.
 * Achieved errors are measured against analytic solutions or a long double
 * Gragg-Bulirsch-Stoer reference of the same right-hand side.  Writes
 * build/bench/ode_work_precision.csv and runs the plot script. */
#include "ode/ode.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include "ode_problems.h"
#include "bench/timing.h"

#define PI 3.14159265358979323846
#define NMAX 32

/* ---------- problems, written once for double and long double ---------- */

#define AREN_MU 0.012277471L
#define AREN_T 17.0652165601579625588917206249L

#define DEFINE_ARENSTORF(NAME, T, POW)                                          \
    static int NAME(T t, const T *y, T *f, void *p)                            \
    {                                                                          \
        (void)t; (void)p;                                                      \
        const T mu = (T)AREN_MU, mp = 1 - mu;                                  \
        T d1 = (y[0] + mu) * (y[0] + mu) + y[1] * y[1];                        \
        T d2 = (y[0] - mp) * (y[0] - mp) + y[1] * y[1];                        \
        d1 = POW(d1, (T)1.5);                                                  \
        d2 = POW(d2, (T)1.5);                                                  \
        f[0] = y[2];                                                           \
        f[1] = y[3];                                                           \
        f[2] = y[0] + 2 * y[3] - mp * (y[0] + mu) / d1 - mu * (y[0] - mp) / d2; \
        f[3] = y[1] - 2 * y[2] - mp * y[1] / d1 - mu * y[1] / d2;              \
        return 0;                                                              \
    }
DEFINE_ARENSTORF(aren_d, double, pow)
DEFINE_ARENSTORF(aren_l, long double, powl)

/* Chain of NP coupled nonlinear pendula with a dense coupling matrix
 * (n = 2 NP = 16):
 *   theta_i'' = -w_i sin(theta_i) + sum_j K_ij sin(d) exp(-d^2/4) cos(d/2) (1 + tanh(d)/4),
 * d = theta_j - theta_i.  Each evaluation costs 4 NP^2 + NP transcendental
 * calls, about 2-3 us; it stands in for an expensive model RHS. */
#define NP 8
static double Kd[NP][NP], Wd[NP];
static long double Kl[NP][NP], Wl[NP];

#define DEFINE_CHAIN(NAME, T, K, W, SIN, COS, EXP, TANH)                              \
    static int NAME(T t, const T *y, T *f, void *p)                            \
    {                                                                          \
        (void)t; (void)p;                                                      \
        for (int i = 0; i < NP; i++) {                                         \
            T acc = -W[i] * SIN(y[i]);                                         \
            for (int j = 0; j < NP; j++) {                                     \
                T d = y[j] - y[i];                                             \
                acc += K[i][j] * SIN(d) * EXP(-(T)0.25 * d * d) * COS((T)0.5 * d) *  \
                       (1 + (T)0.25 * TANH(d));                                \
            }                                                                  \
            f[i] = y[NP + i];                                                  \
            f[NP + i] = acc;                                                   \
        }                                                                      \
        return 0;                                                              \
    }
DEFINE_CHAIN(chain_d, double, Kd, Wd, sin, cos, exp, tanh)
DEFINE_CHAIN(chain_l, long double, Kl, Wl, sinl, cosl, expl, tanhl)

static void chain_setup(double *y0)
{
    for (int i = 0; i < NP; i++) {
        Wd[i] = 1.0 + 0.15 * i;
        Wl[i] = 1.0L + 0.15L * i;
        for (int j = 0; j < NP; j++) {
            int a = i < j ? i : j, b = i < j ? j : i;
            double k = 0.3 * (1.0 + ((a * 7 + b * 3) % 5)) / NP;   /* symmetric, dense */
            Kd[i][j] = k;
            Kl[i][j] = k;
        }
        y0[i] = 0.8 * sin(1.0 + i);
        y0[NP + i] = 0.5 * cos(1.3 * i);
    }
}

/* 8 uncoupled linear oscillators (n = 16): a nearly free RHS, used to
 * measure the integrator's own cost per RHS evaluation */
static int lin16_rhs(double t, const double *y, double *f, void *p)
{
    (void)t; (void)p;
    for (int i = 0; i < 8; i++) {
        f[i] = y[8 + i];
        f[8 + i] = -(1.0 + 0.1 * i) * y[i];
    }
    return 0;
}

/* ---------- long double reference: adaptive Gragg-Bulirsch-Stoer ---------- */

typedef int (*rhs_l)(long double t, const long double *y, long double *f, void *p);

/* modified midpoint over H with m substeps */
static void midpoint(rhs_l f, size_t n, long double t, const long double *y, const long double *f0,
                     long double H, int m, long double *out)
{
    long double h = H / m, z0[NMAX], z1[NMAX], fz[NMAX];
    for (size_t i = 0; i < n; i++) {
        z0[i] = y[i];
        z1[i] = y[i] + h * f0[i];
    }
    for (int k = 1; k < m; k++) {
        f(t + k * h, z1, fz, NULL);
        for (size_t i = 0; i < n; i++) {
            long double z2 = z0[i] + 2 * h * fz[i];
            z0[i] = z1[i];
            z1[i] = z2;
        }
    }
    f(t + H, z1, fz, NULL);
    for (size_t i = 0; i < n; i++)
        out[i] = 0.5L * (z0[i] + z1[i] + h * fz[i]);
}

static void gbs_reference(rhs_l f, size_t n, const double *y0d, double t1, double *out)
{
    enum { KX = 12 };
    long double y[NMAX], f0[NMAX], T[KX][NMAX], t = 0, H = 0.05L, tol = 1e-18L;
    int seq[KX];
    for (int j = 0; j < KX; j++)
        seq[j] = 2 * (j + 1);
    for (size_t i = 0; i < n; i++)
        y[i] = y0d[i];
    while (t < t1) {
        if (t + H > t1)
            H = t1 - t;
        f(t, y, f0, NULL);
        int conv = -1;
        for (int j = 0; j < KX; j++) {
            midpoint(f, n, t, y, f0, H, seq[j], T[j]);
            /* Aitken-Neville extrapolation in h^2, in place along the row */
            for (int k = j - 1; k >= 0; k--) {
                long double r = (long double)seq[j] / seq[k];
                r = r * r - 1;
                for (size_t i = 0; i < n; i++)
                    T[k][i] = T[k + 1][i] + (T[k + 1][i] - T[k][i]) / r;
            }
            if (j >= 3) {
                long double e = 0;
                for (size_t i = 0; i < n; i++)
                    e = fmaxl(e, fabsl(T[0][i] - T[1][i]) / (1 + fabsl(T[0][i])));
                if (e < tol) {
                    conv = j;
                    break;
                }
            }
            /* rows: T[0] is the most extrapolated; shift the newest into T[j] */
        }
        if (conv < 0) {
            H *= 0.5L;
            continue;
        }
        for (size_t i = 0; i < n; i++)
            y[i] = T[0][i];
        t += H;
        if (conv <= 6)
            H *= 1.5L;
        else if (conv >= 10)
            H *= 0.7L;
    }
    for (size_t i = 0; i < n; i++)
        out[i] = (double)y[i];
}

/* ---------- benchmark driver ---------- */

typedef struct {
    const char *name;
    swim_ode_func f;
    size_t n;
    double t1;
    double y0[NMAX], yref[NMAX];
} problem;

static double cpu_now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
    return ts.tv_sec + 1e-9 * ts.tv_nsec;
}

typedef struct {
    swim_ode_func f;
    double (*rec)[NMAX];
    long cap, count;
    size_t n;
} recorder;

static int record_rhs(double t, const double *y, double *f, void *p)
{
    recorder *r = p;
    if (r->count < r->cap)
        memcpy(r->rec[r->count++], y, r->n * sizeof(double));
    return r->f(t, y, f, NULL);
}

static int solve(const problem *p, const char *method, double tol, double *y, swim_ode_stats *st)
{
    swim_ode_system sys = { p->f, p->n, NULL, NULL };
    swim_ode_options o;
    swim_ode_options_default(&o);
    o.rtol = tol;
    o.atol = tol;
    if (strcmp(method, "abm-step") == 0) {   /* abm with STEP's step-size rule, no look-ahead */
        method = "abm";
        o.lookahead = 0;
    }
    swim_ode *s;
    int rc = swim_ode_create(method, &sys, &o, 0.0, p->y0, &s);
    if (rc)
        return rc;
    rc = swim_ode_advance(s, p->t1, y);
    if (st)
        swim_ode_get_stats(s, st);
    swim_ode_free(s);
    return rc;
}

#define NREP 5
/* CPU time of one solve, averaged over a batch of repetitions lasting about
 * 10 ms (reps chosen from a first untimed-for-result run). */
static int batch_reps(const problem *p, const char *method, double tol)
{
    double y[NMAX];
    double t0 = cpu_now();
    solve(p, method, tol, y, NULL);
    double one = cpu_now() - t0;
    return one > 1e-2 ? 1 : (int)(1e-2 / fmax(one, 1e-7)) + 1;
}

static double time_batch(const problem *p, const char *method, double tol, int reps)
{
    double y[NMAX];
    double t0 = cpu_now();
    for (int i = 0; i < reps; i++)
        solve(p, method, tol, y, NULL);
    return (cpu_now() - t0) / reps;
}

typedef struct {
    double err, evals, cpu;
    long steps, rej;
    int ok;
} point;

#define NTOL 12
#define NMETH 5
#define NPEER 4   /* methods[1..NPEER-1] are the other codes; the last is abm without look-ahead */
static const char *methods[NMETH] = { "abm", "msadams", "rk8pd", "cvode-adams", "abm-step" };

/* log-log interpolation of quantity q at achieved error e (points sorted by error) */
static double at_error(const point *pt, int np, double e, int use_cpu)
{
    double le = log10(e);
    int idx[NTOL], m = 0;
    for (int i = 0; i < np; i++)
        if (pt[i].ok && pt[i].err > 0)
            idx[m++] = i;
    /* sort by error, descending */
    for (int i = 0; i < m; i++)
        for (int j = i + 1; j < m; j++)
            if (pt[idx[j]].err > pt[idx[i]].err) {
                int tmp = idx[i]; idx[i] = idx[j]; idx[j] = tmp;
            }
    for (int i = 0; i + 1 < m; i++) {
        double e0 = log10(pt[idx[i]].err), e1 = log10(pt[idx[i + 1]].err);
        if (le <= e0 && le >= e1) {
            double q0 = log10(use_cpu ? pt[idx[i]].cpu : pt[idx[i]].evals);
            double q1 = log10(use_cpu ? pt[idx[i + 1]].cpu : pt[idx[i + 1]].evals);
            double w = e0 == e1 ? 0.0 : (le - e0) / (e1 - e0);
            return pow(10.0, q0 + w * (q1 - q0));
        }
    }
    return NAN;   /* error not reached in the tolerance range */
}

int main(int argc, char **argv)
{
    const char *csv = argc > 1 ? argv[1] : "build/bench/ode_work_precision.csv";
    static problem P[4];
    int np = 0;
    double y0k[4] = { 0.5, 0.0, 0.0, sqrt(1.5 / 0.5) };

    problem *p = &P[np++];
    p->name = "harmonic";
    p->f = ho_rhs;
    p->n = 2;
    p->t1 = 50.0;
    p->y0[0] = 1.0;
    p->yref[0] = cos(50.0);
    p->yref[1] = -sin(50.0);

    p = &P[np++];
    p->name = "kepler_e0.5";
    p->f = kepler_rhs;
    p->n = 4;
    p->t1 = 8 * PI;   /* four periods: back at perihelion */
    memcpy(p->y0, y0k, sizeof y0k);
    memcpy(p->yref, y0k, sizeof y0k);

    p = &P[np++];
    p->name = "arenstorf";
    p->f = aren_d;
    p->n = 4;
    p->t1 = (double)AREN_T;
    p->y0[0] = 0.994;
    p->y0[3] = -2.00158510637908252240537862224;
    fprintf(stderr, "computing long double references ...\n");
    gbs_reference(aren_l, 4, p->y0, p->t1, p->yref);

    p = &P[np++];
    p->name = "chain_n16";
    p->f = chain_d;
    p->n = 2 * NP;
    p->t1 = 50.0;
    chain_setup(p->y0);
    gbs_reference(chain_l, p->n, p->y0, p->t1, p->yref);

    /* Cost of one evaluation of the expensive RHS, timed on the states an
     * ABM run actually visits (recorded, then replayed). */
    double trhs;
    {
        static double rec[20000][NMAX];
        recorder r = { p->f, rec, 20000, 0, p->n };
        swim_ode_system sys = { record_rhs, p->n, &r, NULL };
        swim_ode_options o;
        swim_ode_options_default(&o);
        o.rtol = o.atol = 1e-9;
        swim_ode *s;
        double y[NMAX], f[NMAX], tt[NREP];
        swim_ode_create("abm", &sys, &o, 0.0, p->y0, &s);
        swim_ode_advance(s, p->t1, y);
        swim_ode_free(s);
        volatile double sink = 0;
        for (int k = 0; k < NREP; k++) {
            double t0 = cpu_now();
            for (int rep = 0; rep < 5; rep++)
                for (long i = 0; i < r.count; i++) {
                    chain_d(0.0, rec[i], f, NULL);
                    sink += f[NP + (i % NP)];   /* keep the result live */
                }
            tt[k] = (cpu_now() - t0) / (5.0 * r.count);
        }
        (void)sink;
        qsort(tt, NREP, sizeof(double), bench_cmp);
        trhs = tt[NREP / 2];
    }
    printf("expensive RHS chain_n16: %.2f us per evaluation\n", trhs * 1e6);

    FILE *fc = fopen(csv, "w");
    if (!fc) {
        perror(csv);
        return 1;
    }
    fprintf(fc, "problem,method,tol,error,rhs_evals,steps,rejected,cpu_s\n");
    static point res[4][NMETH][NTOL];
    for (int ip = 0; ip < np; ip++) {
        p = &P[ip];
        printf("\n%s (n = %zu, t = %g)\n", p->name, p->n, p->t1);
        printf("%-12s %8s %10s %9s %7s %5s %11s\n", "method", "tol", "error", "rhs_evals", "steps", "rej", "cpu_median");
        /* accuracy and counts */
        for (int im = 0; im < NMETH; im++) {
            for (int it = 0; it < NTOL; it++) {
                double tol = pow(10.0, -4.0 - it), y[NMAX];
                swim_ode_stats st;
                int rc = solve(p, methods[im], tol, y, &st);
                double err = 0;
                for (size_t i = 0; i < p->n; i++)
                    err = fmax(err, fabs(y[i] - p->yref[i]));
                point *q = &res[ip][im][it];
                q->ok = rc == 0;
                q->err = err;
                q->evals = st.rhs_evals;
                q->steps = st.steps;
                q->rej = st.rejected;
            }
        }
        /* CPU: the methods are timed in turn within each of the NREP rounds,
         * so that all of them see the same machine load; median per method */
        for (int it = 0; it < NTOL; it++) {
            double tol = pow(10.0, -4.0 - it), tt[NMETH][NREP];
            int reps[NMETH];
            for (int im = 0; im < NMETH; im++)
                reps[im] = res[ip][im][it].ok ? batch_reps(p, methods[im], tol) : 0;
            for (int r = 0; r < NREP; r++)
                for (int im = 0; im < NMETH; im++)
                    tt[im][r] = reps[im] ? time_batch(p, methods[im], tol, reps[im]) : NAN;
            for (int im = 0; im < NMETH; im++) {
                qsort(tt[im], NREP, sizeof(double), bench_cmp);
                res[ip][im][it].cpu = res[ip][im][it].ok ? tt[im][NREP / 2] : NAN;
            }
        }
        for (int im = 0; im < NMETH; im++) {
            for (int it = 0; it < NTOL; it++) {
                point *q = &res[ip][im][it];
                double tol = pow(10.0, -4.0 - it);
                printf("%-12s %8.0e %10.2e %9.0f %7ld %5ld %9.1f us%s\n", methods[im], tol, q->err, q->evals,
                       q->steps, q->rej, q->cpu * 1e6, q->ok ? "" : "  FAILED");
                fprintf(fc, "%s,%s,%.1e,%.6e,%.0f,%ld,%ld,%.6e\n", p->name, methods[im], tol, q->err, q->evals,
                        q->steps, q->rej, q->cpu);
            }
        }
        if (ip == np - 1) {
            printf("CPU per RHS evaluation (the RHS alone costs %.2f us, measured separately):\n", trhs * 1e6);
            for (int im = 0; im < NMETH; im++) {
                printf("  %-12s", methods[im]);
                for (int it = 0; it < NTOL; it += 3) {
                    point *q = &res[ip][im][it];
                    printf("  tol 1e-%d: %.2f us", 4 + it, q->cpu / q->evals * 1e6);
                }
                printf("\n");
            }
        }
    }
    fclose(fc);

    /* Integrator overhead with a nearly free RHS at n = 16. */
    {
        problem lp = { "lin16", lin16_rhs, 16, 50.0, { 0 }, { 0 } };
        for (int i = 0; i < 8; i++)
            lp.y0[i] = 1.0;
        printf("\nOverhead per RHS evaluation with a nearly free RHS (8 linear oscillators, n = 16, t = 50):\n");
        for (int im = 0; im < NMETH; im++) {
            printf("  %-12s", methods[im]);
            for (int it = 0; it < NTOL; it += 3) {
                double tol = pow(10.0, -4.0 - it), y[NMAX];
                swim_ode_stats st;
                solve(&lp, methods[im], tol, y, &st);
                int reps = batch_reps(&lp, methods[im], tol);
                double tt[NREP];
                for (int r = 0; r < NREP; r++)
                    tt[r] = time_batch(&lp, methods[im], tol, reps);
                qsort(tt, NREP, sizeof(double), bench_cmp);
                double c = tt[NREP / 2];
                printf("  tol 1e-%d: %.3f us", 4 + it, c / st.rhs_evals * 1e6);
            }
            printf("\n");
        }
    }

    /* comparison at equal achieved error */
    printf("\nAt equal achieved error (log-log interpolation between tolerances; '-' = error not reached):\n");
    printf("%-12s %7s", "problem", "error");
    for (int im = 0; im < NMETH; im++)
        printf(" %22s", methods[im]);
    printf("\n%-20s", "");
    for (int im = 0; im < NMETH; im++)
        printf(" %22s", "evals / CPU us");
    printf("\n");
    char verdict[4][512];
    for (int ip = 0; ip < np; ip++) {
        int ev_ok = 0, ev_bad = 0, cpu_ok = 0, cpu_bad = 0, unreached = 0, st_ok = 0, st_n = 0;
        double st_ratio = 0.0;
        for (int ie = 6; ie <= 12; ie++) {
            double e = pow(10.0, -ie), ev[NMETH], cp[NMETH];
            for (int im = 0; im < NMETH; im++) {
                ev[im] = at_error(res[ip][im], NTOL, e, 0);
                cp[im] = at_error(res[ip][im], NTOL, e, 1);
            }
            printf("%-12s %7.0e", P[ip].name, e);
            for (int im = 0; im < NMETH; im++) {
                if (isnan(ev[im]))
                    printf(" %22s", "-");
                else
                    printf(" %10.0f / %9.1f", ev[im], cp[im] * 1e6);
            }
            printf("\n");
            if (isnan(ev[0])) {
                unreached++;
                continue;
            }
            if (!isnan(ev[NMETH - 1])) {
                st_n++;
                st_ok += ev[0] < ev[NMETH - 1];
                st_ratio += log(ev[0] / ev[NMETH - 1]);
            }
            for (int im = 1; im < NPEER; im++) {
                if (isnan(ev[im]))
                    continue;   /* peer does not reach this error: ABM wins trivially, not counted */
                if (ev[0] < ev[im]) ev_ok++; else ev_bad++;
                if (im <= 2) {
                    if (cp[0] < cp[im]) cpu_ok++; else cpu_bad++;
                }
            }
        }
        snprintf(verdict[ip], sizeof verdict[ip],
                 "%-12s fewer evaluations: %d of %d comparisons; less CPU than msadams/rk8pd: %d of %d; "
                 "errors not reached by abm: %d of 7; vs abm-step: fewer evaluations in %d of %d, "
                 "%.3fx its evaluations (geometric mean)",
                 P[ip].name, ev_ok, ev_ok + ev_bad, cpu_ok, cpu_ok + cpu_bad, unreached, st_ok, st_n,
                 st_n ? exp(st_ratio / st_n) : NAN);
    }
    printf("\nTargets at errors 1e-6, 1e-7, ..., 1e-12 (abm vs msadams, rk8pd, cvode-adams):\n");
    for (int ip = 0; ip < np; ip++)
        printf("  %s\n", verdict[ip]);

    char cmd[1024];
    snprintf(cmd, sizeof cmd, "/usr/bin/python3 tests/bench/plot_work_precision.py %s build/bench/ode_work_precision.png", csv);
    int rc = system(cmd);
    if (rc != 0)
        fprintf(stderr, "plot script failed (%d)\n", rc);
    return 0;
}
