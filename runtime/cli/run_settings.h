/* run_settings.h -- the run-setting options of `swim run`, for dynamic scenes and prescribed
 * strokes alike: --t-end, --output-step, --rtol, --atol, --integrator, --step-lookahead.
 */
#ifndef SWIM_CLI_RUN_SETTINGS_H
#define SWIM_CLI_RUN_SETTINGS_H

#include "cli/args.h"
#include "scene/scene.h"

/* The run's settings resolved: the loaded scene's [run] (s->run, which stays as read) with the
 * options given over it (the plain keys' options from their rows, scene/keys.h; --no-projection),
 * into *set, checked once (swim_run_settings_check: its bounds name the option when it came from
 * the command line). 0, or 2 after one line on stderr (an unparsable number, an unknown
 * integrator, a bound). */
int swim_run_settings_options(const swim_opt *opts, int nopts, const swim_scene *s, swim_run_settings *set);

/* The options of the scene keys that have one (scene/keys.h) besides those above, for a command's
 * option list: appended to opts[*nopts ..] (room for cap in all). */
void swim_run_settings_key_options(swim_opt *opts, int *nopts, int cap);
/* --integrator's help: the names of the registry (ode/ode.h), the default. */
const char *swim_run_settings_integrator_help(void);

/* The overrides that write into DIR/scene.toml what the options given resolved in set (--t-end,
 * --output-step, --rtol, --atol, --integrator, --no-projection and every plain key's option),
 * into out (room for SWIM_RUN_SETTINGS_MAX). Their count. */
#define SWIM_RUN_SETTINGS_MAX 32
int swim_run_settings_record(const swim_opt *opts, int nopts, const swim_run_settings *set, swim_override *out);

#endif
