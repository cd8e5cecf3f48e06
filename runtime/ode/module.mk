# ODE integrators: ABM (ode113 class) and GSL/CVODE peers behind swim_ode_*.
RUNTIME_SRCS += runtime/ode/ode.c runtime/ode/events.c runtime/ode/abm.c runtime/ode/peers_gsl.c runtime/ode/peers_cvode.c
BENCH_SRCS   += tests/bench/bench_ode.c tests/bench/bench_step_floor.c
