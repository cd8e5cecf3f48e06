#include "model/specialize.h"

#include "io/files.h"

#include <dlfcn.h>
#include <errno.h>
#include <stdarg.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

#ifndef SWIM_CC
#define SWIM_CC "cc"
#endif
#ifndef SWIM_KERNEL_CFLAGS
#define SWIM_KERNEL_CFLAGS "-O3 -march=native"
#endif

static uint64_t fnv1a(uint64_t h, const void *data, size_t len)
{
    const unsigned char *p = data;
    for (size_t i = 0; i < len; i++) {
        h ^= p[i];
        h *= 1099511628211ull;
    }
    return h;
}

/* Hash of the generator's sources, so that a changed generator invalidates the cache. */
static uint64_t generator_hash(void)
{
    static const char *const files[] = {"generator/generate.py", "generator/swimgen/model.py",
                                        "generator/swimgen/emit.py", "generator/swimgen/template.py",
                                        "generator/swimgen/cprint.py"};
    uint64_t h = 1469598103934665603ull;
    char path[1024], buf[8192];
    for (size_t i = 0; i < sizeof files / sizeof files[0]; i++) {
        snprintf(path, sizeof path, "%s/%s", SWIM_ROOT, files[i]);
        FILE *f = fopen(path, "rb");
        if (!f) continue;
        size_t n;
        while ((n = fread(buf, 1, sizeof buf, f)) > 0) h = fnv1a(h, buf, n);
        fclose(f);
    }
    return h;
}

static int append(char *buf, size_t len, size_t *at, const char *fmt, ...)
    __attribute__((format(printf, 4, 5)));
static int append(char *buf, size_t len, size_t *at, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    int n = vsnprintf(buf + *at, *at < len ? len - *at : 0, fmt, ap);
    va_end(ap);
    if (n > 0) *at += (size_t)n;
    return n;
}

/* Index lists as JSON arrays: coordinates i with free_mask[i] == want_free and pred(i). */
static void index_list(const swim_scene *s, char *buf, size_t len, size_t *at, int which)
{
    int first = 1;
    append(buf, len, at, "[");
    for (int i = 0; i < s->n; i++) {
        int take = 0;
        switch (which) {
        case 0: take = s->free_mask[i]; break;                                   /* free */
        case 1: take = !s->free_mask[i] && s->c0[i] == 0.0; break;               /* locked at 0 */
        case 2: take = s->free_mask[i] && s->elastic && s->stiffness[i] != 0; break;
        case 3: take = s->free_mask[i] && s->damped && s->damping[i] != 0; break;
        case 4: take = s->free_mask[i] && s->forced && s->direction[i] != 0; break;
        }
        if (take) {
            append(buf, len, at, "%s%d", first ? "" : ", ", i);
            first = 0;
        }
    }
    append(buf, len, at, "]");
}

/* The JSON structure the generator reads; its "key" field is the cache key. */
static int structure_json(const swim_scene *s, char *key, size_t klen, char *json, size_t jlen)
{
    char law[1024] = "";
    if (s->forced && swim_expr_to_c(s->forcing, law, sizeof law) < 0) return -1;
    size_t at = 0;
    append(key, klen, &at, "format=1 abi=%d N=%d free=", SWIM_KERNEL_ABI, s->modes);
    index_list(s, key, klen, &at, 0);
    append(key, klen, &at, " zero=");
    index_list(s, key, klen, &at, 1);
    append(key, klen, &at, " elastic=");
    index_list(s, key, klen, &at, 2);
    append(key, klen, &at, " damping=");
    index_list(s, key, klen, &at, 3);
    append(key, klen, &at, " barrier=%d forcing=", s->barrier);
    index_list(s, key, klen, &at, 4);
    append(key, klen, &at, " law=%s generator=%016llx cflags=%s", s->forced ? law : "-",
           (unsigned long long)generator_hash(), SWIM_KERNEL_CFLAGS);
    if (at >= klen) return -1;
    at = 0;
    append(json, jlen, &at, "{\"format\": 1, \"key\": \"%s\", \"modes\": %d, \"free\": ", key, s->modes);
    index_list(s, json, jlen, &at, 0);
    append(json, jlen, &at, ", \"zero\": ");
    index_list(s, json, jlen, &at, 1);
    append(json, jlen, &at, ", \"elastic\": ");
    index_list(s, json, jlen, &at, 2);
    append(json, jlen, &at, ", \"damping\": ");
    index_list(s, json, jlen, &at, 3);
    append(json, jlen, &at, ", \"barrier\": %s, \"forcing\": ", s->barrier ? "true" : "false");
    if (s->forced) {
        append(json, jlen, &at, "{\"law\": \"");
        for (const char *p = s->forcing_text; *p; p++)   /* the law is printed in a comment */
            if (*p != '"' && *p != '\\' && (unsigned char)*p >= 0x20) append(json, jlen, &at, "%c", *p);
        append(json, jlen, &at, "\", \"c\": \"%s\", \"direction\": ", law);
        index_list(s, json, jlen, &at, 4);
        append(json, jlen, &at, "}");
    } else {
        append(json, jlen, &at, "null");
    }
    append(json, jlen, &at, "}\n");
    return at < jlen ? 0 : -1;
}

