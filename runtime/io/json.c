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

json_t *swim_json_num(double v) { return isfinite(v) ? json_real(v) : json_null(); }

json_t *swim_json_fmt(const char *fmt, double v)
{
    char buf[64];
    snprintf(buf, sizeof buf, fmt, v);
    return swim_json_num(strtod(buf, NULL));
}

/* without jansson's UTF-8 check: swim_json_string replaces what is not UTF-8 when it writes */
json_t *swim_json_str(const char *s) { return s ? json_string_nocheck(s) : json_null(); }

json_t *swim_json_vec(const double *v, int n)
{
    json_t *a = json_array();
    for (int i = 0; a && i < n; i++)
        if (json_array_append_new(a, swim_json_num(v[i])) != 0) {
            json_decref(a);
            return NULL;
        }
    return a;
}

int swim_json_set(json_t *o, const char *key, json_t *v)
{
    if (!v) return -1;
    return json_object_set_new_nocheck(o, key, v);   /* takes v, also when it fails */
}

static int is_container(const json_t *v) { return json_is_object(v) || json_is_array(v); }

static void write_value(FILE *f, const json_t *v, int indent)
{
    switch (json_typeof(v)) {
    case JSON_OBJECT: {
        /* the top level one key a line: the layout of every summary.json since the first */
        const int lines = indent == 0;
        const char *key;
        json_t *x;
        int first = 1;
        fputc('{', f);
        json_object_foreach((json_t *)v, key, x) {
            fprintf(f, "%s%*s", first ? (lines ? "\n" : "") : (lines ? ",\n" : ", "), lines ? indent + 2 : 0, "");
            swim_json_string(f, key);
            fputs(": ", f);
            write_value(f, x, indent + 2);
            first = 0;
        }
        fprintf(f, "%s%*s}", lines && !first ? "\n" : "", lines && !first ? indent : 0, "");
        break;
    }
    case JSON_ARRAY: {
        const size_t n = json_array_size(v);
        const int lines = n > 0 && is_container(json_array_get(v, 0));   /* events, strokes, periods */
        fputc('[', f);
        for (size_t i = 0; i < n; i++) {
            if (lines) fprintf(f, "%s\n%*s", i ? "," : "", indent + 2, "");
            else if (i) fputs(", ", f);
            write_value(f, json_array_get(v, i), indent + 2);
        }
        if (lines) fprintf(f, "\n%*s", indent, "");
        fputc(']', f);
        break;
    }
    case JSON_STRING: swim_json_string(f, json_string_value(v)); break;
    case JSON_INTEGER: fprintf(f, "%" JSON_INTEGER_FORMAT, json_integer_value(v)); break;
    case JSON_REAL: swim_json_number(f, json_real_value(v)); break;
    case JSON_TRUE: fputs("true", f); break;
    case JSON_FALSE: fputs("false", f); break;
    default: fputs("null", f); break;
    }
}

void swim_json_write(FILE *f, const json_t *v)
{
    write_value(f, v, 0);
    fputc('\n', f);
}
