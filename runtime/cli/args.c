#include "cli/args.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "io/files.h"
#include "io/message.h"
#include "scene/keys.h"

/* Words of text wrapped at `width` columns, each line indented by `indent`. */
static void wrapped(FILE *f, const char *text, int indent, int width)
{
    int col = indent;
    fprintf(f, "%*s", indent, "");
    for (const char *w = text; *w;) {
        while (*w == ' ') w++;
        size_t len = strcspn(w, " ");
        if (!len) break;
        if (col > indent && col + 1 + (int)len > width) {
            fprintf(f, "\n%*s", indent, "");
            col = indent;
        } else if (col > indent) {
            fputc(' ', f);
            col++;
        }
        fprintf(f, "%.*s", (int)len, w);
        col += (int)len;
        w += len;
    }
    fputc('\n', f);
}

void swim_args_help(FILE *f, const swim_opt *opts, int nopts)
{
    fprintf(f, "options:\n");
    for (int i = 0; i < nopts; i++) {
        const swim_opt *o = &opts[i];
        fprintf(f, "  --%s%s%s%s\n", o->name, o->takes_value ? " " : "", o->takes_value ? (o->arg ? o->arg : "VALUE") : "",
                o->takes_value == 2 ? " (repeatable)" : "");
        wrapped(f, o->help ? o->help : "(undocumented)", 6, 100);
    }
    fprintf(f, "  --help\n      print this list of options and exit\n");
}

int swim_args_parse(const char *cmd, int argc, char **argv, int first, swim_opt *opts, int nopts,
                    const char **positional, int npos, int *npos_out)
{
    for (int i = first; i < argc; i++)
        if (strcmp(argv[i], "--help") == 0 || strcmp(argv[i], "-h") == 0) {
            swim_args_help(stdout, opts, nopts);
            return SWIM_ARGS_HELP;
        }
    int np = 0;
    for (int i = first; i < argc; i++) {
        const char *a = argv[i];
        if (strncmp(a, "--", 2) != 0 || a[2] == '\0') {
            if (np >= npos) {
                swim_message(stderr, "swim %s: unexpected argument '%s'", cmd, a);
                return 2;
            }
            positional[np++] = a;
            continue;
        }
        const char *name = a + 2, *eq = strchr(name, '=');
        size_t len = eq ? (size_t)(eq - name) : strlen(name);
        swim_opt *o = NULL;
        for (int k = 0; k < nopts; k++)
            if (strlen(opts[k].name) == len && strncmp(opts[k].name, name, len) == 0) o = &opts[k];
        if (!o) {
            swim_message(stderr, "swim %s: unknown option '--%.*s' (see swim --help)", cmd, (int)len, name);
            return 2;
        }
        if (o->value && o->takes_value != 2) {
            const char *again = eq ? eq + 1 : i + 1 < argc ? argv[i + 1] : "";
            if (o->takes_value)
                swim_message(stderr, "swim %s: option '--%s' given twice ('%s', then '%s'); give it once",
                             cmd, o->name, o->value, again);
            else
                swim_message(stderr, "swim %s: option '--%s' given twice; give it once", cmd, o->name);
            return 2;
        }
        if (!o->takes_value) {
            if (eq) {
                swim_message(stderr, "swim %s: option '--%s' takes no value (got '%s')", cmd, o->name, eq + 1);
                return 2;
            }
            o->value = "";
        } else if (eq) {
            o->value = eq + 1;
        } else if (i + 1 < argc) {
            o->value = argv[++i];   /* may start with '-': lists of numbers do */
        } else {
            swim_message(stderr, "swim %s: option '--%s' needs a value", cmd, o->name);
            return 2;
        }
    }
    if (npos_out) *npos_out = np;
    return 0;
}

int swim_args_take_all(const char *cmd, int *argc, char **argv, int first, const char *name,
                       const char **vals, int cap)
{
    int count = 0, out = first;
    size_t len = strlen(name);
    for (int i = first; i < *argc; i++) {
        const char *a = argv[i];
        if (strncmp(a, "--", 2) != 0 || strncmp(a + 2, name, len) != 0 || (a[2 + len] != '\0' && a[2 + len] != '=')) {
            argv[out++] = argv[i];
            continue;
        }
        const char *v = a[2 + len] == '=' ? a + 3 + len : NULL;
        if (!v) {
            if (i + 1 >= *argc) {
                swim_message(stderr, "swim %s: option '--%s' needs a value", cmd, name);
                return -1;
            }
            v = argv[++i];
        }
        if (count >= cap) {
            swim_message(stderr, "swim %s: more than %d '--%s' options", cmd, cap, name);
            return -1;
        }
        vals[count++] = v;
    }
    *argc = out;
    return count;
}

const char *swim_args_get(const swim_opt *opts, int nopts, const char *name)
{
    for (int k = 0; k < nopts; k++)
        if (strcmp(opts[k].name, name) == 0) return opts[k].value;
    return NULL;
}

static int parse_number(const char *s, size_t len, double *out)
{
    if (len == 0) return -1;
    char *buf = strndup(s, len);   /* strtod needs the item alone, of any length */
    if (!buf) return -1;
    char *end;
    errno = 0;
    double v = strtod(buf, &end);
    int bad = *end != '\0' || end == buf || errno == ERANGE || !isfinite(v);
    free(buf);
    if (bad) return -1;
    *out = v;
    return 0;
}

int swim_args_double(const char *cmd, const char *opt, const char *s, double *out)
{
    if (parse_number(s, strlen(s), out) != 0) {
        swim_message(stderr, "swim %s: --%s: '%s' is not a finite number", cmd, opt, s);
        return 2;
    }
    return 0;
}

