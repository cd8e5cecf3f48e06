/* model_setup.h -- a scene made ready to compute with, for the commands that integrate it in
 * process many times or with variational equations (swim floquet, swim optimize): the scene
 * read with its --set overrides and validated, its kernels obtained (runtime/codegen), the
 * magnitude check, and the dynamics on the scene kernel. The same stages as swim run's, in the
 * same order, so a scene refused by one is refused by the others with the same line. */
#ifndef SWIM_CONTROL_MODEL_SETUP_H
#define SWIM_CONTROL_MODEL_SETUP_H

#include "codegen/codegen.h"
#include "model/dynamics.h"
#include "scene/scene.h"

#define SWIM_SETUP_MAX_SETS 64

typedef struct {
    swim_scene s;
    swim_compiled kn, spz;     /* the kernel of N modes and the scene's right-hand side */
    swim_dynamics d;
    int loaded, dyn_ready;
} swim_model_setup;

/* 0; 2 with the cause in st (bad scene or override, numbers that overflow); 1 when no kernel
 * could be had or out of memory. swim_setup_load and swim_setup_kernels are its two stages, for a
 * command that judges the scene itself before any kernel is made. */
int swim_setup_open(swim_model_setup *m, const char *cmd, const char *path, const swim_override *sets,
                    int nsets, int generic, int quiet, swim_status *st);
int swim_setup_load(swim_model_setup *m, const char *path, const swim_override *sets, int nsets, swim_status *st);
int swim_setup_kernels(swim_model_setup *m, const char *cmd, int generic, int quiet, swim_status *st);
void swim_setup_close(swim_model_setup *m);

#endif
