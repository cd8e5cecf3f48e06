/* libFuzzer target: the whole scene reader (TOML + validation of every key, admissibility of
 * the shape, constraints on the initial velocity, run settings). Its messages are silenced by
 * libFuzzer's -close_fd_mask (tests/fuzz/run_fuzz.sh). */
#include <math.h>
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "scene/scene.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    static swim_scene s;
    int rc = swim_scene_parse((const char *)data, size, "fuzz.toml", &s, NULL);
    if (rc == 0) {
        if (s.n != 2 * (s.modes + 1) || s.modes < 0 || s.modes > SWIM_KERNEL_MAX_MODES || !(s.run.t_end > 0) || !(s.run.output_step > 0)) abort();
        /* an accepted scene passed the run-settings check (the magnitude check needs the
         * kernel of N modes: swim_scene_check_model, run by swim run) */
        if (!(s.run.t_end / s.run.output_step <= SWIM_ROWS_MAX) || !(s.run.rtol >= SWIM_RTOL_MIN && s.run.rtol <= SWIM_RTOL_MAX) ||
            !(s.run.atol > 0 && s.run.atol <= SWIM_ATOL_MAX))
            abort();
        if (s.forcing && !swim_expr_defined(s.forcing, 0.0, NULL, 0)) abort();
        if (!s.path || !s.title || strcmp(s.path, "fuzz.toml") != 0) abort();
        swim_scene_free(&s);
    } else if (rc != 2) {
        abort();
    }
    return 0;
}