int swim_args_int(const char *cmd, const char *opt, const char *s, long lo, long hi, long *out)
{
    char *end;
    errno = 0;
    long v = strtol(s, &end, 10);
    if (*s == '\0' || *end != '\0' || errno == ERANGE) {
        swim_message(stderr, "swim %s: --%s: '%s' is not an integer", cmd, opt, s);
        return 2;
    }
    if (v < lo || v > hi) {
        swim_message(stderr, "swim %s: --%s: %ld is out of range %ld..%ld", cmd, opt, v, lo, hi);
        return 2;
    }
    *out = v;
    return 0;
}

int swim_args_bounded(const char *cmd, const swim_opt *opts, int nopts, const char *opt, double *out)
{
    const char *v = swim_args_get(opts, nopts, opt);
    if (!v) return 0;
    const swim_scene_key *k = swim_command_option(cmd, opt);
    if (!k) {
        swim_message(stderr, "swim %s: --%s: no bounds for this option (scene/keys.c): a bug, please report it", cmd, opt);
        return 2;
    }
    if (k->kind == SWIM_KEY_INTEGER) {
        long n;
        if (swim_args_int(cmd, opt, v, (long)k->lo, (long)k->hi, &n)) return 2;
        *out = (double)n;
        return 0;
    }
    double x;
    if (swim_args_double(cmd, opt, v, &x)) return 2;
    if (!(x >= k->lo && x < k->hi)) {
        swim_message(stderr, "swim %s: --%s: must be %s, got '%s'", cmd, opt, k->expect, v);
        return 2;
    }
    *out = x;
    return 0;
}

int swim_args_steps_bounded(const char *cmd, const char *opt, double value, double output_step)
{
    if (value / output_step <= SWIM_ROWS_MAX) return 0;
    swim_message(stderr, "swim %s: --%s: %g is %.3g output steps of run.output_step = %g, more than %.0e; give at "
                 "most %g", cmd, opt, value, value / output_step, output_step, SWIM_ROWS_MAX, SWIM_ROWS_MAX * output_step);
    return 2;
}

int swim_args_list(const char *cmd, const char *opt, const char *s, double *out, int cap, int *count)
{
    int k = 0;
    const char *p = s;
    for (;;) {
        const char *comma = strchr(p, ',');
        size_t len = comma ? (size_t)(comma - p) : strlen(p);
        double v;
        if (parse_number(p, len, &v) != 0) {
            swim_message(stderr, "swim %s: --%s: item %d ('%.*s') is not a finite number", cmd, opt,
                    k + 1, (int)len, p);
            return 2;
        }
        if (k < cap) out[k] = v;
        k++;
        if (!comma) break;
        p = comma + 1;
    }
    *count = k;
    return 0;
}

int swim_args_take_sets(const char *cmd, int *argc, char **argv, int first, swim_override *sets, int cap)
{
    const char *vals[256];
    const int n = swim_args_take_all(cmd, argc, argv, first, "set", vals, cap < 256 ? cap : 256);
    if (n < 0) return -1;
    for (int i = 0; i < n; i++) {
        char err[256];
        if (swim_override_parse(vals[i], &sets[i], err, sizeof err) != 0) {
            swim_message(stderr, "swim %s: --set: %s", cmd, err);
            return -1;
        }
    }
    return n;
}

char *swim_args_out_dir(const char *given, const char *scene, const char *suffix)
{
    if (given) return strdup(given);
    const char *base = strrchr(scene, '/');
    base = base ? base + 1 : scene;
    return swim_strprintf("out/%.*s-%s", (int)strcspn(base, "."), base, suffix);
}

int swim_args_out_ready(const char *cmd, const char *dir, const char *const *names, int n)
{
    /* the folder, or the nearest of its parents that exists: there a file must be possible */
    char *at = dir ? strdup(dir) : NULL;
    struct stat st;
    int rc = 0;
    if (!at) {
        swim_message(stderr, "swim %s: out of memory", cmd);
        return 2;
    }
    while (stat(at, &st) != 0) {
        char *slash = strrchr(at, '/');
        if (errno != ENOENT || !slash || slash == at) {
            if (errno == ENOENT && !slash) snprintf(at, strlen(at) + 1, ".");
            else if (errno == ENOENT) at[1] = '\0';   /* "/x": the root */
            else {
                swim_message(stderr, "swim %s: --out: %s: %s", cmd, at, strerror(errno));
                free(at);
                return 2;
            }
            continue;
        }
        *slash = '\0';
    }
    const int exists = strcmp(at, dir) == 0;
    if (!S_ISDIR(st.st_mode)) {
        swim_message(stderr, "swim %s: --out: %s: %s is not a folder", cmd, dir, at);
        free(at);
        return 2;
    }
    /* permissions alone do not say it (root, a read-only mount): a file is made and removed */
    char *probe = swim_strprintf("%s/.swim-probe-XXXXXX", at);
    int fd = probe ? mkstemp(probe) : -1;
    if (fd < 0) {
        swim_message(stderr, "swim %s: --out: cannot write into %s: %s", cmd, at, probe ? strerror(errno) : "out of memory");
        rc = 2;
    } else {
        close(fd);
        unlink(probe);
    }
    free(probe);
    free(at);
    for (int i = 0; i < n && rc == 0 && exists; i++) {
        char *path = swim_path_join(dir, names[i]);
        const int folder = path && stat(path, &st) == 0 && S_ISDIR(st.st_mode);
        if (!path || folder) {
            swim_message(stderr, "swim %s: --out: %s%s", cmd, path ? path : "out of memory",
                         folder ? " is a folder, where the command writes a file" : "");
            rc = 2;
        }
        free(path);
    }
    return rc;
}
