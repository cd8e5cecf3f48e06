#include "scene/material.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

static const char *const invariant[3] = {"I1", "J", "I1bar"};

void swim_material_invariants(int n, const double *c, double r, double theta, double *I1, double *J)
{
    /* h = sum_m m c_-m conj(z)^(m-1), conj(z)^(m-1) = r^(m-1) e^{-i (m-1) theta} */
    double hr = 0.0, hi = 0.0;
    for (int m = 1; 2 * m + 1 < n; m++) {
        const double rho = m * pow(r, m - 1), ph = -(m - 1) * theta;
        const double er = rho * cos(ph), ei = rho * sin(ph), a = c[2 * m], b = c[2 * m + 1];
        hr += a * er - b * ei;
        hi += a * ei + b * er;
    }
    const double A = c[0] * c[0] + c[1] * c[1], H = hr * hr + hi * hi;
    *I1 = 2.0 * (A + H);
    *J = A - H;
}

/* The first word of `law` that is one of names[0..count), or NULL. */
static const char *uses_word(const char *law, const char *const *names, int count)
{
    for (const char *p = law; *p;) {
        if (!((*p >= 'a' && *p <= 'z') || (*p >= 'A' && *p <= 'Z'))) {
            /* a number's exponent (1e-3) or hex digits are not words */
            if (*p >= '0' && *p <= '9')
                while ((*p >= '0' && *p <= '9') || (*p >= 'a' && *p <= 'z') || (*p >= 'A' && *p <= 'Z') || *p == '.' ||
                       ((*p == '-' || *p == '+') && (p[-1] == 'e' || p[-1] == 'E' || p[-1] == 'p' || p[-1] == 'P')))
                    p++;
            else
                p++;
            continue;
        }
        const char *w = p;
        while ((*p >= 'a' && *p <= 'z') || (*p >= 'A' && *p <= 'Z') || (*p >= '0' && *p <= '9') || *p == '_') p++;
        for (int i = 0; i < count; i++)
            if ((size_t)(p - w) == strlen(names[i]) && strncmp(w, names[i], (size_t)(p - w)) == 0) return names[i];
    }
    return NULL;
}

int swim_material_compile(swim_scene *s, char *why, size_t n)
{
    static const char *const rough[] = {"step", "abs"}, *const time[] = {"t"};
    const char *w;
    for (int i = 0; i < s->nparams; i++)
        for (int k = 0; k < 3; k++)
            if (strcmp(s->param_names[i], invariant[k]) == 0) {
                snprintf(why, n, "the parameter %s has the name of an invariant of the law (I1, J, I1bar): rename it",
                         invariant[k]);
                return -1;
            }
    if (uses_word(s->energy_text, time, 1)) {
        snprintf(why, n, "an energy law is a function of I1, J, I1bar and [parameters], not of t");
        return -1;
    }
    if ((w = uses_word(s->energy_text, rough, 2))) {
        snprintf(why, n, "%s is not twice differentiable where it switches, and the run needs the Hessian of W", w);
        return -1;
    }
    const char *names[3 + SWIM_PARAMS_MAX];
    for (int k = 0; k < 3; k++) names[k] = invariant[k];
    for (int i = 0; i < s->nparams; i++) names[3 + i] = s->param_names[i];
    char err[160];
    s->energy = swim_expr_compile_params(s->energy_text, names, 3 + s->nparams, s->energy_vars, err, sizeof err);
    if (!s->energy) {
        /* the grammar's hint names t, which an energy law may not use: name what it may */
        char *hint = strstr(err, " (use t, pi, e");
        if (hint) snprintf(hint, sizeof err - (size_t)(hint - err), " (use I1, J, I1bar, pi, e%s a function such as log)",
                           s->nparams ? ", a name of [parameters]," : ",");
        snprintf(why, n, "%s", err);
        return -1;
    }
    return 0;
}

static void set_vars(swim_scene *s, double I1, double J)
{
    s->energy_vars[0] = I1;
    s->energy_vars[1] = J;
    s->energy_vars[2] = I1 / J;
    for (int i = 0; i < s->nparams; i++) s->energy_vars[3 + i] = s->param_values[i];
}

double swim_material_eval(swim_scene *s, double I1, double J)
{
    set_vars(s, I1, J);
    return swim_expr_eval(s->energy, 0.0);
}

int swim_material_check(swim_scene *s, const double *c, char *why, size_t n)
{
    for (int k = 0; k <= 16; k++)
        for (int l = 0; l < 64; l++) {
            const double r = k / 16.0, theta = 2.0 * M_PI * l / 64.0;
            double I1, J;
            char part[160];
            swim_material_invariants(s->n, c, r, theta, &I1, &J);
            set_vars(s, I1, J);
            if (!swim_expr_defined(s->energy, 0.0, part, sizeof part)) {
                snprintf(why, n, "not finite at c0: at z = %g e^{i %g} (I1 = %.6g, J = %.6g): %s", r, theta, I1, J,
                         part);
                return -1;
            }
        }
    return 0;
}
