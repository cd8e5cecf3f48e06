# runtime/control: sensitivities (variational equations), Floquet multipliers of periodic
# strokes, optimization of scene values, Lyapunov exponents (swim run --sensitivity / --lyapunov, swim floquet,
# swim periodic, swim continue, swim optimize).
RUNTIME_SRCS += runtime/control/sensitivity.c runtime/control/floquet.c runtime/control/model_setup.c runtime/control/optimize.c runtime/control/periodic.c runtime/control/continuation.c runtime/control/lyapunov.c runtime/control/analyses.c
