RUNTIME_SRCS += runtime/model/dynamics.c runtime/model/flow.c runtime/model/bounce.c
TEST_SRCS += tests/test_kernels.c tests/test_bounce.c
