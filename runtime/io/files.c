#define _GNU_SOURCE   /* dladdr */
#include "io/files.h"
#include "io/message.h"

#include <dlfcn.h>
#include <errno.h>
#include <fcntl.h>
#include <limits.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

int swim_mkdirs(const char *path)
{
    char *buf = strdup(path);
    if (!buf) return -1;
    int rc = 0;
    for (char *p = buf + 1; *p && rc == 0; p++)
        if (*p == '/') {
            *p = '\0';
            if (mkdir(buf, 0777) != 0 && errno != EEXIST) rc = -1;
            *p = '/';
        }
    if (rc == 0 && mkdir(buf, 0777) != 0 && errno != EEXIST) rc = -1;
    struct stat st;
    if (rc == 0 && stat(buf, &st) != 0) rc = -1;
    if (rc == 0 && !S_ISDIR(st.st_mode)) {
        errno = ENOTDIR;
        rc = -1;
    }
    int saved = errno;
    free(buf);
    errno = saved;
    return rc;
}

char *swim_path_join(const char *dir, const char *name)
{
    size_t a = strlen(dir), b = strlen(name);
    char *p = malloc(a + b + 2);
    if (!p) return NULL;
    memcpy(p, dir, a);
    p[a] = '/';
    memcpy(p + a + 1, name, b + 1);
    return p;
}

char *swim_canonical_path(const char *path)
{
    char *full = realpath(path, NULL);
    if (full || errno != ENOENT) return full;
    /* Not there yet: resolve the folder, keep the name. */
    char *copy = strdup(path);
    if (!copy) return NULL;
    char *slash = strrchr(copy, '/');
    const char *name = slash ? slash + 1 : copy;
    char *dir = slash ? (slash == copy ? realpath("/", NULL) : (*slash = '\0', realpath(copy, NULL)))
                      : realpath(".", NULL);
    full = dir ? swim_path_join(dir, name) : NULL;
    int saved = errno;
    free(dir);
    free(copy);
    errno = saved;
    return full;
}

static int write_all(int fd, const char *p, size_t len)
{
    while (len > 0) {
        ssize_t k = write(fd, p, len);
        if (k < 0) {
            if (errno == EINTR) continue;
            return -1;
        }
        p += k;
        len -= (size_t)k;
    }
    return 0;
}

static int has_sources(const char *root)
{
    char a[4300], b[4300];
    snprintf(a, sizeof a, "%s/generator/generate.py", root);
    snprintf(b, sizeof b, "%s/runtime/kernel/swim_kernel.h", root);
    return access(a, R_OK) == 0 && access(b, R_OK) == 0;
}

/* Why the search of swim_share_dir failed, for every later call of the thread. */
static void share_missing(swim_status *st, const char *env)
{
    if (env)
        swim_status_fail(st, "swim", NULL, 0, NULL, "SWIM_SHARE=%s holds no generator/generate.py and runtime/kernel/",
                         env);
    else
        swim_status_fail(st, "swim", NULL, 0, NULL, "cannot find the generator (generator/ and runtime/kernel/ next to "
                         "the executable, or PREFIX/share/swim); set SWIM_SHARE");
}

const char *swim_share_dir(swim_status *st)
{
    static _Thread_local char root[4200];
    static _Thread_local int done;
    const char *env = getenv("SWIM_SHARE");
    if (env && !*env) env = NULL;
    if (done) {
        if (!root[0]) share_missing(st, env);
        return root[0] ? root : NULL;
    }
    done = 1;
    if (env) {
        snprintf(root, sizeof root, "%s", env);
        if (has_sources(root)) return root;
        share_missing(st, env);
        root[0] = '\0';
        return NULL;
    }
    /* next to the program (bin/swim, build/tests/x, build/tests/bench/x), else next to the
     * library this code is in (PREFIX/lib/libswim.so: a program of the user's linked with it) */
    char exe[4096];
    ssize_t n = readlink("/proc/self/exe", exe, sizeof exe - 1);
    Dl_info info;
    for (int where = 0; where < 2; where++) {
        if (where == 0 && n <= 0) continue;
        if (where == 0) exe[n] = '\0';
        else if (dladdr((void *)swim_share_dir, &info) && info.dli_fname && info.dli_fname[0] == '/')
            snprintf(exe, sizeof exe, "%s", info.dli_fname);
        else break;
        for (int up = 0; up < 4; up++) {
            char *slash = strrchr(exe, '/');
            if (!slash) break;
            *slash = '\0';
            snprintf(root, sizeof root, "%s/share/swim", exe);
            if (has_sources(root)) return root;
            snprintf(root, sizeof root, "%s", exe);
            if (has_sources(root)) return root;
        }
    }
    root[0] = '\0';
    share_missing(st, NULL);
    return NULL;
}

const char *swim_python(void)
{
    const char *p = getenv("SWIM_PYTHON");
    return p && *p ? p : SWIM_PYTHON;
}

