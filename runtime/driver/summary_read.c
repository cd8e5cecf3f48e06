#include "driver/summary_read.h"

#include <errno.h>
#include <stdio.h>
#include <string.h>

#include <jansson.h>

#include "io/message.h"

static void say(char *err, size_t errlen, const char *fmt, const char *path, const char *what)
{
    if (err && errlen) snprintf(err, errlen, fmt, path, what);
}

/* The value at a dotted path of object root ("stats.steps"), or NULL when a step is absent or
 * not an object. */
static json_t *at(json_t *root, const char *path)
{
    char key[64];
    json_t *v = root;
    while (v && *path) {
        size_t n = strcspn(path, ".");
        if (n >= sizeof key || !json_is_object(v)) return NULL;
        memcpy(key, path, n);
        key[n] = '\0';
        v = json_object_get(v, key);
        path += n + (path[n] == '.');
    }
    return v;
}

static int real_at(json_t *root, const char *key, swim_summary_real *out, const char *path, char *err, size_t errlen)
{
    json_t *v = at(root, key);
    out->set = 0;
    out->value = 0.0;
    if (!v || json_is_null(v)) return 0;
    if (!json_is_number(v)) {
        say(err, errlen, "%s: %s: expected a number or null", path, key);
        return -1;
    }
    out->set = 1;
    /* + 0.0: the writer prints -0.0 as "-0", which reads back as the integer 0, so a summary's zero
     * is +0 whether it is read from the text or from the tree it was written from */
    out->value = json_number_value(v) + 0.0;
    return 0;
}

static int count_at(json_t *root, const char *key, swim_summary_count *out, const char *path, char *err, size_t errlen)
{
    json_t *v = at(root, key);
    out->set = 0;
    out->value = 0;
    if (!v || json_is_null(v)) return 0;
    if (!json_is_integer(v)) {
        say(err, errlen, "%s: %s: expected an integer or null", path, key);
        return -1;
    }
    out->set = 1;
    out->value = (long long)json_integer_value(v);
    return 0;
}

/* Copies a UTF-8 string into out[len], cut at a character boundary when it does not fit. A byte
 * of no UTF-8 text becomes U+FFFD, as the summary's writer writes it (io/json.c): a tree read
 * before it was written gives the text read after (a text parsed by jansson has none). */
static void copy_utf8(char *out, size_t len, const char *s)
{
    static const char replacement[] = "\xEF\xBF\xBD";
    const unsigned char *p = (const unsigned char *)s;
    const size_t n = strlen(s);
    size_t o = 0;
    for (size_t i = 0; i < n;) {
        unsigned long cp;
        const size_t k = swim_utf8_sequence(p + i, n - i, &cp);
        const char *from = k ? s + i : replacement;
        const size_t m = k ? k : sizeof replacement - 1;
        if (o + m >= len) break;
        memcpy(out + o, from, m);
        o += m;
        i += k ? k : 1;
    }
    out[o] = '\0';
}

static int string_at(json_t *root, const char *key, char *out, size_t len, const char *path, char *err, size_t errlen)
{
    json_t *v = at(root, key);
    out[0] = '\0';
    if (!v || json_is_null(v)) return 0;
    if (!json_is_string(v)) {
        say(err, errlen, "%s: %s: expected a string", path, key);
        return -1;
    }
    copy_utf8(out, len, json_string_value(v));
    return 0;
}

static int take(json_t *root, swim_summary *out, const char *path, char *err, size_t errlen)
{
    memset(out, 0, sizeof *out);
    if (!json_is_object(root)) {
        say(err, errlen, "%s: %s", path, "not a JSON object");
        return -1;
    }
    json_t *status = at(root, "status");
    if (json_is_string(status) && strlen(json_string_value(status)) >= sizeof out->status) {
        say(err, errlen, "%s: %s: not a run's status (too long)", path, "status");
        return -1;
    }
    if (string_at(root, "status", out->status, sizeof out->status, path, err, errlen) ||
        string_at(root, "reason", out->reason, sizeof out->reason, path, err, errlen) ||
        real_at(root, "t_reached", &out->t_reached, path, err, errlen) ||
        real_at(root, "final_state.x", &out->x, path, err, errlen) ||
        real_at(root, "final_state.y", &out->y, path, err, errlen) ||
        real_at(root, "final_state.theta", &out->theta, path, err, errlen) ||
        real_at(root, "energy_drift_rel", &out->energy_drift_rel, path, err, errlen) ||
        real_at(root, "energy_drift_abs", &out->energy_balance_abs, path, err, errlen) ||   /* max |E - E0 - W| */
        real_at(root, "jmin", &out->jmin, path, err, errlen) ||
        count_at(root, "stats.steps", &out->steps, path, err, errlen) ||
        count_at(root, "stats.rhs_evaluations", &out->rhs_evaluations, path, err, errlen) ||
        real_at(root, "stats.integrate_seconds", &out->integrate_seconds, path, err, errlen) ||
        real_at(root, "stats.wall_seconds", &out->wall_seconds, path, err, errlen))
        return -1;
    json_t *rss = at(root, "stats.max_rss_kb");
    out->whole = out->status[0] && (strcmp(out->status, "crashed") == 0 || (rss && !json_is_null(rss)));
    out->stopped = out->whole && (strncmp(out->reason, "interrupted", 11) == 0 ||
                                  strncmp(out->reason, "terminated by", 13) == 0);
    return 0;
}

int swim_summary_read(const char *path, const char *text, swim_summary *out, char *err, size_t errlen)
{
    const char *name = path ? path : "summary.json";
    memset(out, 0, sizeof *out);
    if (err && errlen) err[0] = '\0';
    /* strict: one JSON text and nothing after it, each key once; integers kept apart from reals */
    const size_t flags = JSON_REJECT_DUPLICATES;
    json_error_t je;
    json_t *root;
    if (text) {
        root = json_loads(text, flags, &je);
    } else {
        FILE *f = path ? fopen(path, "rb") : NULL;
        if (!f) {
            const int e = path ? errno : EINVAL;
            say(err, errlen, "%s: %s", name, strerror(e));
            errno = e;
            return SWIM_SUMMARY_UNREADABLE;
        }
        root = json_loadf(f, flags, &je);
        const int e = ferror(f) ? errno : 0;
        fclose(f);
        if (e) {
            json_decref(root);
            say(err, errlen, "%s: %s", name, strerror(e));
            errno = e;
            return SWIM_SUMMARY_UNREADABLE;
        }
    }
    if (!root) {
        if (err && errlen) snprintf(err, errlen, "%s:%d:%d: %s", name, je.line, je.column, je.text);
        return SWIM_SUMMARY_INVALID;
    }
    const int rc = swim_summary_take(root, path, out, err, errlen);
    json_decref(root);
    return rc;
}

int swim_summary_take(json_t *root, const char *path, swim_summary *out, char *err, size_t errlen)
{
    if (err && errlen) err[0] = '\0';
    if (take(root, out, path ? path : "summary.json", err, errlen)) {
        memset(out, 0, sizeof *out);
        return SWIM_SUMMARY_INVALID;
    }
    return SWIM_SUMMARY_OK;
}
