/* swim sweep: a family of runs of one scene on this machine, up to --jobs members at a time
 * (runtime/sweep/sweep.h has the files, the resume rules and the member processes). */
#include <errno.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

#include "cli/commands.h"
#include "cli/sweep_args.h"
#include "io/clock.h"
#include "sweep/family_hdf5.h"
#include "sweep/sweep.h"
#include "io/message.h"
#include "cli/report.h"

static volatile sig_atomic_t stop_signal;
static pid_t *running_pids;   /* slots; 0 = free */
static long slots;

/* SIGINT/SIGTERM/SIGHUP: stop launching and end the running members now (kill is async-signal-safe);
 * they are unfinished and rerun when the same command resumes the sweep. */
static void on_stop(int sig)
{
    stop_signal = sig;
    for (long i = 0; i < slots; i++)
        if (running_pids[i] > 0) kill(running_pids[i], SIGTERM);
}


int swim_cmd_sweep(int argc, char **argv)
{
    static sweep_plan p;
    int rc = sweep_parse(&p, "sweep", argc, argv, 2);
    if (rc) return rc;
    swim_status st = SWIM_STATUS_STDERR;
    if ((rc = swim_status_shown(&st, sweep_prepare(&p, &st)))) { sweep_free(&p); return rc; }
    FILE *rows = sweep_open_rows(&p, &st);
    if (!rows) { swim_status_print(&st, stderr); sweep_free(&p); return 1; }
    slots = p.jobs;
    running_pids = calloc((size_t)slots, sizeof *running_pids);
    long *ids = calloc((size_t)slots, sizeof *ids);
    if (!running_pids || !ids) { swim_message(stderr, "swim sweep: out of memory"); return 1; }
    struct sigaction sa, old_int, old_term, old_hup;
    memset(&sa, 0, sizeof sa);
    sa.sa_handler = on_stop;   /* no SA_RESTART: waitpid returns EINTR */
    sigaction(SIGINT, &sa, &old_int);
    sigaction(SIGTERM, &sa, &old_term);
    sigaction(SIGHUP, &sa, &old_hup);   /* a closed terminal: the finished rows are kept, as for ^C */

    const double t0 = swim_clock_seconds();
    long next = 0, running = 0, ran = 0, failed = 0, interrupted = 0;
    sweep_progress_state progress = {t0, p.members > 0 ? 10 * p.already / p.members : 10, 0};
    char row[2048];
    if (!p.quiet && p.already)
        swim_message(stderr, "swim sweep: resuming %s: %ld of %ld members already finished", p.dir, p.already, p.members);
    for (;;) {
        while (!stop_signal && running < slots && next < p.members) {
            long m = next++;
            if (p.finished[m]) continue;
            long slot = 0;
            while (running_pids[slot]) slot++;
            pid_t pid = sweep_spawn(&p, m);
            if (pid < 0) {
                swim_message(stderr, "swim sweep: cannot start member %ld: %s", m, strerror(errno));
                stop_signal = -1;
                break;
            }
            ids[slot] = m;
            running_pids[slot] = pid;
            running++;
            if (stop_signal > 0) kill(pid, SIGTERM);   /* the signal came while it was being started */
        }
        if (running == 0) break;
        int status;
        pid_t pid = waitpid(-1, &status, 0);
        if (pid < 0) {
            if (errno == EINTR) continue;
            break;
        }
        long slot = 0;
        while (slot < slots && running_pids[slot] != pid) slot++;
        if (slot == slots) continue;
        running_pids[slot] = 0;
        running--;
        swim_status_clear(&st);
        int bad = 0, got = sweep_collect(&p, ids[slot], status, stop_signal != 0, row, sizeof row, &bad, &st);
        if (got < 0) swim_status_print(&st, stderr);
        if (got > 0) {
            if (sweep_append_row(rows, row) != 0) {
                swim_message(stderr, "swim sweep: cannot append to %s/members.csv: %s", p.dir, strerror(errno));
                stop_signal = -1;
            }
            ran++;
            failed += bad;
        } else if (got == 0) {
            interrupted++;
        } else {
            stop_signal = -1;   /* named on stderr; the next members would meet the same disk */
        }
        char line[256];
        const int due = sweep_progress(&p, ran, failed, t0, &progress, line, sizeof line);
        if (due) fprintf(stderr, due == 2 ? "\r%s\033[K" : "%s\n", line);
    }
    if (progress.drawn) fputc('\n', stderr);
    sigaction(SIGINT, &old_int, NULL);
    sigaction(SIGTERM, &old_term, NULL);
    sigaction(SIGHUP, &old_hup, NULL);
    if (fclose(rows) != 0 && !stop_signal) {
        swim_message(stderr, "swim sweep: cannot write %s/members.csv: %s", p.dir, strerror(errno));
        stop_signal = -1;
    }
    const double seconds = swim_clock_seconds() - t0;
    swim_status_clear(&st);
    /* rows in member order, as a reader expects */
    if (swim_status_shown(&st, sweep_sort_rows(&p, &st))) stop_signal = -1;
    const int with_family = sweep_family_hdf5_due(&p);
    if (with_family && swim_status_shown(&st, sweep_write_family_hdf5(&p, &st))) stop_signal = -1;
    const long finished = p.already + ran, all_failed = p.already_failed + failed;
    if (stop_signal) {
        swim_message(stderr, "swim sweep: %s: stopped%s after %ld of %ld members (%ld failed); run the same command "
                     "again to resume", p.dir, stop_signal == SIGINT ? " by SIGINT" : stop_signal == SIGTERM ? " by SIGTERM"
                     : stop_signal == SIGHUP ? " by SIGHUP" : "",
                     finished, p.members, all_failed);
        rc = 1;
    } else {
        printf("%s: %ld members, %ld completed, %ld failed (%ld ran now in %.3f s, %.2f members/s with %ld jobs%s)\n",
               p.dir, p.members, finished - all_failed, all_failed, ran, seconds, seconds > 0 ? ran / seconds : 0.0,
               p.jobs, p.already ? "; the others were finished before" : "");
        printf("  rows in %s/members.csv%s, definition in %s/sweep.json\n", p.dir,
               with_family ? " and the family in family.h5" : "", p.dir);
        rc = all_failed || finished < p.members ? 1 : 0;
    }
    if (interrupted && !stop_signal)
        swim_message(stderr, "swim sweep: %ld members were stopped by a signal sent to them (not recorded); run the "
                     "same command again to rerun them", interrupted);
    /* The report is the result of the command: a report that could not be written is a failure. */
    swim_status_clear(&st);
    if (swim_status_shown(&st, sweep_finish_stdout(&p, 1, &st))) rc = 1;
    free(running_pids);
    free(ids);
    sweep_free(&p);
    return rc;
}
