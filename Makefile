# crashfree: build, run and test.
#   make            release build: bin/crashfree and lib/libcrashfree.a (+ .mod files in lib/)
#   make run        install what is missing, build, run the default job (the ODB component test,
#                   coupled FE/EFG, about 2 min on one core), plot and tabulate (ODB_FE=1: run fe.k too),
#                   and a picture of the final state (results/odb_component/coupled/results_final_state.png)
#   make taylor     the same for the Taylor bar
#   make vehicle    the same for the vehicle front structure (inputs/vehicle_front; 8 min on 2 threads, NCPU=2)
#   make side-impact  the side-impact dummy component test (inputs/side_impact): fe.k, ribs_efg.k
#                   and coupled.k, then their force plot, sections and table (REPEAT=3: timing study)
#   make test       install what is missing, build, layer check, unit tests (debug build) and
#                   regression tests
#   make layers     check that each folder of src/ uses only the folders below it
#   make bench      performance figures (ns per element per cycle; MPI scaling: tools/bench_mpi.sh;
#                   the embedding API: tools/bench_api.sh)
#   make verify     verification studies (patch test, cantilever): docs/verification.md (NCPU=n)
#   make MODE=debug checked build in build/debug
#   make MPI=no     the one-rank build without MPI (in build/MODE-serial); by default MPI is used when
#                   Open MPI's mpifort is installed (docs/parallel.md: mpirun -np N bin/crashfree ...)
#   make install    the embedding library (lib/libcrashfree_efg.a), its header, Fortran module and
#                   pkg-config file crashfree-efg.pc under PREFIX (default /usr/local); docs/embedding.md
#   make examples   install into build/release/install, then build the host codes of examples/
#                   against it with pkg-config only (build/release/examples; MODE=debug: against
#                   the checked library, in build/debug)
MODE ?= release
MPI ?= $(if $(shell command -v mpifort 2>/dev/null),yes,no)
# With MPI everything is compiled by the mpifort wrapper (the same gfortran underneath) and the
# preprocessed sources (*.F90: the communication module) see CRASHFREE_MPI; without it they
# compile to the one-rank version of the same interface.
ifeq ($(MPI),yes)
  FC := mpifort
  PREPROCESSOR_FLAGS := -DCRASHFREE_MPI
else
  FC := gfortran
  PREPROCESSOR_FLAGS :=
endif
PYTHON ?= python3

HDF5_INCLUDE ?= /usr/include/hdf5/serial
HDF5_LIBDIR ?= /usr/lib/x86_64-linux-gnu/hdf5/serial
LIBS := -L$(HDF5_LIBDIR) -lhdf5_fortran -lhdf5 -lmetis -llapack -lblas

BUILD ?= build/$(MODE)$(if $(filter no,$(MPI)),-serial)
OBJ := $(BUILD)/obj
MOD := $(BUILD)/mod
ifeq ($(MODE),debug)
  FFLAGS := -std=f2008 -Wall -Wextra -Wimplicit-interface -Wno-compare-reals -Wno-maybe-uninitialized \
            -fcheck=all -ffpe-trap=invalid,zero,overflow -finit-real=snan -g -O0 -fbacktrace -fopenmp
else
  FFLAGS := -std=f2008 -O3 -march=native -funroll-loops -fopenmp -g -Wall -Wno-compare-reals \
            -Wno-maybe-uninitialized
endif
LIBRARY := $(BUILD)/lib/libcrashfree.a
# The embedding library (docs/embedding.md): the API modules of src/api and the project modules
# they use (tools/library_objects.py writes EFG_LIBRARY_OBJECTS), nothing that needs HDF5 or METIS.
EFG_LIBRARY := $(BUILD)/lib/libcrashfree_efg.a
EFG_API_SOURCES := $(sort $(wildcard src/api/crashfree_efg*.f90))
PROGRAM := $(BUILD)/bin/crashfree
FFLAGS += -J$(MOD) -I$(MOD) -I$(HDF5_INCLUDE)

