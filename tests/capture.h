/* capture.h -- for a while: a test program's stdout and stderr sent to a file (to check that a
 * library call printed nothing), an environment variable set to another value. */
#ifndef SWIM_TEST_CAPTURE_H
#define SWIM_TEST_CAPTURE_H

#include <fcntl.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
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

typedef struct {
    const char *name;
    char *old;   /* its value before, NULL when it was not set */
} env_saved;

static inline env_saved env_set(const char *name, const char *value)
{
    const char *now = getenv(name);
    env_saved e = {name, now ? strdup(now) : NULL};
    setenv(name, value, 1);
    return e;
}

static inline void env_restore(env_saved e)
{
    if (e.old) setenv(e.name, e.old, 1);
    else unsetenv(e.name);
    free(e.old);
}

#endif
