#include "scene/keys.h"

#include <float.h>
#include <math.h>
#include <stddef.h>
#include <string.h>

#include "scene/scene.h"

#define F(field) offsetof(swim_scene, field)
#define NONE SWIM_KEY_NONE
#define PLAIN SWIM_KEY_PLAIN
#define RT SWIM_KEY_RUNTIME
#define INIT SWIM_KEY_INITIAL
#define STRUCT SWIM_KEY_STRUCTURE
#define REQ SWIM_KEY_REQUIRED

/* "*" as a key: any name (a parameter, a stroke law's coordinate). */
static const swim_scene_key keys[] = {
    {"", "title", SWIM_KEY_TEXT, NONE, 0, 0, 0, {NULL}, NULL, NULL, 0, "shown in the summary and on the plots"},
    {"model", "modes", SWIM_KEY_INTEGER, F(modes), 0, SWIM_KERNEL_MAX_MODES, 0, {NULL}, NULL, NULL, REQ | STRUCT,
     "N, the number of modes c_-1 ... c_-N"},
    {"model", "rho0", SWIM_KEY_NUMBER, F(rho0), 0, INFINITY, 0, {NULL}, NULL, NULL, REQ | RT,
     "body density rho0 in the reference configuration (2.3)"},
    {"model", "rhof", SWIM_KEY_NUMBER, F(rhof), 0, INFINITY, 0, {NULL}, NULL, NULL, REQ | RT,
     "fluid density rho_f, or \"neutral\" for rho0 / mu^2 (2.10)"},
    {"shape", "c0", SWIM_KEY_VECTOR, F(c0), 0, 0, 0, {NULL}, NULL, NULL, REQ | RT | INIT,
     "initial shape c(0), in D (4.1); a locked coordinate keeps its value, which the equations read"},
    {"shape", "dc0", SWIM_KEY_VECTOR, F(dc0), 0, 0, 0, {NULL}, NULL, NULL, REQ | INIT,
     "initial velocity, on G1 (2.8), G2 (2.14) and the locks"},
    {"shape", "free", SWIM_KEY_TEXT, NONE, 0, 0, 0, {NULL}, NULL, NULL, REQ | STRUCT,
     "the coordinates that move (\"all\" or names); the others are locked (4.2.2)"},
    {"elastic", "stiffness", SWIM_KEY_VECTOR, F(stiffness), 0, 0, 0, {NULL}, NULL, NULL, RT | STRUCT,
     "diagonal of the rigidity R (its zeros are the kernel's structure)"},
    {"elastic", "reference", SWIM_KEY_VECTOR, F(reference), 0, 0, 0, {NULL}, NULL, NULL, RT,
     "c_ref of W1 = 1/2 (c - c_ref)^T R (c - c_ref) (ERRATA E2)"},
    {"elastic", "energy", SWIM_KEY_TEXT, NONE, 0, 0, 0, {NULL}, NULL, NULL, STRUCT,
     "U(I1, J) of the energy law W = int_D U dz (I1, J, I1bar and [parameters]; ERRATA B5)"},
    {"barrier", "epsilon", SWIM_KEY_NUMBER, F(epsilon), 0, 0, 0, {NULL}, NULL, NULL, RT | STRUCT,
     "epsilon of W2 (4.1.1); 0 switches the barrier off"},
    {"barrier", "alpha", SWIM_KEY_NUMBER, F(alpha), 0, 0, 0, {NULL}, NULL, NULL, RT, "alpha of W2 (4.1.1)"},
    {"damping", "diagonal", SWIM_KEY_VECTOR, F(damping), 0, 0, 0, {NULL}, NULL, NULL, RT | STRUCT,
     "diagonal of the damping D (4.15) (its zeros are the kernel's structure)"},
    {"forcing", "law", SWIM_KEY_TEXT, NONE, 0, 0, 0, {NULL}, NULL, NULL, STRUCT, "f(t) of F(t) = f(t) direction (5.1)"},
    {"parameters", "*", SWIM_KEY_NUMBER, NONE, 0, 0, 0, {NULL}, NULL, NULL, RT,
     "a named value the laws use, read at run time (the names are the structure)"},
    {"forcing", "direction", SWIM_KEY_VECTOR, F(direction), 0, 0, 0, {NULL}, NULL, NULL, RT | STRUCT,
     "direction of F(t) (5.1) (its zeros are the kernel's structure)"},
    {"run", "t_end", SWIM_KEY_NUMBER, F(run.t_end), 0, 0, 0, {NULL}, NULL, "t-end", REQ, "final time"},
    {"run", "output_step", SWIM_KEY_NUMBER, F(run.output_step), 0, 0, 0, {NULL}, NULL, "output-step", REQ,
     "spacing of the output rows"},
    {"run", "rtol", SWIM_KEY_NUMBER, F(run.rtol), 0, 0, 1e-8, {NULL}, NULL, "rtol", 0, "relative tolerance"},
    {"run", "atol", SWIM_KEY_NUMBER, F(run.atol), 0, 0, 1e-10, {NULL}, NULL, "atol", 0, "absolute tolerance"},
    {"run", "integrator", SWIM_KEY_TEXT, F(run.integrator), 0, 0, 0, {NULL}, NULL, "integrator", 0,
     "the integrator (ode/ode.h's registry)"},
    {"run", "stiff_fallback", SWIM_KEY_TEXT, F(run.stiff_fallback), 0, 0, 0, {NULL}, NULL, NULL, 0,
     "the integrator a run continues with when ABM detects stiffness, or \"none\""},
    {"run", "projection", SWIM_KEY_BOOL, F(run.projection), 0, 0, 1, {NULL}, "true or false", NULL, PLAIN,
     "drift control: the state put back on the constraints after each step"},
    {"run", "origin_shift", SWIM_KEY_BOOL, F(run.origin_shift), 0, 0, 1, {NULL}, "true or false", NULL, PLAIN,
     "abm with a barrier: the state carried relative to an origin near the boundary of D"},
    {"run", "energy_control", SWIM_KEY_BOOL, F(run.energy_control), 0, 0, -1, {NULL}, "true or false", NULL, PLAIN,
     "abm: the energy balance in the error test (default: with a barrier)"},
    {"run", "impact_depth", SWIM_KEY_NUMBER, F(run.impact_depth), 0, 1, 1e-16, {NULL}, "in [0, 1) (0: never)", NULL,
     PLAIN, "abm with a barrier: bounces predicted to turn below impact_depth |c1|^2 taken as impacts"},
    {"run", "step_lookahead", SWIM_KEY_INTEGER, F(run.step_lookahead), 0, 12, -1, {NULL}, "an integer 0..12",
     "step-lookahead", PLAIN, "ABM step-size look-ahead p"},
    {"run", "jacobian", SWIM_KEY_CHOICE, F(run.jacobian_exact), 0, 0, 1, {"differences", "exact", NULL},
     "\"exact\" or \"differences\"", NULL, PLAIN, "the Newton matrix of the BDF integrators"},
    {"events", "list", SWIM_KEY_TEXT, NONE, 0, 0, 0, {NULL}, NULL, NULL, 0, "events to locate, \"COLUMN:KIND[:stop]\""},
    {"run", "project_initial", SWIM_KEY_BOOL, F(run.project_initial), 0, 0, 0, {NULL}, "true or false", NULL, PLAIN,
     "project an inconsistent dc0 onto the constraints instead of refusing it"},
    {"stroke", "*", SWIM_KEY_TEXT, NONE, 0, 0, 0, {NULL}, NULL, NULL, STRUCT, "the law of a prescribed coordinate"},
    {"stroke", "period", SWIM_KEY_NUMBER, F(stroke_period), 0, 0, 0, {NULL}, NULL, NULL, 0,
     "the stroke's period for the per-stroke report"},
};

