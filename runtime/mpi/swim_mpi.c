/* bin/swim-mpi sweep ...: `swim sweep` over MPI ranks (`make mpi`; run under mpirun).
 *
 * Rank 0 validates the sweep, sets up DIR exactly as `swim sweep` does (sweep.json, the finished
 * members, members.csv rebuilt, the kernels generated), then only deals: each worker rank asks for
 * a member, runs it in a child process (a forked copy calling the run command, or with
 * SWIM_MPI_EXEC=1 an exec of the sibling bin/swim; either way its numbers are those of --jobs 1),
 * writes that member's files and sends back the member's members.csv row with its next request. Dealing one member per request balances members whose costs differ by orders of
 * magnitude. Rank 0 appends and flushes the rows, so members.csv has one writer. DIR must be on a
 * file system every rank sees (resume reads the summaries). K ranks run K-1 members at a time.
 * Rank 0 polls with a short sleep (50 us, doubling while idle up to 2 ms) rather than blocking in
 * MPI_Recv, which would spin a core that the workers' members need. */
#include <mpi.h>

#include <errno.h>
#include <fcntl.h>
#include <libgen.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

#include "io/clock.h"
#include "io/message.h"
#include "cli/run_signals.h"
#include "cli/sweep_args.h"
#include "sweep/family_hdf5.h"
#include "sweep/sweep.h"
#include "cli/report.h"


enum { TAG_RESULT = 1, TAG_WORK = 2 };
#define MSG_LEN 2304


/* With SWIM_MPI_EXEC=1 members are run by exec of bin/swim next to this program (for an MPI stack
 * that objects to a forked rank running code without exec); by default the forked child calls the
 * run command directly, as swim sweep does (tested with OpenMPI 4.1: same numbers, no warning). */
static int member_program(sweep_plan *p)
{
    const char *e = getenv("SWIM_MPI_EXEC");
    p->in_process = !(e && strcmp(e, "1") == 0);
    if (p->in_process) return 0;
    char self[4096];
    snprintf(self, sizeof self, "%s", p->exe);
    snprintf(p->exe, sizeof p->exe, "%s/swim", dirname(self));
    if (access(p->exe, X_OK) != 0) {
        swim_message(stderr, "swim-mpi: cannot run %s (build it with make)", p->exe);
        return 2;
    }
    return 0;
}

/* sweep_parse on every rank (each needs the plan), but only rank 0 speaks: the command line is
 * the same on every rank, so is the verdict, and K ranks must not print one error K times. */
static int parse(sweep_plan *p, int rank, int argc, char **argv)
{
    if (rank == 0) return sweep_parse(p, "sweep", argc, argv, 2);
    fflush(stderr);
    int saved = dup(2), null = open("/dev/null", O_WRONLY);
    if (saved >= 0 && null >= 0) dup2(null, 2);
    if (null >= 0) close(null);
    int rc = sweep_parse(p, "sweep", argc, argv, 2);
    fflush(stderr);
    if (saved >= 0) { dup2(saved, 2); close(saved); }
    return rc;
}

