/* Where one right-hand side of a full-coordinate scene goes: ns per call of the whole RHS
 * (scene-specialized kernel), of the barrier quadrature alone (shape/barrier.h, gradient
 * included), of the kernel's K + P + <Gamma, v, v> alone (the kernel of N modes: the same
 * assembly, kernel/assembly.h) and of its K + P without Gamma (the Christoffel contraction is the
 * difference), and the rest (forces, Cholesky factor of K, the constrained solve
 * of (4.12), the frame) by difference. Each at the scene's initial state, median of 7 repetitions
 * of ~50 ms. Scenes: the arguments, else models/example7.toml and models/selfpropelled.toml.
 * One CSV row per scene on stdout and build/bench/rhs_parts.csv. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "model/dynamics.h"
#include "codegen/codegen.h"
#include "scene/scene.h"
#include "shape/barrier.h"
#include "bench/timing.h"
#include "io/status.h"
#include "cli/report.h"

typedef struct {
    swim_dynamics *d;
    const double *y, *x, *v;
    double *dy, *K, *P, *g, W;
} parts;

enum { RHS, BARRIER, REDUCED, REDUCED_KP };

static void once(parts *p, int what)
{
    const swim_scene *s = p->d->scene;
    if (what == RHS) swim_dynamics_rhs(0.1, p->y, p->dy, p->d);
    else if (what == BARRIER) swim_barrier_w2(p->d->barrier, p->x, s->epsilon, s->alpha, &p->W, p->g, NULL);
    else if (what == REDUCED) p->d->k->reduced(p->x, p->v, s->rho0, s->rhof, p->K, p->P, p->g);
    else p->d->k->reduced(p->x, NULL, s->rho0, s->rhof, p->K, p->P, NULL);
}

static double time_ns(parts *p, int what)
{
    long iters = 1;
    double reps[7];
    for (;;) {
        double t0 = bench_now();
        for (long i = 0; i < iters; i++) once(p, what);
        double dt = bench_now() - t0;
        if (dt > 0.05) break;
        iters = dt > 1e-4 ? (long)(iters * 0.06 / dt) + 1 : iters * 10;
    }
    for (int r = 0; r < 7; r++) {
        double t0 = bench_now();
        for (long i = 0; i < iters; i++) once(p, what);
        reps[r] = (bench_now() - t0) / iters * 1e9;
    }
    return bench_median(reps, 7);
}

int main(int argc, char **argv)
{
    static const char *defaults[] = {"models/example7.toml", "models/selfpropelled.toml"};
    const char **scenes = argc > 1 ? (const char **)argv + 1 : defaults;
    const int count = argc > 1 ? argc - 1 : 2;
    FILE *csv = fopen("build/bench/rhs_parts.csv", "w");
    const char *head = "scene,n,barrier_nodes,ns_rhs,ns_barrier,ns_kernel,ns_christoffel,ns_rest\n";
    printf("%s", head);
    if (csv) fputs(head, csv);
    for (int a = 0; a < count; a++) {
        static swim_scene s;
        swim_dynamics d;
        swim_compiled sp;
        swim_status st = SWIM_STATUS_STDERR;
        if (swim_status_shown(&st, swim_scene_load(scenes[a], &s, &st))) return 1;
        const swim_kernel *k = swim_kernel_find(s.modes);
        if (!k || !s.barrier || swim_dynamics_init(&d, &s, k) != 0) return 1;
        if (swim_status_shown(&st, swim_codegen_scene(&s, 0, &sp, 0, &st))) return 1;
        const int n = s.n;
        double *y = calloc((size_t)d.dim, sizeof(double)), *ys = calloc((size_t)d.dim, sizeof(double));
        double *dy = calloc((size_t)d.dim, sizeof(double)), *K = calloc((size_t)n * n, sizeof(double));
        double P[3 * 2 * (SWIM_KERNEL_MAX_MODES + 1)], g[2 * (SWIM_KERNEL_MAX_MODES + 1)];
        swim_dynamics_initial_state(&d, y);
        swim_dynamics_use_scene_kernel(&d, sp.scene, 0);
        swim_dynamics_pack(&d, y, ys);
        parts p = {&d, ys, y + 3, y + 3 + n, dy, K, P, g, 0.0};
        swim_barrier_info info;
        swim_barrier_w2(d.barrier, p.x, s.epsilon, s.alpha, &p.W, g, &info);
        const double rhs = time_ns(&p, RHS), bar = time_ns(&p, BARRIER), red = time_ns(&p, REDUCED);
        const double kp = time_ns(&p, REDUCED_KP);
        char row[512];
        snprintf(row, sizeof row, "%s,%d,%d%s,%.1f,%.1f,%.1f,%.1f,%.1f\n", scenes[a], n, info.nodes, info.graded ? "g" : "", rhs, bar, red,
                 red - kp, rhs - bar - red);
        printf("%s", row);
        if (csv) fputs(row, csv);
        fflush(stdout);
        free(y); free(ys); free(dy); free(K);
        swim_compiled_close(&sp);
        swim_dynamics_free(&d);
        swim_scene_free(&s);
    }
    if (csv) fclose(csv);
    return 0;
}
