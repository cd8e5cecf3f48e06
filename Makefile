# swim: symbolic-to-C toolchain for an elastic swimmer in a 2D perfect fluid.
# `make help` lists the targets. Each module adds its own sources through a
# module.mk fragment (runtime/*/module.mk, tests/*/module.mk).

SHELL      := /bin/bash
MAKEFLAGS  += --no-builtin-rules
# A cold `make test` (or `make`) is mostly compiling -- three builds with the tests: plain, ASan and
# TSan -- so those goals build on every core. Every other goal runs one job at a time: a benchmark
# must not share the machine with another, an install keeps its order. A -j given on the command
# line still decides.
ifeq ($(filter-out all test lib run,$(or $(MAKECMDGOALS),all)),)
MAKEFLAGS  += -j$(shell nproc 2>/dev/null || echo 1)
endif
.SUFFIXES:
PYTHON     ?= /usr/bin/python3
export PYTHON
CC         ?= gcc
# Kernels are fixed-size loops: -O3 unrolls them and -march=native vectorizes them for the
# machine that builds (and runs) the simulator. Override with OPT=-O2 for a portable build.
OPT        ?= -O3 -march=native
# Flags of the kernels bin/swim generates and caches at run time (default: those of the build).
KERNEL_OPT ?= $(OPT)
# Debugging information: full by default; the sanitized twins of the tests (asan-tests,
# tsan-tests) take -g1, the line tables their stack traces need, which compile faster.
DEBUG      ?= -g
CFLAGS     ?= $(OPT) $(DEBUG)
CFLAGS     += -std=c11 -D_XOPEN_SOURCE=700 -Wall -Wextra -Wno-unused-parameter -MMD -MP
CPPFLAGS   += -Iruntime -I/usr/include/sundials
LDLIBS     += -ldl -lgsl -llapacke -llapack -lblas -lsundials_cvode -lsundials_nvecserial -ljansson -lquadmath -lm
# The programs (bin/swim, the tests) link the same libraries from their archives: a run then maps
# no shared library besides libc, libm and libgcc_s, and starts in about 2 ms instead of 25 ms
# (docs/performance.md, "Start-up and the cost around the RHS"). libgslcblas comes before libblas
# so that GSL's cblas calls go where they go in the shared link. LAPACK's archive needs
# libgfortran's (libgfortran-NN-dev, installed with gfortran): without it, LAPACK and BLAS stay
# shared (GFORTRAN_A empty). HDF5 is not linked at all: runtime/sweep/family_hdf5.c opens it when
# a family file is written. The shared library (runtime/lib) keeps LDLIBS.
GFORTRAN_A ?= $(filter /%,$(shell $(CC) -print-file-name=libgfortran.a))
EXE_LDLIBS  = -ldl -Wl,-Bstatic -lgsl -lgslcblas -lsundials_cvode -lsundials_nvecserial -lsundials_sunlinsoldense \
              -lsundials_sunmatrixdense -lsundials_generic -ljansson $(if $(GFORTRAN_A),-llapacke -llapack -lblas) \
              -Wl,-Bdynamic $(if $(GFORTRAN_A),$(GFORTRAN_A),-llapacke -llapack -lblas) -Wl,-Bstatic -lquadmath \
              -Wl,-Bdynamic -lm
BUILD      ?= build
BIN        ?= bin
# Mode counts whose kernels are committed (generated/) and linked into bin/swim; any other N up
# to SWIM_KERNEL_MAX_MODES is generated, compiled and cached by bin/swim on first use.
MODES      ?= 0 1 2 3 4 5 6 7
N          ?= 7
PREFIX     ?= /usr/local