LIBRARY_SOURCES := $(sort $(shell find src \( -name '*.f90' -o -name '*.F90' \) ! -path 'src/app/crashfree.f90'))
LIBRARY_OBJECTS := $(addprefix $(OBJ)/,$(addsuffix .o,$(basename $(notdir $(LIBRARY_SOURCES)))))
TEST_SUPPORT := tests/unit/testing.f90 tests/unit/fixtures.f90
TEST_SOURCES := $(sort $(wildcard tests/unit/test_*.f90))
TEST_PROGRAMS := $(patsubst tests/unit/%.f90,$(BUILD)/tests/%,$(TEST_SOURCES))
# C unit tests of the embedding library's C interface (include/crashfree_efg.h)
C_TEST_SOURCES := $(sort $(wildcard tests/unit/test_*.c))
C_TEST_PROGRAMS := $(patsubst tests/unit/%.c,$(BUILD)/tests/%,$(C_TEST_SOURCES))
ALL_SOURCES := $(LIBRARY_SOURCES) src/app/crashfree.f90 $(TEST_SUPPORT) $(TEST_SOURCES)

vpath %.f90 $(sort $(dir $(ALL_SOURCES)))
vpath %.F90 $(sort $(dir $(ALL_SOURCES)))

.PHONY: all deps run taylor test unit regression bench clean debug verify fuzz layers
# The release build is also published as bin/crashfree and lib/ (libraries and .mod files).
# (Checked at every make, not by date: after `make MPI=no` the MPI build's older program is
# published again.)
ifeq ($(MODE),release)
all: bin/crashfree
.PHONY: bin/crashfree
bin/crashfree: $(PROGRAM) $(EFG_LIBRARY)
	@mkdir -p bin lib
	@cmp -s $(PROGRAM) bin/crashfree || (cp $(PROGRAM) bin/crashfree.new && mv -f bin/crashfree.new bin/crashfree)
	@cmp -s $(LIBRARY) lib/libcrashfree.a && cmp -s $(EFG_LIBRARY) lib/libcrashfree_efg.a || \
	  cp $(LIBRARY) $(EFG_LIBRARY) $(MOD)/*.mod lib/
else
all: $(PROGRAM) $(EFG_LIBRARY)
endif

$(OBJ)/%.o: %.f90 | $(OBJ) $(MOD)
	$(FC) $(FFLAGS) $(SOURCE_FLAGS) -c $< -o $@

$(OBJ)/%.o: %.F90 | $(OBJ) $(MOD)
	$(FC) $(FFLAGS) $(PREPROCESSOR_FLAGS) $(SOURCE_FLAGS) -c $< -o $@

# The keyword readers share one interface (deck_keyword_table's keyword_reader): not every
# reader needs every argument. (`private`: not passed on to the modules they use.)
$(OBJ)/deck_%.o: private SOURCE_FLAGS := -Wno-unused-dummy-argument
# Likewise the element kinds: every group implements element_group's procedures, not every kind
# needs every argument (meshfree parts have no hourglass energy, no mass scaling).
$(OBJ)/element_group.o $(OBJ)/%_group.o: private SOURCE_FLAGS := -Wno-unused-dummy-argument
# The one-rank version of the communication module leaves its arguments alone.
$(OBJ)/rank_communication.o: private SOURCE_FLAGS := -Wno-unused-dummy-argument

$(OBJ) $(MOD) $(BUILD)/tests $(dir $(LIBRARY)) $(dir $(PROGRAM)):
	@mkdir -p $@

$(LIBRARY): $(LIBRARY_OBJECTS) | $(dir $(LIBRARY))
	@rm -f $@
	ar rcs $@ $^

$(PROGRAM): $(OBJ)/crashfree.o $(LIBRARY) | $(dir $(PROGRAM))
	$(FC) $(FFLAGS) $< $(LIBRARY) $(LIBS) -o $@

$(BUILD)/tests/%: $(OBJ)/%.o $(OBJ)/testing.o $(OBJ)/fixtures.o $(LIBRARY) | $(BUILD)/tests
	$(FC) $(FFLAGS) $< $(OBJ)/testing.o $(OBJ)/fixtures.o $(LIBRARY) $(LIBS) -o $@

# A C test is compiled as a C host compiles against the header, and linked with the Fortran
# run-time and OpenMP (the gfortran driver), as a C host links the library.
$(C_TEST_PROGRAMS): $(BUILD)/tests/%: tests/unit/%.c include/crashfree_efg.h $(LIBRARY) | $(BUILD)/tests
	$(CC) -std=c99 -Wall -Wextra -pedantic -g -Iinclude -c $< -o $@.o
	$(FC) -fopenmp $@.o $(LIBRARY) $(LIBS) -o $@

$(BUILD)/deps.mk: $(ALL_SOURCES) tools/fortran_deps.py
	@mkdir -p $(BUILD)
	@$(PYTHON) tools/fortran_deps.py $(OBJ) $(ALL_SOURCES) > $@

$(BUILD)/efg_library.mk: $(LIBRARY_SOURCES) tools/library_objects.py
	@mkdir -p $(BUILD)
	@$(PYTHON) tools/library_objects.py EFG_LIBRARY_OBJECTS $(OBJ) $(EFG_API_SOURCES) -- $(LIBRARY_SOURCES) > $@

ifeq ($(filter deps clean,$(MAKECMDGOALS)),)
include $(BUILD)/deps.mk
include $(BUILD)/efg_library.mk
endif

$(EFG_LIBRARY): $(EFG_LIBRARY_OBJECTS) | $(dir $(EFG_LIBRARY))
	@rm -f $@
	ar rcs $@ $^

# make install PREFIX=DIR: the embedding library, its C header, its Fortran module (gfortran's
# .mod files are compiler-specific: include/crashfree/, apart from the header) and the
# pkg-config file, whose Libs name the static library's own dependencies (tools/crashfree-efg.pc.in).
# Only the API's own .mod is installed: a host needs no other, and the internal module names
# (kinds, model, ...) would collide with a host's own.
PREFIX ?= /usr/local
CRASHFREE_VERSION := $(shell sed -n 's/.*crashfree_version *= *"\([^"]*\)".*/\1/p' src/core/version.f90)
INSTALL_PREFIX = $(abspath $(PREFIX))
.PHONY: install examples
install: $(EFG_LIBRARY)
	@mkdir -p $(DESTDIR)$(INSTALL_PREFIX)/lib/pkgconfig $(DESTDIR)$(INSTALL_PREFIX)/include/crashfree
	cp $(EFG_LIBRARY) $(DESTDIR)$(INSTALL_PREFIX)/lib/
	cp include/crashfree_efg.h $(DESTDIR)$(INSTALL_PREFIX)/include/
	cp $(MOD)/crashfree_efg.mod $(DESTDIR)$(INSTALL_PREFIX)/include/crashfree/
	sed -e 's|@PREFIX@|$(INSTALL_PREFIX)|g' -e 's|@VERSION@|$(CRASHFREE_VERSION)|g' \
	    tools/crashfree-efg.pc.in > $(DESTDIR)$(INSTALL_PREFIX)/lib/pkgconfig/crashfree-efg.pc

