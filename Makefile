# posedrop: build, test, benchmark and install.  `make help` lists the targets.
#
# Switches: WERROR=1 (warnings are errors), SANITIZE=1 (address + undefined),
# DEBUG=1 (no optimisation, internal checks on). Each combination builds in its
# own directory under build/, so switching never mixes objects.

CC      ?= cc
CXX     ?= g++
PREFIX  ?= /usr/local
PKG_CONFIG ?= pkg-config

# Libraries the project links through pkg-config: GSL (quadrature, ODE
# stepping, special functions), ODE with libccd for libposedrop; Bullet, C++,
# for libposedrop-bullet only (src/engines/engine_bullet.cpp), so that a C
# program that does not ask for it needs neither Bullet nor the C++ runtime.
# qhull_r is for the tests' and the benchmark's reference hull only.
LIB_PKGS    := gsl ode ccd
BULLET_PKGS := bullet
TEST_PKGS   := qhull_r

# The version has one home, include/posedrop/version.h; the shared libraries
# are named after it and carry the soname lib*.so.MAJOR.
version_of = $(shell sed -n 's/^.define PD_VERSION_$(1) \([0-9]*\)$$/\1/p' include/posedrop/version.h)
MAJOR   := $(call version_of,MAJOR)
VERSION := $(MAJOR).$(call version_of,MINOR).$(call version_of,PATCH)

CONFIG := opt
# -O3 changes no result (no reassociation without -ffast-math): measured with
# callgrind on the median drops of make bench's parts, 4-6% fewer
# instructions than -O2, the same bytes out. -fno-math-errno lets sqrt compile
# to its instruction without the errno call path; posedrop reads errno only
# after strtod/strtol and I/O, which the flag does not touch.
CFLAGS_OPT := -O3 -fno-math-errno
ifeq ($(DEBUG),1)
CONFIG := debug
CFLAGS_OPT := -O0 -g3 -DPD_DEBUG
endif
ifeq ($(SANITIZE),1)
CONFIG := $(CONFIG)-san
CFLAGS_OPT += -fsanitize=address,undefined -fno-sanitize-recover=undefined -fno-omit-frame-pointer
LDFLAGS_SAN := -fsanitize=address,undefined
endif
ifeq ($(WERROR),1)
CFLAGS_WERROR := -Werror
endif

BUILD := build/$(CONFIG)

WARN := -Wall -Wextra -Wpedantic -Wshadow -Wmissing-prototypes -Wstrict-prototypes \
        -Wvla -Wdouble-promotion
# -ffp-contract=off: no fused multiply-add, so results are bit-identical across
# machines and compilers; never -ffast-math.
# -fvisibility=hidden: only what the public headers mark PD_API leaves the
# shared libraries (posedrop/export.h); -fPIC since the same objects go into
# the static and the shared library (hidden symbols are called directly, so
# position independence costs no indirection inside the library).
CFLAGS_ALL := -std=c11 -g -pthread $(CFLAGS_OPT) $(WARN) $(CFLAGS_WERROR) -ffp-contract=off \
              -fPIC -fvisibility=hidden \
              -D_DEFAULT_SOURCE -Iinclude -Isrc $(shell $(PKG_CONFIG) --cflags $(LIB_PKGS) 2>/dev/null) \
              $(CFLAGS)
# The one C++ file (the Bullet adapter). Bullet's headers come in as system
# headers (-isystem) so their own warnings do not trip WERROR=1.
CXXFLAGS_ALL := -std=c++17 -g -pthread $(CFLAGS_OPT) -Wall -Wextra $(CFLAGS_WERROR) -ffp-contract=off \
                -fPIC -fvisibility=hidden -fvisibility-inlines-hidden \
                -Iinclude -Isrc $(patsubst -I%,-isystem %,$(shell $(PKG_CONFIG) --cflags $(BULLET_PKGS) 2>/dev/null)) \
                $(CXXFLAGS)