/* A target that exists and is not a regular file: a device such as /dev/null, a FIFO, a
 * terminal. Renaming a new file over it would put a regular file in the device's place, so the
 * data are written to it directly. 0, or -1 with errno set (EISDIR for a folder). */
static int write_in_place(const char *path, const struct stat *st, const void *data, size_t len)
{
    if (S_ISDIR(st->st_mode)) {
        errno = EISDIR;
        return -1;
    }
    int fd = open(path, O_WRONLY | O_NOCTTY | O_CLOEXEC);
    if (fd < 0) return -1;
    int rc = write_all(fd, data, len);
    int saved = errno;
    if (close(fd) != 0 && rc == 0) { rc = -1; saved = errno; }
    errno = saved;
    return rc;
}

int swim_replace_file(const char *path, const void *data, size_t len)
{
    struct stat st;
    if (stat(path, &st) == 0 && !S_ISREG(st.st_mode)) return write_in_place(path, &st, data, len);
    size_t n = strlen(path);
    char *tmp = malloc(n + sizeof ".tmp.XXXXXX");
    if (!tmp) return -1;
    memcpy(tmp, path, n);
    memcpy(tmp + n, ".tmp.XXXXXX", sizeof ".tmp.XXXXXX");
    int fd = mkstemp(tmp);
    if (fd < 0) {
        int saved = errno;
        free(tmp);
        errno = saved;
        return -1;
    }
    mode_t mask = umask(0);   /* mkstemp makes the file 0600; give it the mode fopen would */
    umask(mask);
    int rc = fchmod(fd, 0666 & ~mask);
    if (rc == 0) rc = write_all(fd, data, len);
    if (rc == 0) rc = fsync(fd);
    int saved = errno;
    if (close(fd) != 0 && rc == 0) { rc = -1; saved = errno; }
    if (rc == 0 && rename(tmp, path) != 0) { rc = -1; saved = errno; }
    if (rc != 0) unlink(tmp);
    free(tmp);
    errno = saved;
    return rc;
}

int swim_replace_file_with(const char *path, void (*fill)(FILE *f, void *ctx), void *ctx)
{
    char *buf = NULL;
    size_t len = 0;
    FILE *m = open_memstream(&buf, &len);
    if (!m) return -1;
    fill(m, ctx);
    int bad = ferror(m);
    if (fclose(m) != 0 || bad) {
        free(buf);
        errno = ENOMEM;
        return -1;
    }
    int rc = swim_replace_file(path, buf, len);
    int saved = errno;
    free(buf);
    errno = saved;
    return rc;
}

int swim_still_names(const char *path, const struct stat *st)
{
    struct stat now;
    if (stat(path, &now) != 0) return 0;
    if (now.st_dev != st->st_dev || now.st_ino != st->st_ino) {
        errno = ESTALE;
        return 0;
    }
    return 1;
}

int swim_copy_file(const char *src, const char *dst)
{
    char *a = swim_canonical_path(src), *b = swim_canonical_path(dst);
    int same = a && b && strcmp(a, b) == 0;
    free(a);
    free(b);
    if (same) return 0;
    FILE *in = fopen(src, "rb");
    if (!in) return -1;
    char *buf = NULL;
    size_t len = 0;
    FILE *m = open_memstream(&buf, &len);
    if (!m) {
        fclose(in);
        errno = ENOMEM;
        return -1;
    }
    char chunk[8192];
    size_t k;
    int bad = 0;
    while ((k = fread(chunk, 1, sizeof chunk, in)) > 0)
        if (fwrite(chunk, 1, k, m) != k) { bad = ENOMEM; break; }
    if (!bad && ferror(in)) bad = errno ? errno : EIO;
    fclose(in);
    if (fclose(m) != 0 && !bad) bad = ENOMEM;
    int rc = bad ? -1 : swim_replace_file(dst, buf, len);
    int saved = bad ? bad : errno;
    free(buf);
    errno = saved;
    return rc;
}

char *swim_read_file(const char *path, size_t max, size_t *len)
{
    FILE *f = fopen(path, "rb");
    if (!f) return NULL;
    size_t cap = 4096, n = 0;
    char *buf = malloc(cap + 1);
    while (buf) {
        const size_t got = fread(buf + n, 1, cap - n, f);
        n += got;
        if (n < cap) break;
        if (cap >= max + 1) {   /* more than max bytes */
            free(buf);
            buf = NULL;
            errno = EFBIG;
            break;
        }
        cap = cap * 2 > max + 1 ? max + 1 : cap * 2;
        char *nb = realloc(buf, cap + 1);
        if (!nb) free(buf);
        buf = nb;
    }
    const int bad = buf && ferror(f), saved = errno;
    fclose(f);
    if (bad) {
        free(buf);
        errno = saved ? saved : EIO;
        return NULL;
    }
    if (buf && n > max) {
        free(buf);
        errno = EFBIG;
        return NULL;
    }
    if (buf) {
        buf[n] = '\0';
        if (len) *len = n;
    }
    return buf;
}
