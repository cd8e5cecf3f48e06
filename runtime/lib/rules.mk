# runtime/lib's rules (runtime/lib/module.mk says what they build); included after LIB_OBJS.
LIB_SO     := $(BUILD)/lib/libswim.so.$(SWIM_VERSION)
LIB_A      := $(BUILD)/lib/libswim_static.a

.PHONY: lib install-lib uninstall-lib uninstall
lib: $(LIB_SO) $(LIB_A)

# The library's objects are compiled once, position-independent and with hidden symbols (only
# SWIM_API's are seen), for the shared library and for everything linked statically -- bin/swim,
# the tests, libswim_static.a -- alike: hidden symbols bind within the module, so the code is the
# one a position-independent executable gets.
$(LIB_OBJS): CFLAGS += -fPIC -fvisibility=hidden
# A build folder from before (objects without -fPIC, which libswim.so cannot link, or the runtime's
# with straight-line vectorization, Makefile) has no stamp of this name: made now, it is newer than
# those objects, and they are compiled again, once.
LIB_OBJS_STAMP := $(BUILD)/.lib-objects-pic-noslp
$(LIB_OBJS_STAMP):
	@mkdir -p $(dir $@) && touch $@
$(LIB_OBJS): $(LIB_OBJS_STAMP)

$(LIB_SO): $(LIB_OBJS)
	@mkdir -p $(dir $@)
	$(CC) -shared -Wl,-soname,libswim.so.$(SWIM_ABI) -Wl,--no-undefined $(CFLAGS) $^ -o $@ $(LDLIBS)
$(LIB_A): $(LIB_OBJS)
	@mkdir -p $(dir $@)
	rm -f $@ && ar rcs $@ $^

# swim.pc for PREFIX, written at install (PREFIX may hold spaces and quotes: it goes through the
# environment, never through make's text): the shared library with its run path, so a program
# finds it without LD_LIBRARY_PATH; --static links the archive and what it needs.
LIB_INSTALLED = lib/libswim.so.$(SWIM_VERSION) lib/libswim.so.$(SWIM_ABI) lib/libswim.so lib/libswim.a \
                include/swim.h lib/pkgconfig/swim.pc
install: install-lib
install-lib: export SWIM_INSTALL_DEST := $(DESTDIR)$(PREFIX)
install-lib: export SWIM_INSTALL_PREFIX := $(PREFIX)
install-lib: export SWIM_LIBS_PRIVATE := $(LDLIBS)
install-lib: lib | install-begin
	@case "$$SWIM_INSTALL_DEST" in /*) ;; *) echo "make install: PREFIX='$$SWIM_INSTALL_DEST' is not an absolute path" >&2; exit 2 ;; esac
	install -D -m 755 $(LIB_SO) "$$SWIM_INSTALL_DEST/lib/libswim.so.$(SWIM_VERSION)"
	ln -sf libswim.so.$(SWIM_VERSION) "$$SWIM_INSTALL_DEST/lib/libswim.so.$(SWIM_ABI)"
	ln -sf libswim.so.$(SWIM_ABI) "$$SWIM_INSTALL_DEST/lib/libswim.so"
	install -D -m 644 $(LIB_A) "$$SWIM_INSTALL_DEST/lib/libswim.a"
	install -D -m 644 runtime/lib/swim.h "$$SWIM_INSTALL_DEST/include/swim.h"
	install -d "$$SWIM_INSTALL_DEST/lib/pkgconfig"
	{ printf 'prefix=%s\n' "$$SWIM_INSTALL_PREFIX"; printf '%s\n' 'libdir=$${prefix}/lib' 'includedir=$${prefix}/include' '' \
	  'Name: swim' 'Description: an elastic swimmer in a 2D perfect fluid (Munnier), as a C library' \
	  'Version: $(SWIM_VERSION)' 'Cflags: -I$${includedir}' 'Libs: -L$${libdir} -Wl,-rpath,$${libdir} -lswim'; \
	  printf 'Libs.private: %s\n' "$$SWIM_LIBS_PRIVATE"; } > "$$SWIM_INSTALL_DEST/lib/pkgconfig/swim.pc"
	@$(INSTALL_RECORD)

uninstall: uninstall-lib
uninstall-lib: export SWIM_INSTALL_DEST := $(DESTDIR)$(PREFIX)
uninstall-lib:
	cd "$$SWIM_INSTALL_DEST" 2>/dev/null && rm -f $(LIB_INSTALLED); true
	bash tools/install_manifest.sh prune

# The C API's tests (tests/test_library*.c: two threads running two models, two threads building
# one kernel while a third watches the signal handlers) built with ThreadSanitizer in their own
# build folder (the programs tsan-test_library*): `make test` runs them beside the plain suite, so
# the thread promise of swim.h is checked on every change; `make tsan-test` runs them alone. The
# kernels they build keep the plain flags, so they share the test cache.
TSAN_BUILD := build/tsan
TSAN_TESTS := $(patsubst tests/%.c,$(TSAN_BUILD)/tests/%,$(wildcard tests/test_library*.c))
TSAN_ENV := TSAN_OPTIONS=halt_on_error=1
.PHONY: tsan-tests tsan-test
tsan-tests: | $(DEPS_STAMP)
	@$(MAKE) --no-print-directory BUILD=$(TSAN_BUILD) BIN=$(TSAN_BUILD)/bin OPT="-O1 -fsanitize=thread" DEBUG=-g1 \
	  KERNEL_OPT="$(KERNEL_OPT)" $(TSAN_TESTS)
tsan-test: tsan-tests
	@$(TSAN_ENV) SWIM_CACHE=$${SWIM_CACHE:-$(CURDIR)/$(BUILD)/cache} SWIM_BIN=$(CURDIR)/$(BIN)/swim \
	  bash tests/run_tests.sh $(TSAN_TESTS)
