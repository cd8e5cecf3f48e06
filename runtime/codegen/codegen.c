/* memfd_create (Linux): a loaded kernel is a private copy, see load_entry */
#define _GNU_SOURCE
#include "codegen/codegen.h"
#include "codegen/structure.h"

#include <dirent.h>
#include <dlfcn.h>
#include <errno.h>
#include <fcntl.h>
#include <stdarg.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <pwd.h>
#include <signal.h>
#include <sys/file.h>
#include <sys/mman.h>
#include <sys/prctl.h>
#include <sys/stat.h>
#include <sys/utsname.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

#include "io/clock.h"
#include "io/files.h"
#include "io/json.h"
#include "io/message.h"

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

/* Size and hash of what can be read from fd (to its end); with copy >= 0 each block is also
 * written there. -1 on a read error, -2 on a write error. */
static int hash_fd(int fd, uint64_t *hash, long long *size, int copy)
{
    char buf[65536];
    ssize_t n;
    uint64_t h = FNV_START;
    long long total = 0;
    while ((n = read(fd, buf, sizeof buf)) != 0) {
        if (n < 0) {
            if (errno == EINTR) continue;
            return -1;
        }
        h = fnv1a(h, buf, (size_t)n);
        total += n;
        for (ssize_t done = 0; copy >= 0 && done < n;) {
            ssize_t w = write(copy, buf + done, (size_t)(n - done));
            if (w < 0 && errno != EINTR) return -2;
            if (w > 0) done += w;
        }
    }
    *hash = h;
    *size = total;
    return 0;
}

/* Size and hash of a file's contents; -1 when it cannot be read. */
static int hash_file(const char *path, uint64_t *hash, long long *size)
{
    int fd = open(path, O_RDONLY | O_CLOEXEC);
    if (fd < 0) return -1;
    int rc = hash_fd(fd, hash, size, -1);
    close(fd);
    return rc;
}

static int skip_entry(const struct dirent *e)
{
    const char *n = e->d_name;
    size_t len = strlen(n);
    return n[0] != '.' && strcmp(n, "__pycache__") != 0 && !(len > 4 && strcmp(n + len - 4, ".pyc") == 0);
}

/* Every file under `dir` (sorted, recursively) folded into h: its name and, with contents, what
 * it holds, else its stamp (size, modification time in ns, inode, device: what changes when the
 * file is written or replaced, found without reading it). */
static uint64_t hash_tree(uint64_t h, const char *dir, const char *rel, int contents)
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
            h = hash_tree(h, path, name, contents);
        } else if (stat(path, &st) == 0 && S_ISREG(st.st_mode)) {
            uint64_t fh;
            long long size;
            h = fnv1a(h, name, strlen(name) + 1);
            if (!contents) {
                const long long stamp[5] = {(long long)st.st_size, (long long)st.st_mtim.tv_sec,
                                            (long long)st.st_mtim.tv_nsec, (long long)st.st_ino, (long long)st.st_dev};
                h = fnv1a(h, stamp, sizeof stamp);
            } else if (hash_file(path, &fh, &size) == 0) {
                h = fnv1a(h, &fh, sizeof fh);
            }
        }
        free(list[i]);
    }
    free(list);
    return h;
}

/* ---- where things are ------------------------------------------------------------------ */

/* The folders whose files shape the generated code besides the key's own text, hashed by
 * contents or by stamps (hash_tree). */
static uint64_t sources_tree(const char *root, int contents)
{
    char dir[SWIM_CODEGEN_PATH];
    uint64_t h = FNV_START;
    snprintf(dir, sizeof dir, "%s/generator", root);
    h = hash_tree(h, dir, "generator", contents);
    snprintf(dir, sizeof dir, "%s/runtime/kernel", root);
    return hash_tree(h, dir, "runtime/kernel", contents);
}

static int identity_recall(const char *kind, const char *stamp, char *value, size_t len);
static void identity_keep(const char *kind, const char *stamp, const char *value);

/* Hash of the contents of sources_tree, read again only when a stamp there changed (the last
 * hash is kept with the stamps in the cache, identity_recall). Computed once per thread. */
static uint64_t sources_hash(const char *root)
{
    static _Thread_local uint64_t h;
    static _Thread_local int done;
    if (!done) {
        char stamp[SWIM_CODEGEN_PATH + 32], kept[32];
        snprintf(stamp, sizeof stamp, "%016llx %s", (unsigned long long)sources_tree(root, 0), root);
        char *end = NULL;
        if (identity_recall("sources", stamp, kept, sizeof kept) == 0 && strlen(kept) == 16)
            h = strtoull(kept, &end, 16);
        if (!end || *end) {
            h = sources_tree(root, 1);
            snprintf(kept, sizeof kept, "%016llx", (unsigned long long)h);
            identity_keep("sources", stamp, kept);
        }
        done = 1;
    }
    return h;
}

/* The cache root: $SWIM_CACHE, $XDG_CACHE_HOME/swim, $HOME/.cache/swim, or the home folder of
 * the effective user from the password database. 0, or -1 when there is none (no HOME and no
 * password entry): then no shared folder is used at all, only a private one per run -- a fixed
 * fallback such as /tmp/.cache would be a folder another local user could prepare. */
static int cache_root(char *buf, size_t len)
{
    const char *c = getenv("SWIM_CACHE"), *x = getenv("XDG_CACHE_HOME"), *home = getenv("HOME");
    if (c && *c) return snprintf(buf, len, "%s", c) < (int)len ? 0 : -1;
    if (x && *x == '/') return snprintf(buf, len, "%s/swim", x) < (int)len ? 0 : -1;
    if (!(home && *home == '/')) {
        struct passwd pw, *found = NULL;
        char pwbuf[4096];
        if (getpwuid_r(geteuid(), &pw, pwbuf, sizeof pwbuf, &found) != 0 || !found || !pw.pw_dir
            || pw.pw_dir[0] != '/')
            return -1;
        return snprintf(buf, len, "%s/.cache/swim", pw.pw_dir) < (int)len ? 0 : -1;
    }
    return snprintf(buf, len, "%s/.cache/swim", home) < (int)len ? 0 : -1;
}

/* ---- trust: who can have written what is loaded ------------------------------------------
 * A kernel.so is code that runs in this process, so it is loaded only from files and folders
 * that nobody but this user (or root, who can replace swim itself) can have written. */

static int trusted_uid(uid_t uid) { return uid == geteuid() || uid == 0; }

/* A file or folder this user or root owns and that neither group nor others may write.
 * 0, or -1 with the reason in why. */
static int private_stat(const struct stat *st, const char *path, char *why, size_t len)
{
    if (!trusted_uid(st->st_uid)) {
        snprintf(why, len, "%s belongs to another user (uid %ld)", path, (long)st->st_uid);
        return -1;
    }
    if (st->st_mode & (S_IWGRP | S_IWOTH)) {
        snprintf(why, len, "%s can be written by %s (mode %03o)", path,
                 (st->st_mode & S_IWOTH) ? "every user" : "its group", (unsigned)(st->st_mode & 0777));
        return -1;
    }
    return 0;
}

/* The cache root and the folders above it: the root private (private_stat), every folder above
 * it this user's or root's, and writable by others only with the sticky bit (as /tmp is), so
 * that nobody else can rename the root away and put another in its place. 0, or -1 (why). */
