#include "cli/run_signals.h"
#include "codegen/codegen.h"
#include "io/clock.h"
#include "io/message.h"

#include <string.h>
#include <sys/types.h>
#include <time.h>

volatile sig_atomic_t swim_run_stop;

static const int signals[SWIM_RUN_NSIGNALS] = {SIGINT, SIGTERM, SIGHUP};

static void on_signal(int sig) { swim_run_stop = sig; }

void swim_run_signals_install(swim_run_signals *s)
{
    struct sigaction sa;
    memset(&sa, 0, sizeof sa);
    sa.sa_handler = on_signal;
    for (int i = 0; i < SWIM_RUN_NSIGNALS; i++) sigaction(signals[i], &sa, &s->old[i]);
}

void swim_run_signals_restore(const swim_run_signals *s)
{
    for (int i = 0; i < SWIM_RUN_NSIGNALS; i++) sigaction(signals[i], &s->old[i], NULL);
}


/* ---- kernel builds ---- */

static volatile sig_atomic_t build_child, build_stop;
static struct sigaction build_old[SWIM_RUN_NSIGNALS];

static void on_build_signal(int sig)
{
    build_stop = sig;
    if (build_child > 0) kill((pid_t)build_child, sig);
}

static void build_note(void *ctx, const char *line)
{
    (void)ctx;
    swim_message(stderr, "%s", line);
}

static void build_child_hook(void *ctx, long pid)
{
    (void)ctx;
    if (pid > 0) {
        build_stop = 0;
        build_child = (sig_atomic_t)pid;
        struct sigaction sa;
        memset(&sa, 0, sizeof sa);
        sa.sa_handler = on_build_signal;
        for (int i = 0; i < SWIM_RUN_NSIGNALS; i++) {
            sigaction(signals[i], NULL, &build_old[i]);
            if (build_old[i].sa_handler != SIG_IGN) sigaction(signals[i], &sa, NULL);
        }
    } else {
        for (int i = 0; i < SWIM_RUN_NSIGNALS; i++) sigaction(signals[i], &build_old[i], NULL);
        build_child = 0;
    }
}

static void build_stopped(void *ctx, int sig)
{
    (void)ctx;
    if (sig > 0) raise(sig);
}

void swim_kernel_hooks_install(void)
{
    const swim_codegen_hooks h = {build_note, build_child_hook, build_stopped, &build_stop, NULL};
    swim_codegen_set_hooks(&h);
}
