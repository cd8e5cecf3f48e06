/* ns per right-hand-side evaluation of each scene given on the command line, generic kernel
 * (every coordinate carried, locks through multipliers) vs the scene-specialized kernel, both
 * generated (runtime/codegen), at the scene's initial state. Medians of 7 repetitions, each
 * ~50 ms. One CSV row per scene on stdout:
 * scene,n_free,state_generic,state_specialized,c_lines,ns_generic,ns_specialized */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "model/dynamics.h"
#include "codegen/codegen.h"
#include "scene/scene.h"
#include "bench/timing.h"

static double time_rhs(swim_dynamics *d, const double *y, double *dy)
{
    long iters = 1;
    double reps[7];
    for (;;) {
        double t0 = bench_now();
        for (long i = 0; i < iters; i++) swim_dynamics_rhs(0.1, y, dy, d);
        double dt = bench_now() - t0;
        if (dt > 0.05) break;
        iters = dt > 1e-4 ? (long)(iters * 0.06 / dt) + 1 : iters * 10;
    }
    for (int r = 0; r < 7; r++) {
        double t0 = bench_now();
        for (long i = 0; i < iters; i++) swim_dynamics_rhs(0.1, y, dy, d);
        reps[r] = (bench_now() - t0) / iters * 1e9;
    }
        return bench_median(reps, 7);
}

static long count_lines(const char *path)
{
    FILE *f = fopen(path, "r");
    long n = 0;
    int c;
    if (!f) return -1;
    while ((c = fgetc(f)) != EOF) n += c == '\n';
    fclose(f);
    return n;
}

int main(int argc, char **argv)
{
    printf("scene,n_free,state_generic,state_specialized,c_lines,ns_generic,ns_specialized\n");
    for (int a = 1; a < argc; a++) {
        static swim_scene s;
        swim_dynamics d;
        swim_compiled gen, sp;
        if (swim_scene_load(argv[a], &s, NULL) != 0 || swim_dynamics_init(&d, &s, NULL) != 0) return 1;
        if (swim_codegen_scene(&s, 1, &gen, 0, NULL) != 0 || swim_codegen_scene(&s, 0, &sp, 0, NULL) != 0) return 1;
        double *y = calloc((size_t)d.dim, sizeof(double)), *ys = calloc((size_t)d.dim, sizeof(double));
        double *dy = calloc((size_t)d.dim, sizeof(double));
        swim_dynamics_initial_state(&d, y);
        swim_dynamics_use_scene_kernel(&d, gen.scene, 1);
        swim_dynamics_pack(&d, y, ys);
        double ns_gen = time_rhs(&d, ys, dy);
        swim_dynamics_use_scene_kernel(&d, sp.scene, 0);
        swim_dynamics_pack(&d, y, ys);
        double ns_spec = time_rhs(&d, ys, dy);
        int nf = sp.scene->nfree;
        printf("%s,%d,%d,%d,%ld,%.1f,%.1f\n", argv[a], nf, d.dim, 4 + 2 * nf, count_lines(sp.source), ns_gen, ns_spec);
        fflush(stdout);
        free(y); free(ys); free(dy);
        swim_compiled_close(&sp);
        swim_compiled_close(&gen);
        swim_dynamics_free(&d);
        swim_scene_free(&s);
    }
    return 0;
}