static int deal(sweep_plan *p, int ranks)
{
    swim_status st = {0};
    FILE *rows = sweep_open_rows(p, &st);
    if (!rows) return swim_status_print(&st, stderr), 1;
    long next = 0, ran = 0, failed = 0, handled = 0;
    int stop = 0;   /* a row or a summary could not be written (named on stderr): deal no more */
    int active = ranks - 1;
    double busy = 0.0, t0 = swim_clock_seconds();
    sweep_progress_state progress = {t0, p->members > 0 ? 10 * p->already / p->members : 10, 0};
    long nap = 50000;   /* ns; doubles while idle up to 2 ms: few wake-ups, at most 2 ms of latency */
    char msg[MSG_LEN];
    while (active > 0) {
        int flag = 0;
        MPI_Status st;
        MPI_Iprobe(MPI_ANY_SOURCE, TAG_RESULT, MPI_COMM_WORLD, &flag, &st);
        if (!flag) {
            nanosleep(&(struct timespec){0, nap}, NULL);
            nap = nap < 2000000 ? 2 * nap : 2000000;
            continue;
        }
        nap = 50000;
        double tb = swim_clock_seconds();
        MPI_Recv(msg, MSG_LEN, MPI_CHAR, st.MPI_SOURCE, TAG_RESULT, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
        long id;
        int finished, bad, off = 0;
        if (sscanf(msg, "%ld %d %d %n", &id, &finished, &bad, &off) == 3 && id >= 0) {
            if (finished > 0) {
                if (sweep_append_row(rows, msg + off) != 0) {
                    swim_message(stderr, "swim-mpi: cannot append to %s/members.csv: %s", p->dir, strerror(errno));
                    stop = 1;
                }
                ran++;
                failed += bad;
            } else if (finished < 0) {
                stop = 1;   /* the worker named the file and the reason */
            }
            handled++;
            char line[256];
            const int due = sweep_progress(p, ran, failed, t0, &progress, line, sizeof line);
            if (due) fprintf(stderr, due == 2 ? "\r%s\033[K" : "%s\n", line);
        }
        while (next < p->members && p->finished[next]) next++;
        long give = next < p->members && !stop ? next++ : -1;
        if (give < 0) active--;
        MPI_Send(&give, 1, MPI_LONG, st.MPI_SOURCE, TAG_WORK, MPI_COMM_WORLD);
        busy += swim_clock_seconds() - tb;
    }
    if (progress.drawn) fputc('\n', stderr);
    if (fclose(rows) != 0 && !stop) {
        swim_message(stderr, "swim-mpi: cannot write %s/members.csv: %s", p->dir, strerror(errno));
        stop = 1;
    }
    double seconds = swim_clock_seconds() - t0;
    swim_status_clear(&st);
    if (sweep_sort_rows(p, &st) != 0) {   /* rows in member order, as a reader expects */
        swim_status_print(&st, stderr);
        stop = 1;
    }
    swim_status_clear(&st);
    if (sweep_family_hdf5_due(p) && sweep_write_family_hdf5(p, &st) != 0) {
        swim_status_print(&st, stderr);
        stop = 1;
    }
    const long finished = p->already + ran, all_failed = p->already_failed + failed;
    if (stop) {
        swim_message(stderr, "swim-mpi: %s: stopped after %ld of %ld members (%ld failed); run the same command "
                     "again to resume", p->dir, finished, p->members, all_failed);
        return 1;
    }
    printf("%s: %ld members, %ld completed, %ld failed (%ld ran now in %.3f s, %.2f members/s on %d worker ranks%s)\n",
           p->dir, p->members, finished - all_failed, all_failed, ran, seconds, seconds > 0 ? ran / seconds : 0.0,
           ranks - 1, p->already ? "; the others were finished before" : "");
    printf("  rank 0: %ld results handled, %.6f s busy (%.2f us per member)\n", handled, busy,
           handled ? 1e6 * busy / handled : 0.0);
    swim_status_clear(&st);
    if (sweep_finish_stdout(p, 0, &st) != 0) return swim_status_print(&st, stderr), 1;
    return all_failed || finished < p->members ? 1 : 0;
}

static void work(sweep_plan *p)
{
    char msg[MSG_LEN], row[2048];
    snprintf(msg, sizeof msg, "-1 0 0 ");
    for (;;) {
        MPI_Send(msg, (int)strlen(msg) + 1, MPI_CHAR, 0, TAG_RESULT, MPI_COMM_WORLD);
        long m;
        MPI_Recv(&m, 1, MPI_LONG, 0, TAG_WORK, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
        if (m < 0) return;
        int status = 0, bad = 0, finished = 0;
        pid_t pid = sweep_spawn(p, m);
        swim_status st = {0};
        if (pid > 0 && waitpid(pid, &status, 0) == pid)
            finished = sweep_collect(p, m, status, 0, row, sizeof row, &bad, &st);
        if (finished < 0) swim_status_print(&st, stderr);
        snprintf(msg, sizeof msg, "%ld %d %d %s", m, finished, bad, finished > 0 ? row : "");
    }
}

int main(int argc, char **argv)
{
    MPI_Init(&argc, &argv);
    swim_kernel_hooks_install();   /* the program owns its signals and what a kernel build prints */
    int rank, ranks;
    MPI_Comm_rank(MPI_COMM_WORLD, &rank);
    MPI_Comm_size(MPI_COMM_WORLD, &ranks);
    static sweep_plan p;
    int rc = 0;
    if (argc < 2 || strcmp(argv[1], "sweep") != 0) {
        if (rank == 0) swim_message(stderr, "usage: mpirun -np K swim-mpi sweep SCENE --out DIR --vary KEY=SPEC ... (as swim sweep)");
        rc = 2;
    } else if (ranks < 2) {
        if (rank == 0) swim_message(stderr, "swim-mpi: needs at least 2 ranks (rank 0 deals, the others run members); "
                                    "on one machine without MPI use swim sweep --jobs J");
        rc = 2;
    } else {
        rc = parse(&p, rank, argc, argv);
        if (!rc) rc = member_program(&p);
        if (!rc && rank == 0) {
            swim_status st = SWIM_STATUS_STDERR;
            rc = sweep_prepare(&p, &st);
            swim_status_print(&st, stderr);
        }
    }
    /* Every rank learns whether the sweep is valid (rank 0 checked every member) before any runs. */
    int any = rc;
    MPI_Allreduce(&any, &rc, 1, MPI_INT, MPI_MAX, MPI_COMM_WORLD);
    if (!rc) {
        if (rank == 0) rc = deal(&p, ranks);
        else work(&p);
    }
    sweep_free(&p);
    MPI_Finalize();
    return rc < 0 ? 0 : rc;   /* < 0: --help was printed */
}