# Debian packages a fresh machine lacks (checked by `make deps`). libjansson-dev: the JSON parser
# that reads summaries back (runtime/driver/summary_read.c). python3-pip, -venv, -setuptools,
# -wheel: `pip install ./python` offline into a virtual environment (tests/test_python_pip.sh).
DEB_PKGS   := libgsl-dev liblapacke-dev libsundials-dev libjansson-dev python3-sympy python3-numpy python3-scipy python3-matplotlib python3-pytest python3-pip python3-venv python3-setuptools python3-wheel strace jupyter-nbconvert python3-nbclient python3-ipykernel
# Installed on demand by the targets that need them (animations, the page and its browser test):
# ffmpeg pulls ~90 packages and chromium ~280 MB, too much for a plain build.
MEDIA_PKGS := ffmpeg chromium
# `make fuzz` only: clang with libFuzzer and the sanitizer runtimes (compiler-rt).
FUZZ_PKGS  := clang libclang-rt-14-dev

RUNTIME_SRCS :=
TEST_SRCS    := $(sort $(wildcard tests/test_*.c))
TEST_LIB_SRCS :=
BENCH_SRCS   :=

# Stamps of the package checks (the rule is below); modules name them as prerequisites.
DEPS_STAMP  := $(BUILD)/.deps-ok
MEDIA_STAMP := $(BUILD)/.deps-media-ok
MPI_STAMP   := $(BUILD)/.deps-mpi-ok
FUZZ_STAMP  := $(BUILD)/.deps-fuzz-ok

include $(wildcard runtime/*/module.mk) $(wildcard tests/*/module.mk)

KERNEL_SRCS := $(foreach n,$(MODES),generated/swim_kernel_n$(n).c)
LIB_SRCS    := $(RUNTIME_SRCS) $(KERNEL_SRCS)
LIB_OBJS    := $(LIB_SRCS:%.c=$(BUILD)/%.o) $(BUILD)/kernel_table.o
# No straight-line (SLP) vectorization of the runtime: GCC 12's turns pairs a b - c d, a d + b c
# (complex products, rotations) into fused vfmaddsub instructions although -std=c11 turns
# contraction off, and which pairs it fuses depends on the code around them, so an edit anywhere
# in a function could move the last bits of its results. It buys the runtime nothing measurable
# (docs/performance.md); the generated kernels keep it (their straight-line code needs it).
RUNTIME_OBJS := $(RUNTIME_SRCS:%.c=$(BUILD)/%.o)
$(RUNTIME_OBJS): CFLAGS += -fno-tree-slp-vectorize
export PYTHONHASHSEED := 0
TESTLIB_OBJS := $(TEST_LIB_SRCS:%.c=$(BUILD)/%.o)
include runtime/lib/rules.mk
include python/rules.mk
TEST_BINS   := $(patsubst %.c,$(BUILD)/%,$(TEST_SRCS))
BENCH_BINS  := $(patsubst %.c,$(BUILD)/%,$(BENCH_SRCS))

.PHONY: FORCE asan-tests all deps deps-media paper paper-test help install test sanitize fuzz bench bench-docs docs-numbers bench-accuracy bench-drift bench-variational bench-optimize bench-hard bench-soft generate generate-all run readme-figures clean
.DEFAULT_GOAL := all
all: $(BIN)/swim

