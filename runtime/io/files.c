#include "io/files.h"

#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

int swim_mkdirs(const char *path)
{
    char buf[1024];
    if (snprintf(buf, sizeof buf, "%s", path) >= (int)sizeof buf) {
        errno = ENAMETOOLONG;
        return -1;
    }
    for (char *p = buf + 1; *p; p++)
        if (*p == '/') {
            *p = '\0';
            if (mkdir(buf, 0777) != 0 && errno != EEXIST) return -1;
            *p = '/';
        }
    if (mkdir(buf, 0777) != 0 && errno != EEXIST) return -1;
    struct stat st;
    if (stat(buf, &st) != 0) return -1;
    if (!S_ISDIR(st.st_mode)) {
        errno = ENOTDIR;
        return -1;
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

const char *swim_share_dir(void)
{
    static char root[4200];
    static int done;
    if (done) return root[0] ? root : NULL;
    done = 1;
    const char *env = getenv("SWIM_SHARE");
    if (env && *env) {
        snprintf(root, sizeof root, "%s", env);
        if (has_sources(root)) return root;
        fprintf(stderr, "swim: SWIM_SHARE=%s holds no generator/generate.py and runtime/kernel/\n", env);
        root[0] = '\0';
        return NULL;
    }
    char exe[4096];
    ssize_t n = readlink("/proc/self/exe", exe, sizeof exe - 1);
    if (n > 0) {
        exe[n] = '\0';
        for (int up = 0; up < 4; up++) {   /* bin/swim, build/tests/x, build/tests/bench/x */
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
    fprintf(stderr, "swim: cannot find the generator (generator/ and runtime/kernel/ next to the "
            "executable, or PREFIX/share/swim); set SWIM_SHARE\n");
    return NULL;
}

const char *swim_python(void)
{
    const char *p = getenv("SWIM_PYTHON");
    return p && *p ? p : SWIM_PYTHON;
}

int swim_copy_file(const char *src, const char *dst)
{
    char a[4096], b[4096];
    if (realpath(src, a) && realpath(dst, b) && strcmp(a, b) == 0) return 0;
    FILE *in = fopen(src, "rb");
    if (!in) return -1;
    FILE *out = fopen(dst, "wb");
    if (!out) {
        int e = errno;
        fclose(in);
        errno = e;
        return -1;
    }
    char buf[8192];
    size_t k;
    int bad = 0;
    while ((k = fread(buf, 1, sizeof buf, in)) > 0)
        if (fwrite(buf, 1, k, out) != k) { bad = 1; break; }
    bad |= ferror(in);
    fclose(in);
    if (fclose(out) != 0) bad = 1;
    if (bad && errno == 0) errno = EIO;
    return bad ? -1 : 0;
}
