#include "io/csv.h"

#include <math.h>

int swim_csv_open(swim_csv *w, const char *path, const char *const *names, int columns)
{
    w->f = fopen(path, "w");
    w->columns = columns;
    if (!w->f) return -1;
    for (int i = 0; i < columns; i++) fprintf(w->f, "%s%s", i ? "," : "", names[i]);
    fputc('\n', w->f);
    return fflush(w->f) == 0 ? 0 : -1;
}

int swim_csv_row(swim_csv *w, const double *v)
{
    for (int i = 0; i < w->columns; i++) {
        if (i) fputc(',', w->f);
        if (isfinite(v[i])) fprintf(w->f, "%.17g", v[i]);
        else fputs("nan", w->f);
    }
    fputc('\n', w->f);
    return fflush(w->f) == 0 && !ferror(w->f) ? 0 : -1;
}

int swim_csv_close(swim_csv *w)
{
    int rc = w->f ? fclose(w->f) : 0;
    w->f = NULL;
    return rc;
}
