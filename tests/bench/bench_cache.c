/* What a later use of a run-time kernel costs: the first swim_codegen_kernel(N) of a fresh
 * process on a warm cache (hash of the generator folder and the kernel headers, manifest check
 * with the hash of kernel.so, dlopen), in milliseconds, one line "N,ms" per N on the command
 * line. Run it several times and take the median (tests/bench/bench_latency.py does). */
#include <stdio.h>
#include <stdlib.h>

#include "bench/timing.h"
#include "codegen/codegen.h"

int main(int argc, char **argv)
{
    for (int a = 1; a < argc; a++) {
        int N = atoi(argv[a]);
        swim_compiled c;
        double t0 = bench_now();
        int rc = swim_codegen_kernel(N, &c, 0, NULL);
        double ms = 1e3 * (bench_now() - t0);
        if (rc != 0) return 1;
        printf("%d,%.3f,%s\n", N, ms, c.from_cache ? "cache" : c.handle ? "built" : "linked");
        swim_compiled_close(&c);
    }
    return 0;
}
