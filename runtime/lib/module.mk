# runtime/lib: libswim, the public C API (swim.h) over the run driver, as a shared library
# (libswim.so.SWIM_ABI, its symbols limited to swim.h's) and a static one, with swim.pc for
# pkg-config. `make lib` builds them; `make install` installs them with the header; `make
# uninstall` removes exactly what install put there. The version is VERSION's, the one file.
SWIM_VERSION := $(shell cat VERSION 2>/dev/null || echo unknown)
# The ABI's number, the SONAME's (libswim.so.SWIM_ABI): swim.h's SWIM_ABI, apart from VERSION.
SWIM_ABI     := $(shell sed -n 's/^.define SWIM_ABI \([0-9][0-9]*\)$$/\1/p' runtime/lib/swim.h)
CPPFLAGS     += -DSWIM_VERSION='"$(SWIM_VERSION)"'
# swim.c refuses to build when swim.h's SWIM_VERSION_* or SWIM_ABI are not these
$(BUILD)/runtime/lib/swim.o: CPPFLAGS += \
  $(shell echo "$(SWIM_VERSION)" | awk -F. '{printf "-DSWIM_BUILD_MAJOR=%d -DSWIM_BUILD_MINOR=%d -DSWIM_BUILD_PATCH=%d", $$1, $$2, $$3}') \
  -DSWIM_BUILD_ABI=$(SWIM_ABI)
RUNTIME_SRCS += runtime/lib/swim.c
# members through libswim on 1 and 2 threads and in 2 processes (make bench)
BENCH_SRCS   += tests/bench/bench_lib_threads.c

# The rules are in runtime/lib/rules.mk, read once LIB_OBJS is known.
# The objects that print the version are rebuilt when VERSION changes.
$(BUILD)/runtime/lib/swim.o $(BUILD)/runtime/driver/summary.o $(BUILD)/runtime/export/export.o: VERSION
