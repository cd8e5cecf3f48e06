/* What compiler flags of the generated kernels would buy: the scene kernel's source (from the
 * cache, runtime/codegen) compiled again with the kernels' flags (KERNEL_OPT) and with each set of
 * extra flags given, then ns per RHS of each at the scene's initial state, measured in
 * interleaved rounds (301 rounds of 200 calls, the kernels in a shuffled order per round, so that a change of the
 * machine's load falls on all of them alike): the minimum and the median over the rounds, and
 * whether the derivative is the same to the bit as with the kernels' own flags.
 *
 *   bench_kernel_flags [--jacobian] [SCENE [FLAGS ...]]
 *     (default: models/example7.toml, "-ffp-contract=fast", and that with reassociation)
 *
 * With --jacobian the scene kernel's exact Jacobian is timed instead (10 calls per round; the
 * CSV is then build/bench/kernel_flags_jacobian.csv), e.g. against "-O2", the level its tangent
 * code would need for a compile twice as fast (docs/performance.md).
 *
 * One CSV row per build on stdout and build/bench/kernel_flags.csv:
 * scene,flags,ns_min,ns_median,ratio_min,same_bits  (ratio: the kernels' own flags over these). */
#include <dlfcn.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "bench/timing.h"
#include "cli/report.h"
#include "codegen/codegen.h"
#include "io/files.h"
#include "io/status.h"
#include "model/dynamics.h"
#include "scene/scene.h"

#ifndef SWIM_KERNEL_CFLAGS
#define SWIM_KERNEL_CFLAGS "-O3 -march=native"
#endif
#ifndef SWIM_CC
#define SWIM_CC "cc"
#endif

enum { MAXK = 8, ROUNDS = 301, CALLS = 200, CALLS_J = 10 };

/* One timed call: the RHS, or the exact Jacobian into out. */
static void call(const swim_scene_kernel *k, int jacobian, const double *y, double *out,
                 const swim_scene_params *p)
{
    if (jacobian)
        k->jacobian(0.1, y, out, p);
    else
        k->rhs(0.1, y, out, p);
}

/* The kernel source compiled with the kernels' flags and extra ones into dir/k<i>.so, loaded. */
static const swim_scene_kernel *build(const char *source, const char *share, const char *extra,
                                      const char *dir, int i)
{
    char so[600], cmd[8192];
    snprintf(so, sizeof so, "%s/k%d.so", dir, i);
    snprintf(cmd, sizeof cmd, "%s %s %s -std=c11 -shared -fPIC -I%s/runtime -o %s %s -lm", SWIM_CC,
             SWIM_KERNEL_CFLAGS, extra, share, so, source);
    if (system(cmd) != 0) {
        fprintf(stderr, "bench_kernel_flags: failed: %s\n", cmd);
        return NULL;
    }
    void *h = dlopen(so, RTLD_NOW | RTLD_LOCAL);
    if (!h) {
        fprintf(stderr, "bench_kernel_flags: %s\n", dlerror());
        return NULL;
    }
    return dlsym(h, "swim_scene_kernel_entry");
}

