/* family_hdf5.c -- DIR/family.h5 from a sweep's folder (sweep/family_hdf5.h has the layout). */
#include "sweep/family_hdf5.h"

#include <dlfcn.h>
#include <errno.h>
#include <hdf5.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "io/files.h"
#include "io/message.h"

#include "io/version.h"

#define MAX_TRAJECTORY_BYTES (4ull << 30)   /* a member's trajectory.csv read whole: 4 GiB at most */

/* ---- the HDF5 library, loaded when a family file is written ---------------------------------
 * Only `swim sweep --format hdf5` needs HDF5, and with its dependencies (curl, TLS, Kerberos,
 * LDAP, ...) it is most of what the dynamic loader would map and relocate at every start of
 * bin/swim; so it is opened here, by the soname the build found (SWIM_HDF5_SONAME), and its
 * functions and type ids are looked up by name into a table the writer passes down. The table
 * lives on the caller's stack: no global state. The library stays loaded (no dlclose), as it
 * would linked in: a file whose close failed leaves HDF5 state that must never be touched again. */
#ifndef SWIM_HDF5_SONAME
#define SWIM_HDF5_SONAME "libhdf5_serial.so.103"
#endif

#define H5_FUNCTIONS(X)                                                                              \
    X(H5open) X(H5dont_atexit) X(H5Eset_auto2) X(H5Fcreate) X(H5Fclose) X(H5Gcreate2) X(H5Gclose)  \
    X(H5Tcopy) X(H5Tset_size) X(H5Tset_cset) X(H5Tclose) X(H5Screate) X(H5Screate_simple)        \
    X(H5Sclose) X(H5Acreate2) X(H5Awrite) X(H5Aclose) X(H5Pcreate) X(H5Pset_chunk)                \
    X(H5Pset_shuffle) X(H5Pset_deflate) X(H5Pclose) X(H5Dcreate2) X(H5Dopen2) X(H5Dwrite) X(H5Dclose)
#define H5_IDS(X)                                                                                    \
    X(H5T_C_S1_g) X(H5T_STD_I64LE_g) X(H5T_NATIVE_LLONG_g) X(H5T_IEEE_F64LE_g) X(H5T_NATIVE_DOUBLE_g) \
    X(H5P_CLS_DATASET_CREATE_ID_g)

typedef struct {
#define FIELD(name) __typeof__(name) *name;
    H5_FUNCTIONS(FIELD)
#undef FIELD
#define FIELD(name) hid_t name;
    H5_IDS(FIELD)
#undef FIELD
} h5lib;

/* H5F_ACC_TRUNC without the calls the header's macro makes (H5check, which aborts the process
 * on a version mismatch, and H5open): h5lib_open has opened the library. */
#define FILE_TRUNCATE 0x0002u

/* 0, or -1 with the reason in why. */
static int h5lib_open(h5lib *h, char *why, size_t len)
{
    void *lib = dlopen(SWIM_HDF5_SONAME, RTLD_NOW | RTLD_LOCAL);
    if (!lib) {
        const char *e = dlerror();
        snprintf(why, len, "HDF5 cannot be loaded (%s)", e ? e : SWIM_HDF5_SONAME);
        return -1;
    }
    const char *missing = NULL;
#define LOOK(name) if (!(*(void **)&h->name = dlsym(lib, #name)) && !missing) missing = #name;
    H5_FUNCTIONS(LOOK)
#undef LOOK
    /* no clean-up at exit, said before H5open starts the library (which would otherwise register
     * it): a file whose close failed cannot be closed again (write_file). The type ids are
     * variables the library sets in H5open (the headers' H5OPEN does the same). */
    if (!missing) h->H5dont_atexit();   /* fails only when said before: ignored */
    if (!missing && h->H5open() < 0) missing = "H5open";
#define LOOK(name) { const hid_t *v = dlsym(lib, #name); if (v) h->name = *v; else if (!missing) missing = #name; }
    H5_IDS(LOOK)
#undef LOOK
    if (missing) {
        snprintf(why, len, "%s lacks %s", SWIM_HDF5_SONAME, missing);
        return -1;
    }
    return 0;
}

/* ---- HDF5 in small pieces: each returns 0 or -1 ------------------------------------------ */

