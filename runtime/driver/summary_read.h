/* summary_read.h -- the one summary reader: what a run's summary.json says, read back in C.
 *
 * A sweep reads its members' summaries to write members.csv and to know, on resume, which members
 * are finished. The text is parsed as JSON (jansson: RFC 8259, strict -- trailing text, duplicate
 * keys and a truncated file are errors with their line and column; integers stay 64-bit json_int_t,
 * apart from reals) and every value is taken at its path in the tree, never by searching the text:
 * the total of accepted steps is stats.steps, not projection.steps or step_checks.steps.
 *
 * The summaries read are those of swim run (driver/summary.h, both kinds of run) and the one swim
 * sweep writes for a member that died without one (scene, status "crashed", reason). Keys read, by
 * path (sweep_columns names the same paths, tests/test_summary_read.c checks they agree):
 *
 *   status, reason                       strings
 *   t_reached, energy_drift_rel, jmin    numbers
 *   energy_drift_abs                     number: max |E - E0 - W| over the run,
 *                                        the energy-balance residual (members.csv's
 *                                        energy_balance_abs; = the drift without forcing/damping)
 *   final_state.x, .y, .theta            numbers
 *   stats.steps, stats.rhs_evaluations   integers (accepted steps of every integrator the run used)
 *   stats.integrate_seconds, stats.wall_seconds   numbers
 *   stats.max_rss_kb                     present only in a summary written to its end
 *
 * A value that is null (the writer's NaN and infinities) or absent is "not set"; a value of the
 * wrong type is an error. Library style: no output, no exit, no globals.
 */
#ifndef SWIM_SUMMARY_READ_H
#define SWIM_SUMMARY_READ_H

#include <jansson.h>
#include <stddef.h>

/* A number of the summary: set = 0 when null or absent. */
typedef struct {
    int set;
    double value;
} swim_summary_real;

/* An integer of the summary, exactly (64 bits): set = 0 when null or absent. */
typedef struct {
    int set;
    long long value;
} swim_summary_count;

#define SWIM_SUMMARY_STATUS 32
#define SWIM_SUMMARY_REASON 1024

typedef struct {
    char status[SWIM_SUMMARY_STATUS];   /* "completed", "failed", "crashed"; "" when absent */
    char reason[SWIM_SUMMARY_REASON];   /* UTF-8 as decoded, cut at a character boundary when
                                         * longer; "" when absent */
    swim_summary_real t_reached, x, y, theta;            /* x, y, theta: final_state */
    swim_summary_real energy_drift_rel, energy_balance_abs, jmin;
    swim_summary_count steps, rhs_evaluations;           /* stats */
    swim_summary_real integrate_seconds, wall_seconds;   /* stats */
    int whole;     /* written to its end: a non-empty status, and stats.max_rss_kb or status "crashed" */
    int stopped;   /* whole, and stopped by a signal: reason begins "interrupted" or "terminated by" */
} swim_summary;

/* Status of swim_summary_read. */
enum {
    SWIM_SUMMARY_OK = 0,
    SWIM_SUMMARY_UNREADABLE = -1,   /* the file cannot be opened or read (errno kept) */
    SWIM_SUMMARY_INVALID = -2       /* not JSON, not an object, or a value of the wrong type */
};

/* Reads a summary: from text (NUL-terminated) when text is not NULL, else from the file path.
 * path names the summary in messages either way (NULL: "summary.json"). On SWIM_SUMMARY_OK *out
 * holds the values; otherwise *out is cleared (not whole) and err holds one line saying why, with
 * the path and, for a JSON error, its line and column ("PATH:LINE:COLUMN: ..."). err may be NULL. */
int swim_summary_read(const char *path, const char *text, swim_summary *out, char *err, size_t errlen);
/* The same values from a summary's tree (driver/summary.h's swim_run_summary) without its text:
 * the numbers swim_summary_read gives for the text written from that tree (the writer's digits
 * read back to the same doubles). SWIM_SUMMARY_OK or SWIM_SUMMARY_INVALID, as there. */
int swim_summary_take(json_t *root, const char *path, swim_summary *out, char *err, size_t errlen);

#endif
