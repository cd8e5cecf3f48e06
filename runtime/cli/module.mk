RUNTIME_SRCS += runtime/cli/args.c runtime/cli/inspect.c runtime/cli/run.c runtime/cli/plot.c
