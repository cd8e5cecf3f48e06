# runtime/sweep: families of runs (swim sweep; bin/swim-mpi with `make mpi`).
RUNTIME_SRCS += runtime/sweep/sweep.c
