# runtime/control: Floquet multipliers of periodic strokes, periodic orbits, continuation,
# optimization of scene values (swim floquet, swim periodic, swim continue, swim optimize). They
# integrate nothing themselves: every flow map, monodromy and gradient is a driver run
# (driver/flow.h).
RUNTIME_SRCS += runtime/control/floquet.c runtime/control/optimize.c runtime/control/periodic.c runtime/control/continuation.c