static const char *const tables[] = {"title", "model", "shape", "elastic", "barrier", "damping", "forcing", "run",
                                     "events", "stroke", "parameters", NULL};

/* ---- the numeric options of the commands, besides the run settings above ------------------
 * One row per option: `table` is the command, `key` the option (without "--"); an INTEGER in
 * [lo, hi], a NUMBER finite in [lo, hi) (lo = DBL_MIN: "> 0"); `expect` says it in words for the
 * message, dflt is the default. The commands read their options through this table
 * (cli/args.h, swim_args_bounded), so no option is parsed without its bounds. A bound that
 * depends on the scene (a count of rows over t_end) is checked where the scene is known; the row
 * says it in `expect`. The hard limits below are also those of the code that runs:
 * SWIM_PERIODIC_MAX_ITER 40, SWIM_CONT_MAX_POINTS 1000, SWIM_OPT_MAX_STARTS 64 (a test compares).
 * swim inspect's numbers are the library's arguments (swim_inspect), bounded by its own rows. */
static const swim_scene_key command_options[] = {
    {"run", "lyapunov-interval", SWIM_KEY_NUMBER, NONE, DBL_MIN, INFINITY, 1, {NULL},
     "a number > 0 giving at most 10^6 renormalizations over t_end", NULL, 0, "renormalization interval"},
    {"periodic", "tol", SWIM_KEY_NUMBER, NONE, DBL_MIN, 1, 1e-11, {NULL}, "in (0, 1)", NULL, 0, "Newton tolerance"},
    {"periodic", "max-iter", SWIM_KEY_INTEGER, NONE, 1, 40, 20, {NULL}, "an integer 1..40", NULL, 0, "Newton iterations"},
    {"periodic", "t-max", SWIM_KEY_NUMBER, NONE, DBL_MIN, 1e6, 0, {NULL},
     "> 0 and below 1e6, with at most 10^7 output steps (run.output_step) of the guess run", NULL, 0,
     "how long the guess run looks for two events"},
    {"continue", "max-points", SWIM_KEY_INTEGER, NONE, 2, 1000, 11, {NULL}, "an integer 2..1000", NULL, 0,
     "points of the branch"},
    {"continue", "tol", SWIM_KEY_NUMBER, NONE, DBL_MIN, 1, 1e-11, {NULL}, "in (0, 1)", NULL, 0, "Newton tolerance"},
    {"floquet", "t-max", SWIM_KEY_NUMBER, NONE, DBL_MIN, 1e6, 0, {NULL},
     "> 0 and below 1e6, with at most 10^7 output steps (run.output_step) of the run for the period", NULL, 0,
     "how long to look for two events"},
    {"optimize", "starts", SWIM_KEY_INTEGER, NONE, 1, 64, 1, {NULL}, "an integer 1..64", NULL, 0, "local searches"},
    {"optimize", "max-iter", SWIM_KEY_INTEGER, NONE, 1, 100000, 60, {NULL}, "an integer 1..100000", NULL, 0,
     "iterations per start"},
    {"optimize", "tol", SWIM_KEY_NUMBER, NONE, DBL_MIN, 1, 1e-3, {NULL}, "in (0, 1)", NULL, 0,
     "the search's stopping size"},
    {"sweep", "jobs", SWIM_KEY_INTEGER, NONE, 1, 4096, 0, {NULL}, "an integer 1..4096", NULL, 0,
     "members run at once"},
    {"sweep", "progress", SWIM_KEY_NUMBER, NONE, 0, 1e6, 10, {NULL}, "seconds between progress lines, 0 to 1e6",
     NULL, 0, "progress interval"},
    {"cache", "older-than", SWIM_KEY_NUMBER, NONE, 0, 1e6, 0, {NULL}, "an age >= 0 and below 10^6 days", NULL, 0,
     "the age of the entries removed"},
    {"flow", "frames", SWIM_KEY_INTEGER, NONE, 1, 100000, 10, {NULL}, "an integer 1..100000", NULL, 0, "frames"},
};

