/* The flow map as a driver run (runtime/driver/flow.h), on models/example3.toml:
 *   - a section (a maximum of the first carried coordinate) whose hit ends the flow at its second
 *     event: the flow ends there, completed, at the time told, with that coordinate's velocity 0
 *     in the state it returns;
 *   - the monodromy columns d y(T) / d y0 carried on the flow's steps map the flow direction at the
 *     start onto the flow direction at the end (M f(y0) = f(y(T)), the columns' defining identity
 *     along the orbit);
 *   - columns outside the error test leave the state bit for bit the flow's without them;
 *   - the flow starts from the state it is given (a flow of 0.5 from the end of a flow of 0.5 is
 *     the flow of 1 to the tolerance). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "driver/flow.h"
#include "problem/problem.h"

#define SCENE "models/example3.toml"

typedef struct {
    int count, stop_at;
    double t[4];
} hits;

static int on_hit(void *ctx, double t)
{
    hits *h = ctx;
    if (h->count < 4) h->t[h->count] = t;
    return ++h->count >= h->stop_at;
}

int main(void)
{
    swim_problem *p = calloc(1, sizeof *p);
    swim_status st = {0};
    const swim_problem_source src = {.path = SCENE};
    int rc = swim_problem_open(p, &src, "test", 0, 0, &st);
    CHECK(rc == 0 && p->dyn_ready, "opened %s: %d", SCENE, rc);
    if (rc) return check_report("test_flow_map");
    swim_dynamics *d = &p->d;
    const int n = swim_dynamics_state_dim(d), nf = d->spec->nfree, n2 = 2 * nf;
    double *y0 = malloc(sizeof(double) * n), *full = calloc((size_t)d->dim, sizeof(double));
    double *f0 = malloc(sizeof(double) * n), *f1 = malloc(sizeof(double) * n);
    swim_dynamics_initial_state(d, full);
    swim_dynamics_pack(d, full, y0);

    /* the section: the second maximum of the first carried coordinate ends the flow */
    hits h = {0, 2, {0}};
    const swim_run_section sec = {3, 'x', on_hit, &h};
    swim_flow f;
    rc = swim_flow_map(&(swim_flow_request){.model = d, .t_end = 50.0, .section = &sec}, &f, &st);
    CHECK(rc == 0 && f.section_ended && h.count == 2 && f.t == h.t[1] && h.t[0] > 0 && h.t[1] > h.t[0] &&
          f.t < 50.0, "ended at the second maximum: rc %d, ended %d, %d hits, t %.17g, hits at %g, %g", rc,
          f.section_ended, h.count, f.t, h.t[0], h.t[1]);
    if (rc == 0)
        CHECK(fabs(f.Y[3 + nf]) < 1e-7, "the coordinate's velocity at its maximum: %.3g", f.Y[3 + nf]);
    swim_flow_free(&f);

    /* the monodromy over T = 1: M f(y0) = f(y(T)) */
    const double T = 1.0;
    swim_flow m;
    rc = swim_flow_map(&(swim_flow_request){.model = d, .y0 = y0, .t_end = T, .vars = {3, n2, NULL, 0, "test", 1}},
                       &m, &st);
    CHECK(rc == 0 && m.S.nkeys == n2 && m.t == T, "the monodromy's flow: rc %d, %d columns, t %g", rc, m.S.nkeys, m.t);
    if (rc == 0 && swim_dynamics_rhs(0.0, y0, f0, d) == 0 && swim_dynamics_rhs(T, m.Y, f1, d) == 0) {
        double err = 0.0, scale = 0.0;
        for (int i = 0; i < n2; i++) {
            double mf = 0.0;
            for (int j = 0; j < n2; j++) mf += m.Y[(size_t)(j + 1) * n + 3 + i] * f0[3 + j];
            err = fmax(err, fabs(mf - f1[3 + i]));
            scale = fmax(scale, fabs(f1[3 + i]));
        }
        CHECK(err <= 1e-7 * scale, "M f(y0) = f(y(T)): max error %.3g of %.3g", err, scale);
    }

    /* outside the error test the state is the flow's without them, bit for bit */
    swim_flow plain, riding;
    const int prc = swim_flow_map(&(swim_flow_request){.model = d, .y0 = y0, .t_end = T}, &plain, &st);
    const int rrc = swim_flow_map(&(swim_flow_request){.model = d, .y0 = y0, .t_end = T,
                                                       .vars = {3, n2, NULL, 0, "test", 0}}, &riding, &st);
    CHECK(prc == 0 && rrc == 0 && memcmp(plain.Y, riding.Y, sizeof(double) * n) == 0,
          "columns outside the error test leave the state as it was: %d %d", prc, rrc);
    if (rc == 0 && prc == 0) {
        double diff = 0.0;   /* in the error test the steps differ: the same state to the tolerance */
        for (int i = 0; i < n; i++) diff = fmax(diff, fabs(plain.Y[i] - m.Y[i]));
        CHECK(diff > 0 && diff < 1e-7, "in the error test: the same state to %.3g", diff);
    }

    /* from a given state: 0.5 then 0.5 is 1 */
    swim_flow half, second;
    const int hrc = swim_flow_map(&(swim_flow_request){.model = d, .y0 = y0, .t_end = 0.5}, &half, &st);
    const int src2 = hrc == 0 ? swim_flow_map(&(swim_flow_request){.model = d, .y0 = half.Y, .t_end = 0.5}, &second, &st) : 1;
    if (hrc == 0 && src2 == 0 && prc == 0) {
        double diff = 0.0;
        for (int i = 3; i < 3 + n2; i++) diff = fmax(diff, fabs(second.Y[i] - plain.Y[i]));
        CHECK(diff < 1e-7, "a flow from the state it is given: 0.5 + 0.5 vs 1 differ by %.3g", diff);
        swim_flow_free(&second);
    } else {
        CHECK(0, "the two half flows: %d %d", hrc, src2);
    }
    swim_flow_free(&half);
    swim_flow_free(&plain);
    swim_flow_free(&riding);
    swim_flow_free(&m);
    free(y0); free(full); free(f0); free(f1);
    swim_problem_close(p);
    free(p);
    return check_report("test_flow_map");
}
