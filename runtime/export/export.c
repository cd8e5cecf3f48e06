/* export.c -- swim export: one scene's self-contained source tree (export.h, docs/export.md). */
#include "export/export.h"

#include <dirent.h>
#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include "codegen/codegen.h"
#include "problem/problem.h"
#include "driver/run.h"
#include "io/files.h"
#include "io/message.h"
#include "io/version.h"
#include "ode/ode.h"
#include "scene/resolve.h"

/* The compiler and flags of the build that made this program (runtime/export/module.mk): the
 * tree is compiled with exactly these, which is what makes its results bit-identical. */
#ifndef SWIM_EXPORT_CC
#define SWIM_EXPORT_CC "cc"
#endif
#ifndef SWIM_EXPORT_CFLAGS
#define SWIM_EXPORT_CFLAGS "-O3 -march=native -g -std=c11 -D_XOPEN_SOURCE=700"
#endif
#ifndef SWIM_EXPORT_KERNEL_OPT
#define SWIM_EXPORT_KERNEL_OPT "-O3 -march=native"
#endif
/* The flags codegen.c compiles cached kernels with, after KERNEL_OPT (build_entry), and the
 * kernel of N modes' extra -O1 (SWIM_KERNEL_CFLAGS_N); barrier.c's own flags (shape/module.mk). */
#define KERNEL_FLAGS "-std=c11 -fPIC"
#define KERNEL_N_EXTRA "-O1"
#define BARRIER_FLAGS "-fcx-limited-range -fno-math-errno"
#define MARKER ".swim-export"

/* The runtime's C a run needs (output/job.h down), besides every header of these folders. */
static const char *const sources[] = {
    "runtime/cli/args.c", "runtime/cli/run_settings.c",   /* simulate reads swim run's options with swim run's code */
    "runtime/codegen/structure.c",
    "runtime/driver/columns.c", "runtime/driver/events.c", "runtime/driver/watch.c", "runtime/driver/kinds.c",
    "runtime/driver/run.c", "runtime/driver/stroke_run.c", "runtime/driver/summary.c", "runtime/driver/analyses.c",
    "runtime/io/json.c", "runtime/io/csv.c", "runtime/io/files.c", "runtime/io/message.c", "runtime/io/status.c",
    "runtime/io/clock.c", "runtime/io/stdout_check.c",
    "runtime/model/dynamics.c", "runtime/model/flow.c", "runtime/model/bounce.c", "runtime/model/sensitivity.c",
    "runtime/model/lyapunov.c",
    "runtime/ode/ode.c", "runtime/ode/events.c", "runtime/ode/abm.c", "runtime/ode/peers_gsl.c",
    "runtime/output/folder.c", "runtime/output/job.c", "runtime/problem/problem.c",
    "runtime/scene/toml.c", "runtime/scene/scene.c", "runtime/scene/keys.c", "runtime/scene/expr.c",
    "runtime/scene/resolve.c", "runtime/scene/material.c",
    "runtime/shape/shape.c", "runtime/shape/constraints.c", "runtime/shape/barrier.c",
    "runtime/stroke/stroke.c",
    "runtime/export/kernels.c",
};
static const char *const extra[] = {"runtime/ode/peers_cvode.c", "runtime/export/no_cvode.c"};
static const char *const header_dirs[] = {"cli", "codegen", "control", "driver", "io", "kernel", "model", "ode", "output",
                                          "problem", "scene", "shape", "stroke"};
/* headers of those folders that belong to what the tree leaves out */
static const char *const skip_headers[] = {"commands.h", "run_signals.h", "sweep_args.h", "summary_read.h", "floquet.h", "optimize.h", "periodic.h", "continuation.h"};

typedef struct {
    const swim_export_request *req;
    swim_export_result *res;
    const char *share;
    swim_status *st;   /* where a failure goes */
    char who[64];      /* "swim CMD", its lines' start */
} ctx;

