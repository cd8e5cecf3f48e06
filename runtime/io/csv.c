#include "io/csv.h"

#include <errno.h>
#include <math.h>

/* fflush, and the stream's error flag: fprintf may have failed earlier without a visible return. */
static int flush_checked(FILE *f)
{
    if (fflush(f) != 0) return -1;
    if (ferror(f)) {
        if (errno == 0) errno = EIO;
        return -1;
    }
    return 0;
}

int swim_csv_open(swim_csv *w, const char *path, const char *const *names, int columns)
{
    w->f = fopen(path, "w");
    w->columns = columns;
    if (!w->f) return -1;
    for (int i = 0; i < columns; i++) fprintf(w->f, "%s%s", i ? "," : "", names[i]);
    fputc('\n', w->f);
    if (flush_checked(w->f) != 0 || fstat(fileno(w->f), &w->st) != 0) {
        int saved = errno;
        fclose(w->f);
        w->f = NULL;
        errno = saved;
        return -1;
    }
    return 0;
}

int swim_csv_row(swim_csv *w, const double *v)
{
    errno = 0;
    for (int i = 0; i < w->columns; i++) {
        if (i) fputc(',', w->f);
        if (isfinite(v[i])) fprintf(w->f, "%.17g", v[i]);
        else fputs("nan", w->f);
    }
    fputc('\n', w->f);
    return flush_checked(w->f);
}

int swim_csv_close(swim_csv *w)
{
    if (!w->f) return 0;
    errno = 0;
    int rc = ferror(w->f) ? -1 : 0, saved = errno ? errno : EIO;
    if (fclose(w->f) != 0 && rc == 0) {
        rc = -1;
        saved = errno;
    }
    w->f = NULL;
    if (rc) errno = saved;
    return rc;
}