# make examples: install into EXAMPLES_PREFIX, then build the two host codes of examples/ with
# their own Makefiles, which know the library only through pkg-config.
EXAMPLES_PREFIX ?= $(BUILD)/install
EXAMPLES_OUT ?= $(BUILD)/examples
examples:
	@$(MAKE) --no-print-directory install PREFIX=$(EXAMPLES_PREFIX)
	@mkdir -p $(EXAMPLES_OUT)
	PKG_CONFIG_PATH=$(abspath $(EXAMPLES_PREFIX))/lib/pkgconfig $(MAKE) --no-print-directory -C examples/host_fortran \
	    OUT=$(abspath $(EXAMPLES_OUT))
	PKG_CONFIG_PATH=$(abspath $(EXAMPLES_PREFIX))/lib/pkgconfig $(MAKE) --no-print-directory -C examples/host_c \
	    OUT=$(abspath $(EXAMPLES_OUT))

deps:
	@bash tools/install_dependencies.sh

debug:
	@$(MAKE) --no-print-directory MODE=debug all

# Unit tests: every tests/unit/test_*.f90 program; prints the sum of their counts.
unit: $(TEST_PROGRAMS) $(C_TEST_PROGRAMS)
	@bash tools/run_unit_tests.sh $(TEST_PROGRAMS) $(C_TEST_PROGRAMS)

