RUNTIME_SRCS += runtime/io/json.c
