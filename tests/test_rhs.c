/* The generated right-hand side (runtime/codegen -> runtime/kernel/scene_rhs.h around SymPy's
 * expressions, driven through model/dynamics.c as `swim run` drives it) against the independent
 * loop reference tests/reference/ref_rhs.c (exact Christoffel symbol, saddle-point solve, no
 * shared code), on random states, for N = 0..7, 12, 20 and 32 (SWIM_TEST_RHS_MODES overrides
 * the list), each structure kind (all four up to N = 12, see main for 20 and 32):
 *   - specialized, every effect on (W1, W2, damping, a forcing law using the whole expression
 *     language), locked coordinates both at 0 (folded) and at a non-zero value;
 *   - specialized, every effect off;
 *   - generic (every coordinate carried, locks by multipliers, every effect present), with the
 *     scene's effects on and off.
 * Relative difference max|dy - dy_ref| / max|dy_ref| <= 1e-12. Kernels come from the cache
 * ($SWIM_CACHE; `make test` keeps it in build/cache), generated on the first run. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "codegen/codegen.h"
#include "io/message.h"
#include "model/dynamics.h"
#include "reference/ref_rhs.h"
#include "shape/shape.h"

#define NMAX (2 * (SWIM_KERNEL_MAX_MODES + 1))

static double urand(void) { return 2.0 * rand() / (double)RAND_MAX - 1.0; }

/* The law given to the generator as text, and the same function written in C. */
static const char *const LAW = "0.3*sin(2*t)^2 - step(t - 0.5)*atan(t)/pi + 2^-1*exp(-t) + abs(cos(t))^1.5";
static double law_c(double t)
{
    return 0.3 * pow(sin(2 * t), 2) - (t - 0.5 >= 0 ? 1.0 : 0.0) * atan(t) / M_PI + 0.5 * exp(-t)
         + pow(fabs(cos(t)), 1.5);
}

/* A random shape well inside D: sum_m m |c_-m| <= spread |c_1|. Coordinates with keep[i] == 0
 * keep the value they have. */
static void random_shape(int N, double *x, const int *keep, double spread)
{
    double c1 = 1.0 + 0.2 * urand(), ang = 3.0 * urand(), w[SWIM_KERNEL_MAX_MODES + 1], tot = 0.0;
    if (keep[0]) x[0] = c1 * cos(ang);
    if (keep[1]) x[1] = c1 * sin(ang);
    c1 = hypot(x[0], x[1]);
    for (int m = 1; m <= N; m++) {
        w[m] = (0.2 + fabs(urand())) / m;
        tot += m * w[m];
    }
    for (int m = 1; m <= N; m++) {
        double r = spread * c1 * w[m] / tot, a = 3.14159 * urand();
        if (keep[2 * m]) x[2 * m] = r * cos(a);
        if (keep[2 * m + 1]) x[2 * m + 1] = r * sin(a);
    }
}

typedef struct {
    const char *name;
    int generic, effects;
} kind;

