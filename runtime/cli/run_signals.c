#include "cli/run_signals.h"
#include "io/clock.h"

#include <string.h>
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

