/* libFuzzer target: the run-settings check (swim_run_settings_check in runtime/scene/scene.c)
 * on any t_end, output_step, rtol, atol, command-line origin and forcing law. Invariants: it
 * returns 0 or 2; when it accepts, the bounds documented in scene.h hold, and the law is
 * finite at t0 and up to the recorded forcing_finite_until. The input: 4 doubles, 1 byte of
 * origin flags, then the law text. */
#include <math.h>
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "scene/scene.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    if (size < 4 * sizeof(double) + 1 || size > 512) return 0;
    static swim_scene s;
    memset(&s, 0, sizeof s);
    double v[4];
    memcpy(v, data, sizeof v);
    s.run.t_end = v[0];
    s.run.output_step = v[1];
    s.run.rtol = v[2];
    s.run.atol = v[3];
    s.path = "fuzz.toml";
    swim_run_overrides cli;
    for (int i = 0; i < SWIM_SET_COUNT; i++) cli.given[i] = (data[sizeof v] >> i) & 1;
    size_t lawlen = size - sizeof v - 1;
    char *law = malloc(lawlen + 1), err[160];
    if (!law) return 0;
    memcpy(law, data + sizeof v + 1, lawlen);
    law[lawlen] = '\0';
    s.forcing = lawlen ? swim_expr_compile(law, err, sizeof err) : NULL;
    s.forcing_text = law;
    s.forced = s.forcing != NULL;
    int rc = swim_run_settings_check(&s, (data[sizeof v] & 0x80) ? NULL : &cli, NULL);
    if (rc != 0 && rc != 2) abort();
    if (rc == 0) {
        if (!(s.run.t_end > 0) || !(s.run.output_step > 0) || !(s.run.t_end / s.run.output_step <= SWIM_ROWS_MAX)) abort();
        if (!(s.run.rtol >= SWIM_RTOL_MIN && s.run.rtol <= SWIM_RTOL_MAX) || !(s.run.atol > 0 && s.run.atol <= SWIM_ATOL_MAX)) abort();
        if (s.forcing) {
            if (!swim_expr_defined(s.forcing, 0.0, NULL, 0) || !isfinite(swim_expr_eval(s.forcing, 0.0))) abort();
            double u = s.run.forcing_finite_until;
            if (!(u > 0)) abort();
            /* a recorded onset is a time where the law was evaluated and a part of it found not finite */
            if (isfinite(u) && (u > s.run.t_end || swim_expr_defined(s.forcing, u, NULL, 0))) abort();
        }
    }
    swim_expr_free(s.forcing);
    free(law);
    return 0;
}
