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
 * scene.toml (the scene text as read and validated once at the start: every member runs this
 * copy, so editing the scene file during a sweep cannot mix two scenes in one family, and a
 * resume whose scene file no longer has this text is refused), sweep.lock (flock(2)-ed by the
 * sweep that uses DIR, for its whole life, and holding its pid: a second sweep into the same DIR
 * is refused while the first runs), members/ID/summary.json (+ trajectory.csv with --keep
 * trajectories, + log.txt: the member's stdout and stderr), and members.csv, one row per
 * finished member, rebuilt from the summaries when a sweep starts or resumes, then appended
 * and flushed as members finish, and rewritten in member-id order when the sweep ends.
 *
 * Summaries are read back by the one summary reader (driver/summary_read.h, jansson): values at
 * their path in the JSON tree (steps is stats.steps). A member is finished when its summary.json
 * is whole (one JSON object with stats.max_rss_kb, or a "crashed" one) and does not say it was
 * interrupted.
 * A member stopped by a signal someone sent (SIGINT, SIGTERM, SIGHUP, SIGKILL: a user, a batch
 * scheduler, a stopping sweep) is interrupted and reruns on resume; a member whose process died
 * otherwise without a summary (SIGSEGV, SIGBUS, SIGABRT, ..., or an exit status other than 0/1)
 * gets one written for it (status "crashed"), so resuming does not retry a member that crashes
 * every time.
 */
#ifndef SWIM_SWEEP_H
#define SWIM_SWEEP_H

#include <stdio.h>
#include <sys/types.h>

#include "driver/summary_read.h"
#include "scene/scene.h"

#define SWEEP_MAX_VARY 8
#define SWEEP_MAX_SETS 48   /* with SWEEP_MAX_VARY: at most the 64 --set of swim run */
#define SWEEP_MAX_MEMBERS 1000000L

/* The longest path a sweep holds: the system's PATH_MAX. A longer scene path or DIR is refused
 * (one line, exit 2), never cut. */
#define SWIM_SWEEP_PATH 4096

typedef struct {
    char key[128];
    const char *spec;     /* the SPEC as given (the command line's, any length) */
    swim_override tmpl;   /* table, key, index of KEY */
    double *values;
    long count;
} sweep_vary;

typedef struct {
    char cmd[16];                 /* "sweep" (for messages) */
    char scene[SWIM_SWEEP_PATH];
    char dir[SWIM_SWEEP_PATH];
    char exe[SWIM_SWEEP_PATH];               /* the program members run with (`EXE run ...`) */
    int in_process;               /* 1: the forked child runs `swim run` without exec (this program
                                   * is bin/swim); 0: it execs exe */
    sweep_vary vary[SWEEP_MAX_VARY];
    int nvary, zip, keep_trajectories, generic, no_projection, quiet;
    int format_hdf5;              /* --format hdf5: also DIR/family.h5 (sweep/family_hdf5.h) */
    double progress_every;        /* seconds between progress lines on stderr when it is not a
                                   * terminal (--progress; on a terminal one line is redrawn) */
    long jobs;
    char integrator[32];
    swim_override sets[SWEEP_MAX_SETS];   /* --set and --t-end, --rtol, ... as run.* overrides */
    const char *set_option[SWEEP_MAX_SETS];   /* "t-end", ... for those, NULL for a --set (messages) */
    int nsets;
    char *scene_text;             /* the scene file as read once by sweep_prepare (owned) */
    size_t scene_len;
    int lock_fd;                  /* DIR/sweep.lock, held from sweep_prepare to sweep_free; -1 */
    long members;
    unsigned char *finished;      /* per member, after sweep_prepare */
    long already, already_failed; /* members found finished (and of them failed) at the start */
} sweep_plan;

/* The command line of a sweep is read by cli/sweep_args.h (sweep_parse). */
/* Parses one SPEC into a freshly allocated array of values. 0, or -1 with a reason in err. */
int sweep_parse_spec(const char *spec, double **values, long *count, char *err, size_t errlen);
/* The value of varied key v for member m (grid: the last --vary varies fastest). */
double sweep_value(const sweep_plan *p, long m, int v);

/* Everything before the first member runs: the scene file read once, every member validated as
 * swim run validates a scene (the scene reader, then the magnitude check of its model on its
 * kernel: a bad member is one line naming the member and the key, 2), DIR locked (another sweep
 * using it: one line naming DIR and that sweep's pid, 2), DIR set up (sweep.json and scene.toml
 * written, or compared with the ones there: a different definition or scene text is 2), the
 * finished members found and members.csv rebuilt from their summaries, the kernel of every
 * distinct structure (runtime/codegen) generated once. 0, 1 (I/O error or a structure without a
 * kernel) or 2, with the cause in st. */
int sweep_prepare(sweep_plan *p, swim_status *st);

/* Starts member m as a child process running DIR/scene.toml (stdout/stderr to its log.txt, where
 * the member's refusal or a failed exec is written); its pid, or -1. The child dies with the parent (PR_SET_PDEATHSIG), so a killed sweep leaves no
 * member running, and does not hold DIR's lock. */
pid_t sweep_spawn(const sweep_plan *p, long m);
/* After the child of member m exited with wait status `status`: writes a "crashed" summary if it
 * left none and was not interrupted (by a signal someone sent, or `interrupted`: the sweep is
 * stopping), and formats the member's members.csv row (with '\n') into row. Returns 1 if the
 * member is finished (row valid) and sets *failed, 0 if it must be rerun, -1 if its crashed
 * summary could not be written (one line naming the file and strerror in st). */
int sweep_collect(const sweep_plan *p, long m, int status, int interrupted, char *row, size_t len,
                  int *failed, swim_status *st);

/* members.csv: opened for appending after sweep_prepare rebuilt it; NULL with the cause in st. */
FILE *sweep_open_rows(const sweep_plan *p, swim_status *st);
int sweep_append_row(FILE *f, const char *row);   /* write + flush; 0 or -1 (errno) */

/* A number of a member's summary in the family table: members.csv's column `name` (after id, the
 * varied keys, status and reason), at `offset` in swim_summary, a swim_summary_count when
 * integer, else a swim_summary_real; `path` is where summary.json holds it (keys joined by dots),
 * which is how libswim's users read the same column (swim_family_column). */
typedef struct {
    const char *name;
    size_t offset;
    int integer;
    const char *path;
} sweep_column;
const sweep_column *sweep_columns(int *count);
/* Member m's summary (the one reader): 1 if the member is finished, 0 if not (yet). */
int sweep_member_summary(const sweep_plan *p, long m, swim_summary *s);
void sweep_member_dir(const sweep_plan *p, long m, char *buf, size_t len);   /* DIR/members/ID */

/* members.csv rewritten from the finished members' summaries in member-id order (rows were
 * appended in the order members finished): when the sweep ends, stopped or not. 0, or 1 with the
 * line naming the file in st. */
int sweep_sort_rows(const sweep_plan *p, swim_status *st);

/* Progress of a sweep as one line: "swim sweep: D / T members (F failed), R members/s, about
 * E left" where D counts the members finished before a resume, R is the rate of the members run
 * now since `seconds` ago and E the time the remaining members take at that rate (none while
 * nothing has finished yet). */
void sweep_progress_line(const sweep_plan *p, long ran, long failed, double seconds, char *line, size_t len);

/* The progress line for stderr (not with --quiet), called as members finish: 0 when none is due,
 * else the line (without newline) in line and 1 (print it as a line) or 2 (stderr is a terminal:
 * redraw it in place, "\r" LINE "\033[K"). On a terminal one is due at most every 0.5 s;
 * otherwise every --progress seconds or whenever another tenth of the members is done, whichever
 * comes first (so a short family in a log still shows its progress). */
typedef struct {
    double last;   /* when the line was last drawn (swim_clock_seconds; the sweep's start at first) */
    long decile;   /* tenths of the members done then */
    int drawn;     /* a terminal line is open: the caller ends it with a newline */
} sweep_progress_state;
int sweep_progress(const sweep_plan *p, long ran, long failed, double t0, sweep_progress_state *st, char *line,
                   size_t len);

/* The end of the sweep's report on stdout: flushed and checked (a full disk, /dev/full, a closed
 * pipe), and closed when close_it. 0, or -1 with the line "swim CMD: cannot write the report to
 * stdout: REASON" in st: the caller's exit status is then 1, never that of a reported sweep. */
int sweep_finish_stdout(const sweep_plan *p, int close_it, swim_status *st);

void sweep_free(sweep_plan *p);

#endif