const swim_scene_key *swim_command_option(const char *command, const char *option)
{
    for (size_t i = 0; i < sizeof command_options / sizeof command_options[0]; i++)
        if (strcmp(command_options[i].table, command) == 0 && strcmp(command_options[i].key, option) == 0)
            return &command_options[i];
    return NULL;
}

const swim_scene_key *swim_command_options(int *count)
{
    *count = (int)(sizeof command_options / sizeof command_options[0]);
    return command_options;
}

const swim_scene_key *swim_scene_keys(int *count)
{
    *count = (int)(sizeof keys / sizeof keys[0]);
    return keys;
}

const swim_scene_key *swim_scene_key_find(const char *table, const char *key)
{
    const swim_scene_key *any = NULL;
    for (size_t i = 0; i < sizeof keys / sizeof keys[0]; i++) {
        if (strcmp(keys[i].table, table) != 0) continue;
        if (strcmp(keys[i].key, key) == 0) return &keys[i];
        if (strcmp(keys[i].key, "*") == 0) any = &keys[i];
    }
    return any;
}

int swim_scene_table_keys(const char *table, const char **names, int cap)
{
    int n = 0;
    for (size_t i = 0; i < sizeof keys / sizeof keys[0] && n + 1 < cap; i++)
        if (strcmp(keys[i].table, table) == 0) names[n++] = keys[i].key;
    names[n] = NULL;
    return n;
}

