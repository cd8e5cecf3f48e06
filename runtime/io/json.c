#include "io/json.h"

#include <math.h>

void swim_json_number(FILE *f, double v)
{
    if (isfinite(v))
        fprintf(f, "%.17g", v);
    else
        fputs("null", f);
}

void swim_json_vector(FILE *f, const double *v, int n)
{
    fputc('[', f);
    for (int i = 0; i < n; i++) {
        if (i) fputs(", ", f);
        swim_json_number(f, v[i]);
    }
    fputc(']', f);
}

void swim_json_matrix(FILE *f, const double *m, int rows, int cols, int indent)
{
    fputc('[', f);
    for (int r = 0; r < rows; r++) {
        fprintf(f, "%s\n%*s", r ? "," : "", indent, "");
        swim_json_vector(f, m + (size_t)r * cols, cols);
    }
    fputc(']', f);
}

void swim_json_string(FILE *f, const char *s)
{
    fputc('"', f);
    for (; *s; s++) {
        unsigned char c = (unsigned char)*s;
        if (c == '"' || c == '\\') fprintf(f, "\\%c", c);
        else if (c == '\n') fputs("\\n", f);
        else if (c < 0x20) fprintf(f, "\\u%04x", c);
        else fputc(c, f);
    }
    fputc('"', f);
}
