/* files.h -- the file-system helpers the runtime shares, and where the installed tree is.
 * SWIM_ROOT (the source tree, for the generator and the plot script), SWIM_PYTHON, SWIM_CC and
 * SWIM_KERNEL_CFLAGS are set by the Makefile when it compiles the files that use them. */
#ifndef SWIM_FILES_H
#define SWIM_FILES_H

#ifndef SWIM_ROOT
#define SWIM_ROOT "."
#endif
#ifndef SWIM_PYTHON
#define SWIM_PYTHON "/usr/bin/python3"
#endif

/* mkdir -p; 0, or -1 with errno set (also when the path exists but is not a directory). */
int swim_mkdirs(const char *path);

/* Copies the file src to dst (replaced if present); 0, or -1 with errno set. Copying a file onto
 * itself is a no-op. */
int swim_copy_file(const char *src, const char *dst);

#endif
