#include "codegen/codegen.h"

#include <dirent.h>
#include <dlfcn.h>
#include <errno.h>
#include <fcntl.h>
#include <stdarg.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

#include "io/files.h"
#include "io/json.h"

#ifndef SWIM_CC
#define SWIM_CC "cc"
#endif
#ifndef SWIM_KERNEL_CFLAGS
#define SWIM_KERNEL_CFLAGS "-O3 -march=native"
#endif
/* The kernel of N modes serves diagnostics once per output row and `swim inspect`, not the
 * integration: -O1 compiles its straight-line code about 4x faster than -O3 (N = 32: 36 s
 * against ~150 s of CPU), which is most of its first-use latency. Results are the same: strict
 * C11 (no FP contraction, no fast-math) at every level. */
#define SWIM_KERNEL_CFLAGS_N SWIM_KERNEL_CFLAGS " -O1"
#define MANIFEST_MAGIC "swim-kernel-cache 1"

/* ---- hashing (FNV-1a, 64 bit: detects damage and changes, not an adversary) ------------- */

static uint64_t fnv1a(uint64_t h, const void *data, size_t len)
{
    const unsigned char *p = data;
    for (size_t i = 0; i < len; i++) {
        h ^= p[i];
        h *= 1099511628211ull;
    }
    return h;
}
#define FNV_START 1469598103934665603ull

/* Size and hash of a file's contents; -1 when it cannot be read. */
static int hash_file(const char *path, uint64_t *hash, long long *size)
{
    FILE *f = fopen(path, "rb");
    if (!f) return -1;
    char buf[65536];
    size_t n;
    uint64_t h = FNV_START;
    long long total = 0;
    while ((n = fread(buf, 1, sizeof buf, f)) > 0) {
        h = fnv1a(h, buf, n);
        total += (long long)n;
    }
    int bad = ferror(f);
    fclose(f);
    if (bad) return -1;
    *hash = h;
    *size = total;
    return 0;
}

static int skip_entry(const struct dirent *e)
{
    const char *n = e->d_name;
    size_t len = strlen(n);
    return n[0] != '.' && strcmp(n, "__pycache__") != 0 && !(len > 4 && strcmp(n + len - 4, ".pyc") == 0);
}

/* Every file under `dir` (sorted, recursively; names and contents) folded into h. */
static uint64_t hash_tree(uint64_t h, const char *dir, const char *rel)
{
    struct dirent **list;
    int count = scandir(dir, &list, skip_entry, alphasort);
    if (count < 0) return fnv1a(h, "?", 1);
    for (int i = 0; i < count; i++) {
        char path[SWIM_CODEGEN_PATH], name[SWIM_CODEGEN_PATH];
        snprintf(path, sizeof path, "%s/%s", dir, list[i]->d_name);
        snprintf(name, sizeof name, "%s/%s", rel, list[i]->d_name);
        struct stat st;
        if (stat(path, &st) == 0 && S_ISDIR(st.st_mode)) {
            h = hash_tree(h, path, name);
        } else if (stat(path, &st) == 0 && S_ISREG(st.st_mode)) {
            uint64_t fh;
            long long size;
            h = fnv1a(h, name, strlen(name) + 1);
            if (hash_file(path, &fh, &size) == 0) h = fnv1a(h, &fh, sizeof fh);
        }
        free(list[i]);
    }
    free(list);
    return h;
}

/* ---- where things are ------------------------------------------------------------------ */

/* Hash of everything that shapes the generated code besides the key's own text. */
static uint64_t sources_hash(const char *root)
{
    static uint64_t h;
    static int done;
    if (!done) {
        char dir[SWIM_CODEGEN_PATH];
        h = FNV_START;
        snprintf(dir, sizeof dir, "%s/generator", root);
        h = hash_tree(h, dir, "generator");
        snprintf(dir, sizeof dir, "%s/runtime/kernel", root);
        h = hash_tree(h, dir, "runtime/kernel");
        done = 1;
    }
    return h;
}

static void cache_root(char *buf, size_t len)
{
    const char *c = getenv("SWIM_CACHE"), *x = getenv("XDG_CACHE_HOME"), *home = getenv("HOME");
    if (c && *c) snprintf(buf, len, "%s", c);
    else if (x && *x) snprintf(buf, len, "%s/swim", x);
    else snprintf(buf, len, "%s/.cache/swim", home && *home ? home : "/tmp");
}

