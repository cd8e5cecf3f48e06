# runtime/mpi: bin/swim-mpi, `swim sweep` over MPI ranks. Not part of the default build: `make mpi`
# installs OpenMPI from Debian if it is missing (as root) and builds it next to bin/swim.
MPI_PKGS := libopenmpi-dev openmpi-bin
.PHONY: mpi mpi-deps test-mpi
mpi: $(BIN)/swim-mpi

mpi-deps: $(MPI_STAMP)   # the Makefile's package rule with MPI_PKGS

$(BIN)/swim-mpi: runtime/mpi/swim_mpi.c $(BUILD)/libswim.a $(BIN)/swim | $(MPI_STAMP)
	mpicc $(CPPFLAGS) $(filter-out -MMD -MP,$(CFLAGS)) runtime/mpi/swim_mpi.c $(BUILD)/libswim.a -o $@ $(LDLIBS)

# The MPI sweep tests alone (they also run from `make test` when bin/swim-mpi can be built).
test-mpi: $(BIN)/swim $(BIN)/swim-mpi
	@SWIM_CACHE=$${SWIM_CACHE:-$(CURDIR)/$(BUILD)/cache} SWIM_BIN=$(CURDIR)/$(BIN)/swim SWIM_MPI=1 bash tests/run_tests.sh tests/test_sweep_mpi.py