static int fail_write(const ctx *c, const char *path)
{
    swim_status_fail(c->st, c->who, NULL, 0, NULL, "--out: cannot write '%s': %s", path, strerror(errno));
    return 1;
}

static int counted(const ctx *c, const char *path)
{
    struct stat st;
    if (stat(path, &st) != 0) return fail_write(c, path);
    c->res->files++;
    c->res->bytes += st.st_size;
    return 0;
}

/* src (absolute) to DIR/rel, its folders made. */
static int copy_to(const ctx *c, const char *src, const char *rel)
{
    char *dst = swim_path_join(c->req->out, rel);
    if (!dst) return fail_write(c, rel);
    char *slash = strrchr(dst, '/');
    *slash = '\0';
    int rc = swim_mkdirs(dst) != 0;
    *slash = '/';
    if (!rc && swim_copy_file(src, dst) != 0) {
        swim_status_fail(c->st, c->who, NULL, 0, NULL, "cannot copy '%s' to '%s': %s", src, dst, strerror(errno));
        free(dst);
        return 1;
    }
    rc = rc ? fail_write(c, dst) : counted(c, dst);
    free(dst);
    return rc;
}

static int copy_share(const ctx *c, const char *rel, const char *dst_rel)
{
    char *src = swim_path_join(c->share, rel);
    const int rc = src ? copy_to(c, src, dst_rel ? dst_rel : rel) : 1;
    free(src);
    return rc;
}

static int write_text(const ctx *c, const char *rel, const char *text)
{
    char *dst = swim_path_join(c->req->out, rel);
    int rc = !dst || swim_replace_file(dst, text, strlen(text)) != 0 ? fail_write(c, dst ? dst : rel) : counted(c, dst);
    free(dst);
    return rc;
}

/* A C string literal of s (octal escapes for what is not printable ASCII). */
static void c_string(FILE *f, const char *s)
{
    fputc('"', f);
    for (const unsigned char *p = (const unsigned char *)s; *p; p++) {
        if (*p == '"' || *p == '\\') fprintf(f, "\\%c", *p);
        else if (*p < 32 || *p >= 127 || *p == '?') fprintf(f, "\\%03o", *p);
        else fputc(*p, f);
    }
    fputc('"', f);
}

static int headers(const ctx *c)
{
    for (size_t d = 0; d < sizeof header_dirs / sizeof header_dirs[0]; d++) {
        char rel[256];
        snprintf(rel, sizeof rel, "runtime/%s", header_dirs[d]);
        char *dir = swim_path_join(c->share, rel);
        DIR *h = dir ? opendir(dir) : NULL;
        if (!h) {
            swim_status_fail(c->st, c->who, NULL, 0, NULL, "cannot read the runtime's headers in '%s': %s", dir ? dir : rel,
                         strerror(errno));
            free(dir);
            return 1;
        }
        struct dirent *e;
        int rc = 0;
        while (!rc && (e = readdir(h))) {
            const size_t n = strlen(e->d_name);
            if (n < 3 || strcmp(e->d_name + n - 2, ".h") != 0) continue;
            int skip = 0;
            for (size_t k = 0; k < sizeof skip_headers / sizeof skip_headers[0]; k++) skip |= !strcmp(e->d_name, skip_headers[k]);
            if (skip) continue;
            char file[512];
            snprintf(file, sizeof file, "%s/%s", rel, e->d_name);
            rc = copy_share(c, file, NULL);
        }
        closedir(h);
        free(dir);
        if (rc) return rc;
    }
    return 0;
}

/* generate.py --modes N --out DIR/kernels: the committed file's bytes, for a share without
 * generated/. 0 or 1 after one line. */
