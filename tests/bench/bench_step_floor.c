/* What a multistep integrator's own step costs, apart from any right-hand side: ABM against
 * GSL msadams and CVODE-Adams on 12 uncoupled harmonic oscillators (the dimension of Example
 * 3's state, 4 free coordinates) whose right-hand side costs a few nanoseconds, at Example 3's
 * tolerances (rtol 1e-10, atol 1e-12) and rows (every 0.05, dense output), the frequencies
 * scaled so that ABM takes about Example 3's steps per unit of time at about its orders. The
 * net cost per step (CPU time less the calls of the right-hand side, timed on their own) is the
 * floor under any run of that size: a run's step control can cost no less than its method.
 * Medians of BENCH_RUNS (default 5) runs; one CSV row per case on stdout and in
 * build/bench/step_floor.csv.
 *
 * Usage: bench_step_floor [T]   (default T = 300) */
#include "ode/ode.h"

#include <stdio.h>
#include <stdlib.h>
#include <time.h>
#include "bench/timing.h"

#define DIM 12
#define ROW_STEP 0.05
#define MAX_RUNS 15

/* 6 oscillators, q'' = -w^2 q; the scale puts ABM near Example 3's 69 steps per unit of time */
static const double omega[DIM / 2] = {2.65, 4.28, 5.91, 7.55, 1.43, 3.88};

static int oscillators(double t, const double *y, double *f, void *params)
{
    (void)t;
    (void)params;
    for (int i = 0; i < DIM / 2; i++) {
        f[2 * i] = y[2 * i + 1];
        f[2 * i + 1] = -omega[i] * omega[i] * y[2 * i];
    }
    return 0;
}

static double cpu_now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
    return ts.tv_sec + 1e-9 * ts.tv_nsec;
}

/* ns per call of the right-hand side alone (median of 5 loops of 10^6 calls) */
static double rhs_ns(void)
{
    double y[DIM], f[DIM], v[5];
    for (int i = 0; i < DIM; i++) y[i] = 1.0 / (i + 1);
    for (int r = 0; r < 5; r++) {
        const double t0 = cpu_now();
        for (int k = 0; k < 1000000; k++) {
            oscillators(0.0, y, f, NULL);
            y[k % DIM] += 1e-300 * f[(k + 1) % DIM];   /* a dependence the compiler must keep */
        }
        v[r] = (cpu_now() - t0) * 1e3;
    }
    volatile double sink = y[0];   /* the loop's result is used: it cannot be left out */
    (void)sink;
    return bench_median(v, 5);
}

typedef struct {
    long steps, evals, high_order;
    double seconds;
} run_result;

/* One integration over [0, T] with a row every ROW_STEP (rows = 0: one call to T). */
static int one_run(const char *method, double T, int rows, run_result *out)
{
    swim_ode_system sys = {oscillators, DIM, NULL, NULL};
    swim_ode_options opt;
    swim_ode_options_default(&opt);
    opt.rtol = 1e-10;
    opt.atol = 1e-12;
    double y[DIM];
    for (int i = 0; i < DIM; i++) y[i] = i % 2 ? 0.3 * omega[i / 2] : 1.0;
    swim_ode *s;
    int rc = swim_ode_create(method, &sys, &opt, 0.0, y, &s);
    if (rc) return rc;
    const double t0 = cpu_now();
    if (rows) {
        const long n = (long)(T / ROW_STEP + 0.5);
        for (long i = 1; i <= n && !rc; i++) rc = swim_ode_advance(s, i * ROW_STEP, y);
    } else {
        rc = swim_ode_advance(s, T, y);
    }
    out->seconds = cpu_now() - t0;
    swim_ode_stats st;
    swim_ode_get_stats(s, &st);
    out->steps = st.steps;
    out->evals = st.rhs_evals;
    out->high_order = 0;
    for (int k = 10; k <= 12; k++) out->high_order += st.order_hist[k];
    swim_ode_free(s);
    return rc;
}

int main(int argc, char **argv)
{
    const double T = argc > 1 ? atof(argv[1]) : 300.0;
    const char *env = getenv("BENCH_RUNS");
    int runs = env ? atoi(env) : 5;
    if (runs < 1) runs = 1;
    if (runs > MAX_RUNS) runs = MAX_RUNS;
    if (!(T > 0.0)) {
        fprintf(stderr, "bench_step_floor: T must be > 0, got %s\n", argv[1]);
        return 2;
    }
    const double f_ns = rhs_ns();
    struct {
        const char *method;
        int rows;
    } cases[] = {{"abm", 1}, {"abm", 0}, {"msadams", 1}, {"cvode-adams", 1}};
    const int ncases = (int)(sizeof cases / sizeof cases[0]);
    FILE *csv = fopen("build/bench/step_floor.csv", "w");   /* NULL: stdout only */
    const char *head = "method,rows,T,steps,rhs_evals,order_10_12_share,ns_per_step,ns_rhs_call,ns_per_step_net\n";
    fprintf(stderr, "bench_step_floor: 12 oscillators, rtol 1e-10, atol 1e-12, T = %g; one right-hand side %.1f ns; "
            "CPU time, medians of %d runs\n", T, f_ns, runs);
    /* runs interleaved over the cases, so that the machine's load falls on all of them alike */
    double per_step[4][MAX_RUNS];
    run_result last[4];
    for (int r = 0; r < runs; r++)
        for (int c = 0; c < ncases; c++) {
            int rc = one_run(cases[c].method, T, cases[c].rows, &last[c]);
            if (rc) {
                fprintf(stderr, "bench_step_floor: %s failed: %s\n", cases[c].method, swim_ode_strerror(rc));
                if (csv) fclose(csv);
                return 1;
            }
            per_step[c][r] = 1e9 * last[c].seconds / (double)last[c].steps;
        }
    printf("%s", head);
    if (csv) fputs(head, csv);
    for (int c = 0; c < ncases; c++) {
        const run_result *x = &last[c];
        const double ns = bench_median(per_step[c], runs);
        const double net = ns - f_ns * (double)x->evals / (double)x->steps;
        char row[256];
        snprintf(row, sizeof row, "%s,%d,%g,%ld,%ld,%.3f,%.1f,%.2f,%.1f\n", cases[c].method,
                 cases[c].rows ? (int)(T / ROW_STEP + 0.5) : 0, T, x->steps, x->evals,
                 (double)x->high_order / (double)x->steps, ns, f_ns, net);
        printf("%s", row);
        if (csv) fputs(row, csv);
    }
    if (csv) fclose(csv);
    return 0;
}
