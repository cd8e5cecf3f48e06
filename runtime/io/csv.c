#include "io/csv.h"

#include "io/json.h"

#include <errno.h>
#include <fcntl.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

/* "%.17g" of a double is at most 24 characters ("-2.2250738585072014e-308"), plus a comma. */
#define CELL_MAX 26

/* Write the whole line or nothing: a partial write is cut off again (ftruncate to the last
 * whole row), so readers never see half a row. */
static int write_line(swim_csv *w, const char *p, size_t len)
{
    size_t done = 0;
    while (done < len) {
        ssize_t k = write(w->fd, p + done, len - done);
        if (k < 0 && errno == EINTR) continue;
        if (k <= 0) {
            int saved = k < 0 ? errno : ENOSPC;
            if (ftruncate(w->fd, w->size) == 0) lseek(w->fd, w->size, SEEK_SET);
            errno = saved;
            return -1;
        }
        done += (size_t)k;
    }
    w->size += (off_t)len;
    return 0;
}

int swim_csv_open(swim_csv *w, const char *path, const char *const *names, int columns)
{
    memset(w, 0, sizeof *w);
    size_t header = 2;
    for (int i = 0; i < columns; i++) header += strlen(names[i]) + 1;
    w->cap = (size_t)columns * CELL_MAX + 2 > header ? (size_t)columns * CELL_MAX + 2 : header;
    w->columns = columns;
    w->line = malloc(w->cap);
    if (!w->line) return -1;
    w->fd = open(path, O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0666);
    if (w->fd < 0) {
        int saved = errno;
        free(w->line);
        w->line = NULL;
        errno = saved;
        return -1;
    }
    size_t at = 0;
    for (int i = 0; i < columns; i++) at += (size_t)sprintf(w->line + at, "%s%s", i ? "," : "", names[i]);
    w->line[at++] = '\n';
    if (write_line(w, w->line, at) != 0 || fstat(w->fd, &w->st) != 0) {
        int saved = errno;
        close(w->fd);
        free(w->line);
        w->line = NULL;
        errno = saved;
        return -1;
    }
    return 0;
}

int swim_csv_row(swim_csv *w, const double *v)
{
    size_t at = 0;
    for (int i = 0; i < w->columns; i++) {
        if (i) w->line[at++] = ',';
        if (isfinite(v[i])) at += (size_t)swim_number_text(w->line + at, w->cap - at, v[i]);
        else at += (size_t)snprintf(w->line + at, w->cap - at, "nan");
    }
    w->line[at++] = '\n';
    return write_line(w, w->line, at);
}

int swim_csv_close(swim_csv *w)
{
    if (!w->line) return 0;
    free(w->line);
    w->line = NULL;
    /* Rows may sit in the page cache with their blocks not yet allocated (delayed allocation):
     * a full disk can show only now. fsync does not apply to pipes and character devices. */
    int rc = fsync(w->fd) == 0 || errno == EINVAL || errno == EROFS ? 0 : -1, saved = errno;
    if (close(w->fd) != 0 && rc == 0) { rc = -1; saved = errno; }
    errno = saved;
    return rc;
}
