RUNTIME_SRCS += runtime/cli/args.c runtime/cli/inspect.c