static int trusted_root(const char *croot, char *why, size_t len)
{
    char *real = realpath(croot, NULL);
    if (!real) {
        snprintf(why, len, "%s cannot be resolved: %s", croot, strerror(errno));
        return -1;
    }
    struct stat st;
    int rc = 0;
    if (stat(real, &st) != 0 || !S_ISDIR(st.st_mode)) {
        snprintf(why, len, "%s is not a folder", real);
        rc = -1;
    } else {
        rc = private_stat(&st, real, why, len);
    }
    for (char *slash = strrchr(real, '/'); rc == 0 && slash; slash = strrchr(real, '/')) {
        if (slash == real) slash[1] = '\0';
        else *slash = '\0';
        if (stat(real, &st) != 0) {
            snprintf(why, len, "%s cannot be read: %s", real, strerror(errno));
            rc = -1;
        } else if (!trusted_uid(st.st_uid)) {
            snprintf(why, len, "the folder above it, %s, belongs to another user (uid %ld)", real, (long)st.st_uid);
            rc = -1;
        } else if ((st.st_mode & (S_IWGRP | S_IWOTH)) && !(st.st_mode & S_ISVTX)) {
            snprintf(why, len, "the folder above it, %s, can be written by others without the sticky bit", real);
            rc = -1;
        }
        if (slash == real) break;
    }
    free(real);
    return rc;
}

/* The process (or the system) is out of descriptors or memory: a file that cannot be opened
 * now says nothing about the entry, which must not be taken for damaged and rebuilt. */
static int out_of_resources(int e) { return e == EMFILE || e == ENFILE || e == ENOMEM; }

/* Opens dir/name for reading only if it is a regular file (no symbolic link) that private_stat
 * accepts; its fstat in *st. The descriptor, or -1 (why; *absent 1 when it does not exist, -1
 * when it could not be opened for want of descriptors or memory). */
static int open_trusted(const char *dir, const char *name, struct stat *st, int *absent, char *why, size_t len)
{
    char path[SWIM_CODEGEN_PATH + 32];
    snprintf(path, sizeof path, "%s/%s", dir, name);
    *absent = 0;
    int fd = open(path, O_RDONLY | O_NOFOLLOW | O_CLOEXEC);
    if (fd < 0) {
        *absent = errno == ENOENT ? 1 : out_of_resources(errno) ? -1 : 0;
        snprintf(why, len, "%s %s", name, errno == ENOENT ? "is missing" : errno == ELOOP ? "is a symbolic link" : strerror(errno));
        return -1;
    }
    if (fstat(fd, st) != 0 || !S_ISREG(st->st_mode)) {
        snprintf(why, len, "%s is not a regular file", name);
        close(fd);
        return -1;
    }
    if (private_stat(st, path, why, len) != 0) {
        close(fd);
        return -1;
    }
    return fd;
}

/* Makes the folders of path that do not exist, private to this user (mode 0700). 0, or -1. */
static int make_private_dirs(const char *path)
{
    char *buf = strdup(path);
    if (!buf) return -1;
    int rc = 0;
    for (char *p = buf + 1; rc == 0; p++) {
        if (*p != '/' && *p != '\0') continue;
        const char keep = *p;
        *p = '\0';
        if (mkdir(buf, 0700) != 0 && errno != EEXIST) rc = -1;
        *p = keep;
        if (keep == '\0') break;
    }
    struct stat st;
    if (rc == 0 && (stat(buf, &st) != 0 || !S_ISDIR(st.st_mode))) rc = -1;
    free(buf);
    return rc;
}

/* Removes what the folder open at dfd holds whose name contains `part` (everything when part
 * is NULL), sub-folders with their contents. Every step is relative to an open folder and
 * none follows a symbolic link: a link is removed itself, never what it points to, so a link
 * planted in the cache cannot turn a clean into the removal of a folder outside it. */
static void remove_entries_at(int dfd, const char *part)
{
    const int iter = dup(dfd);
    DIR *d = iter >= 0 ? fdopendir(iter) : NULL;
    if (!d) {
        if (iter >= 0) close(iter);
        return;
    }
    struct dirent *e;
    while ((e = readdir(d))) {
        if (strcmp(e->d_name, ".") == 0 || strcmp(e->d_name, "..") == 0) continue;
        if (part && !strstr(e->d_name, part)) continue;
        struct stat st;
        if (fstatat(dfd, e->d_name, &st, AT_SYMLINK_NOFOLLOW) == 0 && S_ISDIR(st.st_mode)) {
            const int sub = openat(dfd, e->d_name, O_RDONLY | O_DIRECTORY | O_NOFOLLOW | O_CLOEXEC);
            if (sub >= 0) {
                remove_entries_at(sub, NULL);
                close(sub);
            }
            unlinkat(dfd, e->d_name, AT_REMOVEDIR);
        } else {
            unlinkat(dfd, e->d_name, 0);
        }
    }
    closedir(d);
}

/* The same for the folder at `dir`, which must be a folder itself, not a link to one. */
static void remove_entries(const char *dir, const char *part)
{
    const int fd = open(dir, O_RDONLY | O_DIRECTORY | O_NOFOLLOW | O_CLOEXEC);
    if (fd < 0) return;
    remove_entries_at(fd, part);
    close(fd);
}

/* Removes a private folder of this run with what it holds. */
static void remove_private(const char *dir)
{
    remove_entries(dir, NULL);
    rmdir(dir);
}

/* ---- what a key says of the compiler and the sources, kept between runs --------------------
 * The compiler's version costs a child process (cc --version) and the sources' hash reads every
 * file of generator/ and runtime/kernel/; both change only when files change. So each is kept in
 * the cache root's .identity (a dot name: never an entry, untouched by `swim cache clean`) with
 * a stamp of what it was found from, and found again only when the stamp differs: for the
 * compiler the program the PATH search finds, its resolved path, size, modification time (ns),
 * inode and device; for the sources the same of every file (hash_tree). .identity is read only
 * from a root trusted_root accepts and as open_trusted opens a kernel: whoever could alter it
 * could alter the kernels themselves. One line per kind: "KIND STAMP<tab>VALUE". */

#define IDENTITY_FILE ".identity"
#define IDENTITY_MAX 8192

/* The trusted cache root in buf, or -1 (none, or not trusted: nothing is kept); made first
 * (private, as obtain makes it) when `make`, else -1 when it does not exist yet. */
static int identity_root(char *buf, size_t len, int make)
{
    char why[SWIM_CODEGEN_PATH + 128];
    struct stat st;
    if (cache_root(buf, len) != 0 || (make ? make_private_dirs(buf) : stat(buf, &st)) != 0) return -1;
    return trusted_root(buf, why, sizeof why);
}

/* The identity file's text (at most IDENTITY_MAX - 1 bytes) in text; "" when there is none. */
static void identity_text(const char *root, char *text, size_t len)
{
    struct stat st;
    int absent;
    char why[SWIM_CODEGEN_PATH + 128];
    text[0] = '\0';
    const int fd = open_trusted(root, IDENTITY_FILE, &st, &absent, why, sizeof why);
    if (fd < 0) return;
    size_t got = 0;
    for (ssize_t n; got + 1 < len && (n = read(fd, text + got, len - 1 - got)) != 0;) {
        if (n < 0 && errno == EINTR) continue;
        if (n < 0) {
            got = 0;
            break;
        }
        got += (size_t)n;
    }
    text[got] = '\0';
    close(fd);
}

