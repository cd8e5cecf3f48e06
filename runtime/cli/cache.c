/* swim cache path|list|clean: where the kernel cache is, what it holds, and removing entries
 * (runtime/codegen/codegen.h; the security model in docs/trust.md). */
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cli/args.h"
#include "cli/commands.h"
#include "codegen/codegen.h"
#include "io/message.h"
#include "cli/report.h"
#include "scene/keys.h"

/* --older-than D: a number of days, or with a unit s, m, h, d (30d, 12h). 0 or 2. */
static int parse_age(const char *s, double *days)
{
    char *end;
    errno = 0;
    double v = strtod(s, &end);
    double unit = 1.0;
    if (end != s && *end && !end[1]) {
        switch (*end) {
        case 's': unit = 1.0 / 86400; end++; break;
        case 'm': unit = 1.0 / 1440; end++; break;
        case 'h': unit = 1.0 / 24; end++; break;
        case 'd': end++; break;
        }
    }
    if (end == s || *end || errno || !isfinite(v)) {
        swim_message(stderr, "swim cache: --older-than: '%s' is not an age (days, or a number with s, m, h or d)", s);
        return 2;
    }
    const swim_scene_key *k = swim_command_option("cache", "older-than");
    if (!(v * unit >= k->lo && v * unit < k->hi)) {
        swim_message(stderr, "swim cache: --older-than: must be %s, got '%s'", k->expect, s);
        return 2;
    }
    *days = v * unit;
    return 0;
}

/* The structure part of a key (before its build fields), cut to fit a table. */
static void key_summary(const char *key, char *buf, size_t len)
{
    if (!key) {
        snprintf(buf, len, "-");
        return;
    }
    const char *end = strstr(key, " abi=");
    size_t n = end ? (size_t)(end - key) : strlen(key);
    if (n > 72) n = 72;
    snprintf(buf, len, "%.*s%s", (int)n, key, (end ? (size_t)(end - key) : strlen(key)) > n ? "..." : "");
}

/* The report's flush: one line naming the true reason, and main's check after it stays silent
 * (cli/report.h prints once per process). */
static int finish(void) { return swim_stdout_check("cache") != 0; }

int swim_cmd_cache(int argc, char **argv)
{
    swim_opt opts[] = {{"older-than", 1, NULL, "D", "with clean: only entries not used for D days (or a number "
                                                    "with s, m, h or d: 12h, 30d); default: every entry"}};
    const char *pos[2];
    int npos = 0;
    const int prc = swim_args_parse("cache", argc, argv, 2, opts, 1, pos, 2, &npos);
    if (prc) return prc;
    const char *what = npos >= 1 ? pos[0] : NULL;
    if (!what || npos > 1 || (strcmp(what, "path") && strcmp(what, "list") && strcmp(what, "clean"))) {
        swim_message(stderr, "swim cache: expected one of path, list, clean%s%s", what ? ", got " : "", what ? what : "");
        return 2;
    }
    const char *age = swim_args_get(opts, 1, "older-than");
    double days = -1;
    if (age && strcmp(what, "clean") != 0) {
        swim_message(stderr, "swim cache: --older-than goes with clean only");
        return 2;
    }
    if (age && parse_age(age, &days)) return 2;
    char *root = NULL, why[4352];
    int where = swim_cache_location(&root, why, sizeof why);
    if (where < 0) {
        swim_message(stderr, "swim cache: no cache folder: %s", why);
        return 1;
    }
    int rc = 0;
    if (strcmp(what, "path") == 0) {
        printf("%s\n", root);
        if (where > 0) swim_message(stderr, "swim cache: %s is not used: %s", root, why);
    } else if (where > 0) {
        swim_message(stderr, "swim cache: %s is not used, so it is not %s: %s", root,
                     strcmp(what, "list") == 0 ? "listed" : "cleaned", why);
        rc = 1;
    } else if (strcmp(what, "list") == 0) {
        swim_cache_entry *list;
        int count;
        if (swim_cache_entries(root, &list, &count) != 0) {
            swim_message(stderr, "swim cache: cannot read %s: %s", root, strerror(errno));
            free(root);
            return 1;
        }
        long long total = 0;
        printf("%-16s  %-8s  %9s  %8s  %s\n", "entry", "state", "size", "unused", "kernel");
        for (int i = 0; i < count; i++) {
            char summary[96];
            key_summary(list[i].key, summary, sizeof summary);
            printf("%-16s  %-8s  %7.1f k  %6.1f d  %s%s%s\n", list[i].name,
                   list[i].state == 0 ? "sound" : list[i].state > 0 ? "partial" : "damaged",
                   list[i].bytes / 1024.0, list[i].age_days, summary, list[i].state ? "; " : "",
                   list[i].state ? list[i].why : "");
            total += list[i].bytes;
        }
        printf("%d entries, %.1f MB in %s\n", count, total / 1048576.0, root);
        swim_cache_entries_free(list, count);
    } else {
        int removed, busy, foreign;
        long long freed;
        if (swim_cache_clean(root, days, &removed, &busy, &foreign, &freed) != 0) {
            swim_message(stderr, "swim cache: cannot clean %s: %s", root, strerror(errno));
            free(root);
            return 1;
        }
        printf("removed %d entries (%.1f MB) from %s", removed, freed / 1048576.0, root);
        if (busy) printf("; %d in use by a build, kept", busy);
        if (foreign) printf("; %d not entry folders (symbolic links or files), left alone", foreign);
        printf("\n");
    }
    free(root);
    int out = finish();
    return rc ? rc : out;
}