/* ---- processes ------------------------------------------------------------------------- */

static double now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return ts.tv_sec + 1e-9 * ts.tv_nsec;
}

/* Run argv (found through PATH, no shell); stdout and stderr go to `log`. Exit status or -1. */
static int run_command(char *const argv[], const char *log)
{
    pid_t pid = fork();
    if (pid < 0) return -1;
    if (pid == 0) {
        int fd = open(log, O_WRONLY | O_CREAT | O_APPEND, 0644);
        if (fd >= 0) {
            dup2(fd, 1);
            dup2(fd, 2);
            close(fd);
        }
        execvp(argv[0], argv);
        fprintf(stderr, "cannot run %s: %s\n", argv[0], strerror(errno));
        _exit(127);
    }
    int st;
    while (waitpid(pid, &st, 0) < 0)
        if (errno != EINTR) return -1;
    return WIFEXITED(st) ? WEXITSTATUS(st) : -1;
}

/* ---- one cache entry ------------------------------------------------------------------- */

typedef struct {
    const char *key;          /* full key text (stored in the manifest) */
    const char *json;         /* scene structure for the generator, or NULL for a kernel of N */
    int modes;
    const char *what;         /* "kernel for N = 20", for messages */
    const char *cflags;       /* compiler flags (part of the key) */
    int stroke;               /* json is a stroke structure (generate.py --stroke) */
} entry_spec;

static int write_atomic(const char *path, const char *text)
{
    char tmp[SWIM_CODEGEN_PATH + 32];
    snprintf(tmp, sizeof tmp, "%s.tmp%ld", path, (long)getpid());
    FILE *f = fopen(tmp, "w");
    if (!f) return -1;
    int ok = fputs(text, f) >= 0;
    ok &= fflush(f) == 0 && fsync(fileno(f)) == 0;
    if (fclose(f) != 0 || !ok || rename(tmp, path) != 0) {
        unlink(tmp);
        return -1;
    }
    return 0;
}

/* Checks the manifest of the entry in `dir` against the files: 0 when sound, 1 when there is no
 * entry yet, -1 when damaged (why in `why`). */
static int verify_entry(const char *dir, const char *key, char *why, size_t len)
{
    char path[SWIM_CODEGEN_PATH + 32];
    snprintf(path, sizeof path, "%s/manifest", dir);
    FILE *f = fopen(path, "r");
    if (!f) {
        snprintf(path, sizeof path, "%s/kernel.so", dir);
        if (access(path, F_OK) != 0) return 1;
        snprintf(why, len, "kernel.so without a manifest (an interrupted build)");
        return -1;
    }
    char magic[64] = "";
    long long csize = -1, ssize = -1;
    unsigned long long chash = 0, shash = 0;
    int ok = fgets(magic, sizeof magic, f) != NULL
          && fscanf(f, "c %lld %llx\nso %lld %llx\nkey ", &csize, &chash, &ssize, &shash) == 4;
    char *stored = NULL;
    size_t cap = 0;
    ssize_t n = ok ? getline(&stored, &cap, f) : -1;
    fclose(f);
    magic[strcspn(magic, "\n")] = '\0';
    if (!ok || n < 0 || strcmp(magic, MANIFEST_MAGIC) != 0) {
        free(stored);
        snprintf(why, len, "unreadable manifest");
        return -1;
    }
    stored[strcspn(stored, "\n")] = '\0';
    int same = strcmp(stored, key) == 0;
    free(stored);
    if (!same) {
        snprintf(why, len, "its manifest is for another key");
        return -1;
    }
    static const char *const files[2] = {"kernel.c", "kernel.so"};
    const long long want_size[2] = {csize, ssize};
    const uint64_t want_hash[2] = {chash, shash};
    for (int i = 0; i < 2; i++) {
        uint64_t h;
        long long size;
        snprintf(path, sizeof path, "%s/%s", dir, files[i]);
        if (hash_file(path, &h, &size) != 0) {
            snprintf(why, len, "%s is missing", files[i]);
            return -1;
        }
        if (size != want_size[i] || h != want_hash[i]) {
            snprintf(why, len, "%s has %lld bytes%s, the manifest says %lld", files[i], size,
                     size == want_size[i] ? " of other content" : "", want_size[i]);
            return -1;
        }
    }
    return 0;
}