int swim_specialize_key(const swim_scene *s, char *buf, size_t len)
{
    char json[8192];
    if (structure_json(s, buf, len, json, sizeof json) != 0) return -1;
    return (int)strlen(buf);
}

static double now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return ts.tv_sec + 1e-9 * ts.tv_nsec;
}

/* Run argv (no shell); its output goes to `log`. Returns the exit status, or -1. */
static int run_command(char *const argv[], const char *log)
{
    pid_t pid = fork();
    if (pid < 0) return -1;
    if (pid == 0) {
        FILE *f = freopen(log, "w", stdout);
        if (f) dup2(fileno(stdout), 2);
        execv(argv[0], argv);
        _exit(127);
    }
    int st;
    while (waitpid(pid, &st, 0) < 0)
        if (errno != EINTR) return -1;
    return WIFEXITED(st) ? WEXITSTATUS(st) : -1;
}

static int read_text(const char *path, char *buf, size_t len)
{
    FILE *f = fopen(path, "rb");
    if (!f) return -1;
    size_t n = fread(buf, 1, len - 1, f);
    fclose(f);
    buf[n] = '\0';
    return 0;
}

static int write_text(const char *path, const char *text)
{
    FILE *f = fopen(path, "w");
    if (!f) return -1;
    int ok = fputs(text, f) >= 0;
    return fclose(f) == 0 && ok ? 0 : -1;
}

static int load(swim_specialized *sp, const char *so, const char *key)
{
    sp->handle = dlopen(so, RTLD_NOW | RTLD_LOCAL);
    if (!sp->handle) return -1;
    sp->kernel = dlsym(sp->handle, "swim_scene_kernel_entry");
    if (!sp->kernel || sp->kernel->abi != SWIM_KERNEL_ABI || strcmp(sp->kernel->structure, key) != 0) {
        dlclose(sp->handle);
        sp->handle = NULL;
        sp->kernel = NULL;
        return -1;
    }
    return 0;
}

