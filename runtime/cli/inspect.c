/* swim inspect: the mass matrices of section 3.2, K and the Christoffel symbol at one shape. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cli/args.h"
#include "cli/commands.h"
#include "io/json.h"
#include "io/message.h"
#include "shape/shape.h"
#include "codegen/codegen.h"
#include "kernel/swim_kernel.h"
#include "scene/scene.h"

int swim_cmd_inspect(int argc, char **argv)
{
    swim_opt opts[] = {{"modes", 1, NULL}, {"shape", 1, NULL}, {"velocity", 1, NULL},
                       {"rho0", 1, NULL},  {"rhof", 1, NULL},  {"full", 0, NULL}};
    const int nopts = (int)(sizeof opts / sizeof opts[0]);
    if (swim_args_parse("inspect", argc, argv, 2, opts, nopts, NULL, 0, NULL)) return 2;
    const char *ms = swim_args_get(opts, nopts, "modes"), *ss = swim_args_get(opts, nopts, "shape");
    if (!ms || !ss) {
        swim_message(stderr, "swim inspect: --modes and --shape are required");
        return 2;
    }
    long N;
    if (swim_args_int("inspect", "modes", ms, 0, SWIM_KERNEL_MAX_MODES, &N)) return 2;
    const int n = 2 * ((int)N + 1);
    double x[2 * (SWIM_KERNEL_MAX_MODES + 1)], v[2 * (SWIM_KERNEL_MAX_MODES + 1)];
    int count;
    if (swim_args_list("inspect", "shape", ss, x, n, &count)) return 2;
    if (count != n) {
        swim_message(stderr, "swim inspect: --shape: N = %ld needs %d coordinates "
                "(a1,b1,a-1,b-1,...), got %d", N, n, count);
        return 2;
    }
    const char *vs = swim_args_get(opts, nopts, "velocity");
    if (vs) {
        if (swim_args_list("inspect", "velocity", vs, v, n, &count)) return 2;
        if (count != n) {
            swim_message(stderr, "swim inspect: --velocity: N = %ld needs %d components, got %d", N, n, count);
            return 2;
        }
    }
    double rho0 = 1.0, rhof = 1.0;
    const char *r0 = swim_args_get(opts, nopts, "rho0"), *rf = swim_args_get(opts, nopts, "rhof");
    if (r0 && swim_args_double("inspect", "rho0", r0, &rho0)) return 2;
    if (rf && swim_args_double("inspect", "rhof", rf, &rhof)) return 2;
    if (!(rho0 > 0.0) || !(rhof > 0.0)) {
        swim_message(stderr, "swim inspect: --%s: density must be > 0 (got %g)",
                rho0 > 0.0 ? "rhof" : "rho0", rho0 > 0.0 ? rhof : rho0);
        return 2;
    }
    double jmin = swim_shape_jmin((int)N, x);
    if (!(jmin > 0.0)) {
        swim_message(stderr, "swim inspect: --shape: %s is outside the admissible set D "
                "(min J = %.6g <= 0 on the unit circle, (4.1))", ss, jmin);
        return 2;
    }

    swim_compiled kc;   /* linked in, cached, or generated now (progress on stderr) */
    if (swim_codegen_kernel((int)N, &kc, 1) != 0) return 1;
    const swim_kernel *k = kc.kernel;
    /* Numbers that overflow would print as null: refuse them, naming the option that did it. */
    static const char *const culprit[] = {NULL, "shape", "rho0", "rhof", "velocity"};
    int over = swim_model_overflow(k, x, vs ? v : NULL, rho0, rhof);
    if (over != SWIM_INPUT_OK) {
        swim_message(stderr, "swim inspect: --%s: too large: the mass matrices, K or the Christoffel term "
                     "exceed %g at these values", culprit[over], SWIM_MAGNITUDE_MAX);
        swim_compiled_close(&kc);
        return 2;
    }
    int full = swim_args_get(opts, nopts, "full") != NULL;
    double *buf = calloc((size_t)(9 + 3 * n + 3 * n * n + (full ? n * n * n : 0) + n), sizeof(double));
    if (!buf) {
        swim_message(stderr, "swim inspect: out of memory");
        swim_compiled_close(&kc);
        return 1;
    }
    double *Mr = buf, *Nc = Mr + 9, *Md = Nc + 3 * n, *K = Md + n * n, *gvv = K + n * n;
    double *G = gvv + n;
    k->mass(x, rho0, rhof, Mr, Nc, Md);
    if (k->reduced(x, vs ? v : NULL, rho0, rhof, K, NULL, vs ? gvv : NULL) != 0 ||
        (full && k->reduced_deriv(x, rho0, rhof, NULL, G) != 0)) {
        swim_message(stderr, "swim inspect: Mr is not positive definite at this shape");
        free(buf);
        swim_compiled_close(&kc);
        return 1;
    }
    size_t count_out = (size_t)(9 + 3 * n + 2 * n * n + (vs ? n : 0));
    int finite = 1;
    for (size_t i = 0; i < count_out; i++) finite &= isfinite(buf[i]) != 0;
    for (size_t i = 0; full && i < (size_t)n * n * n; i++) finite &= isfinite(G[i]) != 0;
    if (!finite) {   /* within bounds but a derivative still overflowed */
        swim_message(stderr, "swim inspect: --shape: the results are not finite at this shape");
        free(buf);
        swim_compiled_close(&kc);
        return 2;
    }
    printf("{\n  \"modes\": %ld,\n  \"rho0\": ", N);
    swim_json_number(stdout, rho0);
    printf(",\n  \"rhof\": ");
    swim_json_number(stdout, rhof);
    printf(",\n  \"jmin\": ");
    swim_json_number(stdout, jmin);
    printf(",\n  \"mass_rigid\": ");
    swim_json_matrix(stdout, Mr, 3, 3, 4);
    printf(",\n  \"mass_coupling\": ");
    swim_json_matrix(stdout, Nc, 3, n, 4);
    printf(",\n  \"mass_shape\": ");
    swim_json_matrix(stdout, Md, n, n, 4);
    printf(",\n  \"mass_reduced\": ");
    swim_json_matrix(stdout, K, n, n, 4);
    if (vs) {
        printf(",\n  \"christoffel_vv\": ");
        swim_json_vector(stdout, gvv, n);
    }
    if (full) {
        printf(",\n  \"christoffel\": [");
        for (int i = 0; i < n; i++) {
            printf("%s\n    ", i ? "," : "");
            swim_json_matrix(stdout, G + (size_t)i * n * n, n, n, 6);
        }
        printf("]");
    }
    printf("\n}\n");
    free(buf);
    swim_compiled_close(&kc);
    return 0;
}