static hid_t string_type(const h5lib *h)
{
    hid_t t = h->H5Tcopy(h->H5T_C_S1_g);
    if (t < 0) return t;
    if (h->H5Tset_size(t, H5T_VARIABLE) < 0 || h->H5Tset_cset(t, H5T_CSET_UTF8) < 0) {
        h->H5Tclose(t);
        return -1;
    }
    return t;
}

static int text_attribute(const h5lib *h, hid_t obj, const char *name, const char *text)
{
    hid_t t = string_type(h), sp = h->H5Screate(H5S_SCALAR);
    hid_t a = t >= 0 && sp >= 0 ? h->H5Acreate2(obj, name, t, sp, H5P_DEFAULT, H5P_DEFAULT) : -1;
    int rc = a >= 0 && h->H5Awrite(a, t, &text) >= 0 ? 0 : -1;
    if (a >= 0) h->H5Aclose(a);
    if (sp >= 0) h->H5Sclose(sp);
    if (t >= 0) h->H5Tclose(t);
    return rc;
}

static int long_attribute(const h5lib *h, hid_t obj, const char *name, long value)
{
    const long long v = value;
    hid_t sp = h->H5Screate(H5S_SCALAR);
    hid_t a = sp >= 0 ? h->H5Acreate2(obj, name, h->H5T_STD_I64LE_g, sp, H5P_DEFAULT, H5P_DEFAULT) : -1;
    int rc = a >= 0 && h->H5Awrite(a, h->H5T_NATIVE_LLONG_g, &v) >= 0 ? 0 : -1;
    if (a >= 0) h->H5Aclose(a);
    if (sp >= 0) h->H5Sclose(sp);
    return rc;
}

static int names_attribute(const h5lib *h, hid_t obj, const char *name, const char *const *names, int n)
{
    const hsize_t dims[1] = {(hsize_t)n};
    hid_t t = string_type(h), sp = h->H5Screate_simple(1, dims, NULL);
    hid_t a = t >= 0 && sp >= 0 ? h->H5Acreate2(obj, name, t, sp, H5P_DEFAULT, H5P_DEFAULT) : -1;
    int rc = a >= 0 && h->H5Awrite(a, t, names) >= 0 ? 0 : -1;
    if (a >= 0) h->H5Aclose(a);
    if (sp >= 0) h->H5Sclose(sp);
    if (t >= 0) h->H5Tclose(t);
    return rc;
}

/* A 1-D or 2-D dataset of `type` in the file, `memtype` in memory; 2-D ones are chunked and
 * compressed (trajectories: long, smooth columns). */
static int dataset(const h5lib *h, hid_t where, const char *name, hid_t type, hid_t memtype, int rank, const hsize_t *dims,
                   const void *data)
{
    hid_t sp = h->H5Screate_simple(rank, dims, NULL), pl = h->H5Pcreate(h->H5P_CLS_DATASET_CREATE_ID_g);
    int rc = sp >= 0 && pl >= 0 ? 0 : -1;
    if (rc == 0 && rank == 2 && dims[0] > 0 && dims[1] > 0) {
        const hsize_t chunk[2] = {dims[0] < 4096 ? dims[0] : 4096, dims[1]};
        rc = h->H5Pset_chunk(pl, 2, chunk) < 0 || h->H5Pset_shuffle(pl) < 0 || h->H5Pset_deflate(pl, 4) < 0 ? -1 : 0;
    }
    hid_t d = rc == 0 ? h->H5Dcreate2(where, name, type, sp, H5P_DEFAULT, pl, H5P_DEFAULT) : -1;
    if (d < 0 || (dims[0] > 0 && h->H5Dwrite(d, memtype, H5S_ALL, H5S_ALL, H5P_DEFAULT, data) < 0)) rc = -1;
    if (d >= 0) h->H5Dclose(d);
    if (pl >= 0) h->H5Pclose(pl);
    if (sp >= 0) h->H5Sclose(sp);
    return rc;
}

static int text_dataset(const h5lib *h, hid_t where, const char *name, const char *const *texts, long n)
{
    const hsize_t dims[1] = {(hsize_t)n};
    hid_t t = string_type(h);
    int rc = t >= 0 ? dataset(h, where, name, t, t, 1, dims, texts) : -1;
    if (t >= 0) h->H5Tclose(t);
    return rc;
}