regression: all
	@$(PYTHON) -m pytest -q tests/regression

# The layering of src/ (tools/check_layers.py lists the order and every use against it).
layers:
	@$(PYTHON) tools/check_layers.py

# The default job (tools/run_default.sh), then a picture of the barrier's final state through
# ParaView's XDMF reader (postproc/render_state.py: results/odb_component/coupled/
# results_final_state.png), seen from the impactor's side above the crushed corner, coloured by
# the displacement (the honeycomb has no plastic strain to show).
run: deps
	@$(MAKE) --no-print-directory all
	@bash tools/run_default.sh
	@$(PYTHON) postproc/render_state.py results/odb_component/coupled/results.xdmf --field displacement \
	    --view=-1,0.7,1.3

taylor: deps
	@$(MAKE) --no-print-directory all
	@bash tools/run_taylor_bar.sh

test: deps
	@bash tools/run_all_tests.sh

# The vehicle front structure into a rigid wall (inputs/vehicle_front), then its plots and table.
.PHONY: vehicle
vehicle: deps
	@$(MAKE) --no-print-directory all
	@bash tools/run_vehicle_front.sh

# The side-impact dummy component test (inputs/side_impact, docs/examples/side_impact.md).
.PHONY: side-impact
side-impact: deps
	@$(MAKE) --no-print-directory all
	@bash inputs/side_impact/run.sh

bench: deps
	@$(MAKE) --no-print-directory all
	@bash tools/bench.sh
	@bash tools/bench_contact.sh
	@bash tools/bench_mpi.sh
	@bash tools/bench_api.sh

# Verification studies: write the decks, run every case (NCPU threads each, default 1), then
# write docs/verification.md and its plots (also when a case failed; the exit status says so).
VERIFY_DIR := results/verification
verify: deps
	@$(MAKE) --no-print-directory all
	@$(PYTHON) verification/patch_test.py --out $(VERIFY_DIR)/patch
	@$(PYTHON) verification/cantilever.py --out $(VERIFY_DIR)/cantilever --traction both --interpolated-levels 2 4 8 \
	    --width-series 4
	@status=0; $(PYTHON) verification/run_cases.py $(VERIFY_DIR)/patch/manifest.json \
	    $(VERIFY_DIR)/cantilever/manifest.json --ncpu $(or $(NCPU),1) || status=$$?; \
	  $(PYTHON) postproc/verification_report.py $(VERIFY_DIR) --doc docs/verification.md \
	    --figures docs/verification || status=$$?; \
	  exit $$status

# Deck fuzzing (docs/fuzzing.md): FUZZ_DECKS mutants of the seed decks, each run with the release
# and the checked debug build; a table of outcomes at the end; fails when any run fails
# (findings in the temp folder, or FUZZ_FINDINGS=DIR).
FUZZ_DECKS ?= 10000
FUZZ_SEED ?= 1
FUZZ_JOBS ?= 2
fuzz: deps
	@$(MAKE) --no-print-directory all
	@$(MAKE) --no-print-directory MODE=debug all
	@$(PYTHON) tests/fuzz/fuzz.py run --decks $(FUZZ_DECKS) --seed $(FUZZ_SEED) --jobs $(FUZZ_JOBS) \
	    $(if $(FUZZ_FINDINGS),--findings $(FUZZ_FINDINGS))

clean:
	rm -rf build lib bin