help:
	@echo "make            build bin/swim (installs missing Debian packages first)"
	@echo "make deps       check/install: $(DEB_PKGS)"
	@echo "make deps-media check/install: $(MEDIA_PKGS) (for animations, the page and make test)"
	@echo "make paper      run every paper scene and family (fig-4-N sweeps), build out/paper/index.html (~3 min)"
	@echo "make paper-test make paper, then check the page in headless Chromium (out/paper/screenshot.png)"
	@echo "make test       build and run every test program in tests/ (T=PATTERN: only those whose name matches)"
	@echo "make mpi        bin/swim-mpi: swim sweep over MPI ranks (installs OpenMPI); make test-mpi tests it"
	@echo "make sanitize   the whole test suite under AddressSanitizer + UndefinedBehaviorSanitizer"
	@echo "                 (make test already runs the C unit tests so built, as asan-test_*)"
	@echo "make fuzz       fuzz the scene parser, the CLI arguments, message quoting and run settings (libFuzzer, FUZZ_SECONDS=60)"
	@echo "make bench      run the benchmarks (numbers quoted in README.md)"
	@echo "make bench-accuracy  work-precision diagrams and table for every paper scene (~9 min)"
	@echo "make bench-sweep     sweep throughput: --jobs 1/2, MPI 2/4 ranks, rank 0's cost (~3 min)"
	@echo "make paper-families  Figs 4.1, 4.2, 4.5, 4.6, 4.7 (sweeps + swim plot) into out/families/"
	@echo "make bench-optimize  Nelder-Mead vs BFGS, multi-start and the tolerance check on Section 5.2 (~30 min)"
	@echo "make bench-docs      the measurements README.md and docs/ quote (~7 min, build/bench/docs/)"
	@echo "make docs-numbers    rewrite the docs' generated number blocks from them (and the last make test)"
	@echo "make bench-variational  sensitivities and Lyapunov in a run: cost, before/after (~1 min)"
	@echo "make bench-drift     energy drift of the T = 1000 runs vs tolerance and step look-ahead (~30 s)"
	@echo "make bench-hard      every hard scene at its own settings and at rtol 1e-10 (~30 min)"
	@echo "make bench-soft      perturbed families of the soft hard scenes: completion, energy, time (~20 min)"
	@echo "make generate N=12   regenerate the kernel for one mode count into generated/"
	@echo "make generate-all    regenerate the committed kernels (N = $(MODES))"
	@echo "make install PREFIX=/usr/local   bin/swim (and bin/swim-mpi if built) + the generator, kernel headers and plot scripts,"
	@echo "                 libswim, swim.h, swim.pc, the Python package, swim(1) and the bash completion"
	@echo "make uninstall PREFIX=/usr/local removes exactly what install put there"
	@echo "make run        main job: simulate models/example3.toml and plot it"
	@echo "make readme-figures  rebuild docs/figures/ from the main job"
	@echo "make clean      remove build/ and bin/"