/* The line of `kind` in text, or NULL. */
static char *identity_line(char *text, const char *kind)
{
    const size_t k = strlen(kind);
    for (char *line = text; line && *line; line = strchr(line, '\n') ? strchr(line, '\n') + 1 : NULL)
        if (strncmp(line, kind, k) == 0 && line[k] == ' ') return line;
    return NULL;
}

/* The value kept for kind with this stamp, in value: 0, or -1 (none kept, or with another stamp). */
static int identity_recall(const char *kind, const char *stamp, char *value, size_t len)
{
    char root[SWIM_CODEGEN_PATH], text[IDENTITY_MAX];
    if (identity_root(root, sizeof root, 0) != 0) return -1;
    identity_text(root, text, sizeof text);
    char *line = identity_line(text, kind);
    if (!line) return -1;
    line += strlen(kind) + 1;
    char *tab = strchr(line, '\t'), *eol = strchr(line, '\n');
    if (!tab || !eol || tab > eol || (size_t)(tab - line) != strlen(stamp) || strncmp(line, stamp, strlen(stamp)) != 0)
        return -1;
    snprintf(value, len, "%.*s", (int)(eol - tab - 1), tab + 1);
    return 0;
}

/* Keeps value for kind with this stamp (the other kinds' lines as they are), written whole
 * under a temporary name and renamed: a reader sees the old file or the new one. Best effort:
 * a cache that cannot be written only means the value is found again next time. */
static void identity_keep(const char *kind, const char *stamp, const char *value)
{
    char root[SWIM_CODEGEN_PATH], text[IDENTITY_MAX], tmp[SWIM_CODEGEN_PATH + 64], path[SWIM_CODEGEN_PATH + 32];
    if (strpbrk(stamp, "\t\n") || strpbrk(value, "\t\n") || identity_root(root, sizeof root, 1) != 0) return;
    identity_text(root, text, sizeof text);
    char *line = identity_line(text, kind);
    if (line) {   /* this kind's old line goes */
        char *eol = strchr(line, '\n');
        memmove(line, eol ? eol + 1 : line + strlen(line), strlen(eol ? eol + 1 : line + strlen(line)) + 1);
    }
    snprintf(tmp, sizeof tmp, "%s/%s.%ld.tmp", root, IDENTITY_FILE, (long)getpid());
    snprintf(path, sizeof path, "%s/%s", root, IDENTITY_FILE);
    const int fd = open(tmp, O_WRONLY | O_CREAT | O_EXCL | O_NOFOLLOW | O_CLOEXEC, 0600);
    if (fd < 0) return;
    FILE *f = fdopen(fd, "w");
    if (!f) {
        close(fd);
        unlink(tmp);
        return;
    }
    fprintf(f, "%s%s %s\t%s\n", text, kind, stamp, value);
    if (fclose(f) != 0 || rename(tmp, path) != 0) unlink(tmp);
}

/* ---- processes ------------------------------------------------------------------------- */


/* The calling thread's hooks (swim_codegen_set_hooks); all NULL: a build is silent and runs
 * its children to their end. The library installs no signal handler: a program that wants its
 * stop signals to reach a generator says so through these hooks. */
static _Thread_local swim_codegen_hooks hooks;

void swim_codegen_set_hooks(const swim_codegen_hooks *h)
{
    if (h) hooks = *h;
    else memset(&hooks, 0, sizeof hooks);
}

/* A line of progress or a notice, to the program's note hook (nothing without one). */
static void say(const char *fmt, ...) __attribute__((format(printf, 1, 2)));
static void say(const char *fmt, ...)
{
    if (!hooks.note) return;
    va_list ap;
    va_start(ap, fmt);
    char *line = swim_vstrprintf(fmt, ap);
    va_end(ap);
    if (line) hooks.note(hooks.ctx, line);
    free(line);
}

/* Run argv (found through PATH, no shell); stdout and stderr go to `log`. Exit status or -1.
 * While the child runs the program's stop flag (hooks.stop) is polled: once set, the child is
 * sent SIGTERM and waited for, and *stopped gets the flag's value, so that the caller removes
 * its temporary files and reports the build interrupted. The child also ends with its parent
 * (PR_SET_PDEATHSIG): no generator runs on, writing into the cache, after the process that
 * wanted it is gone. */
static int run_command(char *const argv[], const char *log, int *stopped)
{
    const pid_t parent = getpid();
    *stopped = 0;
    pid_t pid = fork();
    if (pid == 0) {
        prctl(PR_SET_PDEATHSIG, SIGTERM);
        if (getppid() != parent) _exit(127);   /* the parent ended before the line above */
        int fd = open(log, O_WRONLY | O_CREAT | O_APPEND, 0600);
        if (fd >= 0) {
            dup2(fd, 1);
            dup2(fd, 2);
            close(fd);
        }
        execvp(argv[0], argv);
        dprintf(2, "cannot run %s: %s\n", argv[0], strerror(errno));
        _exit(127);
    }
    int st = 0, rc = -1;
    if (pid > 0) {
        if (hooks.child) hooks.child(hooks.ctx, (long)pid);
        int forwarded = 0;
        for (;;) {
            const sig_atomic_t stop = hooks.stop ? *hooks.stop : 0;
            if (stop && !forwarded) {
                *stopped = (int)stop;
                kill(pid, SIGTERM);
                forwarded = 1;
            }
            const pid_t got = waitpid(pid, &st, forwarded ? 0 : WNOHANG);
            if (got == pid) break;
            if (got < 0 && errno != EINTR) { st = -1; break; }
            if (got == 0) {
                const struct timespec poll = {0, 10 * 1000 * 1000};   /* 10 ms: a stop is seen at once */
                nanosleep(&poll, NULL);
            }
        }
        if (hooks.child) hooks.child(hooks.ctx, 0);
        if (!*stopped && hooks.stop && *hooks.stop) *stopped = (int)*hooks.stop;
        rc = st != -1 && WIFEXITED(st) ? WEXITSTATUS(st) : -1;
    }
    if (*stopped) rc = -1;
    return rc;
}

/* ---- one cache entry ------------------------------------------------------------------- */

typedef struct {
    const char *key;          /* full key text (stored in the manifest) */
    const char *json;         /* scene structure for the generator, or NULL for a kernel of N */
    int modes;
    const char *what;         /* "kernel for N = 20", for messages */
    const char *cflags;       /* compiler flags (part of the key) */
    int stroke;               /* json is a stroke structure (generate.py --stroke) */
    swim_status *st;          /* where a failure goes (nothing is printed here) */
} entry_spec;

/* The last lines of a failed build's log, for the status's detail (a reader's, not a terminal's). */
static void log_tail(const char *log, swim_status *st)
{
    FILE *f = st ? fopen(log, "r") : NULL;
    if (!f) return;
    const long cap = (long)sizeof st->detail - 1;
    long size = fseek(f, 0, SEEK_END) == 0 ? ftell(f) : -1;
    const int cut = size > cap;
    if (size < 0 || fseek(f, cut ? size - cap : 0, SEEK_SET) != 0) {
        fclose(f);
        return;
    }
    const size_t got = fread(st->detail, 1, (size_t)cap, f);
    fclose(f);
    st->detail[got] = '\0';
    const char *nl = cut ? strchr(st->detail, '\n') : NULL;   /* a line cut at the start is not shown */
    if (nl) memmove(st->detail, nl + 1, strlen(nl + 1) + 1);
}

