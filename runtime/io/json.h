/* json.h -- the one JSON writer: numbers as the shortest text that reads back to the same double
 * (swim_number_text, also every CSV's format), NaN/inf as null. */
#ifndef SWIM_JSON_H
#define SWIM_JSON_H

#include <jansson.h>
#include <stdio.h>

/* v as the shortest text strtod reads back to the same double: %.15g, %.16g or %.17g, the first
 * that round-trips (a double has 15.95 digits, so any shorter exact text is the %.15g one with its
 * trailing zeros dropped): 30 as "30", 0.05 as "0.05", never "3e+01" or "0.050000000000000003";
 * "nan", "inf" or "-inf" when not finite. len >= 32. Returns the length. */
int swim_number_text(char *buf, size_t len, double v);
/* FILE gets swim_number_text(v) (nan/inf as the text says; for JSON use swim_json_number). */
void swim_number_print(FILE *f, double v);
void swim_json_number(FILE *f, double v);
/* [v0, v1, ...] */
void swim_json_vector(FILE *f, const double *v, int n);
/* [[row0], [row1], ...] for a row-major rows x cols matrix; indent = spaces before rows. */
void swim_json_matrix(FILE *f, const double *m, int rows, int cols, int indent);
/* A JSON string literal with escapes; bytes that are not UTF-8 become U+FFFD (JSON text is UTF-8). */
void swim_json_string(FILE *f, const char *s);

/* ---- documents built as jansson values, written as text by swim_json_write ----
 * The builders return a new reference, NULL when out of memory (swim_json_set then fails). */

/* v, or null when it is not finite (JSON has no NaN or infinity). */
json_t *swim_json_num(double v);
/* The number printf(fmt, v) shows (a value given to a few digits, "%.3g"), null when not finite. */
json_t *swim_json_fmt(const char *fmt, double v);
/* A string of any bytes (the writer makes bytes that are not UTF-8 U+FFFD); null for NULL. */
json_t *swim_json_str(const char *s);
/* [v0, v1, ...], each as swim_json_num. */
json_t *swim_json_vec(const double *v, int n);
/* o[key] = v, taking v's reference. 0; -1 when v is NULL or out of memory. */
int swim_json_set(json_t *o, const char *key, json_t *v);
/* Value v as text: numbers as swim_number_text (integers exactly), strings as swim_json_string; an
 * object at the top one key a line, indented by two, and an array of objects or arrays one element
 * a line; everything else on one line ("key": value, separated by ", "). A newline at the end of a
 * top-level document. */
void swim_json_write(FILE *f, const json_t *v);

#endif
