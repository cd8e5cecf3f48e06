/* family_hdf5.h -- a sweep's family in one HDF5 file (swim sweep --format hdf5), for h5py.
 *
 * DIR/family.h5, written when the sweep ends (stopped or not) from the member folders, the same
 * finished members as members.csv and in its order (member id):
 *
 *   /                  attributes: swim_version, definition (sweep.json's text), scene (the
 *                      scene text every member ran), members (how many the family has)
 *   /members/COLUMN    (attribute "columns": the names in members.csv's order)
 *                      one dataset per members.csv column: id (int64), each varied key (float64,
 *                      named by the key, e.g. "model.rho0"), status and reason (strings), the
 *                      numbers of the summaries (float64, NaN where a summary has none; steps and
 *                      rhs_evaluations int64, -1 where none)
 *   /trajectories/ID   with --keep trajectories: member ID's trajectory.csv as a float64 matrix
 *                      (rows x columns), its attribute "columns" the CSV header's names
 *
 * The folder stays the sweep's state (resume reads the summaries); family.h5 is rewritten from it
 * at every end, under a temporary name then renamed, so a reader never sees half a file -- also
 * at the end of a resume without --format hdf5 (swim sweep), so it never lists fewer members than
 * members.csv. When it cannot be written (a full disk), no family.h5 is left at all.
 */
#ifndef SWIM_FAMILY_HDF5_H
#define SWIM_FAMILY_HDF5_H

#include <stddef.h>

#include "sweep/sweep.h"

/* 1 when the sweep's end writes family.h5: --format hdf5, or a family.h5 already in DIR (made by
 * an earlier run of the sweep with --format hdf5, which this run resumes). */
int sweep_family_hdf5_due(const sweep_plan *p);
/* 0, or 1 with one line naming the file and the reason in st. */
int sweep_write_family_hdf5(const sweep_plan *p, swim_status *st);
/* 0 when the HDF5 library (opened at run time, not linked) can be loaded with every function
 * the writer uses, else -1 with the reason in why: said before any member runs. */
int sweep_family_hdf5_ready(char *why, size_t len);

#endif