static int load_entry(const char *dir, const entry_spec *e, swim_compiled *out)
{
    char so[SWIM_CODEGEN_PATH + 32];
    snprintf(so, sizeof so, "%s/kernel.so", dir);
    out->handle = dlopen(so, RTLD_NOW | RTLD_LOCAL);
    if (!out->handle) return -1;
    if (e->stroke) {
        out->stroke = dlsym(out->handle, "swim_stroke_kernel_entry");
        if (out->stroke && out->stroke->abi == SWIM_STROKE_ABI && strcmp(out->stroke->structure, e->key) == 0)
            return 0;
    } else if (e->json) {
        out->scene = dlsym(out->handle, "swim_scene_kernel_entry");
        if (out->scene && out->scene->abi == SWIM_KERNEL_ABI && strcmp(out->scene->structure, e->key) == 0)
            return 0;
    } else {
        char sym[64];
        snprintf(sym, sizeof sym, "swim_kernel_n%d", e->modes);
        out->kernel = dlsym(out->handle, sym);
        if (out->kernel && out->kernel->modes == e->modes) return 0;
    }
    dlclose(out->handle);
    out->handle = NULL;
    out->scene = NULL;
    out->kernel = NULL;
    out->stroke = NULL;
    return -1;
}

/* Generate and compile into `dir` (lock held). 0; -1 on a failure (message printed);
 * -2 when the folder cannot be written (nothing printed). */
static int build_entry(const char *root, const char *dir, const entry_spec *e, swim_compiled *out)
{
    char path[SWIM_CODEGEN_PATH + 64], log[SWIM_CODEGEN_PATH + 32], tmp[SWIM_CODEGEN_PATH + 128];
    char gen[SWIM_CODEGEN_PATH + 32], inc[SWIM_CODEGEN_PATH + 32], so[SWIM_CODEGEN_PATH + 32];
    snprintf(path, sizeof path, "%s/manifest", dir);
    if (unlink(path) != 0 && errno != ENOENT) return -2;
    snprintf(log, sizeof log, "%s/build.log", dir);
    FILE *lf = fopen(log, "w");
    if (!lf) return -2;
    fclose(lf);
    snprintf(gen, sizeof gen, "%s/generator/generate.py", root);
    snprintf(out->source, sizeof out->source, "%s/kernel.c", dir);
    const char *python = swim_python();
    double t0 = now();
    int rc;
    if (e->json) {
        snprintf(path, sizeof path, "%s/structure.json", dir);
        if (write_atomic(path, e->json) != 0) return -2;
        snprintf(tmp, sizeof tmp, "%s/kernel.c.tmp%ld", dir, (long)getpid());
        char *argv[] = {(char *)python, gen, e->stroke ? "--stroke" : "--scene", path, "--out", tmp, "--quiet", NULL};
        rc = run_command(argv, log);
    } else {
        char modes[16];
        snprintf(modes, sizeof modes, "%d", e->modes);
        snprintf(path, sizeof path, "%s/gen.tmp%ld", dir, (long)getpid());
        char *argv[] = {(char *)python, gen, "--modes", modes, "--out", path, "--quiet", NULL};
        rc = run_command(argv, log);
        snprintf(tmp, sizeof tmp, "%s/swim_kernel_n%d.c", path, e->modes);
    }
    if (rc != 0 || rename(tmp, out->source) != 0) {
        fprintf(stderr, "swim: generating the %s failed (see %s)\n", e->what, log);
        unlink(tmp);
        if (!e->json) rmdir(path);
        return -1;
    }
    if (!e->json) rmdir(path);
    double t1 = now();
    snprintf(tmp, sizeof tmp, "%s/kernel.so.tmp%ld", dir, (long)getpid());
    snprintf(inc, sizeof inc, "-I%s/runtime", root);
    char flags[512];
    snprintf(flags, sizeof flags, "%s", e->cflags);
    char *argv[64];
    int c = 0;
    argv[c++] = SWIM_CC;
    for (char *tok = strtok(flags, " "); tok && c < 48; tok = strtok(NULL, " ")) argv[c++] = tok;
    char *rest[] = {"-std=c11", "-shared", "-fPIC", inc, "-o", tmp, out->source, "-lm", NULL};
    for (int i = 0; rest[i]; i++) argv[c++] = rest[i];
    argv[c] = NULL;
    snprintf(so, sizeof so, "%s/kernel.so", dir);
    if (run_command(argv, log) != 0 || rename(tmp, so) != 0) {
        fprintf(stderr, "swim: compiling the %s failed (see %s)\n", e->what, log);
        unlink(tmp);
        return -1;
    }
    out->generate_seconds = t1 - t0;
    out->compile_seconds = now() - t1;
    /* the manifest last: an entry without one is never loaded */
    uint64_t ch, sh;
    long long cs, ss;
    if (hash_file(out->source, &ch, &cs) != 0 || hash_file(so, &sh, &ss) != 0) return -2;
    size_t mlen = strlen(e->key) + 256;
    char *manifest = malloc(mlen);
    if (!manifest) return -1;
    snprintf(manifest, mlen, "%s\nc %lld %016llx\nso %lld %016llx\nkey %s\n", MANIFEST_MAGIC, cs,
             (unsigned long long)ch, ss, (unsigned long long)sh, e->key);
    snprintf(path, sizeof path, "%s/manifest", dir);
    rc = write_atomic(path, manifest);
    free(manifest);
    return rc == 0 ? 0 : -2;
}

