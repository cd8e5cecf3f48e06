#include "cli/run_settings.h"

#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "io/files.h"
#include "io/message.h"
#include "ode/ode.h"
#include "scene/keys.h"

/* A number option: parsed into *dst; *given says whether it was on the command line. */
static int number_option(const swim_opt *opts, int nopts, const char *name, double *dst, int *given)
{
    const char *v = swim_args_get(opts, nopts, name);
    *given = v != NULL;
    return v ? swim_args_double("run", name, v, dst) : 0;
}

/* The options of the plain keys (scene/keys.h): each parsed and bounded as its row says. 0 or 2. */
static int plain_options(const swim_opt *opts, int nopts, swim_scene *s)
{
    int count;
    const swim_scene_key *keys = swim_scene_keys(&count);
    for (int i = 0; i < count; i++) {
        const swim_scene_key *k = &keys[i];
        const char *v = k->option && (k->flags & SWIM_KEY_PLAIN) ? swim_args_get(opts, nopts, k->option) : NULL;
        if (!v) continue;
        void *field = (char *)s + k->offset;
        long p;
        double x;
        int found = -1;
        switch (k->kind) {
        case SWIM_KEY_INTEGER:
            if (swim_args_int("run", k->option, v, (long)k->lo, (long)k->hi, &p)) return 2;
            *(int *)field = (int)p;
            break;
        case SWIM_KEY_NUMBER:
            if (swim_args_double("run", k->option, v, &x)) return 2;
            if (!(x >= k->lo && x < k->hi)) {
                swim_message(stderr, "swim run: --%s: must be %s, got '%s'", k->option, k->expect, v);
                return 2;
            }
            *(double *)field = x;
            break;
        case SWIM_KEY_BOOL:
        case SWIM_KEY_CHOICE: {
            static const char *const tf[] = {"false", "true", NULL};
            const char *const *words = k->kind == SWIM_KEY_BOOL ? tf : k->words;
            for (int j = 0; words[j]; j++)
                if (strcmp(v, words[j]) == 0) found = j;
            if (found < 0) {
                swim_message(stderr, "swim run: --%s: expected %s, got '%s'", k->option, k->expect, v);
                return 2;
            }
            *(int *)field = found;
            break;
        }
        default:
            break;
        }
    }
    return 0;
}

int swim_run_settings_options(const swim_opt *opts, int nopts, swim_scene *s)
{
    swim_run_overrides cli = {{0}};
    if (number_option(opts, nopts, "t-end", &s->run.t_end, &cli.given[SWIM_SET_T_END]) ||
        number_option(opts, nopts, "output-step", &s->run.output_step, &cli.given[SWIM_SET_OUTPUT_STEP]) ||
        number_option(opts, nopts, "rtol", &s->run.rtol, &cli.given[SWIM_SET_RTOL]) ||
        number_option(opts, nopts, "atol", &s->run.atol, &cli.given[SWIM_SET_ATOL]))
        return 2;
    const char *v;
    if ((v = swim_args_get(opts, nopts, "integrator"))) {
        if (!swim_ode_method_known(v)) {
            swim_message(stderr, "swim run: --integrator: unknown integrator '%s' (%s)", v, swim_ode_method_list());
            return 2;
        }
        snprintf(s->run.integrator, sizeof s->run.integrator, "%s", v);   /* a known name: it fits */
    }
    if (plain_options(opts, nopts, s)) return 2;
    swim_status st = SWIM_STATUS_STDERR;
    return swim_status_shown(&st, swim_run_settings_check(s, &cli, &st)) ? 2 : 0;
}

int swim_run_settings_record(const swim_opt *opts, int nopts, const swim_scene *s, swim_override *out)
{
    static const char *const numeric[][2] = {{"t-end", "run.t_end"}, {"output-step", "run.output_step"},
                                             {"rtol", "run.rtol"}, {"atol", "run.atol"}};
    const double values[] = {s->run.t_end, s->run.output_step, s->run.rtol, s->run.atol};
    char text[160];
    int n = 0;
    for (int i = 0; i < 4; i++)
        if (swim_args_get(opts, nopts, numeric[i][0])) {
            snprintf(text, sizeof text, "%s=%.17g", numeric[i][1], values[i]);
            if (swim_override_parse(text, &out[n], NULL, 0) == 0) n++;
        }
    if (swim_args_get(opts, nopts, "integrator")) {
        snprintf(text, sizeof text, "run.integrator=%s", s->run.integrator);
        if (swim_override_parse(text, &out[n], NULL, 0) == 0) n++;
    }
    int count;
    const swim_scene_key *keys = swim_scene_keys(&count);
    for (int i = 0; i < count; i++) {   /* the plain keys' options, as their rows spell the value */
        const swim_scene_key *k = &keys[i];
        if (!k->option || !(k->flags & SWIM_KEY_PLAIN) || !swim_args_get(opts, nopts, k->option)) continue;
        const void *field = (const char *)s + k->offset;
        if (k->kind == SWIM_KEY_NUMBER) snprintf(text, sizeof text, "run.%s=%.17g", k->key, *(const double *)field);
        else if (k->kind == SWIM_KEY_BOOL) snprintf(text, sizeof text, "run.%s=%s", k->key, *(const int *)field ? "true" : "false");
        else if (k->kind == SWIM_KEY_CHOICE) snprintf(text, sizeof text, "run.%s=%s", k->key, k->words[*(const int *)field]);
        else snprintf(text, sizeof text, "run.%s=%d", k->key, *(const int *)field);
        if (swim_override_parse(text, &out[n], NULL, 0) == 0) n++;
    }
    if (swim_args_get(opts, nopts, "no-projection") && swim_override_parse("run.projection=false", &out[n], NULL, 0) == 0) n++;
    return n;
}

void swim_run_settings_key_options(swim_opt *opts, int *nopts, int cap)
{
    static char help[8][320];   /* the command line's, for --help: its row's documentation */
    int count, made = 0;
    const swim_scene_key *keys = swim_scene_keys(&count);
    for (int i = 0; i < count && *nopts < cap; i++)
        if (keys[i].option && (keys[i].flags & SWIM_KEY_PLAIN)) {
            const swim_scene_key *k = &keys[i];
            char dflt[64] = "";
            if (k->kind == SWIM_KEY_INTEGER && k->dflt < 0) snprintf(dflt, sizeof dflt, "; default: the integrator's own");
            else if (k->kind == SWIM_KEY_INTEGER || k->kind == SWIM_KEY_NUMBER) snprintf(dflt, sizeof dflt, "; default %g", k->dflt);
            if (made < 8) snprintf(help[made], sizeof help[made], "%s (run.%s: %s%s)", k->doc, k->key, k->expect, dflt);
            opts[(*nopts)++] = (swim_opt){k->option, 1, NULL, "VALUE", made < 8 ? help[made] : k->doc};
            made++;
        }
}

const char *swim_run_settings_integrator_help(void)
{
    static char help[512];
    snprintf(help, sizeof help, "the integrator, one of %s (default: the scene's run.integrator, else abm; "
             "docs/integrators-and-events.md compares them)", swim_ode_method_list());
    return help;
}