const char *const *swim_scene_tables(void) { return tables; }

/* ---- the library's own numeric arguments (lib/swim.h), besides the scene keys above ----------
 * Checked by libswim at the top of the function named in `table`; a value outside [lo, hi) (or
 * not finite) is SWIM_EINPUT naming the argument. */
static const swim_scene_key library_args[] = {
    {"swim_inspect", "modes", SWIM_KEY_INTEGER, NONE, 0, SWIM_KERNEL_MAX_MODES, 0, {NULL},
     "an integer 0.." SWIM_STR(SWIM_KERNEL_MAX_MODES), NULL, 0, "the mode count"},
    {"swim_inspect", "rho0", SWIM_KEY_NUMBER, NONE, DBL_MIN, SWIM_MAGNITUDE_MAX, 0, {NULL}, "> 0 and < 1e150", NULL, 0,
     "the body's density"},
    {"swim_inspect", "rhof", SWIM_KEY_NUMBER, NONE, DBL_MIN, SWIM_MAGNITUDE_MAX, 0, {NULL}, "> 0 and < 1e150", NULL, 0,
     "the fluid's density"},
    {"swim_sim_advance", "t", SWIM_KEY_NUMBER, NONE, 0, INFINITY, 0, {NULL},
     "a finite time >= 0, not before the time of an earlier call", NULL, 0, "the time to advance to"},
    {"swim_model_from_file", "nsets", SWIM_KEY_INTEGER, NONE, 0, 64, 0, {NULL}, "an integer 0..64", NULL, 0,
     "the number of overrides"},
    {"swim_sim_create", "nevents", SWIM_KEY_INTEGER, NONE, 0, SWIM_LIB_MAX_EVENTS, 0, {NULL},
     "an integer 0.." SWIM_STR(SWIM_LIB_MAX_EVENTS), NULL, 0, "the number of events"},
};

const swim_scene_key *swim_library_arg(const char *function, const char *arg)
{
    for (size_t i = 0; i < sizeof library_args / sizeof library_args[0]; i++)
        if (strcmp(library_args[i].table, function) == 0 && strcmp(library_args[i].key, arg) == 0)
            return &library_args[i];
    return NULL;
}
