/* capture.h -- a test program's stdout and stderr sent to a file for a while, to check that a
 * library call printed nothing. */
#ifndef SWIM_TEST_CAPTURE_H
#define SWIM_TEST_CAPTURE_H

#include <fcntl.h>
#include <stdio.h>
#include <sys/stat.h>
#include <unistd.h>

typedef struct {
    int saved1, saved2;
    const char *path;
} capture_fds;

/* stdout and stderr into `path` (created empty) until capture_end. */
static inline capture_fds capture_begin(const char *path)
{
    fflush(stdout);
    fflush(stderr);
    capture_fds q = {dup(1), dup(2), path};
    const int to = open(path, O_WRONLY | O_CREAT | O_TRUNC, 0600);
    dup2(to, 1);
    dup2(to, 2);
    close(to);
    return q;
}

/* stdout and stderr back; the bytes written to the file meanwhile (-1 if it cannot be read). */
static inline long long capture_end(capture_fds q)
{
    fflush(stdout);
    fflush(stderr);
    dup2(q.saved1, 1);
    dup2(q.saved2, 2);
    close(q.saved1);
    close(q.saved2);
    struct stat st;
    return stat(q.path, &st) == 0 ? (long long)st.st_size : -1;
}

#endif
