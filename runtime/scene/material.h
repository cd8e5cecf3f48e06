/* material.h -- energy laws U(I1, J) of a scene's [elastic] energy (ERRATA B5): read and checked
 * before any work; the kernel computes W = int_D U dz (generator/swimgen/material.py).
 *
 * At z in the unit disk D, with h(z) = sum_{m=1}^N m c_-m conj(z)^(m-1) (ERRATA B2):
 *   I1 = tr(F F^T) = 2 (|c_1|^2 + |h|^2),  J = det F = |c_1|^2 - |h|^2,  I1bar = I1 / J   (2.4)
 */
#ifndef SWIM_SCENE_MATERIAL_H
#define SWIM_SCENE_MATERIAL_H

#include <stddef.h>

#include "scene/scene.h"

/* I1 and J of shape c (n = 2(N+1) coordinates) at z = r e^{i theta}. */
void swim_material_invariants(int n, const double *c, double r, double theta, double *I1, double *J);

/* Compiles s->energy_text into s->energy: the names I1, J, I1bar and the scene's [parameters];
 * refused (why, -1) when it uses t, a name it does not know, or step or abs (not twice
 * differentiable where they switch, and the Hessian of W is needed). 0 on success. */
int swim_material_compile(swim_scene *s, char *why, size_t n);

/* U at (I1, J) with the scene's current parameter values (the interpreter). */
double swim_material_eval(swim_scene *s, double I1, double J);

/* The law finite at every point of a polar grid of the closed disk (r = k/16, k = 0..16, and 64
 * angles) at shape c: W = int_D U dz then exists and the kernel can start. 0, or -1 with the
 * first point where it is not in why. */
int swim_material_check(swim_scene *s, const double *c, char *why, size_t n);

#endif