/* ---- the members table ------------------------------------------------------------------- */

typedef struct {
    long n;                 /* finished members */
    long long *id;
    double *vary;           /* [v * n + row] */
    char **status, **reason;
    double *real;           /* [c * n + row], the numbers of sweep_columns */
    long long *count;
} table;

static void table_free(table *t)
{
    for (long i = 0; i < t->n; i++) {
        if (t->status) free(t->status[i]);
        if (t->reason) free(t->reason[i]);
    }
    free(t->id);
    free(t->vary);
    free(t->status);
    free(t->reason);
    free(t->real);
    free(t->count);
}

static int table_read(const sweep_plan *p, table *t)
{
    int ncol;
    const sweep_column *cols = sweep_columns(&ncol);
    const size_t cap = (size_t)p->members ? (size_t)p->members : 1;
    memset(t, 0, sizeof *t);
    t->id = malloc(cap * sizeof *t->id);
    t->vary = malloc(cap * (size_t)(p->nvary ? p->nvary : 1) * sizeof *t->vary);
    t->status = calloc(cap, sizeof *t->status);
    t->reason = calloc(cap, sizeof *t->reason);
    t->real = malloc(cap * (size_t)ncol * sizeof *t->real);
    t->count = malloc(cap * (size_t)ncol * sizeof *t->count);
    if (!t->id || !t->vary || !t->status || !t->reason || !t->real || !t->count) return -1;
    long r = 0;
    for (long m = 0; m < p->members; m++) {
        swim_summary s;
        if (!sweep_member_summary(p, m, &s)) continue;
        t->id[r] = m;
        for (int v = 0; v < p->nvary; v++) t->vary[(size_t)v * cap + (size_t)r] = sweep_value(p, m, v);
        t->status[r] = strdup(s.status);
        t->reason[r] = strdup(s.reason);
        t->n = r + 1;   /* freed from here on */
        if (!t->status[r] || !t->reason[r]) return -1;
        for (int c = 0; c < ncol; c++) {
            const char *field = (const char *)&s + cols[c].offset;
            const swim_summary_real *x = (const swim_summary_real *)field;
            const swim_summary_count *k = (const swim_summary_count *)field;
            t->real[(size_t)c * cap + (size_t)r] = cols[c].integer ? NAN : x->set ? x->value : NAN;
            t->count[(size_t)c * cap + (size_t)r] = cols[c].integer && k->set ? k->value : -1;
        }
        r++;
    }
    return 0;
}

static int table_write(const h5lib *h, const sweep_plan *p, const table *t, hid_t file)
{
    int ncol;
    const sweep_column *cols = sweep_columns(&ncol);
    const size_t cap = (size_t)p->members ? (size_t)p->members : 1;
    const hsize_t dims[1] = {(hsize_t)t->n};
    hid_t g = h->H5Gcreate2(file, "members", H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT);
    if (g < 0) return -1;
    int rc = dataset(h, g, "id", h->H5T_STD_I64LE_g, h->H5T_NATIVE_LLONG_g, 1, dims, t->id);
    for (int v = 0; rc == 0 && v < p->nvary; v++)
        rc = dataset(h, g, p->vary[v].key, h->H5T_IEEE_F64LE_g, h->H5T_NATIVE_DOUBLE_g, 1, dims, t->vary + (size_t)v * cap);
    if (rc == 0) rc = text_dataset(h, g, "status", (const char *const *)t->status, t->n);
    if (rc == 0) rc = text_dataset(h, g, "reason", (const char *const *)t->reason, t->n);
    for (int c = 0; rc == 0 && c < ncol; c++)
        rc = cols[c].integer
                 ? dataset(h, g, cols[c].name, h->H5T_STD_I64LE_g, h->H5T_NATIVE_LLONG_g, 1, dims, t->count + (size_t)c * cap)
                 : dataset(h, g, cols[c].name, h->H5T_IEEE_F64LE_g, h->H5T_NATIVE_DOUBLE_g, 1, dims, t->real + (size_t)c * cap);
    /* HDF5 lists a group's datasets by name: the attribute keeps members.csv's order */
    const char *order[SWEEP_MAX_VARY + 32];
    int k = 0;
    order[k++] = "id";
    for (int v = 0; v < p->nvary; v++) order[k++] = p->vary[v].key;
    order[k++] = "status";
    order[k++] = "reason";
    for (int c = 0; c < ncol && k < (int)(sizeof order / sizeof order[0]); c++) order[k++] = cols[c].name;
    if (rc == 0) rc = names_attribute(h, g, "columns", order, k);
    h->H5Gclose(g);
    return rc;
}

