/* csv.h -- the one CSV writer: a header row, then rows of numbers (%.17g, exact round trip; nan/inf as "nan"),
 * each row flushed so that a run that stops keeps every row it wrote. Every write is checked:
 * a row that did not reach the file, or a close that failed, is an error with errno set. */
#ifndef SWIM_CSV_H
#define SWIM_CSV_H

#include <stdio.h>
#include <sys/stat.h>

typedef struct {
    FILE *f;
    int columns;
    struct stat st;   /* the file as opened, to notice it being removed or replaced */
} swim_csv;

/* 0, or -1 with errno set when the file cannot be created or the header not written. */
int swim_csv_open(swim_csv *w, const char *path, const char *const *names, int columns);
int swim_csv_row(swim_csv *w, const double *values);   /* 0, or -1 with errno on a write error */
/* 0, or -1 with errno set when buffered data could not be written or the close failed.
 * Closing a never-opened (zeroed) writer is a no-op. */
int swim_csv_close(swim_csv *w);

#endif
