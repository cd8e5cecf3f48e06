/* csv.h -- the one CSV writer: a header row, then rows of numbers (%.17g, exact round trip; nan/inf as "nan"),
 * each row flushed so that a run that stops keeps every row it wrote. */
#ifndef SWIM_CSV_H
#define SWIM_CSV_H

#include <stdio.h>

typedef struct {
    FILE *f;
    int columns;
} swim_csv;

/* 0, or -1 with errno set when the file cannot be created. */
int swim_csv_open(swim_csv *w, const char *path, const char *const *names, int columns);
int swim_csv_row(swim_csv *w, const double *values);   /* 0, or -1 on a write error */
int swim_csv_close(swim_csv *w);

#endif
