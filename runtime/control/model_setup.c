#include "control/model_setup.h"

#include <string.h>

#include <stdio.h>

#include "io/status.h"

int swim_setup_open(swim_model_setup *m, const char *cmd, const char *path, const swim_override *sets,
                    int nsets, int generic, int quiet, swim_status *st)
{
    int rc = swim_setup_load(m, path, sets, nsets, st);
    return rc ? rc : swim_setup_kernels(m, cmd, generic, quiet, st);
}

int swim_setup_load(swim_model_setup *m, const char *path, const swim_override *sets, int nsets, swim_status *st)
{
    memset(m, 0, sizeof *m);
    if (swim_scene_load_with(path, sets, nsets, &m->s, st)) return 2;
    m->loaded = 1;
    return 0;
}

int swim_setup_kernels(swim_model_setup *m, const char *cmd, int generic, int quiet, swim_status *st)
{
    const char *path = m->s.path;
    char who[64];
    snprintf(who, sizeof who, "swim %s", cmd);
    /* a prescribed stroke has no scene kernel: the caller builds its stroke kernel */
    if (swim_codegen_kernel(m->s.modes, &m->kn, quiet ? 0 : 1, st) != 0 ||
        (!m->s.stroke && swim_codegen_scene(&m->s, generic, &m->spz, quiet ? 0 : 1, st) != 0)) {
        swim_status_fail(st, who, path, 0, NULL, "%s: no kernel for this scene, nothing computed", path);
        return 1;
    }
    if (swim_scene_check_model(&m->s, m->kn.kernel, st)) return 2;
    if (swim_dynamics_init(&m->d, &m->s, m->kn.kernel) != 0) {
        swim_status_fail(st, who, NULL, 0, NULL, "out of memory");
        return 1;
    }
    m->dyn_ready = 1;
    if (!m->s.stroke) swim_dynamics_use_scene_kernel(&m->d, m->spz.scene, generic);
    return 0;
}

void swim_setup_close(swim_model_setup *m)
{
    if (m->dyn_ready) swim_dynamics_free(&m->d);
    swim_compiled_close(&m->spz);
    swim_compiled_close(&m->kn);
    if (m->loaded) swim_scene_free(&m->s);
    m->dyn_ready = m->loaded = 0;
}