/* Look up or build the entry for e under the cache root `croot`. -2: cannot write there. */
static int obtain_in(const char *croot, const char *root, const entry_spec *e, swim_compiled *out,
                     int verbose)
{
    uint64_t h = fnv1a(FNV_START, e->key, strlen(e->key));
    snprintf(out->dir, sizeof out->dir, "%s/%016llx", croot, (unsigned long long)h);
    char why[256];
    /* a sound entry is used without writing anything (read-only caches work) */
    if (verify_entry(out->dir, e->key, why, sizeof why) == 0 && load_entry(out->dir, e, out) == 0) {
        snprintf(out->source, sizeof out->source, "%s/kernel.c", out->dir);
        out->from_cache = 1;
        if (verbose > 1) fprintf(stderr, "swim: %s from cache %s\n", e->what, out->dir);
        return 0;
    }
    if (swim_mkdirs(out->dir) != 0) return -2;
    char lock[SWIM_CODEGEN_PATH + 16];
    snprintf(lock, sizeof lock, "%s/lock", out->dir);
    int fd = open(lock, O_RDWR | O_CREAT | O_CLOEXEC, 0644);
    if (fd < 0) return -2;
    while (flock(fd, LOCK_EX) != 0)
        if (errno != EINTR) { close(fd); return -2; }
    /* another process may have built it while we waited */
    int state = verify_entry(out->dir, e->key, why, sizeof why);
    if (state == 0 && load_entry(out->dir, e, out) == 0) {
        close(fd);
        snprintf(out->source, sizeof out->source, "%s/kernel.c", out->dir);
        out->from_cache = 1;
        if (verbose > 1) fprintf(stderr, "swim: %s from cache %s (built by another process)\n", e->what, out->dir);
        return 0;
    }
    if (state < 0)
        fprintf(stderr, "swim: kernel cache entry %s is damaged (%s); rebuilding it\n", out->dir, why);
    else if (state == 0)
        fprintf(stderr, "swim: kernel cache entry %s does not load as a %s; rebuilding it\n", out->dir, e->what);
    if (verbose) fprintf(stderr, "swim: generating %s ...\n", e->what);
    int rc = build_entry(root, out->dir, e, out);
    if (rc == 0 && load_entry(out->dir, e, out) != 0) {
        fprintf(stderr, "swim: cannot load the %s %s/kernel.so: %s\n", e->what, out->dir,
                dlerror() ? dlerror() : "wrong entry");
        rc = -1;
    }
    close(fd);
    if (rc == 0 && verbose)
        fprintf(stderr, "swim: %s generated in %.2f s, compiled in %.2f s (%s)\n", e->what,
                out->generate_seconds, out->compile_seconds, out->dir);
    return rc;
}

