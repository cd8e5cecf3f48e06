/* codegen.h -- kernels generated, compiled and cached at run time.
 *
 * Three kinds of kernels come from here (the third, a prescribed stroke's laws, is at the end):
 *   - the kernel of N modes (swim_kernel: mass matrices, K, Gamma, J; diagnostics and
 *     `swim inspect`): linked in for N = 0..7 (generated/), generated on first use for any
 *     other N up to SWIM_KERNEL_MAX_MODES;
 *   - the right-hand side of a scene (swim_scene_kernel), generated for the scene's structure:
 *     N, which coordinates are free, which locked ones are 0 (folded away), which effects are
 *     present (free coordinates with R != 0, with D != 0, the barrier, the forcing law and the
 *     coordinates it drives). `generic` asks for the structure "every coordinate carried, locks
 *     held by multipliers, every effect present" instead. Initial values, t_end, tolerances,
 *     densities and the values of R, cref, D, epsilon, alpha are run-time parameters: changing
 *     them never regenerates.
 *
 * The cache: $SWIM_CACHE, else $XDG_CACHE_HOME/swim, else $HOME/.cache/swim, else the effective
 * user's home folder from the password database (never a fixed shared path). One folder per
 * entry, named by a hash of its key: the structure (or N), the kernel ABI, the compiler and its
 * flags, and a hash of every file under the generator folder and of the hand-written C the
 * kernels include (runtime/kernel/). Files are written under temporary names and installed by
 * rename only; the manifest, written last, holds the key and the size and hash of kernel.c and
 * kernel.so, so a truncated or empty file is rebuilt (a notice) rather than loaded.
 * Trust (docs/trust.md): a cache root is used only when it and its entry folders belong to this
 * user (or root) and nobody else may write them, and the folders above it are this user's or
 * root's and writable by others only with the sticky bit; manifest, kernel.c and kernel.so must
 * be regular files (no symbolic links) with the same owners and no group or other write bit.
 * kernel.so is copied into an anonymous memory file while it is hashed, and that copy is loaded:
 * the code that runs is the code that was checked, and a cache file changed later cannot touch
 * a running process. Concurrent first uses wait on a lock file in the entry; a cache that cannot
 * be written or is not trusted is replaced for this run by a private folder (mode 0700 under
 * $TMPDIR or /tmp, with a notice) that is removed once the kernel is loaded. The child (generator
 * or compiler) ends with its parent even on SIGKILL.
 *
 * Messages and signals belong to the program, not to this code (swim_codegen_hooks): a failure
 * fills the caller's status (io/status.h; a failed build keeps the end of its build.log there),
 * which bin/swim prints and libswim turns into its swim_error; progress ("generating ...") and notices of damage and fallbacks go to the note hook the
 * calling thread installed, nowhere without one. No signal handler is ever installed here: a
 * build stops when the program's stop flag is set (its child sent SIGTERM, its temporary files
 * removed, then the stopped hook called), and the program decides what its signals do.
 *
 * The generator and the headers are found relative to the executable (/proc/self/exe): in the
 * source tree (bin/swim -> generator/, runtime/kernel/) or an installation (PREFIX/bin/swim ->
 * PREFIX/share/swim/generator/, PREFIX/share/swim/runtime/kernel/); $SWIM_SHARE overrides.
 */
#ifndef SWIM_CODEGEN_H
#define SWIM_CODEGEN_H

#include <signal.h>

#include "kernel/stroke_kernel.h"
#include "kernel/swim_kernel.h"
#include "scene/scene.h"

#define SWIM_CODEGEN_PATH 4096

typedef struct {
    const swim_kernel *kernel;            /* the kernel of N modes */
    const swim_scene_kernel *scene;       /* a scene's right-hand side (swim_codegen_scene) */
    void *handle;                         /* dlopen handle, owned (NULL when linked in) */
    int loaded_fd1;                       /* descriptor of the loaded copy + 1 (0: none), owned */
    char dir[SWIM_CODEGEN_PATH];          /* its cache entry ("" when linked in) */
    char source[SWIM_CODEGEN_PATH + 16];  /* its generated C file */
    int from_cache, generic;
    double generate_seconds, compile_seconds;
    const swim_stroke_kernel *stroke;     /* a prescribed stroke's laws (swim_codegen_stroke) */
    int refused_index;                    /* swim_codegen_stroke -2: the coordinate of the law refused */
    char refused[512];                    /* ... and why (the generator's words) */
} swim_compiled;

