/* Times one generated kernel (compiled in with -DBENCH_N=N) against the loop reference with a
 * central finite-difference Christoffel vector. Prints one CSV row:
 * N,ns_K,ns_K_gamma,ns_ref_K,ns_ref_K_fd_gamma  (medians of 7 repetitions). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <time.h>

#include "reference/ref_model.h"
#include "kernel/swim_kernel.h"
#include "bench/timing.h"

#define CAT_(a, b) a##b
#define CAT(a, b) CAT_(a, b)
extern const swim_kernel CAT(swim_kernel_n, BENCH_N);

static volatile double sink;

/* Route 0: generated K; 1: generated K + contracted Gamma; 2: loop reference K;
 * 3: loop reference K + central finite-difference Gamma. */
static void route(int which, const double *x, const double *v, double *K, double *g)
{
    const swim_kernel *k = &CAT(swim_kernel_n, BENCH_N);
    if (which == 0) k->reduced(x, NULL, 1.0, 1.0, K, NULL, NULL);
    else if (which == 1) k->reduced(x, v, 1.0, 1.0, K, NULL, g);
    else if (which == 2) ref_mass(BENCH_N, x, 1.0, 1.0, NULL, NULL, NULL, K);
    else {
        ref_mass(BENCH_N, x, 1.0, 1.0, NULL, NULL, NULL, K);
        ref_christoffel_fd(BENCH_N, x, v, 1.0, 1.0, 1e-5, g);
    }
    sink += K[0] + g[0];
}

/* Median over 7 repetitions of ns per call of route `which`. */
static double time_route(int which, const double *x, const double *v, int n)
{
    double *K = calloc((size_t)n * n, sizeof(double)), *g = calloc((size_t)n, sizeof(double)), reps[7];
    long iters = 1;
    for (;;) {   /* calibrate to ~50 ms per repetition */
        double t0 = bench_now();
        for (long i = 0; i < iters; i++) route(which, x, v, K, g);
        double dt = bench_now() - t0;
        if (dt > 0.05) break;
        iters = dt > 1e-4 ? (long)(iters * 0.06 / dt) + 1 : iters * 10;
    }
    for (int r = 0; r < 7; r++) {
        double t0 = bench_now();
        for (long i = 0; i < iters; i++) route(which, x, v, K, g);
        reps[r] = (bench_now() - t0) / iters * 1e9;
    }
    free(K);
    free(g);
    return bench_median(reps, 7);
}

int main(void)
{
    const int N = BENCH_N, n = 2 * (N + 1);
    double *x = calloc(n, sizeof(double)), *v = calloc(n, sizeof(double));
    srand(7);
    x[0] = 1.0;
    for (int m = 1; m <= N; m++) {   /* sum m |c_-m| = 0.5: admissible */
        x[2 * m] = 0.5 / (N * m) * cos(m);
        x[2 * m + 1] = 0.5 / (N * m) * sin(m);
    }
    for (int i = 0; i < n; i++) v[i] = rand() / (double)RAND_MAX - 0.5;
    printf("%d,%.1f,%.1f,%.1f,%.1f\n", N, time_route(0, x, v, n), time_route(1, x, v, n),
           time_route(2, x, v, n), time_route(3, x, v, n));
    return 0;
}
