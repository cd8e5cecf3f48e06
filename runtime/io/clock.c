#include "io/clock.h"

#include <time.h>

double swim_clock_seconds(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return ts.tv_sec + 1e-9 * ts.tv_nsec;
}

double swim_clock_sample_total(const swim_clock_sample *s)
{
    return s->timed ? s->seconds * ((double)s->calls / (double)s->timed) : 0.0;
}
