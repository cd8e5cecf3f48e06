/* files.h -- the file-system helpers the runtime shares, and where its data files are.
 * SWIM_PYTHON (the interpreter for the generator and the plots; $SWIM_PYTHON overrides it at run
 * time) is set by the Makefile. Paths have no length limit here: every path is a malloc'd string
 * the caller frees. */
#ifndef SWIM_FILES_H
#define SWIM_FILES_H

#include <stddef.h>
#include <stdio.h>
#include <sys/stat.h>

#include "io/status.h"

#ifndef SWIM_PYTHON
#define SWIM_PYTHON "/usr/bin/python3"
#endif

/* The folder holding generator/, runtime/kernel/ and runtime/plot/: $SWIM_SHARE if set, else
 * found from the executable's own path (/proc/self/exe): the source tree's root for bin/swim
 * (or build/tests/...), PREFIX/share/swim for PREFIX/bin/swim. NULL, with the reason in st
 * (may be NULL), when there is none. */
const char *swim_share_dir(swim_status *st);
/* The Python interpreter to run: $SWIM_PYTHON or SWIM_PYTHON. */
const char *swim_python(void);

/* mkdir -p; 0, or -1 with errno set (also when the path exists but is not a directory). */
int swim_mkdirs(const char *path);

/* "dir/name" in a new string, NULL when out of memory. */
char *swim_path_join(const char *dir, const char *name);

/* The absolute path with every symbolic link resolved, also for a file that does not exist yet
 * (its folder must): two spellings of one file give the same string. NULL with errno set. */
char *swim_canonical_path(const char *path);

/* Replaces `path` with the len bytes of data, atomically: they go to a temporary file in the
 * same folder, are flushed to the disk, and the file is renamed over `path` (rename(2) is
 * atomic within a file system). Readers see the old file, no file, or the whole new one, never
 * a part. A path that names something other than a regular file -- a device such as /dev/null,
 * a FIFO, a terminal (also through a symbolic link, as /dev/stdout) -- is written to directly
 * instead: renaming over it would replace the device node by a regular file. A folder is
 * EISDIR. 0, or -1 with errno set (the temporary file is removed). */
int swim_replace_file(const char *path, const void *data, size_t len);

/* The same for text that `fill` writes to a stream in memory (fill(f, ctx)): nothing reaches
 * `path` unless the whole text could be formatted. 0, or -1 with errno set. */
int swim_replace_file_with(const char *path, void (*fill)(FILE *f, void *ctx), void *ctx);

/* 1 if `path` still names the file whose fstat is *st (same device and inode), 0 if it names
 * another file or nothing (the file or its folder was removed or replaced), with errno set. */
int swim_still_names(const char *path, const struct stat *st);

/* Copies the file src to dst, replacing dst atomically (swim_replace_file): a reader never sees
 * a partial copy. 0, or -1 with errno set. Copying a file onto itself is a no-op. */
int swim_copy_file(const char *src, const char *dst);

/* The whole file at path, NUL-terminated, in a new buffer (*len bytes without the NUL; len may be
 * NULL). NULL with errno set when it cannot be opened or read, or EFBIG when it holds more than
 * max bytes. The one read-whole-file of the runtime. */
char *swim_read_file(const char *path, size_t max, size_t *len);

#endif