/* What a program lets kernel builds of the calling thread do for it (swim_codegen_set_hooks).
 * Every member may be NULL. bin/swim prints the notes on stderr and, while a child runs, passes
 * SIGINT, SIGTERM and SIGHUP on to it (runtime/cli/run_signals.h); libswim installs none. */
typedef struct {
    void (*note)(void *ctx, const char *line);   /* progress and notices, one line without '\n' */
    void (*child)(void *ctx, long pid);          /* a generator or compiler started (pid > 0), ended (0) */
    void (*stopped)(void *ctx, int stop);        /* a build stopped by *stop has removed its files */
    volatile sig_atomic_t *stop;                 /* polled while a child runs: nonzero stops the build */
    void *ctx;
} swim_codegen_hooks;

/* Installs a copy of h for the calling thread (NULL: none, the default). */
void swim_codegen_set_hooks(const swim_codegen_hooks *h);

/* verbose: 0 quiet (damage and fallback notices only), 1 also progress of a generation,
 * 2 also where a cached kernel came from. */

/* The kernel of N modes (0 <= N <= SWIM_KERNEL_MAX_MODES). 0, or -1 with the cause in st. */
int swim_codegen_kernel(int modes, swim_compiled *out, int verbose, swim_status *st);
/* The right-hand side for the scene's structure (generic: see above). 0, or -1 with the cause in st. */
int swim_codegen_scene(const swim_scene *s, int generic, swim_compiled *out, int verbose, swim_status *st);
void swim_compiled_close(swim_compiled *c);

/* The kernels a run of s needs: the kernel of N modes and the scene's right-hand side (generic:
 * the generated generic structure) or, for a prescribed stroke, its laws (swim_codegen_stroke),
 * linked in, cached or generated now (verbose 1: progress of a generation); then the magnitude
 * check of a dynamic scene's initial state. 0; 1 when no kernel could be had (the cause in st,
 * then "swim CMD: FILE: no kernel for this scene, nothing computed"); 2 for a law the generator
 * refuses or numbers that overflow (st names the key). */
int swim_codegen_for_scene(const char *cmd, const swim_scene *s, int generic, int verbose, swim_compiled *kn,
                           swim_compiled *sys, swim_status *st);


/* The laws of the scene's [stroke] with their exact first and second derivatives
 * (generator/swimgen/stroke.py), cached like scene kernels under the key "stroke {structure}".
 * 0; -1 with the cause in st; -2 when a law is refused (st untouched): it parses and is
 * finite, but the generator finds it not twice differentiable (an abs or step, perhaps hidden,
 * as in sqrt((t-1)^2)); out->refused_index is its coordinate, out->refused says why. */
int swim_codegen_stroke(const swim_scene *s, swim_compiled *out, int verbose, swim_status *st);

/* The structure key of a scene as the cache uses it (malloc'd, caller frees), or NULL. */
char *swim_codegen_scene_key(const swim_scene *s, int generic);

/* ---- the cache as its user manages it (swim cache) ---- */

/* The cache root this process uses (*root, malloc'd): 0 when it is used (or will be made on
 * first use), 1 when it exists but is not trusted (why; kernels then go to private folders),
 * -1 when there is none (why; *root NULL). */
int swim_cache_location(char **root, char *why, size_t len);

typedef struct {
    char name[32];        /* the entry's folder: the hash of its key */
    char *key;            /* the key from its manifest; NULL without one */
    long long bytes;      /* size of its files */
    double age_days;      /* since its last use (loads refresh the manifest's time) */
    int state;            /* 0 sound; -1 damaged or not trusted (why); 1 no manifest yet (why) */
    int foreign;          /* named like an entry but not an entry folder of this user (a symbolic
                           * link, a file, another user's folder): listed, never looked into */
    char why[256];
} swim_cache_entry;

/* Every entry under root, sorted by name, checked as a load would check it (nothing is
 * loaded). 0 (an absent root has no entries), or -1 with errno set. */
int swim_cache_entries(const char *root, swim_cache_entry **list, int *count);
void swim_cache_entries_free(swim_cache_entry *list, int count);

/* Removes the entries unused for at least older_days (every entry when older_days < 0),
 * except those whose lock a build holds (*busy) and what only looks like an entry (*foreign:
 * a symbolic link or anything but a folder of this user, left alone: nothing is followed).
 * 0 with the counts, or -1 with errno set. */
int swim_cache_clean(const char *root, double older_days, int *removed, int *busy, int *foreign, long long *freed);

#endif
