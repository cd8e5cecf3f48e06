RUNTIME_SRCS += runtime/model/dynamics.c runtime/model/flow.c runtime/model/bounce.c runtime/model/sensitivity.c runtime/model/lyapunov.c
BENCH_SRCS   += tests/bench/bench_rhs_parts.c
