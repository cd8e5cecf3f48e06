# The shape on the unit circle: J, min J, the barrier quadrature, and the constraints G1, G2, locks.
RUNTIME_SRCS += runtime/shape/shape.c runtime/shape/constraints.c runtime/shape/barrier.c
# The quadrature's complex arithmetic never meets infinities or NaN (J > 0 is checked first), so
# the textbook product and quotient are exact enough and avoid libgcc's checked __muldc3/__divdc3.
# Nor does it read errno: without -fno-math-errno GCC keeps every sqrt a scalar call (it might set
# errno), and the node loops of J^-1/2 stop vectorizing.
$(BUILD)/runtime/shape/barrier.o: CFLAGS += -fcx-limited-range -fno-math-errno
