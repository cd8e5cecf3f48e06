/* version.h -- swim's version: VERSION's number, given by the Makefile as -DSWIM_VERSION (a
 * build without it, such as a fuzz target's, says "unknown"). Reported by swim --version,
 * swim_version(), summary.json, family.h5 and exported trees. */
#ifndef SWIM_IO_VERSION_H
#define SWIM_IO_VERSION_H

#ifndef SWIM_VERSION
#define SWIM_VERSION "unknown"
#endif

#endif
