RUNTIME_SRCS += runtime/model/dynamics.c runtime/model/flow.c runtime/model/bounce.c
BENCH_SRCS   += tests/bench/bench_rhs_parts.c