static int run_generator(const ctx *c, int modes)
{
    char gen[4200], out[4200], n[16];
    snprintf(gen, sizeof gen, "%s/generator/generate.py", c->share);
    snprintf(out, sizeof out, "%s/kernels", c->req->out);
    snprintf(n, sizeof n, "%d", modes);
    const pid_t pid = fork();
    if (pid == 0) {
        execlp(swim_python(), swim_python(), gen, "--modes", n, "--out", out, "--quiet", (char *)NULL);
        _exit(127);
    }
    int status = 0;
    while (pid > 0 && waitpid(pid, &status, 0) < 0 && errno == EINTR) {}
    if (pid < 0 || !WIFEXITED(status) || WEXITSTATUS(status) != 0) {
        swim_status_fail(c->st, c->who, NULL, 0, NULL, "generating the kernel of N = %d into '%s' failed (%s %s)", modes, out,
                     swim_python(), gen);
        return 1;
    }
    snprintf(out, sizeof out, "%s/kernels/swim_kernel_n%d.c", c->req->out, modes);
    return counted(c, out);
}

/* The kernel of N modes' C: generated/ (linked into bin/swim), its cache entry, or the generator. */
static int kernel_n_source(const ctx *c, const swim_compiled *kn, int modes)
{
    char rel[128], dst[128];
    snprintf(rel, sizeof rel, "generated/swim_kernel_n%d.c", modes);
    snprintf(dst, sizeof dst, "kernels/swim_kernel_n%d.c", modes);
    if (kn->dir[0]) {
        snprintf(c->res->kernel_source, sizeof c->res->kernel_source, "cache");
        return copy_to(c, kn->source, dst);
    }
    char *src = swim_path_join(c->share, rel);
    const int there = src && access(src, R_OK) == 0;
    free(src);
    snprintf(c->res->kernel_source, sizeof c->res->kernel_source, there ? "generated/" : "generator");
    return there ? copy_share(c, rel, dst) : run_generator(c, modes);
}

static char *info_text(const swim_scene *s, const swim_compiled *sys, int stroke)
{
    char *text = NULL;
    size_t len;
    FILE *f = open_memstream(&text, &len);
    if (!f) return NULL;
    fprintf(f, "/* export_info.h -- written by swim export (swim %s): what this tree was exported for. */\n", SWIM_VERSION);
    fprintf(f, "#ifndef SWIM_EXPORT_INFO_H\n#define SWIM_EXPORT_INFO_H\n\n");
    fprintf(f, "/* the scene as named to swim export (summary.json's \"scene\", the default out/NAME) */\n");
    fprintf(f, "#define SWIM_EXPORT_SCENE_NAME ");
    c_string(f, s->path);
    fprintf(f, "\n#define SWIM_EXPORT_MODES %d\n#define SWIM_EXPORT_STROKE %d\n", s->modes, stroke);
    fprintf(f, "/* the cache entry its scene kernel came from (summary.json: kernel.cache, provenance.kernel_key) */\n");
    fprintf(f, "#define SWIM_EXPORT_SYSTEM_DIR ");
    c_string(f, sys->dir);
    fprintf(f, "\n\n#endif\n");
    fclose(f);
    return text;
}

/* Make's text of a value: a '$' doubled. */
static void make_value(FILE *f, const char *s)
{
    for (; *s; s++) {
        if (*s == '$') fputc('$', f);
        if (*s != '\n') fputc(*s, f);
    }
}

