/* libFuzzer target: the whole scene reader (TOML + validation of every key, admissibility of
 * the shape, constraints on the initial velocity). Its messages are silenced by
 * libFuzzer's -close_fd_mask (tests/fuzz/run_fuzz.sh). */
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>

#include "scene/scene.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    static swim_scene s;
    int rc = swim_scene_parse((const char *)data, size, "fuzz.toml", &s);
    if (rc == 0) {
        if (s.n != 2 * (s.modes + 1) || s.modes < 0 || s.modes > SWIM_KERNEL_MAX_MODES || !(s.t_end > 0) || !(s.output_step > 0)) abort();
        swim_scene_free(&s);
    } else if (rc != 2) {
        abort();
    }
    return 0;
}
