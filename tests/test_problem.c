/* A problem built once (runtime/problem/problem.h):
 *   - opened from a file, it keeps the text: a value set after the file is gone is set, with the
 *     kernels and the dynamics' kernel the ones it had (no kernel looked up again) and the scene
 *     what a scene read with that override holds;
 *   - a structure key (model.modes), a value that changes the kernel's structure (a stiffness
 *     item made zero) and a bad value (rho0 = -1) are refused with a status naming the key, the
 *     problem as it was;
 *   - with SWIM_PROBLEM_RESOLVE the text with the overrides written in follows the values set;
 *   - a [parameters] value set in place is what the scene's compiled forcing law reads, and the
 *     law is the one compiled when the problem was opened. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "check.h"
#include "io/files.h"
#include "problem/problem.h"
#include "scene/expr.h"

#define SCENE "models/example3.toml"

static int refused(swim_problem *p, const char *key, const char *value, const char *words)
{
    swim_status st = {0};
    const int rc = swim_problem_set(p, key, value, &st);
    char msg[1024];
    swim_status_message(&st, msg, sizeof msg);
    CHECK(rc == 2 && strcmp(st.key, key) == 0 && strstr(msg, words), "%s=%s refused: %d key '%s' (%s)", key, value,
          rc, st.key, msg);
    return rc;
}

int main(void)
{
    char path[] = "/tmp/swim_test_problem_XXXXXX";
    const int fd = mkstemp(path);
    size_t len = 0;
    char *text = swim_read_file(SCENE, 1 << 20, &len);
    CHECK(fd >= 0 && text && write(fd, text, len) == (ssize_t)len, "a copy of " SCENE);
    if (fd >= 0) close(fd);

    swim_problem *p = calloc(1, sizeof *p);
    swim_status st = {0};
    const swim_problem_source src = {.path = path, .flags = SWIM_PROBLEM_RESOLVE};
    int rc = swim_problem_open(p, &src, "test", 0, 0, &st);
    CHECK(rc == 0 && p->kernels && p->dyn_ready, "opened: %d", rc);
    unlink(path);   /* from now on the file cannot be read again */
    const swim_kernel *kn = p->kn.kernel;
    const swim_scene_kernel *sk = p->spz.scene;

    rc = swim_problem_set(p, "model.rho0", "2", &st);
    CHECK(rc == 0 && p->s->rho0 == 2.0, "model.rho0 set to 2 with the file gone: %d, rho0 %g", rc, p->s->rho0);
    CHECK(p->kn.kernel == kn && p->spz.scene == sk && p->d.k == kn && p->d.scene == p->s,
          "the same kernels, the dynamics on the problem's scene");
    CHECK(p->resolved && strstr(p->resolved, "rho0 = 2"), "the text with the value written in");

    /* the scene set in place is the scene read with the override */
    swim_override ov;
    char why[200];
    swim_scene ref;
    swim_override_parse("model.rho0=2", &ov, why, sizeof why);
    CHECK(swim_scene_parse_with(text, len, path, &ov, 1, &ref, &st) == 0, "the scene read with --set model.rho0=2");
    CHECK(ref.rho0 == p->s->rho0 && ref.rhof == p->s->rhof && memcmp(ref.c0, p->s->c0, sizeof ref.c0) == 0 &&
          memcmp(ref.dc0, p->s->dc0, sizeof ref.dc0) == 0 && ref.run.t_end == p->s->run.t_end, "the same values");
    swim_scene_free(&ref);

    refused(p, "model.modes", "3", "structure key");
    refused(p, "elastic.stiffness.am1", "0", "changes the kernel's structure");
    refused(p, "model.rho0", "-1", "--set model.rho0=-1");
    refused(p, "model.rho0", "abc(", "--set");
    CHECK(p->s->rho0 == 2.0 && p->kn.kernel == kn && p->spz.scene == sk && p->nsets == 1,
          "after the refusals, the problem as it was (rho0 %g, %d overrides)", p->s->rho0, p->nsets);

    /* the same key again replaces its override */
    rc = swim_problem_set(p, "model.rho0", "1.5", &st);
    CHECK(rc == 0 && p->s->rho0 == 1.5 && p->nsets == 1, "set again: %d, rho0 %g, %d overrides", rc, p->s->rho0,
          p->nsets);
    rc = swim_problem_set(p, "run.rtol", "1e-9", &st);
    CHECK(rc == 0 && p->s->run.rtol == 1e-9 && p->nsets == 2, "a run setting: %d", rc);
    swim_problem_close(p);

    /* a parameter: the law compiled at the opening reads the value set */
    const swim_problem_source law = {.path = "models/control/selfpropelled_params.toml"};
    rc = swim_problem_open(p, &law, "test", 0, 0, &st);
    CHECK(rc == 0 && p->s->forcing, "a scene with [parameters] and a forcing law: %d", rc);
    if (rc == 0) {
        const swim_expr *f = p->s->forcing;
        const double before = swim_expr_eval(f, 1.3);
        rc = swim_problem_set(p, "parameters.A", "3", &st);
        const double after = swim_expr_eval(p->s->forcing, 1.3);
        swim_scene ref;
        swim_override_parse("parameters.A=3", &ov, why, sizeof why);
        const int rrc = swim_scene_load_with(law.path, &ov, 1, &ref, &st);
        CHECK(rc == 0 && p->s->forcing == f && after != before && rrc == 0 && after == swim_expr_eval(ref.forcing, 1.3),
              "parameters.A = 3 in place: f(1.3) %.17g, read with the override %.17g (before %.17g)", after,
              rrc == 0 ? swim_expr_eval(ref.forcing, 1.3) : NAN, before);
        if (rrc == 0) swim_scene_free(&ref);
    }
    swim_problem_close(p);
    free(p);
    free(text);
    return check_report("test_problem");
}