static char *makefile_text(const swim_scene *s, const swim_compiled *kn, int cvode)
{
    char *text = NULL;
    size_t len;
    FILE *f = open_memstream(&text, &len);
    if (!f) return NULL;
    fprintf(f, "# swim export tree (swim %s) of ", SWIM_VERSION);
    make_value(f, s->path);
    fprintf(f, ": `make` builds ./simulate (README).\n"
               "# The compiler and flags are those of the build of bin/swim that exported it: the same\n"
               "# flags give the same machine code, hence the results of `swim run` to the last digit.\n"
               "CC         = ");
    make_value(f, SWIM_EXPORT_CC);
    fprintf(f, "\n# OPT -g -std=c11 ... of that build (Makefile: CFLAGS)\nCFLAGS     = ");
    make_value(f, SWIM_EXPORT_CFLAGS);
    fprintf(f, "\n# the flags codegen compiles cached kernels with (Makefile: KERNEL_OPT), then " KERNEL_FLAGS "\nKERNEL_OPT = ");
    make_value(f, SWIM_EXPORT_KERNEL_OPT);
    fprintf(f, "\nCPPFLAGS   = -I. -Iruntime -DSWIM_VERSION='\"%s\"'\n", SWIM_VERSION);
    fprintf(f, "# SUNDIALS (CVODE): %s. CVODE = no builds without it; a run then\n"
               "# fails where it would switch to a CVODE integrator (the stiff fallback), and is identical otherwise.\n"
               "CVODE      = %s\n", cvode ? "the scene's integrator or its stiff fallback is a CVODE one" :
               "not used by this scene", cvode ? "yes" : "no");
    /* jansson: summary.json is built as one JSON object (driver/summary.h) */
    fprintf(f, "LDLIBS     = -lgsl -llapacke -llapack -lblas -ljansson -lquadmath -ldl -lm\n\nSRCS := simulate.c");
    for (size_t i = 0; i < sizeof sources / sizeof sources[0]; i++) fprintf(f, " \\\n        %s", sources[i]);
    fprintf(f, "\nifeq ($(CVODE),yes)\nSRCS     += %s\nCPPFLAGS += -I/usr/include/sundials\n"
               "LDLIBS   := -lsundials_cvode -lsundials_nvecserial $(LDLIBS)\nelse\nSRCS     += %s\nendif\n",
            extra[0], extra[1]);
    if (!cvode) fprintf(f, "\n");
    else fprintf(f, "ifneq ($(CVODE),yes)\n$(info CVODE = no: a run that switches to a CVODE integrator fails)\nendif\n\n");
    fprintf(f, "# the kernel of N = %d modes (%s) and the %s\n", s->modes,
            kn->dir[0] ? "from the kernel cache: compiled as codegen compiles it" : "linked into bin/swim: compiled as the runtime",
            s->stroke_count > 0 ? "stroke's laws" : "scene's right-hand side");
    fprintf(f, "KERNEL_N := build/kernels/swim_kernel_n%d.o\nSYSTEM   := build/kernels/system.o\n"
               "OBJS     := $(SRCS:%%.c=build/%%.o) $(KERNEL_N) $(SYSTEM)\n\n"
               ".PHONY: all clean\nall: simulate\n\n"
               "simulate: $(OBJS)\n\t$(CC) $(CFLAGS) $(OBJS) -o $@ $(LDLIBS)\n\n"
               "build/%%.o: %%.c export_info.h\n\t@mkdir -p $(dir $@)\n\t$(CC) $(CPPFLAGS) $(CFLAGS) -c $< -o $@\n\n"
               "build/runtime/shape/barrier.o: CFLAGS += " BARRIER_FLAGS "\n\n"
               "$(SYSTEM): kernels/system.c\n\t@mkdir -p $(dir $@)\n\t$(CC) $(KERNEL_OPT) " KERNEL_FLAGS " -Iruntime -c $< -o $@\n\n", s->modes);
    if (kn->dir[0])
        fprintf(f, "$(KERNEL_N): kernels/swim_kernel_n%d.c\n\t@mkdir -p $(dir $@)\n\t$(CC) $(KERNEL_OPT) " KERNEL_N_EXTRA " "
                   KERNEL_FLAGS " -Iruntime -c $< -o $@\n\n", s->modes);
    fprintf(f, "clean:\n\trm -rf build simulate\n");
    fclose(f);
    return text;
}

/* The README's description of the outputs: trajectory.csv's columns for this scene (the run
 * driver's own list, swim_run_columns), summary.json's fields, and how events are added. */
