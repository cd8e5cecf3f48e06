# runtime/sweep: families of runs (swim sweep; bin/swim-mpi with `make mpi`).
RUNTIME_SRCS += runtime/sweep/sweep.c runtime/sweep/family_hdf5.c
# --format hdf5: Debian's serial HDF5 (h5py reads the file; the tests use it)
DEB_PKGS     += libhdf5-dev python3-h5py
HDF5_CFLAGS  := $(shell pkg-config --cflags hdf5-serial 2>/dev/null || echo -I/usr/include/hdf5/serial)
HDF5_LIBS    := $(shell pkg-config --libs hdf5-serial 2>/dev/null || echo -L/usr/lib/x86_64-linux-gnu/hdf5/serial -lhdf5)
CPPFLAGS     += $(HDF5_CFLAGS)
# Not linked: family_hdf5.c opens the library by its soname when it writes a file (HDF5 and what
# it needs -- curl, TLS, Kerberos, LDAP -- are most of the start-up of a program that links it).
# Read when the object is compiled, after `make deps` has installed libhdf5-dev.
HDF5_SONAME   = $(shell objdump -p $(firstword $(patsubst -L%,%,$(filter -L%,$(HDF5_LIBS))) /usr/lib)/libhdf5.so \
                2>/dev/null | awk '/SONAME/ {print $$2}')
$(BUILD)/runtime/sweep/family_hdf5.o: \
    CPPFLAGS += $(if $(HDF5_SONAME),-DSWIM_HDF5_SONAME='"$(HDF5_SONAME)"')
$(BUILD)/runtime/sweep/family_hdf5.o: VERSION

# The paper's families (Figs 4.1, 4.2, 4.5, 4.6, 4.7): one sweep and one `swim plot` each, into
# out/families/; initial data on the curve (4.17) from runtime/plot/reduction_members.py.
FAMILIES   ?= out/families
REDUCTION  := $(PYTHON) runtime/plot/reduction_members.py --gamma 0.5
.PHONY: paper-families fig-4-1 fig-4-2 fig-4-5 fig-4-6 fig-4-7
paper-families: fig-4-1 fig-4-2 fig-4-5 fig-4-6 fig-4-7

# Fig. 4.2: y(t) of Example 1 for beta'0 = 2, 1.55, ..., -2 (gamma = 0.5, beta0 = 0):
# b'_-2(0) = gamma beta'0 / sqrt 2 (ERRATA D1), the only entry of c'0 that changes.
fig-4-2: $(BIN)/swim
	./$(BIN)/swim sweep models/example1.toml --out $(FAMILIES)/fig4_2 --keep trajectories --quiet \
	  --vary shape.dc0.bm2=0.70710678118654746,0.54800775094912268,0.38890872965260115,0.22980970835607961,0.070710678118654752,-0.070710678118654752,-0.22980970835607961,-0.38890872965260115,-0.54800775094912268,-0.70710678118654746
	./$(BIN)/swim plot $(FAMILIES)/fig4_2

# Fig. 4.1: Example 1, no potential: every solution passes (beta turns), none is trapped.
fig-4-1: $(BIN)/swim
	./$(BIN)/swim sweep models/example1.toml --out $(FAMILIES)/fig4_1 --keep trajectories --quiet --t-end 40 \
	  $$($(REDUCTION) --beta0 0 --betadot 0.3,0.6,0.9,1.2,1.5,-0.3,-0.6,-0.9,-1.2,-1.5)
	./$(BIN)/swim plot $(FAMILIES)/fig4_1

# Fig. 4.5: R = 0.5, cref the ellipse beta = 0: one well at (0, 0).
fig-4-5: $(BIN)/swim
	./$(BIN)/swim sweep models/example2a.toml --out $(FAMILIES)/fig4_5 --keep trajectories --quiet --t-end 40 \
	  $$($(REDUCTION) --beta0 0 --betadot 0.3,0.6,0.9,1.2,1.5,1.8,2.1,-0.3,-0.6,-0.9,-1.2,-1.5,-1.8,-2.1)
	./$(BIN)/swim plot $(FAMILIES)/fig4_5

# Fig. 4.6: kappa_3,4 = 0.2, kappa_5,6 = 2: wells at (0, 0) and (pi, 0).
fig-4-6: $(BIN)/swim
	./$(BIN)/swim sweep models/example2b.toml --out $(FAMILIES)/fig4_6 --keep trajectories --quiet --t-end 40 \
	  $$($(REDUCTION) --beta0 0 --betadot 0.2,0.4,0.6,0.8,1.2,1.6,2.0,-0.4,-0.8,-1.2,-1.6,-2.0 --beta0 pi --betadot 0.15,0.3,0.45)
	./$(BIN)/swim plot $(FAMILIES)/fig4_6

# Fig. 4.7: R = 0.5, cref the shape of Fig. 4.3(i): one well at (pi/3, 0).
fig-4-7: $(BIN)/swim
	./$(BIN)/swim sweep models/example2c.toml --out $(FAMILIES)/fig4_7 --keep trajectories --quiet --t-end 40 \
	  $$($(REDUCTION) --beta0 pi/3 --betadot 0.15,0.3,0.45,0.6,0.75,0.9,1.1,1.3,1.6,2.0,-0.9,-1.1,-1.3,-1.6,-2.0)
	./$(BIN)/swim plot $(FAMILIES)/fig4_7

# Sweep throughput (~2-3 min on 2 cores; not part of `make bench`): --jobs 1/2, MPI 2/4 ranks,
# rank 0's cost per member. Builds bin/swim-mpi when it can.
.PHONY: bench-sweep
bench-sweep: $(BIN)/swim
	@$(MAKE) --no-print-directory mpi >/dev/null 2>&1 || echo "make mpi failed: MPI rows skipped"
	$(PYTHON) tests/bench/bench_sweep.py
