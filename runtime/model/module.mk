RUNTIME_SRCS += runtime/model/dynamics.c runtime/model/flow.c runtime/model/bounce.c