static void readme_outputs(FILE *f, const swim_scene *s)
{
    const char *names[SWIM_RUN_MAX_COLUMNS];
    static char storage[SWIM_RUN_MAX_COLUMNS][24];
    const int n = swim_run_columns(s, names, storage);
    fprintf(f, "\nOUT/trajectory.csv: one row per output step (run.output_step, or --output-step), %d columns:\n", n);
    int w = 0;   /* the current line's width: lines of at most ~96 characters */
    for (int i = 0; i < n; i++) {
        const int len = (int)strlen(names[i]) + 1;
        if (w && w + len + 1 > 96) {
            fputc('\n', f);
            w = 0;
        }
        fprintf(f, "%s%s%s", w ? " " : "  ", names[i], i + 1 < n ? "," : "\n");
        w += len + (w ? 1 : 2);
    }
    fprintf(f,
        "  t: time; x, y, theta: the body frame's position and angle; then the %d shape coordinates (a1, b1, am1, bm1, ...:\n"
        "  the boundary's Fourier coefficients) and their rates (d...); kinetic_fluid, kinetic_shape,\n"
        "  kinetic_rigid, potential, energy: the energy's parts and total; impulse_*: the impulses of the body,\n"
        "  of the fluid from the rigid motion and from the deformation (fixed frame; x, y, angular; they sum\n"
        "  to zero); res_volume, res_volume_rate, res_angular, res_locks: the\n"
        "  constraints' residuals; jmin: the smallest Jacobian of the map on the boundary (> 0: not\n"
        "  self-intersecting); work: the work done on the shape; w1, w2: the elastic and the barrier parts of\n"
        "  the potential%s.\n"
        "  Numbers are the shortest text that reads back to the same double; nan where undefined.\n",
        s->n, s->stroke_count > 0 ? "; power, work_positive, phase_c1: the stroke's power, its positive work and phase" : "");
    fprintf(f,
        "\nOUT/summary.json, the fields: scene, title, out; modes, rho0, rhof, integrator, rtol, atol,\n"
        "  step_lookahead, free, effects (elastic, barrier, damping, forcing), kernel, projection: what ran;\n"
        "  status (completed / failed / interrupted), reason, t_end, t_reached, rows: how it ended;\n"
        "  final_state (t, x, y, theta, c, cdot); energy_initial, energy_drift_abs, energy_drift_rel,\n"
        "  forcing_work, max_residuals, jmin, jmin_t, left_D_t: checks; integrator_switch_t, stiff_switch,\n"
        "  step_checks, origin_shift, impacts, energy_control: what the driver did on the way; events,\n"
        "  event_stop, periodic: the events found (and the period of a periodic column); provenance (the\n"
        "  command line, versions, the scene as given) and stats (steps, RHS evaluations, timings).\n"
        "  A field that does not apply is null; numbers as in the CSV.\n");
    fprintf(f,
        "\nEvents: ./simulate --event COLUMN:KIND[:stop] (repeatable), as `swim run --event`: COLUMN is any\n"
        "  column of trajectory.csv but t, KIND is zero, min or max, :stop ends the run at the first one.\n"
        "  Or put them into scene.toml for every run, without rebuilding:\n"
        "      [events]\n"
        "      list = [\"am1:max\", \"y:zero\"]\n"
        "  The times and values go into OUT/events.csv (t, column, kind, value) and into summary.json's\n"
        "  events (a column's period, when it is periodic).\n");
}

