#include "io/clock.h"

#include <time.h>

double swim_clock_seconds(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return ts.tv_sec + 1e-9 * ts.tv_nsec;
}

int swim_clock_sample_start(swim_clock_sample *s)
{
    const int timed = s->calls++ % SWIM_CLOCK_EVERY == 0;
    if (timed) s->t0 = swim_clock_seconds();
    return timed;
}

void swim_clock_sample_stop(swim_clock_sample *s, int timed)
{
    if (!timed) return;
    s->seconds += swim_clock_seconds() - s->t0;
    s->timed++;
}

double swim_clock_sample_total(const swim_clock_sample *s)
{
    return s->timed ? s->seconds * ((double)s->calls / (double)s->timed) : 0.0;
}