int swim_specialize(const swim_scene *s, swim_specialized *sp, int verbose)
{
    memset(sp, 0, sizeof *sp);
    char key[4096], json[8192], path[1200], so[1200], old[4096];
    if (structure_json(s, key, sizeof key, json, sizeof json) != 0) {
        fprintf(stderr, "swim: %s: cannot describe the scene structure for a specialized kernel\n", s->path);
        return -1;
    }
    const char *cache = getenv("SWIM_CACHE");
    uint64_t h = fnv1a(1469598103934665603ull, key, strlen(key));
    snprintf(sp->dir, sizeof sp->dir, "%s/%016llx", cache && *cache ? cache : SWIM_ROOT "/build/cache",
             (unsigned long long)h);
    snprintf(so, sizeof so, "%s/kernel.so", sp->dir);
    snprintf(sp->source, sizeof sp->source, "%s/kernel.c", sp->dir);
    snprintf(path, sizeof path, "%s/key.txt", sp->dir);
    if (read_text(path, old, sizeof old) == 0 && strcmp(old, key) == 0 && load(sp, so, key) == 0) {
        sp->from_cache = 1;
        if (verbose) fprintf(stderr, "swim: specialized kernel from cache %s\n", sp->dir);
        return 0;
    }
    if (swim_mkdirs(sp->dir) != 0) {
        fprintf(stderr, "swim: cannot create kernel cache %s: %s\n", sp->dir, strerror(errno));
        return -1;
    }
    snprintf(path, sizeof path, "%s/structure.json", sp->dir);
    if (write_text(path, json) != 0) {
        fprintf(stderr, "swim: cannot write %s: %s\n", path, strerror(errno));
        return -1;
    }
    char gen[1200], log[1200], tmp[1200], inc[1200];
    snprintf(gen, sizeof gen, "%s/generator/generate.py", SWIM_ROOT);
    snprintf(log, sizeof log, "%s/build.log", sp->dir);
    double t0 = now();
    char *gargv[] = {SWIM_PYTHON, gen, "--scene", path, "--out", sp->source, NULL};
    if (run_command(gargv, log) != 0) {
        fprintf(stderr, "swim: generating the specialized kernel failed (see %s)\n", log);
        return -1;
    }
    double t1 = now();
    snprintf(tmp, sizeof tmp, "%s/kernel.so.%ld", sp->dir, (long)getpid());
    snprintf(inc, sizeof inc, "-I%s/generated", SWIM_ROOT);
    char flags[256];
    snprintf(flags, sizeof flags, "%s", SWIM_KERNEL_CFLAGS);
    char *cargv[32];
    int c = 0;
    cargv[c++] = SWIM_CC;
    for (char *tok = strtok(flags, " "); tok && c < 20; tok = strtok(NULL, " ")) cargv[c++] = tok;
    char *rest[] = {"-std=c11", "-shared", "-fPIC", inc, "-o", tmp, sp->source, "-lm", NULL};
    for (int i = 0; rest[i]; i++) cargv[c++] = rest[i];
    cargv[c] = NULL;
    char cc[1200];
    if (SWIM_CC[0] != '/') {   /* execv needs a path: look the compiler up in PATH */
        const char *pathenv = getenv("PATH");
        char dirs[4096];
        snprintf(dirs, sizeof dirs, "%s", pathenv ? pathenv : "/usr/bin:/bin");
        cc[0] = '\0';
        for (char *d = strtok(dirs, ":"); d; d = strtok(NULL, ":")) {
            snprintf(cc, sizeof cc, "%s/%s", d, SWIM_CC);
            if (access(cc, X_OK) == 0) break;
            cc[0] = '\0';
        }
        if (!cc[0]) {
            fprintf(stderr, "swim: no C compiler '%s' in PATH for the specialized kernel\n", SWIM_CC);
            return -1;
        }
        cargv[0] = cc;
    }
    if (run_command(cargv, log) != 0 || rename(tmp, so) != 0) {
        fprintf(stderr, "swim: compiling the specialized kernel failed (see %s)\n", log);
        unlink(tmp);
        return -1;
    }
    sp->generate_seconds = t1 - t0;
    sp->compile_seconds = now() - t1;
    snprintf(path, sizeof path, "%s/key.txt", sp->dir);
    if (write_text(path, key) != 0 || load(sp, so, key) != 0) {
        fprintf(stderr, "swim: cannot load the specialized kernel %s: %s\n", so, dlerror() ? dlerror() : "bad entry");
        return -1;
    }
    if (verbose)
        fprintf(stderr, "swim: specialized kernel generated in %.2f s, compiled in %.2f s (%s)\n",
                sp->generate_seconds, sp->compile_seconds, sp->dir);
    return 0;
}

void swim_specialized_close(swim_specialized *sp)
{
    if (sp->handle) dlclose(sp->handle);
    sp->handle = NULL;
    sp->kernel = NULL;
}
