#include "io/json.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "io/message.h"

int swim_number_text(char *buf, size_t len, double v)
{
    if (!isfinite(v)) return snprintf(buf, len, "%s", isnan(v) ? "nan" : v > 0 ? "inf" : "-inf");
    int n = 0;
    for (int prec = 15; prec <= 17; prec++) {
        n = snprintf(buf, len, "%.*g", prec, v);
        if (strtod(buf, NULL) == v) break;
    }
    return n;
}

void swim_number_print(FILE *f, double v)
{
    char buf[32];
    swim_number_text(buf, sizeof buf, v);
    fputs(buf, f);
}

void swim_json_number(FILE *f, double v)
{
    if (isfinite(v))
        swim_number_print(f, v);
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
    const unsigned char *p = (const unsigned char *)s;
    size_t len = strlen(s);
    fputc('"', f);
    for (size_t i = 0; i < len;) {
        unsigned long cp;
        size_t k = swim_utf8_sequence(p + i, len - i, &cp);
        if (k == 0) {   /* a byte of no UTF-8 text (file names may hold any): JSON needs UTF-8 */
            fputs("\\ufffd", f);
            i++;
            continue;
        }
        if (cp == '"' || cp == '\\') fprintf(f, "\\%c", (int)cp);
        else if (cp == '\n') fputs("\\n", f);
        else if (cp < 0x20 || cp == 0x7F) fprintf(f, "\\u%04lx", cp);
        else fwrite(p + i, 1, k, f);
        i += k;
    }
    fputc('"', f);
}