static int obtain(const entry_spec *e, swim_compiled *out, int verbose)
{
    const char *root = swim_share_dir();
    if (!root) return -1;
    char croot[SWIM_CODEGEN_PATH];
    cache_root(croot, sizeof croot);
    int rc = obtain_in(croot, root, e, out, verbose);
    if (rc != -2) return rc;
    static char priv[64];
    if (!priv[0]) {
        snprintf(priv, sizeof priv, "/tmp/swim-cache-XXXXXX");
        if (!mkdtemp(priv)) {
            priv[0] = '\0';
            fprintf(stderr, "swim: kernel cache %s cannot be written and no temporary folder could be made: %s\n",
                    croot, strerror(errno));
            return -1;
        }
    }
    fprintf(stderr, "swim: kernel cache %s cannot be written; using %s for this run\n", croot, priv);
    rc = obtain_in(priv, root, e, out, verbose);
    if (rc == -2) fprintf(stderr, "swim: cannot write the kernel cache %s either\n", priv);
    return rc == 0 ? 0 : -1;
}

/* ---- keys ------------------------------------------------------------------------------ */

static char *key_suffix(const char *cflags)
{
    const char *root = swim_share_dir();
    char *s = NULL;
    size_t len;
    FILE *f = open_memstream(&s, &len);
    if (!f) return NULL;
    fprintf(f, " abi=%d sources=%016llx cc=%s cflags=%s", SWIM_KERNEL_ABI,
            (unsigned long long)(root ? sources_hash(root) : 0), SWIM_CC, cflags);
    fclose(f);
    return s;
}

int swim_codegen_kernel(int modes, swim_compiled *out, int verbose)
{
    memset(out, 0, sizeof *out);
    if (modes < 0 || modes > SWIM_KERNEL_MAX_MODES) {
        fprintf(stderr, "swim: N = %d is out of range 0..%d\n", modes, SWIM_KERNEL_MAX_MODES);
        return -1;
    }
    if ((out->kernel = swim_kernel_find(modes))) return 0;   /* linked in */
    char *suffix = key_suffix(SWIM_KERNEL_CFLAGS_N), key[1024], what[64];
    if (!suffix) return -1;
    snprintf(key, sizeof key, "kernel N=%d%s", modes, suffix);
    free(suffix);
    snprintf(what, sizeof what, "kernel for N = %d", modes);
    entry_spec e = {key, NULL, modes, what, SWIM_KERNEL_CFLAGS_N, 0};
    return obtain(&e, out, verbose);
}

/* Indices i of the shape vector for which pick(s, i) holds, as a JSON array. */
static void index_list(FILE *f, const swim_scene *s, int generic, int which)
{
    int first = 1;
    fputc('[', f);
    for (int i = 0; i < s->n; i++) {
        int take = 0;
        const int fr = generic || s->free_mask[i];
        switch (which) {
        case 0: take = fr; break;                                              /* carried */
        case 1: take = !fr && s->c0[i] == 0.0; break;                         /* locked at 0 */
        case 2: take = generic || (fr && s->elastic && s->stiffness[i] != 0); break;
        case 3: take = generic || (fr && s->damped && s->damping[i] != 0); break;
        case 4: take = s->forced && (generic || (fr && s->direction[i] != 0)); break;
        }
        if (take) {
            fprintf(f, "%s%d", first ? "" : ", ", i);
            first = 0;
        }
    }
    fputc(']', f);
}

/* The structure as JSON for the generator; with key == NULL, the key itself (no "key" field). */
static char *structure_text(const swim_scene *s, int generic, const char *key)
{
    char *text = NULL;
    size_t len;
    FILE *f = open_memstream(&text, &len);
    if (!f) return NULL;
    fprintf(f, "{\"format\": 2, ");
    if (key) {
        fprintf(f, "\"key\": ");
        swim_json_string(f, key);
        fprintf(f, ", ");
    }
    static const char *const names[] = {"free", "zero", "elastic", "damping"};
    fprintf(f, "\"modes\": %d, \"multipliers\": %s", s->modes, generic ? "true" : "false");
    for (int w = 0; w < 4; w++) {
        fprintf(f, ", \"%s\": ", names[w]);
        index_list(f, s, generic, w);
    }
    fprintf(f, ", \"barrier\": %s, \"forcing\": ", generic || s->barrier ? "true" : "false");
    if (s->forced) {
        fprintf(f, "{\"law\": ");
        swim_json_string(f, s->forcing_text);
        fprintf(f, ", \"direction\": ");
        index_list(f, s, generic, 4);
        if (s->nparams > 0) {   /* the names only: values are run-time (law_params) */
            fprintf(f, ", \"parameters\": [");
            for (int i = 0; i < s->nparams; i++) {
                if (i) fprintf(f, ", ");
                swim_json_string(f, s->param_names[i]);
            }
            fprintf(f, "]");
        }
        fprintf(f, "}");
    } else {
        fprintf(f, "null");
    }
    fprintf(f, "}\n");
    fclose(f);
    return text;
}