int main(int argc, char **argv)
{
    const int jacobian = argc > 1 && strcmp(argv[1], "--jacobian") == 0;
    if (jacobian) {
        argv++;
        argc--;
    }
    const char *scene = argc > 1 ? argv[1] : "models/example7.toml";
    const char *defaults[] = {"-ffp-contract=fast",
                              "-ffp-contract=fast -fassociative-math -fno-signed-zeros -fno-trapping-math"};
    const char *flags[MAXK] = {""};
    int nk = 1;
    if (argc > 2)
        for (int a = 2; a < argc && nk < MAXK; a++) flags[nk++] = argv[a];
    else
        for (int a = 0; a < 2; a++) flags[nk++] = defaults[a];
    static swim_scene s;
    swim_dynamics d;
    swim_compiled sp;
    swim_status st = SWIM_STATUS_STDERR;
    if (swim_status_shown(&st, swim_scene_load(scene, &s, &st))) return 1;
    const swim_kernel *k = swim_kernel_find(s.modes);
    if (!k || swim_dynamics_init(&d, &s, k) != 0) return 1;
    if (swim_status_shown(&st, swim_codegen_scene(&s, 0, &sp, 0, &st))) return 1;
    const char *share = swim_share_dir(&st);
    if (!share || !sp.source[0]) {
        fprintf(stderr, "bench_kernel_flags: the scene kernel's source is not at hand\n");
        return 1;
    }
    char dir[] = "/tmp/swim-kernel-flags-XXXXXX";
    if (!mkdtemp(dir)) return 1;
    const swim_scene_kernel *ks[MAXK];
    int bad = 0;
    for (int i = 0; i < nk && !bad; i++) bad = !(ks[i] = build(sp.source, share, flags[i], dir, i));
    if (!getenv("BENCH_KEEP_KERNELS")) {   /* set, the builds stay for a profiler to read their symbols */
        for (int i = 0; i < nk; i++) {
            char so[600];
            snprintf(so, sizeof so, "%s/k%d.so", dir, i);
            unlink(so);
        }
        rmdir(dir);
    }
    if (bad) return 1;
    double *y = calloc((size_t)d.dim, sizeof(double)), *ys = calloc((size_t)d.dim, sizeof(double));
    const size_t nout = jacobian ? (size_t)d.dim * (size_t)d.dim : (size_t)d.dim;
    double *dy = calloc(nout, sizeof(double)), *dy0 = calloc(nout, sizeof(double));
    swim_dynamics_initial_state(&d, y);
    swim_dynamics_use_scene_kernel(&d, sp.scene, 0);
    swim_dynamics_pack(&d, y, ys);
    static double t[MAXK][ROUNDS];
    unsigned seed = 12345u;
    for (int r = 0; r < ROUNDS; r++) {
        /* each round in its own order (a fixed shuffle): a build timed first, or right after
         * another, in every round would carry whatever that position costs */
        int order[MAXK];
        for (int i = 0; i < nk; i++) order[i] = i;
        for (int i = nk - 1; i > 0; i--) {
            seed = seed * 1103515245u + 12345u;
            const int j = (int)((seed >> 16) % (unsigned)(i + 1)), o = order[i];
            order[i] = order[j];
            order[j] = o;
        }
        for (int q = 0; q < nk; q++) {
            const int i = order[q];
            const double t0 = bench_now();
            const int calls = jacobian ? CALLS_J : CALLS;
            for (int c = 0; c < calls; c++) call(ks[i], jacobian, ys, dy, &d.spec_params);
            t[i][r] = (bench_now() - t0) / calls * 1e9;
        }
    }
    FILE *csv = fopen(jacobian ? "build/bench/kernel_flags_jacobian.csv" : "build/bench/kernel_flags.csv", "w");
    const char *head = "scene,flags,ns_min,ns_median,ratio_min,same_bits\n";
    printf("%s", head);
    if (csv) fputs(head, csv);
    double base = 0.0;
    for (int i = 0; i < nk; i++) {
        call(ks[i], jacobian, ys, dy, &d.spec_params);
        if (i == 0) memcpy(dy0, dy, sizeof(double) * nout);
        const int same = memcmp(dy0, dy, sizeof(double) * nout) == 0;
        const double med = bench_median(t[i], ROUNDS), lo = t[i][0];   /* sorted by the median */
        if (i == 0) base = lo;
        char row[1024];
        snprintf(row, sizeof row, "%s,%s%s%s,%.1f,%.1f,%.3f,%d\n", scene, SWIM_KERNEL_CFLAGS, flags[i][0] ? " " : "",
                 flags[i], lo, med, base / lo, same);
        printf("%s", row);
        if (csv) fputs(row, csv);
    }
    if (csv) fclose(csv);
    swim_compiled_close(&sp);
    swim_dynamics_free(&d);
    swim_scene_free(&s);
    return 0;
}
