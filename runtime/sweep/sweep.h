/* sweep.h -- a family of runs of one scene (swim sweep, swim-mpi sweep).
 *
 * A sweep is a scene, a list of varied keys (each KEY=SPEC with SPEC = START:STOP:COUNT,
 * log:START:STOP:COUNT or V1,V2,...), their Cartesian product (or, with zip, their pairing), fixed
 * overrides and run options. Member i is `swim run SCENE --set KEY=V ...` run in a child process
 * (a crashing member cannot take the sweep down, and its numbers are those of a single run, bit for
 * bit) into DIR/members/ID: in bin/swim a forked copy of this process calls the run command directly
 * (no exec: a member does not pay again for starting the program and loading its libraries),
 * elsewhere (bin/swim-mpi) the child execs bin/swim.
 *
 * Files of DIR: sweep.json (the definition; a different definition in an existing DIR is refused),
 * members/ID/summary.json (+ trajectory.csv with --keep trajectories, + log.txt: the member's
 * stdout and stderr), and members.csv, one row per finished member, rebuilt from the summaries
 * when a sweep starts or resumes and then appended and flushed as members finish.
 *
 * A member is finished when its summary.json is complete and does not say it was interrupted; a
 * member whose process died without a summary gets one written for it (status "crashed"), so
 * resuming does not retry a member that crashes every time. Everything else reruns on resume.
 */
#ifndef SWIM_SWEEP_H
#define SWIM_SWEEP_H

#include <stdio.h>
#include <sys/types.h>

#include "scene/scene.h"

#define SWEEP_MAX_VARY 8
#define SWEEP_MAX_SETS 48   /* with SWEEP_MAX_VARY: at most the 64 --set of swim run */
#define SWEEP_MAX_MEMBERS 1000000L

typedef struct {
    char key[128];
    char spec[512];
    swim_override tmpl;   /* table, key, index of KEY */
    double *values;
    long count;
} sweep_vary;

typedef struct {
    char cmd[16];                 /* "sweep" (for messages) */
    char scene[512];
    char dir[900];
    char exe[1024];               /* the program members run with (`EXE run ...`) */
    int in_process;               /* 1: the forked child runs `swim run` without exec (this program
                                   * is bin/swim); 0: it execs exe */
    sweep_vary vary[SWEEP_MAX_VARY];
    int nvary, zip, keep_trajectories, generic, no_projection, quiet;
    long jobs;
    char integrator[32];
    swim_override sets[SWEEP_MAX_SETS];   /* --set and --t-end, --rtol, ... as run.* overrides */
    int nsets;
    long members;
    unsigned char *finished;      /* per member, after sweep_prepare */
    long already, already_failed; /* members found finished (and of them failed) at the start */
} sweep_plan;

/* Parses `swim sweep SCENE --out DIR --vary KEY=SPEC ... [--zip] [--jobs J] [--keep WHAT]
 * [--set KEY=VALUE ...] [run options]` (argv[first..argc)). 0, or 2 after one line on stderr. */
int sweep_parse(sweep_plan *p, const char *cmd, int argc, char **argv, int first);
/* Parses one SPEC into a freshly allocated array of values. 0, or -1 with a reason in err. */
int sweep_parse_spec(const char *spec, double **values, long *count, char *err, size_t errlen);
/* The value of varied key v for member m (grid: the last --vary varies fastest). */
double sweep_value(const sweep_plan *p, long m, int v);

/* Everything before the first member runs: every member validated as a scene (a bad one: one line
 * naming the member and the key, 2), DIR set up (sweep.json written, or compared with the one there:
 * a different definition is 2), the finished members found and members.csv rebuilt from their
 * summaries, the kernel of every distinct structure (runtime/codegen) generated once. 0, 1 (I/O
 * error or a structure without a kernel, printed) or 2. */
int sweep_prepare(sweep_plan *p);

/* Starts member m as a child process (stdout/stderr to its log.txt); its pid, or -1. The child
 * dies with the parent (PR_SET_PDEATHSIG), so a killed sweep leaves no member running. */
pid_t sweep_spawn(const sweep_plan *p, long m);
/* After the child of member m exited with wait status `status`: writes a "crashed" summary if it
 * left none (unless `interrupted`), and formats the member's members.csv row (with '\n') into
 * row. Returns 1 if the member is finished (row valid), 0 if it must be rerun, and sets *failed. */
int sweep_collect(const sweep_plan *p, long m, int status, int interrupted, char *row, size_t len,
                  int *failed);

/* members.csv: opened for appending after sweep_prepare rebuilt it. */
FILE *sweep_open_rows(const sweep_plan *p);
int sweep_append_row(FILE *f, const char *row);   /* write + flush; 0 or -1 */

void sweep_free(sweep_plan *p);

#endif