char *swim_codegen_scene_key(const swim_scene *s, int generic)
{
    char *structure = structure_text(s, generic, NULL), *suffix = key_suffix(SWIM_KERNEL_CFLAGS);
    char *key = NULL;
    if (structure && suffix) {
        structure[strcspn(structure, "\n")] = '\0';
        size_t len = strlen(structure) + strlen(suffix) + 16;
        key = malloc(len);
        if (key) snprintf(key, len, "scene %s%s", structure, suffix);
    }
    free(structure);
    free(suffix);
    return key;
}

int swim_codegen_scene(const swim_scene *s, int generic, swim_compiled *out, int verbose)
{
    memset(out, 0, sizeof *out);
    out->generic = generic;
    char *key = swim_codegen_scene_key(s, generic);
    char *json = key ? structure_text(s, generic, key) : NULL;
    if (!json) {
        free(key);
        fprintf(stderr, "swim: %s: out of memory describing the scene structure\n", s->path);
        return -1;
    }
    int nfree = 0;
    for (int i = 0; i < s->n; i++) nfree += generic || s->free_mask[i];
    char what[128];
    snprintf(what, sizeof what, "%s kernel for N = %d (%d coordinates)", generic ? "generic scene" : "scene",
             s->modes, nfree);
    entry_spec e = {key, json, s->modes, what, SWIM_KERNEL_CFLAGS, 0};
    int rc = obtain(&e, out, verbose);
    free(key);
    free(json);
    return rc;
}

void swim_compiled_close(swim_compiled *c)
{
    if (c->handle) dlclose(c->handle);
    c->handle = NULL;
    c->kernel = NULL;
    c->scene = NULL;
    c->stroke = NULL;
}

/* ---- prescribed strokes --------------------------------------------------------------------- */

/* The stroke structure as JSON (generator/swimgen/stroke.py); with key == NULL the key itself. */
static char *stroke_text(const swim_scene *s, const char *key)
{
    char *text = NULL;
    size_t len;
    FILE *f = open_memstream(&text, &len);
    if (!f) return NULL;
    fprintf(f, "{\"format\": 1, ");
    if (key) {
        fprintf(f, "\"key\": ");
        swim_json_string(f, key);
        fprintf(f, ", ");
    }
    fprintf(f, "\"modes\": %d, \"laws\": [", s->modes);
    for (int k = 0; k < s->stroke_count; k++) {
        fprintf(f, "%s[%d, ", k ? ", " : "", s->stroke_index[k]);
        swim_json_string(f, s->stroke_law[k]);
        fputc(']', f);
    }
    fprintf(f, "], \"parameters\": [");   /* the names only: values are run-time (par[i]) */
    for (int i = 0; i < s->nparams; i++) {
        if (i) fprintf(f, ", ");
        swim_json_string(f, s->param_names[i]);
    }
    fprintf(f, "]}\n");
    fclose(f);
    return text;
}

int swim_codegen_stroke(const swim_scene *s, swim_compiled *out, int verbose)
{
    memset(out, 0, sizeof *out);
    char *structure = stroke_text(s, NULL), *suffix = key_suffix(SWIM_KERNEL_CFLAGS), *key = NULL, *json = NULL;
    if (structure && suffix) {
        structure[strcspn(structure, "\n")] = '\0';
        size_t len = strlen(structure) + strlen(suffix) + 16;
        if ((key = malloc(len))) snprintf(key, len, "stroke %s%s", structure, suffix);
    }
    if (key) json = stroke_text(s, key);
    free(structure);
    free(suffix);
    if (!json) {
        free(key);
        fprintf(stderr, "swim: %s: out of memory describing the stroke\n", s->path);
        return -1;
    }
    char what[128];
    snprintf(what, sizeof what, "stroke kernel for N = %d (%d laws)", s->modes, s->stroke_count);
    entry_spec e = {key, json, s->modes, what, SWIM_KERNEL_CFLAGS, 1};
    int rc = obtain(&e, out, verbose);
    free(key);
    free(json);
    return rc;
}
