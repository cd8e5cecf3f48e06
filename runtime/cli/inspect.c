/* swim inspect: the mass matrices of section 3.2, K and the Christoffel symbol at one shape. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cli/args.h"
#include "codegen/codegen.h"
#include "cli/commands.h"
#include "io/json.h"
#include "io/message.h"
#include "kernel/swim_kernel.h"
#include "lib/swim.h"
#include "cli/report.h"

/* W_law and grad W_law of the energy law `law` (--param values) at shape x: the scene kernel of a
 * scene with every coordinate free and that law (kernel/swim_kernel.h, material), so the numbers
 * are the ones a run uses. 0, 2 after one line for bad input, 1 otherwise. */
static int inspect_energy(long N, const double *x, double rho0, double rhof, const char *law,
                          const char *const *params, int nparams, double *W, double *grad, double *hess)
{
    const int n = 2 * ((int)N + 1);
    if (strpbrk(law, "\"\\\n")) {
        swim_message(stderr, "swim inspect: --energy: \"%s\": a law has no quotes, backslashes or line breaks", law);
        return 2;
    }
    char *text = NULL;
    size_t len = 0;
    FILE *f = open_memstream(&text, &len);
    if (!f) return 1;
    fprintf(f, "[model]\nmodes = %ld\nrho0 = %.17g\nrhof = %.17g\n[shape]\nc0 = [", N, rho0, rhof);
    for (int i = 0; i < n; i++) fprintf(f, "%s%.17g", i ? ", " : "", x[i]);
    fprintf(f, "]\ndc0 = [");
    for (int i = 0; i < n; i++) fprintf(f, "%s0", i ? ", " : "");
    fprintf(f, "]\nfree = \"all\"\n[elastic]\nenergy = \"%s\"\n[parameters]\n", law);
    for (int i = 0; i < nparams; i++) {
        const char *eq = strchr(params[i], '=');
        double v;
        if (!eq || eq == params[i] || strcspn(params[i], " \t\"[]#") < (size_t)(eq - params[i])) {
            swim_message(stderr, "swim inspect: --param: expected NAME=VALUE, got \"%s\"", params[i]);
            fclose(f);
            free(text);
            return 2;
        }
        if (swim_args_double("inspect", "param", eq + 1, &v)) {
            fclose(f);
            free(text);
            return 2;
        }
        fprintf(f, "%.*s = %.17g\n", (int)(eq - params[i]), params[i], v);
    }
    fprintf(f, "[run]\nt_end = 1\noutput_step = 1\n");
    fclose(f);
    swim_scene s;
    swim_status st = SWIM_STATUS_STDERR;
    int rc = swim_scene_parse(text, len, "swim inspect --energy", &s, &st);
    free(text);
    if (swim_status_shown(&st, rc)) return 2;
    swim_compiled sys;
    memset(&sys, 0, sizeof sys);
    rc = 1;
    if (swim_codegen_scene(&s, 0, &sys, 0, &st) != 0 || !sys.scene->material) {
        swim_status_print(&st, stderr);
        swim_message(stderr, "swim inspect: --energy: no kernel for \"%s\"", law);
    } else {
        swim_scene_params p;
        memset(&p, 0, sizeof p);
        p.rho0 = rho0;
        p.rhof = rhof;
        p.x_locked = s.c0;
        p.law_params = s.param_values;
        if (sys.scene->material(x, &p, W, grad, hess) != 0)
            swim_message(stderr, "swim inspect: --energy: \"%s\" is not finite at this shape", law);
        else
            rc = 0;
    }
    swim_compiled_close(&sys);
    swim_scene_free(&s);
    return rc;
}

int swim_cmd_inspect(int argc, char **argv)
{
    const char *params[32];
    const int nparams = swim_args_take_all("inspect", &argc, argv, 2, "param", params, 32);
    if (nparams < 0) return 2;
    swim_opt opts[] = {
        {"modes", 1, NULL, "N", "the number of modes N, 0..32 (required)"},
        {"shape", 1, NULL, "a1,b1,a-1,b-1,...", "the shape c: 2(N + 1) coordinates, inside the admissible set D (required)"},
        {"velocity", 1, NULL, "V1,V2,...", "a shape velocity (2(N + 1) components): also Gamma(c)(v, v)"},
        {"rho0", 1, NULL, "RHO", "the body's density, > 0 (default 1)"},
        {"rhof", 1, NULL, "RHO", "the fluid's density, > 0 (default 1)"},
        {"full", 0, NULL, NULL, "also the whole Christoffel symbol Gamma^i_jk (n^3 numbers)"},
        {"energy", 1, NULL, "LAW", "an energy law U(I1, J) (docs/materials.md): also W_law = int_D U dz and its gradient"},
        {"param", 2, NULL, "NAME=VALUE", "a parameter of --energy's law (repeatable)"}};
    const int nopts = (int)(sizeof opts / sizeof opts[0]);
    const int prc = swim_args_parse("inspect", argc, argv, 2, opts, nopts, NULL, 0, NULL);
    if (prc) return prc;
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
    const int full = swim_args_get(opts, nopts, "full") != NULL;
    double *buf = calloc((size_t)(9 + 3 * n + 2 * n * n + n + (full ? n * n * n : 0)), sizeof(double));
    if (!buf) {
        swim_message(stderr, "swim inspect: out of memory");
        return 1;
    }
    swim_inspection in = SWIM_INSPECTION_INIT;
    in.mass_rigid = buf;
    in.mass_coupling = buf + 9;
    in.mass_shape = buf + 9 + 3 * n;
    in.mass_reduced = buf + 9 + 3 * n + n * n;
    if (vs) in.christoffel_vv = in.mass_reduced + n * n;
    if (full) in.christoffel = in.mass_reduced + n * n + n;
    swim_error e = SWIM_ERROR_INIT;
    const int rc = swim_inspect((int)N, x, vs ? v : NULL, rho0, rhof, &in, &e);
    if (rc != SWIM_OK) {   /* the library names the argument at fault; here it is an option */
        if (e.key[0]) swim_message(stderr, "swim inspect: --%s: %s", e.key, e.message);
        else swim_message(stderr, "swim inspect: %s", e.message);
        free(buf);
        return rc == SWIM_EINPUT ? 2 : 1;
    }
    const char *law = swim_args_get(opts, nopts, "energy");
    double Wl = 0.0, gl[2 * (SWIM_KERNEL_MAX_MODES + 1)], *hl = NULL;
    if (!law && nparams > 0) {
        swim_message(stderr, "swim inspect: --param: only with --energy");
        free(buf);
        return 2;
    }
    if (law) {
        hl = malloc(sizeof(double) * (size_t)(n * n));
        const int erc = hl ? inspect_energy(N, x, rho0, rhof, law, params, nparams, &Wl, gl, hl) : 1;
        if (erc) {
            free(hl);
            free(buf);
            return erc;
        }
    }
    const double *Mr = in.mass_rigid, *Nc = in.mass_coupling, *Md = in.mass_shape, *K = in.mass_reduced;
    const double *gvv = in.christoffel_vv, *G = in.christoffel, jmin = in.jmin;
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
    if (law) {
        printf(",\n  \"W_law\": ");
        swim_json_number(stdout, Wl);
        printf(",\n  \"grad_W_law\": ");
        swim_json_vector(stdout, gl, n);
        printf(",\n  \"hess_W_law\": ");
        swim_json_matrix(stdout, hl, n, n, 4);
    }
    printf("\n}\n");
    free(hl);
    free(buf);
    return 0;
}
