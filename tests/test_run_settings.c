/* The run settings of their own (scene/settings.h):
 *   - a job's adjustment resolves its settings from the scene's [run] without writing the scene:
 *     the scene keeps what its file says, the job's settings and the run (its summary, its
 *     result) have the command's values;
 *   - the one mapping to the integrator's options puts the drift control on only where the
 *     settings ask for it and the integrator can do it;
 *   - the check reads the settings it is given, not the scene's, and names the option when the
 *     value came from the command line. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "check.h"
#include "driver/run.h"
#include "io/files.h"
#include "model/dynamics.h"
#include "output/job.h"

#define SCENE "models/example3.toml"   /* [run] rtol = 1e-10, projection on (the default) */

/* A command's options over the scene's [run]: a looser rtol, no projection. */
static int adjust(const swim_scene *s, swim_run_settings *set, swim_override *recorded, int *nrecorded, void *ctx,
                  swim_status *st)
{
    (void)recorded;
    (void)ctx;
    *nrecorded = 0;
    set->rtol = 1e-7;
    set->projection = 0;
    swim_run_overrides cli = {{0}};
    cli.given[SWIM_SET_RTOL] = 1;
    return swim_run_settings_check(s, set, &cli, st) != 0 ? 2 : 0;
}

static void job_resolves_without_writing_the_scene(void)
{
    char dir[] = "/tmp/swim_test_run_settings_XXXXXX";
    CHECK(mkdtemp(dir) != NULL, "a folder for the run");
    char out[sizeof dir + 8];
    snprintf(out, sizeof out, "%s/out", dir);
    swim_override set;
    char err[256];
    CHECK(swim_override_parse("run.t_end=0.5", &set, err, sizeof err) == 0, "override: %s", err);
    const swim_run_job req = {.cmd = "run", .scene_file = SCENE, .sets = &set, .nsets = 1, .adjust = adjust,
                              .out = out, .quiet = 1, .summary_only = 1};
    swim_status st = {0};
    swim_job *j = NULL;
    int rc = swim_job_open(&req, &j, &st);
    CHECK(rc == 0 && j, "the job opens: %d", rc);
    if (!j) return;
    const swim_scene *s = swim_job_scene(j);
    const swim_run_settings *r = swim_job_settings(j);
    CHECK(s->run.rtol == 1e-10 && s->run.projection == 1 && s->run.t_end == 0.5,
          "the scene's [run] as read: rtol %g, projection %d, t_end %g", s->run.rtol, s->run.projection, s->run.t_end);
    CHECK(r->rtol == 1e-7 && r->projection == 0 && r->t_end == 0.5 && r->atol == s->run.atol,
          "the resolved settings: rtol %g, projection %d, t_end %g", r->rtol, r->projection, r->t_end);
    rc = swim_job_run(j, &st);
    const swim_run_result *res = swim_job_result(j);
    CHECK(rc == 0 && res->t_reached == 0.5, "the run reaches t_end: %d at %g", rc, res->t_reached);
    CHECK(res->projection == 0 && res->projection_steps == 0, "the run projects nothing: %d, %ld steps",
          res->projection, res->projection_steps);
    CHECK(s->run.rtol == 1e-10 && s->run.projection == 1, "the scene untouched by the run");
    char path[sizeof out + 32];
    snprintf(path, sizeof path, "%s/summary.json", out);
    size_t len = 0;
    char *text = swim_read_file(path, 1 << 20, &len);
    CHECK(text && strstr(text, "\"rtol\": 1e-07,"), "summary.json has the resolved rtol");
    free(text);
    swim_job_free(j);
    remove(path);
    rmdir(out);
    rmdir(dir);
}

static void one_mapping(void)
{
    swim_scene s;
    swim_status st = {0};
    if (swim_scene_load(SCENE, &s, &st) != 0) {
        CHECK(0, "%s loads", SCENE);
        return;
    }
    swim_run_settings set = s.run;
    swim_ode_options o;
    swim_run_ode_options_projected(&set, &o);
    CHECK(o.project == swim_dynamics_project && o.rtol == 1e-10 && o.atol == 1e-12, "abm, projection on: projected");
    set.projection = 0;
    swim_run_ode_options_projected(&set, &o);
    CHECK(o.project == NULL, "projection off: not projected");
    set.projection = 1;
    snprintf(set.integrator, sizeof set.integrator, "rk8pd");
    swim_run_ode_options_projected(&set, &o);
    CHECK(o.project == NULL, "an integrator that cannot project: not projected");
    swim_run_ode_options(&s.run, &o);
    CHECK(o.project == NULL && o.rtol == 1e-10, "the mapping of an augmented state: never projected");

    /* the check reads the settings it is given */
    set = s.run;
    set.rtol = 10;
    swim_run_overrides cli = {{0}};
    cli.given[SWIM_SET_RTOL] = 1;
    swim_status bad = {0};
    char msg[512];
    CHECK(swim_run_settings_check(&s, &set, &cli, &bad) == 2 && strstr(swim_status_message(&bad, msg, sizeof msg), "--rtol"),
          "rtol 10 from the command line refused naming the option: %s", msg);
    CHECK(swim_run_settings_check(&s, &s.run, NULL, &st) == 0, "the scene's own [run] passes");
    swim_scene_free(&s);
}

int main(void)
{
    job_resolves_without_writing_the_scene();
    one_mapping();
    return check_report("test_run_settings");
}