static char *readme_text(const swim_scene *s, int cvode)
{
    char *text = NULL;
    size_t len = 0;
    FILE *f = open_memstream(&text, &len);
    if (!f) return NULL;
    fprintf(f,
        "This folder was made by `swim export %s` (swim %s): the scene, the C of its kernels and the\n"
        "part of swim's runtime that runs it, as one program. Nothing else is needed: no Python, no\n"
        "SymPy, no kernel cache.\n\n"
        "Build:  make            (a C compiler, GNU make, GSL, LAPACK/LAPACKE/BLAS%s)\n"
        "Run:    ./simulate [--out OUT] [--t-end T] [--output-step H] [--rtol R] [--atol A]\n"
        "                   [--event COLUMN:KIND[:stop] ...] [--set KEY=VALUE ...] [--quiet]\n\n"
        "simulate runs scene.toml (next to it) into OUT (default out/<scene name>): OUT/trajectory.csv,\n"
        "OUT/summary.json, OUT/scene.toml (the scene as run), and OUT/events.csv when the scene has\n"
        "events, exactly as `swim run %s --out OUT` with the same options: row for row and digit for\n"
        "digit, since the Makefile compiles the same sources with the compiler and flags of the build\n"
        "that exported it (-march=native: build and run it on the same kind of machine). summary.json\n"
        "differs in provenance.command and in the timings (stats.*_seconds, ns_per_rhs, max_rss_kb,\n"
        "step_checks.seconds). The options are read by swim run's own code: each but --event and --set\n"
        "once. --set changes run-time values (initial data, R, D, densities, ...);\n"
        "one that changes the kernel's structure (frees or locks a coordinate, zeroes a stiffness,\n"
        "changes the forcing law) is refused: export the scene again. Bad input: one line, exit 2.\n"
        "A run that fails, or a report that cannot be written (a full disk or stdout): exit 1.\n",
        s->path, SWIM_VERSION, cvode ? ", SUNDIALS CVODE" : "", s->path);
    readme_outputs(f, s);
    if (fclose(f) != 0) {
        free(text);
        return NULL;
    }
    return text;
}

/* DIR: made, or empty, or an earlier export (its marker). 0 or 2 after one line. */
static int check_out(const ctx *c)
{
    const char *out = c->req->out;
    DIR *d = opendir(out);
    if (!d) {
        if (errno == ENOENT && swim_mkdirs(out) == 0) return 0;
        swim_status_fail(c->st, c->who, NULL, 0, NULL, "--out: cannot make the folder '%s': %s", out,
                     errno == ENOENT ? "a parent cannot be made" : strerror(errno));
        return 2;
    }
    struct dirent *e;
    int other = 0, marked = 0;
    while ((e = readdir(d))) {
        if (!strcmp(e->d_name, ".") || !strcmp(e->d_name, "..")) continue;
        if (!strcmp(e->d_name, MARKER)) marked = 1;
        else other = 1;
    }
    closedir(d);
    if (other && !marked) {
        swim_status_fail(c->st, c->who, NULL, 0, NULL, "--out: '%s' is not empty and not an earlier export (no %s in it): "
                         "give a new folder", out, MARKER);
        return 2;
    }
    return 0;
}

static int scene_text(const ctx *c, char **text)
{
    size_t len = 0, outlen = 0;
    char *orig = swim_read_file(c->req->scene_file, SWIM_SCENE_MAX_BYTES, &len), why[512];
    if (!orig) {
        swim_status_fail(c->st, "swim", c->req->scene_file, 0, NULL, "%s: cannot read: %s", c->req->scene_file,
                         strerror(errno));
        return 2;
    }
    if (c->req->nsets == 0) {
        *text = orig;
        return 0;
    }
    const int rc = swim_scene_resolve(orig, len, c->req->scene_file, c->req->sets, c->req->nsets, text, &outlen, why, sizeof why);
    free(orig);
    if (rc != 0) {
        swim_status_fail(c->st, c->who, NULL, 0, NULL, "%s: cannot write the overrides into scene.toml: %s",
                         c->req->scene_file, why);
        return 2;
    }
    return 0;
}

