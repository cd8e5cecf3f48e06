RUNTIME_SRCS += runtime/model/shape.c runtime/model/constraints.c runtime/model/dynamics.c \
                runtime/model/flow.c runtime/model/specialize.c
$(BUILD)/runtime/model/specialize.o: CPPFLAGS += -DSWIM_ROOT='"$(CURDIR)"' -DSWIM_PYTHON='"$(PYTHON)"' \
    -DSWIM_CC='"$(CC)"' -DSWIM_KERNEL_CFLAGS='"$(OPT)"'
TEST_SRCS += tests/test_kernels.c
