# runtime/lib: libswim, the public C API (swim.h) over the run driver, as a shared library
# (libswim.so.MAJOR, its symbols limited to swim.h's) and a static one, with swim.pc for
# pkg-config. `make lib` builds them; `make install` installs them with the header; `make
# uninstall` removes exactly what install put there. The version is VERSION's, the one file.
SWIM_VERSION := $(shell cat VERSION 2>/dev/null || echo unknown)
SWIM_MAJOR   := $(firstword $(subst ., ,$(SWIM_VERSION)))
CPPFLAGS     += -DSWIM_VERSION='"$(SWIM_VERSION)"'
RUNTIME_SRCS += runtime/lib/swim.c

# The rules are in runtime/lib/rules.mk, read once LIB_OBJS is known.
# The objects that print the version are rebuilt when VERSION changes.
$(BUILD)/runtime/lib/swim.o $(BUILD)/pic/runtime/lib/swim.o \
$(BUILD)/runtime/driver/summary.o $(BUILD)/pic/runtime/driver/summary.o \
$(BUILD)/runtime/export/export.o $(BUILD)/pic/runtime/export/export.o: VERSION