/* ---- trajectories ------------------------------------------------------------------------ */

/* A numeric CSV as swim writes it (runtime/io/csv.h: a header, then rows of %.17g or nan): the
 * names and a row-major matrix. 0, or -1 with a reason. */
static int csv_matrix(const char *text, char ***names, int *ncol, double **data, long *nrow, char *why, size_t len)
{
    *names = NULL;
    *data = NULL;
    *ncol = 0;
    *nrow = 0;
    const char *eol = strchr(text, '\n');
    if (!eol) {
        snprintf(why, len, "no header line");
        return -1;
    }
    int n = 1;
    for (const char *c = text; c < eol; c++) n += *c == ',';
    char **nm = calloc((size_t)n, sizeof *nm);
    if (!nm) return snprintf(why, len, "out of memory"), -1;
    const char *start = text;
    for (int i = 0; i < n; i++) {
        const char *end = memchr(start, ',', (size_t)(eol - start));
        if (!end) end = eol;
        nm[i] = strndup(start, (size_t)(end - start));
        start = end + 1;
    }
    *names = nm;
    *ncol = n;
    long rows = 0;
    for (const char *c = eol + 1; *c; c++) rows += *c == '\n';
    double *d = malloc(((size_t)rows * (size_t)n + 1) * sizeof *d);
    if (!d) return snprintf(why, len, "out of memory"), -1;
    *data = d;
    const char *c = eol + 1;
    for (long r = 0; r < rows; r++)
        for (int j = 0; j < n; j++) {
            char *end;
            d[(size_t)r * (size_t)n + (size_t)j] = strtod(c, &end);
            const char want = j + 1 < n ? ',' : '\n';
            if (end == c || *end != want) {
                snprintf(why, len, "row %ld, column %d is not a number", r + 1, j + 1);
                return -1;
            }
            c = end + 1;
        }
    *nrow = rows;
    return 0;
}

static int trajectories_write(const h5lib *h, const sweep_plan *p, const table *t, hid_t file, char *why, size_t len)
{
    hid_t g = h->H5Gcreate2(file, "trajectories", H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT);
    if (g < 0) return snprintf(why, len, "cannot create /trajectories"), -1;
    int rc = 0;
    for (long r = 0; rc == 0 && r < t->n; r++) {
        char dir[SWIM_SWEEP_PATH + 64], path[SWIM_SWEEP_PATH + 96], name[32];
        sweep_member_dir(p, (long)t->id[r], dir, sizeof dir);
        snprintf(path, sizeof path, "%s/trajectory.csv", dir);
        size_t bytes;
        char *text = swim_read_file(path, MAX_TRAJECTORY_BYTES, &bytes);
        if (!text) continue;   /* a member that failed before writing rows, or crashed */
        char **names;
        double *data;
        int ncol;
        long nrow;
        char bad[128];
        if (csv_matrix(text, &names, &ncol, &data, &nrow, bad, sizeof bad) != 0) {
            snprintf(why, len, "%s: %s", path, bad);
            rc = -1;
        } else {
            const hsize_t dims[2] = {(hsize_t)nrow, (hsize_t)ncol};
            snprintf(name, sizeof name, "%05lld", t->id[r]);
            if (dataset(h, g, name, h->H5T_IEEE_F64LE_g, h->H5T_NATIVE_DOUBLE_g, 2, dims, data) != 0) rc = -1;
            hid_t ds = rc == 0 ? h->H5Dopen2(g, name, H5P_DEFAULT) : -1;
            if (ds < 0 || names_attribute(h, ds, "columns", (const char *const *)names, ncol) != 0) rc = -1;
            if (ds >= 0) h->H5Dclose(ds);
            if (rc) snprintf(why, len, "cannot write /trajectories/%s", name);
        }
        for (int j = 0; names && j < ncol; j++) free(names[j]);
        free(names);
        free(data);
        free(text);
    }
    h->H5Gclose(g);
    return rc;
}