/* Files of an entry are created with fixed modes (0644, kernel.so 0755) whatever the umask, so
 * that the trust check below never refuses what this user wrote. */
static int write_atomic(const char *path, const char *text)
{
    char tmp[SWIM_CODEGEN_PATH + 32];
    snprintf(tmp, sizeof tmp, "%s.tmp%ld", path, (long)getpid());
    int fd = open(tmp, O_WRONLY | O_CREAT | O_TRUNC | O_NOFOLLOW | O_CLOEXEC, 0644);
    FILE *f = fd >= 0 ? fdopen(fd, "w") : NULL;
    if (!f) {
        if (fd >= 0) close(fd);
        unlink(tmp);
        return -1;
    }
    int ok = fchmod(fd, 0644) == 0 && fputs(text, f) >= 0;
    ok &= fflush(f) == 0 && fsync(fileno(f)) == 0;
    if (fclose(f) != 0 || !ok || rename(tmp, path) != 0) {
        unlink(tmp);
        return -1;
    }
    return 0;
}

/* What a sound manifest says kernel.so is. */
typedef struct {
    long long size;
    uint64_t hash;
} so_promise;

/* What lstat says of an entry's own name: a folder (never a symbolic link to one) that this
 * user or root owns and nobody else may write. 0, or -1 (why). */
static int entry_folder(const struct stat *st, char *why, size_t len)
{
    if (S_ISLNK(st->st_mode)) {
        snprintf(why, len, "a symbolic link, not an entry folder");
        return -1;
    }
    if (!S_ISDIR(st->st_mode)) {
        snprintf(why, len, "not a folder");
        return -1;
    }
    return private_stat(st, "the entry folder", why, len);
}

/* Checks the manifest of the entry in `dir` for `key` and kernel.c against it; both must be
 * files only this user or root can have written (open_trusted). 0 when sound (*so filled),
 * 1 when there is no entry yet, -1 when damaged or not trusted (why in `why`), -2 when it
 * cannot be checked now for want of descriptors or memory (why). */
