/* kinds.c -- the run's contract (driver/run.h) over its kind: the kind is chosen once, when the
 * run opens, and every call goes to its table (swim_run_kind). */
#include "driver/run.h"

#include <math.h>
#include <stdlib.h>

struct swim_run {
    const swim_run_kind *kind;
    void *state;
    swim_run_request req;
};

const swim_run_kind *swim_run_kind_for(const swim_scene *s)
{
    return s->stroke_count > 0 ? &swim_run_stroke_kind : &swim_run_scene_kind;
}

int swim_run_columns(const swim_scene *s, const char **names, char storage[][24])
{
    return swim_run_kind_for(s)->columns(s, names, storage);
}

int swim_run_open(const swim_run_request *req, swim_run **out, swim_status *st)
{
    *out = NULL;
    swim_run *run = calloc(1, sizeof *run);
    if (!run) {
        swim_status_fail(st, NULL, NULL, 0, NULL, "out of memory");
        return 1;
    }
    run->kind = swim_run_kind_for(req->scene);
    run->req = *req;
    if (!run->req.settings) run->req.settings = &req->scene->run;   /* as read, checked by the reader */
    const int rc = run->kind->open(&run->req, &run->state, st);
    if (rc) {
        free(run);
        return rc;
    }
    *out = run;
    return 0;
}

int swim_run_integrate(swim_run *run) { return swim_run_advance(run, INFINITY); }

int swim_run_advance(swim_run *run, double t) { return run->kind->advance(run->state, t); }

void swim_run_fail(swim_run *run, const char *reason) { run->kind->fail(run->state, reason); }

const swim_run_result *swim_run_get_result(const swim_run *run) { return run->kind->result(run->state); }

const swim_run_request *swim_run_get_request(const swim_run *run) { return &run->req; }

int swim_run_kind_summary(const swim_run *run, struct json_t *summary)
{
    return run->kind->summary ? run->kind->summary(run->state, summary) : 0;
}

int swim_run_state_at(swim_run *run, double t, double *state, double *t_from, double *t_to)
{
    return run->kind->state_at ? run->kind->state_at(run->state, t, state, t_from, t_to) : -1;
}

swim_dynamics *swim_run_dynamics(swim_run *run) { return run->kind->dynamics(run->state); }

int swim_run_set_variational(swim_run *run, const swim_run_variational *v, swim_status *st)
{
    if (!run->kind->set_variational) {
        swim_status_fail(st, NULL, NULL, 0, NULL, "variational equations: a prescribed stroke has none");
        return 2;
    }
    return run->kind->set_variational(run->state, v, st);
}

const swim_run_var_result *swim_run_get_var_result(swim_run *run)
{
    static const swim_run_var_result none;   /* nothing carried (immutable) */
    return run->kind->var_result ? run->kind->var_result(run->state) : &none;
}

void swim_run_free(swim_run *run)
{
    if (!run) return;
    run->kind->free(run->state);
    free(run);
}
