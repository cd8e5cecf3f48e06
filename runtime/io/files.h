/* files.h -- the file-system helpers the runtime shares, and where its data files are.
 * SWIM_PYTHON (the interpreter for the generator and the plots; $SWIM_PYTHON overrides it at run
 * time) is set by the Makefile. */
#ifndef SWIM_FILES_H
#define SWIM_FILES_H

#ifndef SWIM_PYTHON
#define SWIM_PYTHON "/usr/bin/python3"
#endif

/* The folder holding generator/, runtime/kernel/ and runtime/plot/: $SWIM_SHARE if set, else
 * found from the executable's own path (/proc/self/exe): the source tree's root for bin/swim
 * (or build/tests/...), PREFIX/share/swim for PREFIX/bin/swim. NULL (after one line on stderr)
 * when there is none. */
const char *swim_share_dir(void);
/* The Python interpreter to run: $SWIM_PYTHON or SWIM_PYTHON. */
const char *swim_python(void);

/* mkdir -p; 0, or -1 with errno set (also when the path exists but is not a directory). */
int swim_mkdirs(const char *path);

/* Copies the file src to dst (replaced if present); 0, or -1 with errno set. Copying a file onto
 * itself is a no-op. */
int swim_copy_file(const char *src, const char *dst);

#endif
