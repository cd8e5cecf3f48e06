/* Cost of one exact Jacobian (swim_dynamics_jacobian: the scene kernel's tangent code and the
 * barrier's Hessian) in units of one right-hand-side evaluation, for the mode counts given on
 * the command line (default 7 15 20): every coordinate free, elastic, damping and barrier on
 * (the structure of models/hard/stiff_n15.toml), at an interior shape. A Jacobian by
 * differences costs `state` evaluations (CVODE's dense difference quotients; msbdf: state + 2).
 * Medians of 7 repetitions of ~50 ms each. One CSV row per N on stdout:
 * N,state,ns_rhs,ns_jacobian,jacobian_in_rhs_units */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "bench/timing.h"
#include "codegen/codegen.h"
#include "io/message.h"
#include "model/dynamics.h"

static double *g_J;

static double time_call(swim_dynamics *d, const double *y, double *out, int jac)
{
    long iters = 1;
    double reps[7];
    for (;;) {
        double t0 = bench_now();
        for (long i = 0; i < iters; i++)
            jac ? swim_dynamics_jacobian(0.1, y, g_J, d) : swim_dynamics_rhs(0.1, y, out, d);
        double dt = bench_now() - t0;
        if (dt > 0.05) break;
        iters = dt > 1e-4 ? (long)(iters * 0.06 / dt) + 1 : iters * 10;
    }
    for (int r = 0; r < 7; r++) {
        double t0 = bench_now();
        for (long i = 0; i < iters; i++)
            jac ? swim_dynamics_jacobian(0.1, y, g_J, d) : swim_dynamics_rhs(0.1, y, out, d);
        reps[r] = (bench_now() - t0) / iters * 1e9;
    }
    return bench_median(reps, 7);
}

int main(int argc, char **argv)
{
    int modes[16] = {7, 15, 20}, count = 3;
    if (argc > 1) {
        count = 0;
        for (int a = 1; a < argc && count < 16; a++) modes[count++] = atoi(argv[a]);
    }
    printf("N,state,ns_rhs,ns_jacobian,jacobian_in_rhs_units\n");
    for (int c = 0; c < count; c++) {
        const int N = modes[c], n = 2 * (N + 1);
        static swim_scene s;
        memset(&s, 0, sizeof s);
        s.path = swim_strprintf("bench_jacobian_cost N=%d", N);
        s.modes = N;
        s.n = n;
        s.rho0 = s.rhof = 1.0;
        s.elastic = s.damped = s.barrier = 1;
        s.epsilon = 0.03;
        s.alpha = 0.5;
        for (int i = 0; i < n; i++) {
            s.free_mask[i] = 1;
            s.stiffness[i] = pow(10.0, 4.0 * (i / 2) / (N > 0 ? N : 1));
            s.damping[i] = 0.1;
        }
        s.c0[0] = s.reference[0] = 1.0;
        if (N >= 1) s.c0[2] = s.reference[2] = 0.3;
        if (N >= 2) s.c0[5] = 0.1;
        swim_compiled sc;
        swim_dynamics d;
        if (swim_codegen_scene(&s, 0, &sc, 1, NULL) != 0 || swim_dynamics_init(&d, &s, NULL) != 0) return 1;
        swim_dynamics_use_scene_kernel(&d, sc.scene, 0);
        const int sdim = swim_dynamics_state_dim(&d);
        double *y = calloc((size_t)d.dim, sizeof(double)), *ys = calloc((size_t)sdim, sizeof(double));
        double *dy = calloc((size_t)sdim, sizeof(double));
        g_J = calloc((size_t)sdim * sdim, sizeof(double));
        if (!y || !ys || !dy || !g_J) return 1;
        swim_dynamics_initial_state(&d, y);
        for (int i = 0; i < n; i++) y[3 + n + i] = 0.1 * sin(1.0 + i);   /* a moving state */
        swim_dynamics_pack(&d, y, ys);
        if (swim_dynamics_rhs(0.1, ys, dy, &d) != 0 || swim_dynamics_jacobian(0.1, ys, g_J, &d) != 0) {
            fprintf(stderr, "bench_jacobian_cost: N=%d: the state is outside the domain\n", N);
            return 1;
        }
        const double tr = time_call(&d, ys, dy, 0), tj = time_call(&d, ys, dy, 1);
        printf("%d,%d,%.0f,%.0f,%.1f\n", N, sdim, tr, tj, tj / tr);
        fflush(stdout);
        free(y); free(ys); free(dy); free(g_J);
        swim_dynamics_free(&d);
        swim_compiled_close(&sc);
        swim_scene_free(&s);
    }
    return 0;
}
