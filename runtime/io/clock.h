/* clock.h -- the one clock of swim's timings: monotonic wall-clock seconds (CLOCK_MONOTONIC), so
 * that a run's reported times are differences that a change of the system time cannot disturb.
 */
#ifndef SWIM_IO_CLOCK_H
#define SWIM_IO_CLOCK_H

/* Seconds since an arbitrary fixed point; only differences mean something. */
double swim_clock_seconds(void);

#endif