static void compare(int N, const kind *kd, int trials)
{
    static swim_scene s;
    memset(&s, 0, sizeof s);
    const int n = 2 * (N + 1);
    s.path = swim_strprintf("test_rhs N=%d %s", N, kd->name);   /* owned: swim_scene_free */
    if (!s.path) abort();
    s.modes = N;
    s.n = n;
    s.rho0 = 0.7 + 0.6 * fabs(urand());
    s.rhof = 0.8 + 0.4 * fabs(urand());
    /* locks: a1 and b1 free; from N >= 2 one coordinate locked at 0 and one at a value */
    for (int i = 0; i < n; i++) s.free_mask[i] = 1;
    int ones[NMAX];
    for (int i = 0; i < NMAX; i++) ones[i] = 1;
    random_shape(N, s.c0, ones, 0.3);
    if (N >= 2) {
        s.free_mask[n - 1] = 0;
        s.c0[n - 1] = 0.0;               /* folded away in a specialized kernel */
        s.free_mask[3] = 0;              /* b_-1 locked at its (non-zero) value */
    }
    if (kd->effects) {
        s.elastic = 1;
        s.barrier = 1;
        s.damped = 1;
        s.forced = 1;
        s.epsilon = 0.03;
        s.alpha = 0.5;
        if (!(s.forcing_text = swim_strprintf("%s", LAW))) abort();
        for (int i = 0; i < n; i++) {
            s.stiffness[i] = i % 3 ? 0.5 + fabs(urand()) : 0.0;
            s.reference[i] = 0.1 * urand();
            s.damping[i] = i % 2 ? 0.2 * fabs(urand()) : 0.0;
            s.direction[i] = i % 4 == 1 ? urand() : 0.0;
        }
        s.direction[n - 2] = 0.7;
    }
    swim_compiled sc;
    if (swim_codegen_scene(&s, kd->generic, &sc, 0, NULL) != 0) {
        CHECK(0, "N=%d %s: no kernel", N, kd->name);
        swim_scene_free(&s);
        return;
    }
    swim_dynamics d;
    if (swim_dynamics_init(&d, &s, NULL) != 0) abort();
    swim_dynamics_use_scene_kernel(&d, sc.scene, kd->generic);
    ref_scene rs = {N, s.rho0, s.rhof, s.free_mask, kd->effects ? s.stiffness : NULL, s.reference,
                    kd->effects ? 2048 : 0, s.epsilon, s.alpha,
                    kd->effects ? s.damping : NULL, kd->effects ? law_c : NULL, s.direction};
    const int dim = 3 + 2 * n + 1, sdim = swim_dynamics_state_dim(&d);
    double y[3 + 2 * NMAX + 1], ys[3 + 2 * NMAX + 1], dys[3 + 2 * NMAX + 1];
    double dy[3 + 2 * NMAX + 1], dyr[3 + 2 * NMAX + 1];
    double worst = 0.0;
    for (int trial = 0; trial < trials; trial++) {
        int keep[NMAX] = {0};
        for (int i = 0; i < n; i++) keep[i] = s.free_mask[i];
        memcpy(y + 3, s.c0, sizeof(double) * n);
        random_shape(N, y + 3, keep, 0.4);
        for (int i = 0; i < n; i++) y[3 + n + i] = s.free_mask[i] ? urand() : 0.0;
        y[0] = urand();
        y[1] = urand();
        y[2] = 3.0 * urand();
        y[3 + 2 * n] = urand();
        const double t = 2.0 * fabs(urand());
        swim_dynamics_pack(&d, y, ys);
        int rc = swim_dynamics_rhs(t, ys, dys, &d);
        /* unpack puts c0 in locked slots: the derivative of a locked coordinate is 0 */
        swim_dynamics_unpack(&d, dys, dy);
        if (!kd->generic)
            for (int i = 0; i < n; i++)
                if (!s.free_mask[i]) dy[3 + i] = 0.0;
        int rr = ref_rhs(&rs, t, y, dyr);
        CHECK(rc == 0 && rr == 0, "N=%d %s: rhs status %d, reference %d", N, kd->name, rc, rr);
        double diff = 0.0, scale = 0.0;
        for (int i = 0; i < dim; i++) {
            diff = fmax(diff, fabs(dy[i] - dyr[i]));
            scale = fmax(scale, fabs(dyr[i]));
        }
        worst = fmax(worst, diff / scale);
    }
    CHECK(worst <= 1e-12, "N=%d %s: generated RHS vs loop reference, relative %.3g", N, kd->name, worst);
    printf("  N = %2d  %-30s state %3d  max relative difference %.2e\n", N, kd->name, sdim, worst);
    swim_dynamics_free(&d);
    swim_compiled_close(&sc);
    swim_scene_free(&s);
}

int main(void)
{
    srand(2024);
    int modes[64], count = 0;
    const char *env = getenv("SWIM_TEST_RHS_MODES");
    if (env && *env) {
        for (char *p = (char *)env, *end; *p && count < 64; p = end) {
            long v = strtol(p, &end, 10);
            if (end == p) break;
            modes[count++] = (int)v;
            while (*end == ' ' || *end == ',') end++;
        }
    } else {
        /* Built with AddressSanitizer, which checks the runtime's memory use (the same code at every
         * N), the list stops at N = 12: the reference's loops at N = 20 and 32 took a minute there.
         * The plain build checks every N. */
#if defined(__SANITIZE_ADDRESS__)
        static const int def[] = {0, 1, 2, 3, 4, 5, 6, 7, 12};
#else
        static const int def[] = {0, 1, 2, 3, 4, 5, 6, 7, 12, 20, 32};
#endif
        count = (int)(sizeof def / sizeof def[0]);
        memcpy(modes, def, sizeof def);
    }
    static const kind kinds[] = {{"specialized, every effect", 0, 1},
                                 {"specialized, no effect", 0, 0},
                                 {"generic, scene with effects", 1, 1},
                                 {"generic, scene without effects", 1, 0}};
    /* N = 20 and 32 take minutes of generation and compilation on an empty cache: the kinds that
     * share nothing with the smaller N (N = 20: specialized and generic with effects; N = 32:
     * specialized with every effect); every kind is covered at N = 0..7 and 12. */
    for (int c = 0; c < count; c++)
        for (int k = 0; k < 4; k++) {
            if ((modes[c] >= 20 && (k == 1 || k == 3)) || (modes[c] >= 32 && k == 2)) continue;
            compare(modes[c], &kinds[k], modes[c] >= 20 ? 2 : 5);
        }
    return check_report("test_rhs");
}