static int write_tree(const ctx *c, const swim_scene *s, const swim_compiled *kn, const swim_compiled *sys)
{
    /* the marker first: a tree left partial by a failure (a full disk) is an earlier export to
     * the retry, which replaces it, not a foreign folder it refuses; "incomplete" until the end */
    char *text = NULL, *marker = swim_path_join(c->req->out, MARKER);
    static const char incomplete[] = "swim export (incomplete: export again)\n";
    int rc = !marker || swim_replace_file(marker, incomplete, sizeof incomplete - 1) != 0 ? fail_write(c, MARKER) : 0;
    free(marker);
    if (!rc) rc = scene_text(c, &text);
    if (!rc) rc = write_text(c, "scene.toml", text);
    free(text);
    for (size_t i = 0; !rc && i < sizeof sources / sizeof sources[0]; i++) rc = copy_share(c, sources[i], NULL);
    for (size_t i = 0; !rc && i < sizeof extra / sizeof extra[0]; i++) rc = copy_share(c, extra[i], NULL);
    if (!rc) rc = headers(c);
    if (!rc) rc = copy_share(c, "runtime/export/simulate.c", "simulate.c");
    if (!rc) rc = kernel_n_source(c, kn, s->modes);
    if (!rc) rc = copy_to(c, sys->source, "kernels/system.c");
    char *t[3] = {info_text(s, sys, s->stroke_count > 0), makefile_text(s, kn, c->res->cvode), readme_text(s, c->res->cvode)};
    static const char *const names[3] = {"export_info.h", "Makefile", "README"};
    for (int i = 0; i < 3; i++) {
        if (!rc && !t[i]) {
            swim_status_fail(c->st, c->who, NULL, 0, NULL, "out of memory");
            rc = 1;
        }
        if (!rc) rc = write_text(c, names[i], t[i]);
        free(t[i]);
    }
    if (!rc) rc = write_text(c, MARKER, "swim export\n");
    return rc;
}

static int is_cvode(const char *integrator) { return (swim_ode_capabilities(integrator) & SWIM_ODE_CAP_SUNDIALS) != 0; }

int swim_export(const swim_export_request *req, swim_export_result *res, swim_status *st)
{
    memset(res, 0, sizeof *res);
    ctx c = {req, res, NULL, st, ""};
    snprintf(c.who, sizeof c.who, "swim %s", req->cmd);
    swim_problem *P = calloc(1, sizeof *P);
    if (!P) {
        swim_status_fail(st, c.who, NULL, 0, NULL, "out of memory");
        return 1;
    }
    const swim_problem_source src = {.path = req->scene_file, .sets = req->sets, .nsets = req->nsets};
    if (swim_problem_read(P, &src, st)) {
        swim_problem_close(P);
        free(P);
        return 2;
    }
    const swim_scene *s = P->s;
    res->stroke = s->stroke_count > 0;
    res->modes = s->modes;
    /* peers_cvode.c is the only user of SUNDIALS; a stroke runs its own integrator without fallback */
    res->cvode = is_cvode(s->run.integrator) || (!res->stroke && s->run.stiff_fallback[0] && is_cvode(s->run.stiff_fallback));
    char probe[4200];
    int rc = 0;
    if (!(c.share = swim_share_dir(st))) rc = 1;
    else {
        snprintf(probe, sizeof probe, "%s/runtime/driver/run.c", c.share);
        if (access(probe, R_OK) != 0) {
            swim_status_fail(c.st, c.who, NULL, 0, NULL, "the runtime's C sources are not in '%s' (an installed swim has "
                             "only the kernel headers): export with bin/swim of a source tree", c.share);
            rc = 1;
        }
    }
    if (!rc) rc = check_out(&c);
    if (!rc) rc = swim_problem_kernels(P, req->cmd, 0, req->verbose, st);
    const swim_compiled *kn = &P->kn, *sys = &P->spz;
    /* the tree copies the scene kernel's source from its cache entry: checked before any of it
     * is written */
    if (!rc && !sys->dir[0]) {
        swim_status_fail(c.st, c.who, NULL, 0, NULL, "%s: the scene kernel was built in a private folder, now removed (the "
                         "cache is not usable): set SWIM_CACHE to a folder of your own", s->path);
        rc = 1;
    }
    if (!rc) rc = write_tree(&c, s, kn, sys);
    swim_problem_close(P);
    free(P);
    return rc;
}
