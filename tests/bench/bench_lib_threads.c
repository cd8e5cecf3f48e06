/* bench_lib_threads: members of a family through libswim (swim_model_run_member) on one thread,
 * on two threads of one process, and in two processes, side by side: whether two threads gain
 * what two processes gain. The same work each way: Example 3, model.rho0 from 0.5 to 2 over
 * BENCH_THREADS_MEMBERS members (default 2000) to t = BENCH_THREADS_T_END (default 1), one model
 * per thread or process, each member's key set in it. The three ways alternate, REPEATS times
 * (BENCH_THREADS_REPEATS, default 5); medians. Run on 2 cores that are otherwise idle, or the
 * second core's share is what the others leave: the load average is printed beside.
 * Writes build/bench/lib_threads.csv. */
#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/wait.h>
#include <unistd.h>

#include "lib/swim.h"
#include "timing.h"

static int members;
static char t_end[64];

typedef struct {
    int lo, hi, failed;
} share;

/* Members lo .. hi - 1 on a model of their own. */
static void *run_share(void *arg)
{
    share *w = arg;
    const char *sets[1] = {t_end};
    swim_model *m = NULL;
    swim_error e = SWIM_ERROR_INIT;
    if (swim_model_from_file("models/example3.toml", sets, 1, &m, &e) != SWIM_OK) {
        fprintf(stderr, "bench_lib_threads: %s\n", e.message);
        w->failed = 1;
        return NULL;
    }
    for (int i = w->lo; i < w->hi && !w->failed; i++) {
        char kv[64];
        snprintf(kv, sizeof kv, "model.rho0=%.17g", 0.5 + 1.5 * i / (members > 1 ? members - 1 : 1));
        const char *key[1] = {kv};
        swim_member row = SWIM_MEMBER_INIT;
        if (swim_model_run_member(m, key, 1, NULL, 0, &row, &e) != SWIM_OK || !row.completed) w->failed = 1;
    }
    swim_model_free(m);
    return NULL;
}

/* 1: one thread; 2: two threads; 3: two processes. Seconds, or -1. */
static double way(int how)
{
    share a = {0, members / 2, 0}, b = {members / 2, members, 0}, all = {0, members, 0};
    const double t0 = bench_now();
    if (how == 1) {
        run_share(&all);
        return all.failed ? -1 : bench_now() - t0;
    }
    if (how == 2) {
        pthread_t ta, tb;
        if (pthread_create(&ta, NULL, run_share, &a) != 0) return -1;
        if (pthread_create(&tb, NULL, run_share, &b) != 0) {
            pthread_join(ta, NULL);
            return -1;
        }
        pthread_join(ta, NULL);
        pthread_join(tb, NULL);
        return a.failed || b.failed ? -1 : bench_now() - t0;
    }
    fflush(NULL);
    const pid_t pid = fork();
    if (pid == 0) {
        run_share(&a);
        _exit(a.failed);
    }
    run_share(&b);
    int st = 0;
    if (pid < 0 || waitpid(pid, &st, 0) < 0 || !WIFEXITED(st) || WEXITSTATUS(st) != 0 || b.failed) return -1;
    return bench_now() - t0;
}

int main(void)
{
    const char *v = getenv("BENCH_THREADS_MEMBERS");
    members = v ? atoi(v) : 2000;
    v = getenv("BENCH_THREADS_T_END");
    snprintf(t_end, sizeof t_end, "run.t_end=%s", v ? v : "1");
    v = getenv("BENCH_THREADS_REPEATS");
    const int repeats = v ? atoi(v) : 5;
    if (members < 2 || repeats < 1 || repeats > 99) {
        fprintf(stderr, "bench_lib_threads: BENCH_THREADS_MEMBERS >= 2, BENCH_THREADS_REPEATS 1..99\n");
        return 2;
    }
    share warm = {0, 2, 0};   /* kernels into the cache, the library's pages in memory */
    run_share(&warm);
    double t[3][99], load[1];
    FILE *la = fopen("/proc/loadavg", "r");
    if (!la || fscanf(la, "%lf", &load[0]) != 1) load[0] = -1;
    if (la) fclose(la);
    for (int r = 0; r < repeats; r++)
        for (int how = 1; how <= 3; how++)
            if ((t[how - 1][r] = way(how)) < 0) {
                fprintf(stderr, "bench_lib_threads: a member failed\n");
                return 1;
            }
    static const char *const names[3] = {"1 thread", "2 threads", "2 processes"};
    double med[3];
    for (int how = 0; how < 3; how++) med[how] = bench_median(t[how], repeats);
    printf("libswim members (Example 3, %d members, %s), median of %d, load average %.2f\n", members, t_end, repeats,
           load[0]);
    printf("%-14s %10s %12s %8s\n", "way", "seconds", "members/s", "vs 1");
    FILE *csv = fopen("build/bench/lib_threads.csv", "w");
    if (csv) fprintf(csv, "way,members,median_seconds,members_per_second,speedup\n");
    for (int how = 0; how < 3; how++) {
        printf("%-14s %10.3f %12.1f %7.2fx\n", names[how], med[how], members / med[how], med[0] / med[how]);
        if (csv) fprintf(csv, "%s,%d,%.4f,%.1f,%.3f\n", names[how], members, med[how], members / med[how],
                         med[0] / med[how]);
    }
    if (csv) fclose(csv);
    return 0;
}