LDLIBS_LIB := $(shell $(PKG_CONFIG) --libs $(LIB_PKGS) 2>/dev/null) -lm -pthread
LDLIBS_BULLET := $(shell $(PKG_CONFIG) --libs $(BULLET_PKGS) 2>/dev/null)
LDLIBS_TEST := $(shell $(PKG_CONFIG) --libs $(TEST_PKGS) 2>/dev/null)
CFLAGS_TEST := -Itests/support $(shell $(PKG_CONFIG) --cflags $(TEST_PKGS) 2>/dev/null)

# One folder per layer under src/ (docs/development.md); the Makefile follows
# the tree by wildcard, so adding a file needs no edit here.
LIB_SRCS   := $(wildcard src/*/*.c)
LIB_SRCS   := $(filter-out src/cli/% src/viz/%,$(LIB_SRCS))
LIB_OBJS   := $(LIB_SRCS:%.c=$(BUILD)/%.o)
BULLET_OBJS := $(patsubst %.cpp,$(BUILD)/%.o,$(wildcard src/*/*.cpp))
LIB        := $(BUILD)/libposedrop.a
LIB_BULLET := $(BUILD)/libposedrop-bullet.a
SO         := $(BUILD)/libposedrop.so.$(VERSION)
SO_BULLET  := $(BUILD)/libposedrop-bullet.so.$(VERSION)
# The pictures (src/viz/) are the program's, not the library's: a client of
# the public API that the command and the tests link.
VIZ_OBJS   := $(patsubst %.c,$(BUILD)/%.o,$(wildcard src/viz/*.c))
CLI        := $(BUILD)/posedrop
# The command is every file of src/cli/; posedrop-mpi (MPI=1) swaps run.c,
# which runs the drops in one process, for run_mpi.c.
CLI_SRCS   := $(filter-out src/cli/run_mpi.c,$(wildcard src/cli/*.c))
CLI_OBJS   := $(CLI_SRCS:%.c=$(BUILD)/%.o)
CLI_MPI    := $(BUILD)/posedrop-mpi
CLI_MPI_OBJS := $(patsubst src/cli/%.c,$(BUILD)/mpi/%.o,$(filter-out src/cli/run.c,$(wildcard src/cli/*.c)))
MPICC      ?= mpicc
MPIRUN     ?= mpirun
# make and make check build (and test) posedrop-mpi whenever OpenMPI is
# installed, so it is never older than posedrop; MPI=1 asks for it (and fails
# without OpenMPI: scripts/install-deps.sh mpi).
HAVE_MPI   := $(shell command -v $(MPICC) >/dev/null 2>&1 && command -v $(MPIRUN) >/dev/null 2>&1 && echo 1)
WITH_MPI   := $(if $(filter 1,$(MPI) $(HAVE_MPI)),1)
TEST_SRCS  := $(wildcard tests/unit/*.c tests/support/*.c)
TEST_OBJS  := $(TEST_SRCS:%.c=$(BUILD)/%.o)
TEST_BIN   := $(BUILD)/test_posedrop
BENCH_SRCS := tests/bench/bench.c tests/support/shapes.c tests/support/qhull_ref.c
BENCH_OBJS := $(BENCH_SRCS:%.c=$(BUILD)/bench-%.o)
BENCH_BIN  := $(BUILD)/bench_posedrop
DEMO_PART  := parts/cap.off

.PHONY: all check check-full check-install test bench bench-mujoco referee demo paper install uninstall clean help deps golden lint fuzz fuzz-build \
        check-browser check-readme figures check-figures mpi
.DEFAULT_GOAL := all

all: $(LIB) $(LIB_BULLET) $(SO) $(SO_BULLET) $(CLI) $(if $(WITH_MPI),$(CLI_MPI))

mpi: $(CLI_MPI)

# Objects depend on this Makefile too: a change of flags (the optimisation
# level, warnings) rebuilds them rather than linking old objects with new.
$(BUILD)/%.o: %.c Makefile
	@mkdir -p $(dir $@)
	$(CC) $(CFLAGS_ALL) -MMD -MP -c $< -o $@

$(BUILD)/src/%.o: src/%.cpp Makefile
	@mkdir -p $(dir $@)
	$(CXX) $(CXXFLAGS_ALL) -MMD -MP -c $< -o $@

$(BUILD)/tests/%.o: tests/%.c Makefile
	@mkdir -p $(dir $@)
	$(CC) $(CFLAGS_ALL) $(CFLAGS_TEST) -DPD_CLI_PATH='"$(CLI)"' -DPD_CLI_MPI_PATH='"$(CLI_MPI)"' \
	    -DPD_MPIRUN='"$(MPIRUN)"' -MMD -MP -c $< -o $@

$(BUILD)/bench-%.o: %.c Makefile
	@mkdir -p $(dir $@)
	$(CC) $(CFLAGS_ALL) $(CFLAGS_TEST) -DPD_CLI_PATH='"$(CLI)"' -DPD_CLI_MPI_PATH='"$(CLI_MPI)"' \
	    -DPD_MPIRUN='"$(MPIRUN)"' -MMD -MP -c $< -o $@

$(LIB): $(LIB_OBJS)
	@rm -f $@
	$(AR) rcs $@ $^

$(LIB_BULLET): $(BULLET_OBJS)
	@rm -f $@
	$(AR) rcs $@ $^

# The shared libraries, with the links a linker (lib*.so) and the loader
# (lib*.so.MAJOR, the soname) look for. --no-undefined: each names every
# library it needs, so a program links it without knowing its insides.
$(SO): $(LIB_OBJS)
	$(CC) -shared -Wl,-soname,libposedrop.so.$(MAJOR) -Wl,--no-undefined $(LDFLAGS_SAN) $(LDFLAGS) \
	      -o $@ $^ $(LDLIBS_LIB)
	ln -sf $(notdir $@) $(BUILD)/libposedrop.so.$(MAJOR)
	ln -sf libposedrop.so.$(MAJOR) $(BUILD)/libposedrop.so

$(SO_BULLET): $(BULLET_OBJS) $(SO)
	$(CXX) -shared -Wl,-soname,libposedrop-bullet.so.$(MAJOR) -Wl,--no-undefined $(LDFLAGS_SAN) \
	       $(LDFLAGS) -o $@ $(BULLET_OBJS) $(SO) $(LDLIBS_BULLET)
	ln -sf $(notdir $@) $(BUILD)/libposedrop-bullet.so.$(MAJOR)
	ln -sf libposedrop-bullet.so.$(MAJOR) $(BUILD)/libposedrop-bullet.so

# The command, the tests and the benchmark link the static archives (the tests
# call internal functions the shared library does not export), and with
# $(CXX), since they offer the Bullet engine.
# The command reads numbers with the library's own reader (base/number.c, C
# library only), linked in directly so that it needs nothing the API hides.
$(CLI): $(CLI_OBJS) $(BUILD)/src/base/number.o $(VIZ_OBJS) $(LIB_BULLET) $(LIB)
	$(CXX) $(LDFLAGS_SAN) $(LDFLAGS) -o $@ $^ $(LDLIBS_LIB) $(LDLIBS_BULLET)

# posedrop-mpi (MPI=1): OpenMPI's wrappers give its include and library flags
# (mpicc --showme); the objects are the command's, compiled again with mpi.h
# at hand.
$(BUILD)/mpi/%.o: src/cli/%.c Makefile
	@mkdir -p $(dir $@)
	OMPI_CC=$(CC) $(MPICC) $(CFLAGS_ALL) -MMD -MP -c $< -o $@

$(CLI_MPI): $(CLI_MPI_OBJS) $(BUILD)/src/base/number.o $(VIZ_OBJS) $(LIB_BULLET) $(LIB)
	OMPI_CC=$(CXX) $(MPICC) $(LDFLAGS_SAN) $(LDFLAGS) -o $@ $^ $(LDLIBS_LIB) $(LDLIBS_BULLET) -lstdc++

# The tests (the fuzz targets' replay) read shards as posedrop merge does.
$(TEST_BIN): $(TEST_OBJS) $(VIZ_OBJS) $(BUILD)/src/cli/shard_read.o $(LIB_BULLET) $(LIB)
	$(CXX) $(LDFLAGS_SAN) $(LDFLAGS) -o $@ $^ $(LDLIBS_TEST) $(LDLIBS_LIB) $(LDLIBS_BULLET)

$(BENCH_BIN): $(BENCH_OBJS) $(LIB_BULLET) $(LIB)
	$(CXX) $(LDFLAGS_SAN) $(LDFLAGS) -o $@ $^ $(LDLIBS_TEST) $(LDLIBS_LIB) $(LDLIBS_BULLET)

# Installs the Debian packages when pkg-config cannot find them (quick no-op
# otherwise). The targets a new user runs first go through it; their real work
# runs in a sub-make so that pkg-config is asked again after the install.
deps:
	@scripts/install-deps.sh

# The runner runs TEST_JOBS suites at a time, each in a process of its own,
# printing them in their table's order (tests/support/main.c); the results
# do not depend on it. TEST_FULL=1 (make check-full) selects the long
# variants of the statistical tests.
TEST_JOBS ?= 2
test: $(TEST_BIN) $(CLI) $(if $(WITH_MPI),$(CLI_MPI))
	$(TEST_BIN) -j$(TEST_JOBS) $(if $(filter 1,$(TEST_FULL)),--full) $(SUITES)

# A file may include only its own layer's headers and those of the layers
# below it (scripts/lint-layers.sh holds the table).
lint:
	@scripts/lint-layers.sh

# The library as a user gets it: installed into a temporary prefix, the
# documented example built with plain pkg-config and run
# (tests/install/check-install.sh, which says what it checks).
check-install: all
	+@MAKE="$(MAKE)" CC="$(CC)" CXX="$(CXX)" EXAMPLE_FLAGS="$(LDFLAGS_SAN)" tests/install/check-install.sh

# make check builds on two jobs unless make was given its own -j.
# make check-full is make check with the statistical tests' long variants
# (docs/development.md says which); CI runs both.
check check-full: deps lint
	@$(MAKE) --no-print-directory $(if $(filter -j%,$(MAKEFLAGS)),,-j2) all $(TEST_BIN)
	@$(MAKE) --no-print-directory check-install
	@$(MAKE) --no-print-directory test $(if $(filter check-full,$@),TEST_FULL=1)
	$(if $(filter check-full,$@),@$(MAKE) --no-print-directory check-figures)

# make demo builds as make check does (two jobs unless make was given its
# own -j) and prints the pose classes in words (scripts/demo.sh).
demo: deps
	@$(MAKE) --no-print-directory $(if $(filter -j%,$(MAKEFLAGS)),,-j2) all
	@scripts/demo.sh $(CLI) $(DEMO_PART)

# The report and the SVGs in a real browser and renderer (headless Chromium,
# rsvg-convert; installed when missing): tests/browser/check.sh.
check-browser: deps
	@$(MAKE) --no-print-directory $(CLI)
	POSEDROP=$(CLI) tests/browser/check.sh

# Every command README.md gives, as written: CI's own checked to be in
# .ci/run, the others run from a scratch directory (tests/readme/check.sh).
check-readme: deps
	@$(MAKE) --no-print-directory all
	tests/readme/check.sh

# Every figure behind docs/ that a script makes (docs/figures.md lists them
# with their cost): the insulator cap's gallery, chart and gauss-sphere map
# and make paper's tables on the impulse engine (docs/figures/paper.txt),
# the cost-accuracy chart, the design demonstrations, the small tables of
# scripts/doc_tables.py, the leave-one-out table of docs/validation.md (from
# its kept runs), the table of docs/uncertainty.md and the big-mesh
# table of docs/performance.md. CHART_ONLY=1 redraws the cost-accuracy chart
# from its kept CSV instead of rerunning it; CHEAP=1 makes only the cap's
# pictures, paper.txt and doc_tables.py's cheap tables (seconds); the others
# time make bench's sections, python/bench.py, the trimesh comparison and
# scripts/bench-mujoco.py (PYTHON names a Python with the module, trimesh,
# pytest and mujoco; default .venv's) and make fuzz. Records (doc_tables.py
# --record) are not remade: check-figures guards their text.
figures: deps
	@$(MAKE) --no-print-directory all $(TEST_BIN) $(if $(CHEAP),,$(BENCH_BIN))
	POSEDROP=$(CLI) scripts/figures.sh $(if $(CHEAP),--cheap,$(if $(CHART_ONLY),--chart-only))
	python3 scripts/doc_tables.py -b $(CLI) $(if $(CHEAP),--cheap)
	python3 scripts/loo-table.py --now docs/figures/loo/s1.summary.txt \
	    docs/figures/loo/s2.summary.txt --before docs/figures/loo/before-s1.summary.txt \
	    docs/figures/loo/before-s2.summary.txt --doc docs/validation.md --tag loo-table
	python3 scripts/loo-table.py --now docs/figures/loo/variant-s1.summary.txt \
	    docs/figures/loo/variant-s2.summary.txt --before docs/figures/loo/before-s1.summary.txt \
	    docs/figures/loo/before-s2.summary.txt --doc docs/validation.md --tag loo-table-variant
	python3 scripts/loo-table.py --now docs/figures/loo/noise-s1.summary.txt \
	    docs/figures/loo/noise-s2.summary.txt --before docs/figures/loo/s1.summary.txt \
	    docs/figures/loo/s2.summary.txt --doc docs/validation.md --tag loo-table-noise
	python3 scripts/loo-table.py --now docs/figures/loo/smooth-s1.summary.txt \
	    docs/figures/loo/smooth-s2.summary.txt --before docs/figures/loo/s1.summary.txt \
	    docs/figures/loo/s2.summary.txt --doc docs/validation.md --tag loo-table-smooth
	python3 scripts/loo-table.py --now docs/figures/loo/noise-p16-s1.summary.txt \
	    docs/figures/loo/noise-p16-s2.summary.txt --before docs/figures/loo/noise-s1.summary.txt \
	    docs/figures/loo/noise-s2.summary.txt --doc docs/validation.md --tag loo-table-noise-p16
	$(if $(CHEAP),,POSEDROP=$(CLI) scripts/uncertainty.sh)
	$(if $(CHEAP),,scripts/bigmesh-table.sh $(CLI) > docs/figures/bigmesh.txt)

# The cheap measured files behind docs/ rerun, after the check's own
# controls: fails when a number moved beyond its drops' noise, or when a
# table of doc_tables.py's was edited by hand (make check-full runs it;
# about 1 CPU minute, docs/figures.md).
check-figures:
	@$(MAKE) --no-print-directory $(CLI) $(TEST_BIN)
	python3 scripts/check_figures.py -b $(CLI) --self-test docs/figures/cap.csv \
	    docs/figures/paper/*.csv docs/figures/uncertainty/*-ranged.csv
	python3 scripts/doc_tables.py -b $(CLI) --check --self-test

# The paper's Tables 1-4 with posedrop's columns beside them (results/).
paper: deps
	@$(MAKE) --no-print-directory all
	scripts/paper.sh

# Re-pins the golden outcomes (tests/unit/test_golden.c) on purpose, printing each
# case whose hash moved; the commit that does it says why.
golden: $(TEST_BIN)
	PD_GOLDEN_WRITE=tests/golden.csv $(TEST_BIN) golden

bench: deps
	@$(MAKE) --no-print-directory $(BENCH_BIN) $(CLI) $(if $(WITH_MPI),$(CLI_MPI))
	$(BENCH_BIN) $(BENCH)

# The cost of a drop against MuJoCo (scripts/bench-mujoco.py), which needs the
# mujoco Python package: not a dependency, not part of make check. It uses
# .venv/bin/python when the git-ignored .venv exists, else python3.
MUJOCO_PY ?= $(if $(wildcard .venv/bin/python),.venv/bin/python,python3)
bench-mujoco: deps
	@$(MAKE) --no-print-directory $(CLI)
	$(MUJOCO_PY) scripts/bench-mujoco.py --posedrop $(CLI) $(BENCH_MUJOCO)

# The cross-check corpus on the three engines and MuJoCo, its table put in
# docs/engines-crosscheck.md (scripts/referee-mujoco.py): 400 drops per
# part and engine, MuJoCo's too, and 100 again at half MuJoCo's step; about
# 1.5 hours of CPU, most of it MuJoCo's on the bushing, the white button and
# the insulator cap. -r keeps what results/referee holds: a stopped run
# resumes, and after the engines change only posedrop's runs are redone.
referee: deps
	@$(MAKE) --no-print-directory $(CLI)
	$(MUJOCO_PY) scripts/referee-mujoco.py --posedrop $(CLI) --law --doc docs/engines-crosscheck.md
	$(MUJOCO_PY) scripts/referee-mujoco.py --posedrop $(CLI) -o results/referee -r \
	    -n 400 --mj-n 400 --check-n 100 --doc docs/engines-crosscheck.md $(REFEREE)

# make fuzz: libFuzzer targets built with clang (installed on first use) for
# the OFF, STL and OBJ readers, scene files, the part build (mesh in, part
# model and static estimate out), programs of library calls (api), and the
# command's readers of measured counts (measured) and of shards (shard), each
# run for FUZZ_SECONDS from the seeds in parts/ and tests/fuzz/
# (scripts/fuzz.sh). The C library is built with address and
# undefined-behaviour sanitizers (Bullet, C++, is left out: not registered).
FUZZ_SECONDS ?= 60
FUZZ_TARGETS := off stl obj scene part api measured shard
FUZZ_BUILD   := build/fuzz
FUZZ_CC      ?= clang
FUZZ_CFLAGS  := -std=c11 -g -O1 -pthread -fsanitize=fuzzer-no-link,address,undefined \
                -fno-sanitize-recover=undefined -fno-omit-frame-pointer -ffp-contract=off \
                -D_DEFAULT_SOURCE -Iinclude -Isrc -Itests/support \
                $(shell $(PKG_CONFIG) --cflags $(LIB_PKGS) 2>/dev/null)
FUZZ_SRCS    := $(LIB_SRCS) src/viz/measured.c src/cli/shard_read.c tests/support/fuzz_targets.c
FUZZ_OBJS    := $(FUZZ_SRCS:%.c=$(FUZZ_BUILD)/%.o)
# Kept between runs: make would otherwise delete them as intermediate files
# of the pattern rule below and compile them all again next time.
.SECONDARY: $(FUZZ_OBJS)

fuzz:
	@scripts/install-deps.sh clang libclang-rt-dev
	@$(MAKE) --no-print-directory fuzz-build
	scripts/fuzz.sh $(FUZZ_SECONDS) $(FUZZ_TARGETS)

fuzz-build: $(FUZZ_TARGETS:%=$(FUZZ_BUILD)/fuzz_%)

$(FUZZ_BUILD)/%.o: %.c Makefile
	@mkdir -p $(dir $@)
	$(FUZZ_CC) $(FUZZ_CFLAGS) -MMD -MP -c $< -o $@

$(FUZZ_BUILD)/fuzz_%: tests/fuzz/fuzz_main.c $(FUZZ_OBJS) Makefile
	$(FUZZ_CC) $(FUZZ_CFLAGS) -fsanitize=fuzzer -DPD_FUZZ_TARGET=pd_fuzz_$* -o $@ \
	    tests/fuzz/fuzz_main.c $(FUZZ_OBJS) $(LDLIBS_LIB)

# Both libraries, shared (with their soname and development links) and
# static, the headers, the command and a pkg-config file for each library
# (docs/library.md), and the licence with that page in share/doc/posedrop.
# Under /usr/local, run ldconfig afterwards.
LIBDIR := $(DESTDIR)$(PREFIX)/lib
install: all
	install -d $(DESTDIR)$(PREFIX)/bin $(LIBDIR)/pkgconfig $(DESTDIR)$(PREFIX)/include/posedrop
	install -m 755 $(CLI) $(DESTDIR)$(PREFIX)/bin/posedrop
	install -m 644 $(LIB) $(LIB_BULLET) $(LIBDIR)/
	install -m 755 $(SO) $(SO_BULLET) $(LIBDIR)/
	for l in libposedrop libposedrop-bullet; do \
	    ln -sf $$l.so.$(VERSION) $(LIBDIR)/$$l.so.$(MAJOR) && ln -sf $$l.so.$(MAJOR) $(LIBDIR)/$$l.so; \
	done
	install -m 644 include/posedrop/*.h $(DESTDIR)$(PREFIX)/include/posedrop/
	install -d $(DESTDIR)$(PREFIX)/share/doc/posedrop
	install -m 644 LICENSE NOTICE docs/library.md $(DESTDIR)$(PREFIX)/share/doc/posedrop/
	sed -e 's|@PREFIX@|$(PREFIX)|' -e 's|@VERSION@|$(VERSION)|' -e 's|@REQUIRES@|$(LIB_PKGS)|' \
	    scripts/posedrop.pc.in > $(LIBDIR)/pkgconfig/posedrop.pc
	sed -e 's|@PREFIX@|$(PREFIX)|' -e 's|@VERSION@|$(VERSION)|' -e 's|@REQUIRES@|$(BULLET_PKGS)|' \
	    scripts/posedrop-bullet.pc.in > $(LIBDIR)/pkgconfig/posedrop-bullet.pc

uninstall:
	rm -f $(DESTDIR)$(PREFIX)/bin/posedrop $(LIBDIR)/pkgconfig/posedrop.pc \
	      $(LIBDIR)/pkgconfig/posedrop-bullet.pc
	for l in libposedrop libposedrop-bullet; do \
	    rm -f $(LIBDIR)/$$l.a $(LIBDIR)/$$l.so $(LIBDIR)/$$l.so.$(MAJOR) $(LIBDIR)/$$l.so.$(VERSION); \
	done
	rm -rf $(DESTDIR)$(PREFIX)/include/posedrop $(DESTDIR)$(PREFIX)/share/doc/posedrop

clean:
	rm -rf build

help:
	@echo "make            build libposedrop (.so, .a), libposedrop-bullet and the"
	@echo "                posedrop command ($(BUILD)/)"
	@echo "make demo       install missing packages, build, drop $(DEMO_PART) 2000 times:"
	@echo "                its pose classes and a report (build/demo/)"
	@echo "make check      install missing packages, build and run the tests"
	@echo "                (SUITES='hull static' runs only those suites)"
	@echo "make check-full make check with the long statistical runs (CI runs both)"
	@echo "make paper      the paper's Tables 1-4 with posedrop's columns beside them"
	@echo "make bench      speed figures, as ratios against reference runs"
	@echo "make bench-mujoco  cost per drop against MuJoCo (pip install mujoco; see the script)"
	@echo "make referee    the cross-check corpus on the three engines and MuJoCo, into docs"
	@echo "make lint       check that no layer of src/ includes one above it"
	@echo "make check-browser  the report and pictures in headless Chromium and rsvg-convert"
	@echo "make check-readme   every command README.md gives, run as written"
	@echo "make figures    the cap's pictures, the cost-accuracy chart and the uncertainty table in docs/"
	@echo "make check-install  install to a temporary prefix, build the library example"
	@echo "                with plain pkg-config, compare it with the command"
	@echo "make MPI=1      also build posedrop-mpi with OpenMPI (scripts/install-deps.sh mpi)"
	@echo "make golden     re-pin the golden outcomes on purpose, printing what moved"
	@echo "make fuzz       fuzz the readers, the part build and the API, FUZZ_SECONDS=$(FUZZ_SECONDS) each"
	@echo "make install    install to PREFIX=$(PREFIX) (DESTDIR honoured)"
	@echo "make clean      remove build/"
	@echo "switches: WERROR=1  SANITIZE=1 (address,undefined)  DEBUG=1"

-include $(FUZZ_OBJS:.o=.d) $(LIB_OBJS:.o=.d) $(BULLET_OBJS:.o=.d) $(VIZ_OBJS:.o=.d) $(TEST_OBJS:.o=.d) \
         $(BENCH_OBJS:.o=.d) $(CLI_OBJS:.o=.d) $(CLI_MPI_OBJS:.o=.d)
