RUNTIME_SRCS += runtime/cli/args.c runtime/cli/inspect.c runtime/cli/run.c runtime/cli/run_settings.c runtime/cli/run_signals.c \
                runtime/cli/plot.c runtime/cli/flow.c runtime/cli/animate.c runtime/cli/sweep.c runtime/cli/sweep_args.c runtime/cli/floquet.c runtime/cli/periodic.c runtime/cli/continue.c runtime/cli/optimize.c runtime/cli/cache.c runtime/cli/export.c \
                runtime/cli/report.c
