RUNTIME_SRCS += runtime/cli/args.c runtime/cli/inspect.c runtime/cli/run.c runtime/cli/run_events.c \
                runtime/cli/plot.c runtime/cli/flow.c runtime/cli/animate.c runtime/cli/sweep.c
$(BUILD)/runtime/cli/plot.o: CPPFLAGS += -DSWIM_ROOT='"$(CURDIR)"' -DSWIM_PYTHON='"$(PYTHON)"'
$(BUILD)/runtime/cli/animate.o: CPPFLAGS += -DSWIM_ROOT='"$(CURDIR)"' -DSWIM_PYTHON='"$(PYTHON)"'
