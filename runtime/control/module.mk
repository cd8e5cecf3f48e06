# runtime/control: Floquet multipliers of periodic strokes, periodic orbits, continuation,
# optimization of scene values (swim floquet, swim periodic, swim continue, swim optimize), and the
# variational equations integrated on their own (optimize's gradient; swim run carries them on
# its own steps: driver/analyses.c, model/sensitivity.c).
RUNTIME_SRCS += runtime/control/sensitivity.c runtime/control/floquet.c runtime/control/optimize.c runtime/control/periodic.c runtime/control/continuation.c
