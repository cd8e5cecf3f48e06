#include "cli/run_settings.h"

#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "io/files.h"
#include "io/message.h"
#include "ode/ode.h"
#include "scene/resolve.h"

/* A number option: parsed into *dst; *given says whether it was on the command line. */
static int number_option(const swim_opt *opts, int nopts, const char *name, double *dst, int *given)
{
    const char *v = swim_args_get(opts, nopts, name);
    *given = v != NULL;
    return v ? swim_args_double("run", name, v, dst) : 0;
}

int swim_run_settings_options(const swim_opt *opts, int nopts, swim_scene *s)
{
    swim_run_overrides cli = {{0}};
    if (number_option(opts, nopts, "t-end", &s->t_end, &cli.given[SWIM_SET_T_END]) ||
        number_option(opts, nopts, "output-step", &s->output_step, &cli.given[SWIM_SET_OUTPUT_STEP]) ||
        number_option(opts, nopts, "rtol", &s->rtol, &cli.given[SWIM_SET_RTOL]) ||
        number_option(opts, nopts, "atol", &s->atol, &cli.given[SWIM_SET_ATOL]))
        return 2;
    const char *v;
    if ((v = swim_args_get(opts, nopts, "integrator"))) {
        if (!swim_ode_method_known(v)) {
            swim_message(stderr, "swim run: --integrator: unknown integrator '%s' (%s)", v, swim_ode_method_list());
            return 2;
        }
        snprintf(s->integrator, sizeof s->integrator, "%s", v);   /* a known name: it fits */
    }
    if ((v = swim_args_get(opts, nopts, "step-lookahead"))) {
        long p;
        if (swim_args_int("run", "step-lookahead", v, 0, 12, &p)) return 2;
        s->step_lookahead = (int)p;
    }
    return swim_run_settings_check(s, &cli) != 0 ? 2 : 0;
}

int swim_run_settings_record(const swim_opt *opts, int nopts, const swim_scene *s, swim_override *out)
{
    static const char *const numeric[][2] = {{"t-end", "run.t_end"}, {"output-step", "run.output_step"},
                                             {"rtol", "run.rtol"}, {"atol", "run.atol"}};
    const double values[] = {s->t_end, s->output_step, s->rtol, s->atol};
    char text[160];
    int n = 0;
    for (int i = 0; i < 4; i++)
        if (swim_args_get(opts, nopts, numeric[i][0])) {
            snprintf(text, sizeof text, "%s=%.17g", numeric[i][1], values[i]);
            if (swim_override_parse(text, &out[n], NULL, 0) == 0) n++;
        }
    if (swim_args_get(opts, nopts, "integrator")) {
        snprintf(text, sizeof text, "run.integrator=%s", s->integrator);
        if (swim_override_parse(text, &out[n], NULL, 0) == 0) n++;
    }
    if (swim_args_get(opts, nopts, "step-lookahead")) {
        snprintf(text, sizeof text, "run.step_lookahead=%d", s->step_lookahead);
        if (swim_override_parse(text, &out[n], NULL, 0) == 0) n++;
    }
    if (swim_args_get(opts, nopts, "no-projection") && swim_override_parse("run.projection=false", &out[n], NULL, 0) == 0) n++;
    return n;
}