/* ---- the file ------------------------------------------------------------------------------ */

static int write_file(const h5lib *h, const sweep_plan *p, const char *path, const table *t, char *why, size_t len)
{
    char def_path[SWIM_SWEEP_PATH + 64];
    snprintf(def_path, sizeof def_path, "%s/sweep.json", p->dir);
    size_t def_len;
    char *definition = swim_read_file(def_path, 64u << 20, &def_len);
    if (!definition) return snprintf(why, len, "cannot read %s: %s", def_path, strerror(errno)), -1;
    hid_t file = h->H5Fcreate(path, FILE_TRUNCATE, H5P_DEFAULT, H5P_DEFAULT);
    if (file < 0) {
        free(definition);
        return snprintf(why, len, "cannot create the file"), -1;
    }
    int rc = text_attribute(h, file, "swim_version", SWIM_VERSION) || text_attribute(h, file, "definition", definition) ||
             text_attribute(h, file, "scene", p->scene_text ? p->scene_text : "") ||
             long_attribute(h, file, "members", p->members)
                 ? -1 : 0;
    if (rc) snprintf(why, len, "cannot write the attributes of /");
    if (rc == 0 && table_write(h, p, t, file) != 0) {
        snprintf(why, len, "cannot write /members");
        rc = -1;
    }
    if (rc == 0 && p->keep_trajectories) rc = trajectories_write(h, p, t, file, why, len);
    /* every object of the file is closed by now (the pieces above close theirs on every path),
     * so the close only flushes; when that fails (a full disk) HDF5 keeps the file half-closed,
     * and no further call may touch it: a second close, or the library's exit handler
     * (H5dont_atexit below), crashes on it. The temporary file is removed by the caller. */
    errno = 0;
    if (h->H5Fclose(file) < 0) {
        if (rc == 0) snprintf(why, len, "cannot finish the file (%s)", errno ? strerror(errno) : "a write failed");
        rc = -1;
    }
    free(definition);
    return rc;
}

int sweep_family_hdf5_ready(char *why, size_t len)
{
    h5lib lib;
    return h5lib_open(&lib, why, len);
}

int sweep_family_hdf5_due(const sweep_plan *p)
{
    char path[SWIM_SWEEP_PATH + 64];
    snprintf(path, sizeof path, "%s/family.h5", p->dir);
    return p->format_hdf5 || access(path, F_OK) == 0;
}

int sweep_write_family_hdf5(const sweep_plan *p, swim_status *st)
{
    char path[SWIM_SWEEP_PATH + 64], tmp[SWIM_SWEEP_PATH + 64], why[SWIM_SWEEP_PATH + 256] = "";
    snprintf(path, sizeof path, "%s/family.h5", p->dir);
    snprintf(tmp, sizeof tmp, "%s/family.h5.tmp", p->dir);
    h5lib lib, *h = &lib;
    int rc = h5lib_open(h, why, sizeof why);
    if (rc == 0) {
        h->H5Eset_auto2(H5E_DEFAULT, NULL, NULL);   /* its own error stack print: the one line below says it */
        table t;
        rc = table_read(p, &t);
        if (rc) snprintf(why, sizeof why, "out of memory");
        if (rc == 0) rc = write_file(h, p, tmp, &t, why, sizeof why);
        table_free(&t);
    }
    if (rc == 0 && rename(tmp, path) != 0) {
        snprintf(why, sizeof why, "%s", strerror(errno));
        rc = -1;
    }
    if (rc == 0) return 0;
    remove(tmp);
    /* an earlier family.h5 would say fewer members than members.csv now has: it goes too */
    const int stale = remove(path) == 0;
    swim_status_fail_cmd(st, p->cmd, NULL, NULL, "cannot write %s: %s%s", path, why,
                         stale ? " (the earlier family.h5 is removed: it would not match members.csv)" : "");
    return 1;
}
