RUNTIME_SRCS += runtime/cli/args.c runtime/cli/inspect.c runtime/cli/run.c runtime/cli/plot.c runtime/cli/sweep.c
$(BUILD)/runtime/cli/plot.o: CPPFLAGS += -DSWIM_ROOT='"$(CURDIR)"' -DSWIM_PYTHON='"$(PYTHON)"'
