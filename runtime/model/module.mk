RUNTIME_SRCS += runtime/model/shape.c
TEST_SRCS += tests/test_kernels.c
