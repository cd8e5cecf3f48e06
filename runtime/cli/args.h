/* args.h -- command-line options of the form `--name value` and `--name=value`.
 * Every error is one line on stderr naming the option and the value; callers exit with status 2. */
#ifndef SWIM_ARGS_H
#define SWIM_ARGS_H

#include <stdio.h>

#include "scene/scene.h"

typedef struct {
    const char *name;   /* without the leading "--" */
    int takes_value;    /* 0 = flag, 1 = a value given once, 2 = a value the caller reads from
                         * every occurrence in argv itself (value is the last) */
    const char *value;  /* filled in: the value, "" for a flag that was given, NULL if absent */
    const char *arg;    /* --help: the value's placeholder ("DIR", "T"); NULL for a flag */
    const char *help;   /* --help: what it does, its default and its allowed values */
} swim_opt;

/* What swim_args_parse returns after printing the options for --help (the command then ends
 * with status 0). */
#define SWIM_ARGS_HELP (-1)

/* Parses argv[first..argc). Non-option words go to positional[] (at most npos; their count in
 * *npos_out). Returns 0, or 2 after printing "swim CMD: ..." for an unknown or incomplete option,
 * or one given twice that is not repeatable (keeping only the last would silently drop the first).
 * With --help (or -h) anywhere it prints every option of opts with its help on stdout instead and
 * returns SWIM_ARGS_HELP: the help is made from the table the parser uses, so it lists every
 * option the command accepts. Repeatable options a command takes out of argv beforehand
 * (swim_args_take_all) are listed by giving them a row with takes_value 2. */
int swim_args_parse(const char *cmd, int argc, char **argv, int first, swim_opt *opts, int nopts,
                    const char **positional, int npos, int *npos_out);

/* A repeatable option (`--set A=1 --set B=2`): removes every `--name V` and `--name=V` from
 * argv[first..*argc), compacting argv and *argc, and stores the values in vals (at most cap).
 * Returns their count, or -1 after printing "swim CMD: ..." (value missing, more than cap). */
int swim_args_take_all(const char *cmd, int *argc, char **argv, int first, const char *name,
                       const char **vals, int cap);

/* Every `--set KEY=VALUE` taken out of argv (swim_args_take_all) and parsed into sets (at most cap):
 * how many, or -1 after one line "swim CMD: --set: ..." on stderr. */
int swim_args_take_sets(const char *cmd, int *argc, char **argv, int first, swim_override *sets, int cap);

/* The options block of --help: one entry per option, its help wrapped under it. */
void swim_args_help(FILE *f, const swim_opt *opts, int nopts);

/* The output folder: --out's value, else out/NAME-SUFFIX with NAME the scene file's name without
 * its extension (malloc'd; NULL when out of memory). */
char *swim_args_out_dir(const char *given, const char *scene, const char *suffix);

/* The output folder of a command checked before any work, nothing made: the folder, or the
 * nearest of its parents that exists (where mkdir -p would start), is a folder in which a file
 * can be created (tried, then removed), and none of names[0..n) in it is a folder. 0, or 2
 * after one line "swim CMD: --out: ...: reason". */
int swim_args_out_ready(const char *cmd, const char *dir, const char *const *names, int n);

const char *swim_args_get(const swim_opt *opts, int nopts, const char *name);

/* Strict number parsing: the whole string, finite. 0 or 2 (message printed, naming opt). */
int swim_args_double(const char *cmd, const char *opt, const char *s, double *out);
int swim_args_int(const char *cmd, const char *opt, const char *s, long lo, long hi, long *out);
/* The numeric option --opt of swim cmd, if given: parsed and checked against its row of the
 * commands' option table (scene/keys.h, swim_command_option): an integer in [lo, hi], or a finite
 * number in [lo, hi). 0 (*out set, or left alone when the option is absent), or 2 after one line
 * "swim CMD: --OPT: ..." naming the bound. An option without a row is a programming error: 2,
 * said as such. */
int swim_args_bounded(const char *cmd, const swim_opt *opts, int nopts, const char *opt, double *out);
/* A time option (--t-max) against the scene's output step: at most SWIM_ROWS_MAX steps, as
 * swim run's t_end. 0, or 2 after one line. */
int swim_args_steps_bounded(const char *cmd, const char *opt, double value, double output_step);
/* Comma-separated finite numbers; *count gets how many were read (at most cap). 0 or 2. */
int swim_args_list(const char *cmd, const char *opt, const char *s, double *out, int cap, int *count);

#endif
