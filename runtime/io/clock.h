/* clock.h -- the one clock of swim's timings: monotonic wall-clock seconds (CLOCK_MONOTONIC), so
 * that a run's reported times are differences that a change of the system time cannot disturb.
 */
#ifndef SWIM_IO_CLOCK_H
#define SWIM_IO_CLOCK_H

/* Seconds since an arbitrary fixed point; only differences mean something. */
double swim_clock_seconds(void);

/* The time spent in a function called at every step or more often (the right-hand side, the
 * checks at every step), estimated from every SWIM_CLOCK_EVERY-th call and scaled to all calls:
 * a clock read costs 30-50 ns on a virtual machine's clock (kvm-clock), so timing every call
 * of a 0.4 us right-hand side added a fifth to it and to the time it measured. The period is
 * odd so that calls that alternate (predictor, corrector) are both sampled. */
#define SWIM_CLOCK_EVERY 7
typedef struct {
    long calls, timed;
    double seconds;   /* of the timed calls */
    double t0;
} swim_clock_sample;
/* Before the call: 1 when this call is timed. Inline: the calls not timed cost a count. */
static inline int swim_clock_sample_start(swim_clock_sample *s)
{
    const int timed = s->calls++ % SWIM_CLOCK_EVERY == 0;
    if (timed) s->t0 = swim_clock_seconds();
    return timed;
}
/* After it, with what start returned. */
static inline void swim_clock_sample_stop(swim_clock_sample *s, int timed)
{
    if (!timed) return;
    s->seconds += swim_clock_seconds() - s->t0;
    s->timed++;
}
/* The estimate over every call so far (0 before the first). */
double swim_clock_sample_total(const swim_clock_sample *s);

#endif
