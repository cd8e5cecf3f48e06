/* csv.h -- the one CSV writer: a header row, then rows of numbers (%.17g, exact round trip;
 * nan/inf as "nan"). Each row goes to the file in one write(2) as soon as it is made, so a run
 * that stops keeps every row it wrote; a row that does not fit (disk full, file size limit) is
 * cut off again, so the file always ends with a whole row. Every write and the close are
 * checked: failures return -1 with errno set. */
#ifndef SWIM_CSV_H
#define SWIM_CSV_H

#include <stddef.h>
#include <sys/stat.h>
#include <sys/types.h>

typedef struct {
    int fd;
    int columns;
    char *line;       /* one formatted row; NULL when the writer is not open */
    size_t cap;
    off_t size;       /* bytes of whole rows in the file */
    struct stat st;   /* the file as opened, to notice it being removed or replaced */
} swim_csv;

/* 0, or -1 with errno set when the file cannot be created or the header not written. */
int swim_csv_open(swim_csv *w, const char *path, const char *const *names, int columns);
int swim_csv_row(swim_csv *w, const double *values);   /* 0, or -1 with errno on a write error */
/* Flushes the rows to the disk (fsync) and closes: 0, or -1 with errno set. Closing a writer that is not open (zeroed,
 * or already closed) does nothing and returns 0. */
int swim_csv_close(swim_csv *w);

#endif
