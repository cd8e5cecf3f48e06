/* json.h -- the one JSON writer: numbers at full precision (%.17g), NaN/inf as null. */
#ifndef SWIM_JSON_H
#define SWIM_JSON_H

#include <stdio.h>

void swim_json_number(FILE *f, double v);
/* [v0, v1, ...] */
void swim_json_vector(FILE *f, const double *v, int n);
/* [[row0], [row1], ...] for a row-major rows x cols matrix; indent = spaces before rows. */
void swim_json_matrix(FILE *f, const double *m, int rows, int cols, int indent);
/* A JSON string literal with escapes; bytes that are not UTF-8 become U+FFFD (JSON text is UTF-8). */
void swim_json_string(FILE *f, const char *s);

#endif
