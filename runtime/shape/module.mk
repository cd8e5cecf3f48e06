# The shape on the unit circle: J, min J, the barrier quadrature, and the constraints G1, G2, locks.
RUNTIME_SRCS += runtime/shape/shape.c runtime/shape/constraints.c runtime/shape/barrier.c
TEST_SRCS    += tests/test_barrier.c