# Install what a fresh Debian machine lacks (as root), or say exactly what is missing.
deps: $(DEPS_STAMP)
deps-media: $(MEDIA_STAMP)
$(DEPS_STAMP): PKGS := $(DEB_PKGS)
$(MEDIA_STAMP): PKGS := $(MEDIA_PKGS)
$(MPI_STAMP): PKGS := $(MPI_PKGS)
$(FUZZ_STAMP): PKGS := $(FUZZ_PKGS)
# The stamps depend on the Makefile (and the module fragments listing packages): a package added to
# a list is checked again in a build folder whose stamp predates it. Two stamps can be made at once
# (parallel goals, above): their apt-get runs take turns on a lock, where dpkg's own would fail one.
$(DEPS_STAMP) $(MEDIA_STAMP) $(MPI_STAMP) $(FUZZ_STAMP): Makefile $(wildcard runtime/*/module.mk)
	@missing=""; for p in $(PKGS); do \
	  dpkg-query -W -f='$${Status}' $$p 2>/dev/null | grep -q "ok installed" || missing="$$missing $$p"; \
	done; \
	if [ -n "$$missing" ]; then \
	  if [ "$$(id -u)" = 0 ]; then \
	    echo "installing:$$missing"; \
	    mkdir -p build; \
	    flock build/.apt.lock sh -c 'apt-get update -qq && DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends "$$@" >/dev/null' sh $$missing || exit 1; \
	  else \
	    echo "missing Debian packages:$$missing -- run: sudo apt-get install$$missing" >&2; exit 1; \
	  fi; \
	fi
	@mkdir -p $(BUILD) && touch $@

$(BUILD)/%.o: %.c | $(DEPS_STAMP)
	@mkdir -p $(dir $@)
	$(CC) $(CPPFLAGS) $(CFLAGS) -c $< -o $@

# The table of kernels linked in; rewritten only when MODES changes.
$(BUILD)/kernel_table.c: FORCE | $(DEPS_STAMP)
	@$(PYTHON) generator/generate.py --table $(MODES) --out $@

$(BUILD)/kernel_table.o: $(BUILD)/kernel_table.c
	$(CC) $(CPPFLAGS) $(CFLAGS) -c $< -o $@

$(BUILD)/libswim.a: $(LIB_OBJS)
	rm -f $@ && ar rcs $@ $^   # afresh: a member whose source was moved or removed must not stay

$(BUILD)/libswimtest.a: $(TESTLIB_OBJS)
	ar rcs $@ $^

$(BIN)/swim: $(BUILD)/runtime/cli/main.o $(BUILD)/libswim.a
	@mkdir -p $(BIN)
	$(CC) $(CFLAGS) $^ -o $@ $(EXE_LDLIBS)

$(BUILD)/tests/%: $(BUILD)/tests/%.o $(BUILD)/libswimtest.a $(BUILD)/libswim.a
	$(CC) $(CFLAGS) $^ -o $@ $(EXE_LDLIBS)

$(BUILD)/tests/%.o: CPPFLAGS += -Itests

# Every tests/test_*.py and tests/test_*.sh is a test script, and every tests/test_*.c a test
# program (linked with the runtime and tests/reference/): a new test is picked up by its name.
TEST_SCRIPTS := $(sort $(wildcard tests/test_*.py tests/test_*.sh))

# Tests keep their kernel cache in the build folder, not in the user's ~/.cache/swim.
# bin/swim-mpi is built when OpenMPI is there or can be installed; test_sweep_mpi.py says when it is not.
# The C unit tests also run built with ASan + UBSan (ASAN_BUILD, the programs asan-test_*), beside
# the plain suite; the kernels they generate at run time keep the plain flags, so both share one
# kernel cache. A build that is itself sanitized (make sanitize) does not add them again.
ASAN_BUILD := build/asan
ifeq ($(findstring -fsanitize,$(OPT)),)
ASAN_TEST_BINS := $(patsubst $(BUILD)/%,$(ASAN_BUILD)/%,$(TEST_BINS))
TSAN_TEST_BINS := $(TSAN_TESTS)
endif
SAN_ENV := ASAN_OPTIONS=detect_leaks=1:halt_on_error=1 UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1

asan-tests: | $(DEPS_STAMP)
	@$(MAKE) --no-print-directory BUILD=$(ASAN_BUILD) BIN=$(ASAN_BUILD)/bin OPT="$(SANITIZE_OPT)" DEBUG=-g1 \
	  KERNEL_OPT="$(KERNEL_OPT)" $(ASAN_TEST_BINS)

# make test T=PATTERN runs only the programs whose name (test_io, asan-test_io, test_flow) matches
# the extended regular expression PATTERN.
# Everything the tests install is built first: two tests running `make install` at once only copy.
test: $(BIN)/swim lib $(BUILD)/man/swim.1 $(TEST_BINS) $(if $(ASAN_TEST_BINS),asan-tests) \
      $(if $(TSAN_TEST_BINS),tsan-tests) $(MEDIA_STAMP) $(FUZZ_STAMP)
	@$(MAKE) --no-print-directory mpi >/dev/null 2>&1 || echo "make mpi failed: the MPI sweep tests are skipped"
	@$(SAN_ENV) $(TSAN_ENV) SWIM_CACHE=$${SWIM_CACHE:-$(CURDIR)/$(BUILD)/cache} SWIM_BIN=$(CURDIR)/$(BIN)/swim \
	  TEST_FILTER='$(T)' bash tests/run_tests.sh $(TEST_BINS) $(ASAN_TEST_BINS) $(TSAN_TEST_BINS) $(TEST_SCRIPTS)

# bin/swim finds PREFIX/share/swim from its own location, so the tree can be moved as a whole.
SHARE_FILES := $(shell find generator runtime/kernel -type f -not -path '*/__pycache__/*' -not -name '*.pyc' 2>/dev/null) \
               $(wildcard runtime/plot/*.py)
# The example scenes (PREFIX/share/swim/models) and the documentation (PREFIX/share/doc/swim:
# README.md and docs/, the links between them kept): the man page names both.
MODEL_FILES := $(shell find models -type f -not -path '*/__pycache__/*' 2>/dev/null)
DOC_FILES := README.md $(shell find docs -type f 2>/dev/null)
# The destination reaches the shell through the environment, always inside double quotes: a
# PREFIX with spaces (or quotes, $, *) is one word, never split into stray relative folders.
# Every install rule runs after install-begin (a snapshot of what the destination holds) and
# ends with $(INSTALL_RECORD): what it created goes into DEST/share/swim/install-manifest, which
# `make uninstall` follows (tools/install_manifest.sh). A line added to an install rule before
# $(INSTALL_RECORD) is covered as it is. The snapshot is named by this make's process id, so two
# installs at once keep theirs apart.
INSTALL_SNAPSHOT = $(BUILD)/install-snapshot.$(shell echo $$PPID)
INSTALL_RECORD = bash tools/install_manifest.sh record "$(INSTALL_SNAPSHOT)"
.PHONY: install-begin
install-begin: export SWIM_INSTALL_DEST := $(DESTDIR)$(PREFIX)
install-begin:
	@case "$$SWIM_INSTALL_DEST" in /*) ;; *) echo "make install: PREFIX='$$SWIM_INSTALL_DEST' is not an absolute path" >&2; exit 2 ;; esac
	@mkdir -p $(BUILD) && bash tools/install_manifest.sh begin "$(INSTALL_SNAPSHOT)"

install: export SWIM_INSTALL_DEST := $(DESTDIR)$(PREFIX)
install: export SWIM_INSTALL_BIN := $(BIN)
install: $(BIN)/swim | install-begin
	@case "$$SWIM_INSTALL_DEST" in /*) ;; *) echo "make install: PREFIX='$$SWIM_INSTALL_DEST' is not an absolute path" >&2; exit 2 ;; esac
	install -d "$$SWIM_INSTALL_DEST/bin"
	install -m 755 "$$SWIM_INSTALL_BIN/swim" "$$SWIM_INSTALL_DEST/bin/swim"
	if [ -x "$$SWIM_INSTALL_BIN/swim-mpi" ]; then install -m 755 "$$SWIM_INSTALL_BIN/swim-mpi" "$$SWIM_INSTALL_DEST/bin/swim-mpi"; fi
	for f in $(SHARE_FILES); do install -D -m 644 "$$f" "$$SWIM_INSTALL_DEST/share/swim/$$f" || exit 1; done
	for f in $(MODEL_FILES); do install -D -m 644 "$$f" "$$SWIM_INSTALL_DEST/share/swim/$$f" || exit 1; done
	for f in $(DOC_FILES); do install -D -m 644 "$$f" "$$SWIM_INSTALL_DEST/share/doc/swim/$$f" || exit 1; done
	install -D -m 644 $(BUILD)/man/swim.1 "$$SWIM_INSTALL_DEST/share/man/man1/swim.1"
	install -D -m 644 $(BUILD)/swim.bash "$$SWIM_INSTALL_DEST/share/bash-completion/completions/swim"
	@$(INSTALL_RECORD) && rm -f "$(INSTALL_SNAPSHOT)"

# swim(1) and the bash completion, made from the program's own --help (runtime/cli/help_pages.py).
$(BUILD)/man/swim.1: $(BIN)/swim runtime/cli/help_pages.py
	@mkdir -p $(dir $@)
	$(PYTHON) runtime/cli/help_pages.py $(BIN)/swim --man $@ --completion $(BUILD)/swim.bash
$(BUILD)/swim.bash: $(BUILD)/man/swim.1
install: $(BUILD)/man/swim.1

# Exactly what install put there (the library's and the Python package's files by their own
# rules), then every file of the manifest and the folders install made (those that were there
# before it stay, even empty).
uninstall: export SWIM_INSTALL_DEST := $(DESTDIR)$(PREFIX)
uninstall: uninstall-bin
.PHONY: uninstall-bin
uninstall-bin: export SWIM_INSTALL_DEST := $(DESTDIR)$(PREFIX)
uninstall-bin: uninstall-lib uninstall-python
	@case "$$SWIM_INSTALL_DEST" in /*) ;; *) echo "make uninstall: PREFIX='$$SWIM_INSTALL_DEST' is not an absolute path" >&2; exit 2 ;; esac
	rm -f "$$SWIM_INSTALL_DEST/bin/swim" "$$SWIM_INSTALL_DEST/bin/swim-mpi" "$$SWIM_INSTALL_DEST/share/man/man1/swim.1" \
	  "$$SWIM_INSTALL_DEST/share/bash-completion/completions/swim"
	for f in $(SHARE_FILES) $(MODEL_FILES); do rm -f "$$SWIM_INSTALL_DEST/share/swim/$$f"; done
	for f in $(DOC_FILES); do rm -f "$$SWIM_INSTALL_DEST/share/doc/swim/$$f"; done
	if [ -d "$$SWIM_INSTALL_DEST/share/swim" ]; then find "$$SWIM_INSTALL_DEST/share/swim" -name __pycache__ -type d -prune -exec rm -rf {} +; fi
	bash tools/install_manifest.sh uninstall

# The whole test suite under AddressSanitizer and UndefinedBehaviorSanitizer (own build folder;
# specialized kernels are compiled with the same flags into their own cache entries).
SANITIZE_OPT := -O1 -g -fno-omit-frame-pointer -fsanitize=address,undefined -fno-sanitize-recover=undefined
sanitize: | $(DEPS_STAMP)
	ASAN_OPTIONS=detect_leaks=1 UBSAN_OPTIONS=print_stacktrace=1 \
	  $(MAKE) --no-print-directory BUILD=build/sanitize BIN=build/sanitize/bin OPT="$(SANITIZE_OPT)" test

# Short coverage-guided fuzzing of the scene parser, the command-line arguments, the quoting of
# user text in messages and the run-settings check (libFuzzer,
# clang); FUZZ_SECONDS per target.
FUZZ_SECONDS ?= 60
fuzz: | $(DEPS_STAMP) $(FUZZ_STAMP)
	bash tests/fuzz/run_fuzz.sh $(FUZZ_SECONDS)

BENCH_SCRIPTS := tests/bench/bench_kernels.sh tests/bench/bench_scenes.py tests/bench/bench_latency.py tests/bench/bench_drift.py \
                 tests/bench/bench_step_checks.py tests/bench/bench_jacobian.py tests/bench/bench_python_loop.py \
                 tests/bench/bench_sensitivity.py tests/bench/bench_variational.py tests/bench/bench_materials.py tests/bench/bench_overhead.py \
                 tests/bench/peer/bench_peer.py tests/bench/bench_first_use.py

bench: $(BIN)/swim $(BENCH_BINS) $(BUILD)/tests/bench/bench_rhs $(BUILD)/tests/bench/bench_jacobian_cost
	@bash tests/bench/run_bench.sh $(BENCH_SCRIPTS) $(BENCH_BINS)

generate: | $(DEPS_STAMP)
	$(PYTHON) generator/generate.py --modes $(N) --out generated

generate-all: | $(DEPS_STAMP)
	$(PYTHON) generator/generate.py --modes $(MODES) --out generated

run: $(BIN)/swim
	./$(BIN)/swim run models/example3.toml --out out/example3
	./$(BIN)/swim plot out/example3

# The paper's companion page: every scene of models/, one section per figure of sections 4-5.
paper: $(BIN)/swim $(MEDIA_STAMP)
	SWIM_BIN=$(CURDIR)/$(BIN)/swim $(PYTHON) tools/paper/build_paper.py --out out/paper

paper-test: paper
	$(PYTHON) tools/paper/browser_check.py out/paper/index.html --screenshot out/paper/screenshot.png

# Work-precision per paper scene: build/bench/accuracy/{accuracy.csv,table.md,*.png}.
bench-accuracy: $(BIN)/swim
	$(PYTHON) tests/bench/bench_accuracy.py

# The measurements the docs quote (tests/bench/bench_docs.py, ~7 min, build/bench/docs/), and the
# generated number blocks of README.md and docs/ rewritten from them and from the last make test.
bench-docs: $(BIN)/swim $(BUILD)/tests/bench/bench_rhs $(BUILD)/tests/bench/bench_step_floor $(BUILD)/tests/bench/bench_rhs_parts $(BUILD)/tests/bench/bench_kernel_flags $(BUILD)/tests/bench/bench_jacobian_cost
	SWIM_BIN=$(CURDIR)/$(BIN)/swim BENCH_RHS=$(CURDIR)/$(BUILD)/tests/bench/bench_rhs $(PYTHON) tests/bench/bench_docs.py

docs-numbers:
	$(PYTHON) tools/docs_numbers.py

bench-drift: $(BIN)/swim
	$(PYTHON) tests/bench/bench_drift.py

# The variational equations' cost in a run, before/after side by side when build/bench/swim-before
# exists: build/bench/variational/table.md (~1 min).
bench-variational: $(BIN)/swim
	$(PYTHON) tests/bench/bench_variational.py

# Nelder-Mead against BFGS on Section 5.2: build/bench/optimize/table.md.
bench-optimize: $(BIN)/swim
	$(PYTHON) tests/bench/bench_optimize.py

# Every scene of models/hard/ at its own settings and at rtol 1e-10: build/bench/hard/table.md.
bench-hard: $(BIN)/swim
	$(PYTHON) tests/bench/bench_hard.py

bench-soft: $(BIN)/swim
	$(PYTHON) tests/bench/bench_soft_family.py --scene models/hard/soft_n10_a05.toml --scene models/hard/soft_n10_a1.toml \
	    --variant noshift=run.origin_shift=false --variant nocontrol=run.energy_control=false
	$(PYTHON) tests/bench/bench_soft_family.py --scene models/hard/soft_n15_a05.toml --out build/bench/soft_family_n15
	$(PYTHON) tests/bench/bench_soft_family.py --scene models/hard/soft_n20_a05.toml --members 4 \
	    --variant nocontrol=run.energy_control=false --out build/bench/soft_family_n20
	$(PYTHON) tests/bench/bench_soft_family.py --scene models/hard/soft_n20_a1.toml --members 4 --out build/bench/soft_family_n20_a1

# Figures shown in README.md, rebuilt from the main job.
readme-figures: run
	mkdir -p docs/figures
	cp out/example3/snapshots.png docs/figures/example3_snapshots.png
	cp out/example3/energy.png docs/figures/example3_energy.png
	$(PYTHON) tests/bench/plot_drift.py docs/figures/drift_long_runs.png
	if [ -f build/bench/ode_work_precision.png ]; then cp build/bench/ode_work_precision.png docs/figures/; fi
	if [ -f build/bench/accuracy/work_precision_cpu.png ]; then cp build/bench/accuracy/work_precision_cpu.png docs/figures/scenes_work_precision_cpu.png; fi

clean:
	rm -rf $(BUILD) bin

# (not the dependency files of the other checkout tests/compare_reference.sh builds inside build/:
# their targets have the same names and would force rebuilds)
-include $(shell find $(BUILD) -name '*.d' -not -path '$(BUILD)/compare-reference/*' 2>/dev/null)
# Keep intermediate objects (no rebuild on every make test).
.SECONDARY: $(TEST_BINS:%=%.o)
