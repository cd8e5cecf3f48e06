/* run_signals.h -- what `swim run` (dynamic scenes and prescribed strokes) does with SIGINT,
 * SIGTERM and SIGHUP while it integrates: the handler only records the signal in swim_run_stop,
 * which the integration loops poll; the run then stops, keeps every row and writes its summary.
 */
#ifndef SWIM_CLI_RUN_SIGNALS_H
#define SWIM_CLI_RUN_SIGNALS_H

#include <signal.h>

#define SWIM_RUN_NSIGNALS 3

extern volatile sig_atomic_t swim_run_stop;   /* 0, or the signal that asked the run to stop */

typedef struct {
    struct sigaction old[SWIM_RUN_NSIGNALS];
} swim_run_signals;

/* Install the handler for the three signals, keeping the previous actions in s. */
void swim_run_signals_install(swim_run_signals *s);
/* Put the previous actions back. */
void swim_run_signals_restore(const swim_run_signals *s);

/* The program's side of kernel builds (codegen/codegen.h's hooks), for the calling thread: their
 * progress and notices on stderr; while a generator or compiler runs, SIGINT, SIGTERM and SIGHUP
 * (those not ignored) are passed on to it, and once the build has removed its temporary files
 * the signal is raised again under the program's own actions, so it does what it would have
 * done (ends the process, or is recorded by a run's handler). */
void swim_kernel_hooks_install(void);


#endif
