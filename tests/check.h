/* Minimal assertion helpers shared by every test program in tests/.
 * Each program ends with check_report(), which prints "NAME: P passed, F failed"
 * and returns the exit status (0 when nothing failed). */
#ifndef SWIM_TESTS_CHECK_H
#define SWIM_TESTS_CHECK_H

#include <math.h>
#include <stdio.h>

static int check_passed, check_failed;

#define CHECK(cond, ...)                                                       \
    do {                                                                       \
        if (cond) {                                                            \
            check_passed++;                                                    \
        } else {                                                               \
            check_failed++;                                                    \
            fprintf(stderr, "FAIL %s:%d: ", __FILE__, __LINE__);               \
            fprintf(stderr, __VA_ARGS__);                                      \
            fputc('\n', stderr);                                               \
        }                                                                      \
    } while (0)

/* |a - b| <= tol * max(1, |b|) */
#define CHECK_CLOSE(a, b, tol, what)                                           \
    do {                                                                       \
        double ca_ = (a), cb_ = (b);                                           \
        double sc_ = fabs(cb_) > 1.0 ? fabs(cb_) : 1.0;                        \
        CHECK(fabs(ca_ - cb_) <= (tol) * sc_, "%s: %.17g vs %.17g (tol %g)",   \
              (what), ca_, cb_, (double)(tol));                                \
    } while (0)

static inline int check_report(const char *name)
{
    printf("%s: %d passed, %d failed\n", name, check_passed, check_failed);
    return check_failed != 0;
}

#endif