static int check_entry(const char *dir, const char *key, so_promise *so, char *why, size_t len)
{
    struct stat st;
    int absent;
    if (lstat(dir, &st) != 0) {
        if (errno == ENOENT) return 1;
        snprintf(why, len, "%s cannot be read: %s", dir, strerror(errno));
        return -1;
    }
    if (entry_folder(&st, why, len) != 0) return -1;
    int fd = open_trusted(dir, "manifest", &st, &absent, why, len);
    if (fd < 0 && absent < 0) return -2;
    if (fd < 0) {
        char path[SWIM_CODEGEN_PATH + 32];
        snprintf(path, sizeof path, "%s/kernel.so", dir);
        if (absent && access(path, F_OK) != 0) return 1;
        if (absent) snprintf(why, len, "kernel.so without a manifest (an interrupted build)");
        return -1;
    }
    FILE *f = fdopen(fd, "r");
    if (!f) {
        close(fd);
        snprintf(why, len, "unreadable manifest");
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
    fd = open_trusted(dir, "kernel.c", &st, &absent, why, len);
    if (fd < 0) return absent < 0 ? -2 : -1;
    uint64_t h;
    long long size;
    int bad = hash_fd(fd, &h, &size, -1) != 0;
    close(fd);
    if (bad || size != csize || h != chash) {
        snprintf(why, len, "kernel.c has %lld bytes%s, the manifest says %lld", bad ? -1 : size,
                 size == csize ? " of other content" : "", csize);
        return -1;
    }
    so->size = ssize;
    so->hash = shash;
    return 0;
}

/* Loads kernel.so of the entry in `dir`: the file (open_trusted) is copied into an anonymous
 * memory file while it is hashed, the hash compared with the manifest's, and that copy is what
 * dlopen maps. So the code that runs is exactly the code that was checked (no file swapped in
 * between), and a cache file truncated or overwritten later, while the run still uses it,
 * cannot take pages away from under the run (SIGBUS). 0; -1 when damaged or not trusted (why);
 * -2 when it does not load as the entry asked for (why); -3 when it cannot be loaded now for want
 * of descriptors or memory (why). */
static int load_entry(const char *dir, const entry_spec *e, const so_promise *so, swim_compiled *out,
                      char *why, size_t len)
{
    struct stat st;
    int absent;
    int fd = open_trusted(dir, "kernel.so", &st, &absent, why, len);
    if (fd < 0) return absent < 0 ? -3 : -1;
    int copy = memfd_create("swim-kernel", MFD_CLOEXEC);
    uint64_t h;
    long long size;
    int bad = hash_fd(fd, &h, &size, copy);
    if (bad == -2) {
        /* the copy cannot be written (a file-size limit applies to memory files too): the
         * checked descriptor itself is hashed again and mapped */
        close(copy);
        copy = -1;
        bad = lseek(fd, 0, SEEK_SET) != 0 || hash_fd(fd, &h, &size, -1) != 0;
    }
    if (bad || size != so->size || h != so->hash) {
        snprintf(why, len, "kernel.so has %lld bytes%s, the manifest says %lld", bad ? -1 : size,
                 size == so->size ? " of other content" : "", so->size);
        if (copy >= 0) close(copy);
        close(fd);
        return -1;
    }
    /* Without memory files (very old kernels) the checked descriptor itself is mapped. The
     * descriptor stays open while the kernel is loaded: dlopen knows a library by its path, and
     * /proc/self/fd/N names another file once N is reused, so a second kernel opened under the
     * same N would be taken for the first. */
    const int keep = copy >= 0 ? copy : fd;
    char path[64];
    snprintf(path, sizeof path, "/proc/self/fd/%d", keep);
    out->handle = dlopen(path, RTLD_NOW | RTLD_LOCAL);
    if (keep != fd) close(fd);
    if (out->handle) out->loaded_fd1 = keep + 1;
    else close(keep);
    if (!out->handle) {
        const int saved = errno;
        const char *err = dlerror();
        snprintf(why, len, "%s", err ? err : "dlopen failed");
        return out_of_resources(saved) || strstr(why, strerror(EMFILE)) || strstr(why, strerror(ENFILE)) ? -3 : -2;
    }
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
    swim_compiled_close(out);
    snprintf(why, len, "wrong entry");
    return -2;
}

/* Temporary files of builds that did not finish (the lock is held: no build is running). */
static void remove_stale(const char *dir)
{
    remove_entries(dir, ".tmp");
}

/* Exit status of generate.py --stroke for a law that cannot be a stroke (generator/generate.py). */
#define GENERATOR_LAW_REFUSED 3

/* The generator's "refused law I: why" line in `log` into out->refused_index, out->refused.
 * 0, or -1 when the log holds no such line. */
static int read_refusal(const char *log, swim_compiled *out)
{
    FILE *f = fopen(log, "r");
    if (!f) return -1;
    char line[1024];
    int found = -1;
    while (found != 0 && fgets(line, sizeof line, f)) {
        int index, at = 0;
        if (sscanf(line, "refused law %d: %n", &index, &at) == 1 && at > 0) {
            line[strcspn(line, "\n")] = '\0';
            out->refused_index = index;
            snprintf(out->refused, sizeof out->refused, "%s", line + at);
            found = 0;
        }
    }
    fclose(f);
    return found;
}

/* Generate and compile into `dir` (lock held). 0; -1 on a failure (message printed);
 * -2 when the folder cannot be written (nothing printed); -3 when a signal stopped it (in
 * *stopped; temporary files removed, nothing printed); -4 when the generator refused a stroke
 * law (out->refused_index, out->refused; nothing printed). */
static int build_entry(const char *root, const char *dir, const entry_spec *e, swim_compiled *out, int *stopped)
{
    char path[SWIM_CODEGEN_PATH + 64], log[SWIM_CODEGEN_PATH + 32], tmp[SWIM_CODEGEN_PATH + 128];
    char gen[SWIM_CODEGEN_PATH + 32], inc[SWIM_CODEGEN_PATH + 32], so[SWIM_CODEGEN_PATH + 32];
    remove_stale(dir);
    snprintf(path, sizeof path, "%s/manifest", dir);
    if (unlink(path) != 0 && errno != ENOENT) return -2;
    snprintf(log, sizeof log, "%s/build.log", dir);
    int lfd = open(log, O_WRONLY | O_CREAT | O_TRUNC | O_NOFOLLOW | O_CLOEXEC, 0600);
    if (lfd < 0) return -2;
    close(lfd);
    snprintf(gen, sizeof gen, "%s/generator/generate.py", root);
    snprintf(out->source, sizeof out->source, "%s/kernel.c", dir);
    const char *python = swim_python();
    double t0 = swim_clock_seconds();
    int rc;
    if (e->json) {
        snprintf(path, sizeof path, "%s/structure.json", dir);
        if (write_atomic(path, e->json) != 0) return -2;
        snprintf(tmp, sizeof tmp, "%s/kernel.c.tmp%ld", dir, (long)getpid());
        char *argv[] = {(char *)python, gen, e->stroke ? "--stroke" : "--scene", path, "--out", tmp, "--quiet", NULL};
        rc = run_command(argv, log, stopped);
    } else {
        char modes[16];
        snprintf(modes, sizeof modes, "%d", e->modes);
        snprintf(path, sizeof path, "%s/gen.tmp%ld", dir, (long)getpid());
        char *argv[] = {(char *)python, gen, "--modes", modes, "--out", path, "--quiet", NULL};
        rc = run_command(argv, log, stopped);
        snprintf(tmp, sizeof tmp, "%s/swim_kernel_n%d.c", path, e->modes);
    }
    if (rc == GENERATOR_LAW_REFUSED && e->stroke && !*stopped && read_refusal(log, out) == 0) {
        unlink(tmp);
        return -4;
    }
    if (rc != 0 || chmod(tmp, 0644) != 0 || rename(tmp, out->source) != 0) {
        if (!*stopped) {
            swim_status_fail(e->st, "swim", NULL, 0, NULL, "generating the %s failed (see %s)", e->what, log);
            log_tail(log, e->st);
        }
        unlink(tmp);
        if (!e->json) remove_private(path);
        return *stopped ? -3 : -1;
    }
    if (!e->json) rmdir(path);
    double t1 = swim_clock_seconds();
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
    /* installed by rename only: a process that has the old file open keeps it whole */
    if (run_command(argv, log, stopped) != 0 || chmod(tmp, 0755) != 0 || rename(tmp, so) != 0) {
        if (!*stopped) {
            swim_status_fail(e->st, "swim", NULL, 0, NULL, "compiling the %s failed (see %s)", e->what, log);
            log_tail(log, e->st);
        }
        unlink(tmp);
        return *stopped ? -3 : -1;
    }
    out->generate_seconds = t1 - t0;
    out->compile_seconds = swim_clock_seconds() - t1;
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

/* The manifest's time is the entry's last use (swim cache clean --older-than); a read-only
 * cache keeps its old times. */
static void mark_used(const char *dir)
{
    char path[SWIM_CODEGEN_PATH + 32];
    snprintf(path, sizeof path, "%s/manifest", dir);
    utimensat(AT_FDCWD, path, NULL, AT_SYMLINK_NOFOLLOW);
}

/* Look up or build the entry for e under the cache root `croot`, which trusted_root accepted.
 * 0; -1 failed (message printed); -2 cannot write there; -3 stopped by the signal *stopped. */
static int obtain_in(const char *croot, const char *root, const entry_spec *e, swim_compiled *out,
                     int verbose, int *stopped)
{
    uint64_t h = fnv1a(FNV_START, e->key, strlen(e->key));
    snprintf(out->dir, sizeof out->dir, "%s/%016llx", croot, (unsigned long long)h);
    char why[SWIM_CODEGEN_PATH + 256];
    so_promise so;
    /* a sound entry is used without writing anything (read-only caches work) */
    int first = check_entry(out->dir, e->key, &so, why, sizeof why);
    if (first == 0) first = load_entry(out->dir, e, &so, out, why, sizeof why) == -3 ? -2 : 0;
    if (first == -2) {   /* out of descriptors or memory: the entry is not to blame */
        swim_status_fail(e->st, "swim", NULL, 0, NULL, "the %s in the kernel cache cannot be opened now: %s", e->what, why);
        return -1;
    }
    if (first == 0 && out->handle) {
        snprintf(out->source, sizeof out->source, "%s/kernel.c", out->dir);
        out->from_cache = 1;
        mark_used(out->dir);
        if (verbose > 1) say("swim: %s from cache %s", e->what, out->dir);
        return 0;
    }
    if (make_private_dirs(out->dir) != 0) return -2;
    struct stat st;
    if (lstat(out->dir, &st) != 0 || !S_ISDIR(st.st_mode) || private_stat(&st, out->dir, why, sizeof why) != 0)
        return -2;
    char lock[SWIM_CODEGEN_PATH + 16];
    snprintf(lock, sizeof lock, "%s/lock", out->dir);
    int fd = open(lock, O_RDWR | O_CREAT | O_NOFOLLOW | O_CLOEXEC, 0600);
    if (fd < 0 && out_of_resources(errno)) {
        swim_status_fail(e->st, "swim", NULL, 0, NULL, "the %s in the kernel cache cannot be opened now: lock: %s", e->what,
                         strerror(errno));
        return -1;
    }
    if (fd < 0) return -2;
    while (flock(fd, LOCK_EX) != 0)
        if (errno != EINTR) { close(fd); return -2; }
    /* another process may have built it while we waited */
    int state = check_entry(out->dir, e->key, &so, why, sizeof why);
    const int loaded = state == 0 ? load_entry(out->dir, e, &so, out, why, sizeof why) : -1;
    if (state == -2 || loaded == -3) {
        close(fd);
        swim_status_fail(e->st, "swim", NULL, 0, NULL, "the %s in the kernel cache cannot be opened now: %s", e->what, why);
        return -1;
    }
    if (state == 0) {
        if (loaded == 0) {
            close(fd);
            snprintf(out->source, sizeof out->source, "%s/kernel.c", out->dir);
            out->from_cache = 1;
            if (verbose > 1) say("swim: %s from cache %s (built by another process)", e->what, out->dir);
            return 0;
        }
        if (loaded == -2)
            say("swim: kernel cache entry %s does not load as a %s (%s); rebuilding it", out->dir, e->what, why);
        else
            state = -1;
    }
    if (state < 0)
        say("swim: kernel cache entry %s is damaged (%s); rebuilding it", out->dir, why);
    if (verbose) say("swim: generating %s ...", e->what);
    int rc = build_entry(root, out->dir, e, out, stopped);
    if (rc == 0 && check_entry(out->dir, e->key, &so, why, sizeof why) != 0) rc = -2;
    if (rc == 0 && load_entry(out->dir, e, &so, out, why, sizeof why) != 0) {
        swim_status_fail(e->st, "swim", NULL, 0, NULL, "cannot load the %s %s/kernel.so: %s", e->what, out->dir, why);
        rc = -1;
    }
    close(fd);
    if (rc == 0 && verbose)
        say("swim: %s generated in %.2f s, compiled in %.2f s (%s)", e->what,
                out->generate_seconds, out->compile_seconds, out->dir);
    return rc;
}

/* A private folder for this run alone (mode 0700 under $TMPDIR or /tmp), in which the entry is
 * built, loaded and then removed again; kept only when the build failed, for its log. */
static int obtain_private(const char *root, const entry_spec *e, swim_compiled *out, int verbose, int *stopped)
{
    const char *tmpdir = getenv("TMPDIR");
    char priv[SWIM_CODEGEN_PATH];
    snprintf(priv, sizeof priv, "%s/swim-cache-XXXXXX", tmpdir && *tmpdir == '/' ? tmpdir : "/tmp");
    if (!mkdtemp(priv)) {
        swim_status_fail(e->st, "swim", NULL, 0, NULL, "no private folder for the %s could be made in %s: %s", e->what,
                         tmpdir && *tmpdir == '/' ? tmpdir : "/tmp", strerror(errno));
        return -1;
    }
    int rc = obtain_in(priv, root, e, out, verbose, stopped);
    if (rc == -2) swim_status_fail(e->st, "swim", NULL, 0, NULL, "cannot write the private kernel folder %s either", priv);
    if (rc != -1) remove_private(priv);
    out->dir[0] = '\0';      /* gone with the run */
    out->from_cache = 0;
    return rc;
}

static int obtain(const entry_spec *e, swim_compiled *out, int verbose)
{
    const char *root = swim_share_dir(e->st);
    if (!root) return -1;
    char croot[SWIM_CODEGEN_PATH], why[SWIM_CODEGEN_PATH + 256];
    int stopped = 0, rc = -2;
    if (cache_root(croot, sizeof croot) != 0) {
        say("swim: no kernel cache folder (HOME is not set and user %ld has no home folder); "
                        "kernels are built in a private folder for this run", (long)geteuid());
    } else if (make_private_dirs(croot) == 0 && trusted_root(croot, why, sizeof why) != 0) {
        say("swim: the kernel cache %s is not used, since %s; kernels are built in a private "
                        "folder for this run (set SWIM_CACHE to a folder only you can write)", croot, why);
    } else {
        rc = obtain_in(croot, root, e, out, verbose, &stopped);
        if (rc == -2)
            say("swim: kernel cache %s cannot be written; the %s is built in a private folder for this run",
                    croot, e->what);
    }
    if (rc == -2) rc = obtain_private(root, e, out, verbose, &stopped);
    if (rc == -3) {
        if (hooks.stopped) hooks.stopped(hooks.ctx, stopped);   /* the program's policy: it may end here */
        swim_status_fail(e->st, "swim", NULL, 0, NULL, "generating the %s was interrupted", e->what);
    }
    return rc == 0 ? 0 : rc == -4 ? -2 : -1;
}

/* ---- keys ------------------------------------------------------------------------------ */

/* The first line a command prints on stdout (no shell), without its newline; "" if none. */
static void first_line_of(char *const argv[], char *buf, size_t len)
{
    buf[0] = '\0';
    int fds[2];
    if (pipe(fds) != 0) return;
    pid_t pid = fork();
    if (pid == 0) {
        close(fds[0]);
        dup2(fds[1], 1);
        int devnull = open("/dev/null", O_WRONLY);
        if (devnull >= 0) dup2(devnull, 2);
        execvp(argv[0], argv);
        _exit(127);
    }
    close(fds[1]);
    size_t got = 0;
    ssize_t n;
    char chunk[256];
    while (pid > 0 && (n = read(fds[0], chunk, sizeof chunk)) != 0) {
        if (n < 0 && errno == EINTR) continue;
        if (n < 0) break;
        for (ssize_t i = 0; i < n && got + 1 < len; i++) buf[got++] = chunk[i];
    }
    close(fds[0]);
    buf[got] = '\0';
    buf[strcspn(buf, "\n")] = '\0';
    while (pid > 0 && waitpid(pid, NULL, 0) < 0 && errno == EINTR) {}
}

/* Where the program SWIM_CC is, as execvp finds it, with its stamp: that path, the path it
 * resolves to, size, modification time (ns), inode, device. 0, or -1 when it is not found. */
static int compiler_stamp(char *stamp, size_t len)
{
    const char *cc = SWIM_CC, *search = getenv("PATH");
    char found[SWIM_CODEGEN_PATH] = "";
    struct stat st;
    if (strchr(cc, '/')) {
        snprintf(found, sizeof found, "%s", cc);
    } else {
        if (!search) search = "/bin:/usr/bin";   /* execvp's search path when PATH is unset */
        for (const char *p = search;; p++) {
            const size_t n = strcspn(p, ":");
            snprintf(found, sizeof found, "%.*s/%s", (int)n, n ? p : ".", cc);
            if (stat(found, &st) == 0 && S_ISREG(st.st_mode) && access(found, X_OK) == 0) break;
            found[0] = '\0';
            p += n;
            if (!*p) break;
        }
    }
    char *real = found[0] ? realpath(found, NULL) : NULL;
    const int rc = real && stat(real, &st) == 0 ? 0 : -1;
    if (rc == 0)
        snprintf(stamp, len, "%s %s %lld %lld.%09ld %llu %llu", found, real, (long long)st.st_size,
                 (long long)st.st_mtim.tv_sec, st.st_mtim.tv_nsec, (unsigned long long)st.st_ino,
                 (unsigned long long)st.st_dev);
    free(real);
    return rc;
}

/* The first line of `SWIM_CC --version`, run only when the compiler's stamp is not the one kept
 * with the version in the cache (identity_recall); "" when it cannot be found. */
static void compiler_version(char *version, size_t len)
{
    char stamp[3 * SWIM_CODEGEN_PATH];
    const int stamped = compiler_stamp(stamp, sizeof stamp) == 0;
    if (stamped && identity_recall("cc", stamp, version, len) == 0 && version[0]) return;
    char *argv[] = {SWIM_CC, "--version", NULL};
    first_line_of(argv, version, len);
    if (stamped && version[0]) identity_keep("cc", stamp, version);
}

/* What compiled code depends on besides its sources and flags: the processor (the flags say
 * -march=native, so code built on one machine may not run on another that shares the cache)
 * and the compiler's version. The processor is /proc/cpuinfo's model name (or its
 * implementer and part on ARM), else the machine name of uname. Computed once per thread. */
static const char *machine_text(void)
{
    static _Thread_local char text[512];
    static _Thread_local int done;
    if (done) return text;
    char cpu[200] = "", part[100] = "";
    FILE *f = fopen("/proc/cpuinfo", "r");
    char line[512];
    while (f && fgets(line, sizeof line, f)) {
        char *colon = strchr(line, ':');
        if (!colon) continue;
        char *value = colon + 1 + strspn(colon + 1, " \t");
        value[strcspn(value, "\n")] = '\0';
        if (!cpu[0] && (strncmp(line, "model name", 10) == 0 || strncmp(line, "Hardware", 8) == 0))
            snprintf(cpu, sizeof cpu, "%s", value);
        else if (!part[0] && strncmp(line, "CPU part", 8) == 0)
            snprintf(part, sizeof part, "part %s", value);
    }
    if (f) fclose(f);
    if (!cpu[0]) snprintf(cpu, sizeof cpu, "%s", part);
    if (!cpu[0]) {
        struct utsname u;
        snprintf(cpu, sizeof cpu, "%s", uname(&u) == 0 ? u.machine : "unknown");
    }
    char version[200];
    compiler_version(version, sizeof version);
    /* the key is one line of plain text (manifest, generated C string): no quotes or controls */
    snprintf(text, sizeof text, " cpu=%s ccversion=%s", cpu, version[0] ? version : "unknown");
    for (char *c = text; *c; c++)
        if ((unsigned char)*c < 32 || *c == '"' || *c == '\\') *c = '_';
    done = 1;
    return text;
}

static char *key_suffix(const char *cflags)
{
    const char *root = swim_share_dir(NULL);   /* not found: obtain says so */
    char *s = NULL;
    size_t len;
    FILE *f = open_memstream(&s, &len);
    if (!f) return NULL;
    fprintf(f, " abi=%d sources=%016llx cc=%s cflags=%s%s", SWIM_KERNEL_ABI,
            (unsigned long long)(root ? sources_hash(root) : 0), SWIM_CC, cflags, machine_text());
    fclose(f);
    return s;
}

int swim_codegen_kernel(int modes, swim_compiled *out, int verbose, swim_status *st)
{
    memset(out, 0, sizeof *out);
    if (modes < 0 || modes > SWIM_KERNEL_MAX_MODES) {
        swim_status_fail(st, "swim", NULL, 0, NULL, "N = %d is out of range 0..%d", modes, SWIM_KERNEL_MAX_MODES);
        return -1;
    }
    if ((out->kernel = swim_kernel_find(modes))) return 0;   /* linked in */
    char *suffix = key_suffix(SWIM_KERNEL_CFLAGS_N), key[2048], what[64];
    if (!suffix) {
        swim_status_fail(st, "swim", NULL, 0, NULL, "out of memory");
        return -1;
    }
    snprintf(key, sizeof key, "kernel N=%d%s", modes, suffix);
    free(suffix);
    snprintf(what, sizeof what, "kernel for N = %d", modes);
    entry_spec e = {key, NULL, modes, what, SWIM_KERNEL_CFLAGS_N, 0, st};
    return obtain(&e, out, verbose);
}

char *swim_codegen_scene_key(const swim_scene *s, int generic)
{
    char *structure = swim_codegen_structure_text(s, generic, NULL), *suffix = key_suffix(SWIM_KERNEL_CFLAGS);
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

int swim_codegen_scene(const swim_scene *s, int generic, swim_compiled *out, int verbose, swim_status *st)
{
    memset(out, 0, sizeof *out);
    out->generic = generic;
    char *key = swim_codegen_scene_key(s, generic);
    char *json = key ? swim_codegen_structure_text(s, generic, key) : NULL;
    if (!json) {
        free(key);
        swim_status_fail(st, "swim", s->path, 0, NULL, "%s: out of memory describing the scene structure", s->path);
        return -1;
    }
    int nfree = 0;
    for (int i = 0; i < s->n; i++) nfree += generic || s->free_mask[i];
    char what[128];
    snprintf(what, sizeof what, "%s kernel for N = %d (%d coordinates)", generic ? "generic scene" : "scene",
             s->modes, nfree);
    entry_spec e = {key, json, s->modes, what, SWIM_KERNEL_CFLAGS, 0, st};
    int rc = obtain(&e, out, verbose);
    free(key);
    free(json);
    return rc;
}

void swim_compiled_close(swim_compiled *c)
{
    if (c->handle) dlclose(c->handle);
    if (c->loaded_fd1 > 0) close(c->loaded_fd1 - 1);
    c->loaded_fd1 = 0;
    c->handle = NULL;
    c->kernel = NULL;
    c->scene = NULL;
    c->stroke = NULL;
}

/* ---- the cache as its user manages it ----------------------------------------------------- */

int swim_cache_location(char **root, char *why, size_t len)
{
    char croot[SWIM_CODEGEN_PATH];
    *root = NULL;
    if (cache_root(croot, sizeof croot) != 0) {
        snprintf(why, len, "HOME is not set and user %ld has no home folder", (long)geteuid());
        return -1;
    }
    if (!(*root = strdup(croot))) {
        snprintf(why, len, "out of memory");
        return -1;
    }
    struct stat st;
    if (stat(croot, &st) != 0) return 0;    /* made on first use */
    return trusted_root(croot, why, len) == 0 ? 0 : 1;
}

static long long entry_bytes(const char *dir, double *newest)
{
    long long total = 0;
    DIR *d = opendir(dir);
    if (!d) return 0;
    struct dirent *e;
    while ((e = readdir(d))) {
        char path[SWIM_CODEGEN_PATH + 300];
        snprintf(path, sizeof path, "%s/%s", dir, e->d_name);
        struct stat st;
        if (e->d_name[0] == '.' || lstat(path, &st) != 0) continue;
        total += (long long)st.st_size;
        if (newest && (double)st.st_mtime > *newest) *newest = (double)st.st_mtime;
    }
    closedir(d);
    return total;
}

static int by_name(const void *a, const void *b)
{
    return strcmp(((const swim_cache_entry *)a)->name, ((const swim_cache_entry *)b)->name);
}

/* An entry folder's name: the 16 hex digits of its key's hash. */
static int entry_name(const char *n)
{
    if (strlen(n) != 16) return 0;
    for (const char *c = n; *c; c++)
        if (!((*c >= '0' && *c <= '9') || (*c >= 'a' && *c <= 'f'))) return 0;
    return 1;
}

int swim_cache_entries(const char *root, swim_cache_entry **list, int *count)
{
    *list = NULL;
    *count = 0;
    DIR *d = opendir(root);
    if (!d) return errno == ENOENT ? 0 : -1;
    int cap = 0;
    struct dirent *de;
    const double now_s = (double)time(NULL);
    while ((de = readdir(d))) {
        if (!entry_name(de->d_name)) continue;
        if (*count == cap) {
            cap = cap ? 2 * cap : 16;
            swim_cache_entry *grown = realloc(*list, (size_t)cap * sizeof **list);
            if (!grown) {
                closedir(d);
                return -1;
            }
            *list = grown;
        }
        swim_cache_entry *e = &(*list)[(*count)++];
        memset(e, 0, sizeof *e);
        snprintf(e->name, sizeof e->name, "%s", de->d_name);
        char dir[SWIM_CODEGEN_PATH + 32], path[SWIM_CODEGEN_PATH + 64];
        snprintf(dir, sizeof dir, "%s/%s", root, de->d_name);
        struct stat st;
        if (lstat(dir, &st) != 0 || entry_folder(&st, e->why, sizeof e->why) != 0) {
            e->state = -1;     /* named like an entry but not one: never looked into */
            e->foreign = 1;
            if (!e->why[0]) snprintf(e->why, sizeof e->why, "cannot be read: %s", strerror(errno));
            continue;
        }
        double newest = 0;
        e->bytes = entry_bytes(dir, &newest);
        snprintf(path, sizeof path, "%s/manifest", dir);
        const int has_manifest = lstat(path, &st) == 0;
        e->age_days = ((has_manifest ? (double)st.st_mtime : newest) > 0
                       ? now_s - (has_manifest ? (double)st.st_mtime : newest) : 0) / 86400.0;
        FILE *f = has_manifest ? fopen(path, "r") : NULL;
        char line[4096];
        while (f && fgets(line, sizeof line, f))
            if (strncmp(line, "key ", 4) == 0) {
                line[strcspn(line, "\n")] = '\0';
                e->key = strdup(line + 4);
            }
        if (f) fclose(f);
        so_promise so;
        if (!has_manifest) {
            e->state = 1;
            snprintf(e->why, sizeof e->why, "no manifest (being built, or a build was interrupted)");
        } else if (!e->key || check_entry(dir, e->key, &so, e->why, sizeof e->why) != 0) {
            e->state = -1;
        } else {
            /* kernel.so as load_entry would take it, without loading it */
            int absent, fd = open_trusted(dir, "kernel.so", &st, &absent, e->why, sizeof e->why);
            uint64_t h = 0;
            long long size = -1;
            if (fd >= 0) {
                if (hash_fd(fd, &h, &size, -1) != 0) size = -1;
                close(fd);
            }
            if (fd < 0) e->state = -1;
            else if (size != so.size || h != so.hash) {
                e->state = -1;
                snprintf(e->why, sizeof e->why, "kernel.so differs from its manifest");
            }
        }
    }
    closedir(d);
    if (*count > 1) qsort(*list, (size_t)*count, sizeof **list, by_name);
    return 0;
}

void swim_cache_entries_free(swim_cache_entry *list, int count)
{
    for (int i = 0; i < count; i++) free(list[i].key);
    free(list);
}

int swim_cache_clean(const char *root, double older_days, int *removed, int *busy, int *foreign, long long *freed)
{
    *removed = *busy = *foreign = 0;
    *freed = 0;
    swim_cache_entry *list;
    int count;
    if (swim_cache_entries(root, &list, &count) != 0) return -1;
    const int rootfd = open(root, O_RDONLY | O_DIRECTORY | O_CLOEXEC);
    if (rootfd < 0) {
        const int saved = errno;
        swim_cache_entries_free(list, count);
        errno = saved;
        return errno == ENOENT ? 0 : -1;
    }
    for (int i = 0; i < count; i++) {
        if (list[i].foreign) {
            (*foreign)++;
            continue;
        }
        if (older_days >= 0 && list[i].age_days < older_days) continue;
        /* the entry as a folder, opened without following a link, and checked again once open:
         * what is removed is what was checked, whatever is renamed meanwhile */
        const int dfd = openat(rootfd, list[i].name, O_RDONLY | O_DIRECTORY | O_NOFOLLOW | O_CLOEXEC);
        struct stat st;
        char why[256];
        if (dfd < 0 || fstat(dfd, &st) != 0 || entry_folder(&st, why, sizeof why) != 0) {
            if (dfd >= 0) close(dfd);
            (*foreign)++;
            continue;
        }
        /* a build holds the entry's lock: leave it alone */
        const int fd = openat(dfd, "lock", O_RDONLY | O_NOFOLLOW | O_CLOEXEC);
        if (fd >= 0 && flock(fd, LOCK_EX | LOCK_NB) != 0) {
            close(fd);
            close(dfd);
            (*busy)++;
            continue;
        }
        remove_entries_at(dfd, NULL);
        if (fd >= 0) close(fd);
        close(dfd);
        if (unlinkat(rootfd, list[i].name, AT_REMOVEDIR) != 0 && errno != ENOENT) {
            (*busy)++;
            continue;
        }
        (*removed)++;
        *freed += list[i].bytes;
    }
    close(rootfd);
    swim_cache_entries_free(list, count);
    return 0;
}

/* ---- prescribed strokes --------------------------------------------------------------------- */

int swim_codegen_stroke(const swim_scene *s, swim_compiled *out, int verbose, swim_status *st)
{
    memset(out, 0, sizeof *out);
    char *structure = swim_codegen_stroke_text(s, NULL), *suffix = key_suffix(SWIM_KERNEL_CFLAGS), *key = NULL, *json = NULL;
    if (structure && suffix) {
        structure[strcspn(structure, "\n")] = '\0';
        size_t len = strlen(structure) + strlen(suffix) + 16;
        if ((key = malloc(len))) snprintf(key, len, "stroke %s%s", structure, suffix);
    }
    if (key) json = swim_codegen_stroke_text(s, key);
    free(structure);
    free(suffix);
    if (!json) {
        free(key);
        swim_status_fail(st, "swim", s->path, 0, NULL, "%s: out of memory describing the stroke", s->path);
        return -1;
    }
    char what[128];
    snprintf(what, sizeof what, "stroke kernel for N = %d (%d laws)", s->modes, s->stroke_count);
    entry_spec e = {key, json, s->modes, what, SWIM_KERNEL_CFLAGS, 1, st};
    int rc = obtain(&e, out, verbose);
    free(key);
    free(json);
    return rc;
}

int swim_codegen_for_scene(const char *cmd, const swim_scene *s, int generic, int verbose, swim_compiled *kn, swim_compiled *sys,
                           swim_status *st)
{
    char who[64];
    snprintf(who, sizeof who, "swim %s", cmd);
    if (s->stroke_count > 0) {
        const int got = swim_codegen_kernel(s->modes, kn, verbose, st) != 0 ? -1 : swim_codegen_stroke(s, sys, verbose, st);
        if (got == -2) {   /* a law that parses but is not twice differentiable: bad input */
            char where[640], key[32];
            int k = 0;
            while (k < s->stroke_count - 1 && s->stroke_index[k] != sys->refused_index) k++;
            snprintf(key, sizeof key, "stroke.");
            swim_coord_name(sys->refused_index, key + 7, sizeof key - 7);
            swim_status_fail(st, "swim", s->path, s->stroke_line[k] > 0 ? s->stroke_line[k] : 0, key, "%s: %s",
                             swim_scene_stroke_where(s, sys->refused_index, where, sizeof where), sys->refused);
            return 2;
        }
        if (got != 0) {
            swim_status_fail(st, who, s->path, 0, NULL, "%s: no kernel for this stroke, nothing computed", s->path);
            return 1;
        }
        return 0;
    }
    if (swim_codegen_kernel(s->modes, kn, verbose, st) != 0 || swim_codegen_scene(s, generic, sys, verbose, st) != 0) {
        swim_status_fail(st, who, s->path, 0, NULL, "%s: no kernel for this scene, nothing computed", s->path);
        return 1;
    }
    return swim_scene_check_model(s, kn->kernel, st);
}
