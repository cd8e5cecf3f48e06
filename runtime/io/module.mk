RUNTIME_SRCS += runtime/io/json.c runtime/io/csv.c runtime/io/files.c runtime/io/message.c runtime/io/status.c
$(BUILD)/runtime/io/files.o: CPPFLAGS += -DSWIM_PYTHON='"$(PYTHON)"'
RUNTIME_SRCS += runtime/io/clock.c
