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
# stepping, special functions), ODE with libccd and Bullet for the stepping
# backends (src/engines/). qhull_r is for the
# tests' and the benchmark's reference hull only, never for libposedrop.
LIB_PKGS  := gsl ode ccd bullet
TEST_PKGS := qhull_r

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
CFLAGS_ALL := -std=c11 -g -pthread $(CFLAGS_OPT) $(WARN) $(CFLAGS_WERROR) -ffp-contract=off \
              -D_DEFAULT_SOURCE -Iinclude -Isrc $(shell $(PKG_CONFIG) --cflags $(LIB_PKGS) 2>/dev/null) \
              $(CFLAGS)
# The one C++ file (the Bullet adapter). Bullet's headers come in as system
# headers (-isystem) so their own warnings do not trip WERROR=1.
CXXFLAGS_ALL := -std=c++17 -g -pthread $(CFLAGS_OPT) -Wall -Wextra $(CFLAGS_WERROR) -ffp-contract=off \
                -Iinclude -Isrc $(patsubst -I%,-isystem %,$(shell $(PKG_CONFIG) --cflags bullet 2>/dev/null)) \
                $(CXXFLAGS)
LDLIBS_LIB := $(shell $(PKG_CONFIG) --libs $(LIB_PKGS) 2>/dev/null) -lm -pthread
LDLIBS_TEST := $(shell $(PKG_CONFIG) --libs $(TEST_PKGS) 2>/dev/null)
CFLAGS_TEST := -Itests/support $(shell $(PKG_CONFIG) --cflags $(TEST_PKGS) 2>/dev/null)

# One folder per layer under src/ (docs/development.md); the Makefile follows
# the tree by wildcard, so adding a file needs no edit here.
LIB_SRCS   := $(wildcard src/*/*.c)
LIB_SRCS   := $(filter-out src/cli/% src/viz/%,$(LIB_SRCS))
LIB_CXX_SRCS := $(wildcard src/*/*.cpp)
LIB_OBJS   := $(LIB_SRCS:%.c=$(BUILD)/%.o) $(LIB_CXX_SRCS:%.cpp=$(BUILD)/%.o)
LIB        := $(BUILD)/libposedrop.a
# The pictures (src/viz/) are the program's, not the library's: a client of
# the public API that the command and the tests link.
VIZ_OBJS   := $(patsubst %.c,$(BUILD)/%.o,$(wildcard src/viz/*.c))
CLI        := $(BUILD)/posedrop
TEST_SRCS  := $(wildcard tests/unit/*.c tests/support/*.c)
TEST_OBJS  := $(TEST_SRCS:%.c=$(BUILD)/%.o)
TEST_BIN   := $(BUILD)/test_posedrop
BENCH_SRCS := tests/bench/bench.c tests/support/shapes.c tests/support/qhull_ref.c
BENCH_OBJS := $(BENCH_SRCS:%.c=$(BUILD)/bench-%.o)
BENCH_BIN  := $(BUILD)/bench_posedrop
DEMO_PART  := parts/cap.off

.PHONY: all check test bench demo paper install uninstall clean help deps golden lint \
        check-browser figures
.DEFAULT_GOAL := all

all: $(LIB) $(CLI)

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
	$(CC) $(CFLAGS_ALL) $(CFLAGS_TEST) -DPD_CLI_PATH='"$(CLI)"' -MMD -MP -c $< -o $@

$(BUILD)/bench-%.o: %.c Makefile
	@mkdir -p $(dir $@)
	$(CC) $(CFLAGS_ALL) $(CFLAGS_TEST) -MMD -MP -c $< -o $@

# Binaries link with $(CXX): the archive holds the Bullet adapter, which needs
# the C++ runtime.
$(LIB): $(LIB_OBJS)
	@rm -f $@
	$(AR) rcs $@ $^

$(CLI): $(BUILD)/src/cli/cli.o $(VIZ_OBJS) $(LIB)
	$(CXX) $(LDFLAGS_SAN) $(LDFLAGS) -o $@ $^ $(LDLIBS_LIB)

$(TEST_BIN): $(TEST_OBJS) $(VIZ_OBJS) $(LIB)
	$(CXX) $(LDFLAGS_SAN) $(LDFLAGS) -o $@ $^ $(LDLIBS_TEST) $(LDLIBS_LIB)

$(BENCH_BIN): $(BENCH_OBJS) $(LIB)
	$(CXX) $(LDFLAGS_SAN) $(LDFLAGS) -o $@ $^ $(LDLIBS_TEST) $(LDLIBS_LIB)

# Installs the Debian packages when pkg-config cannot find them (quick no-op
# otherwise). The targets a new user runs first go through it; their real work
# runs in a sub-make so that pkg-config is asked again after the install.
deps:
	@scripts/install-deps.sh

test: $(TEST_BIN) $(CLI)
	$(TEST_BIN) $(SUITES)

# A file may include only its own layer's headers and those of the layers
# below it (scripts/lint-layers.sh holds the table).
lint:
	@scripts/lint-layers.sh

check: deps lint
	@$(MAKE) --no-print-directory test

demo: deps
	@$(MAKE) --no-print-directory all
	$(CLI) -n 2000 -h 0.12 $(DEMO_PART)

# The report and the SVGs in a real browser and renderer (headless Chromium,
# rsvg-convert; installed when missing): tests/browser/check.sh.
check-browser: deps
	@$(MAKE) --no-print-directory $(CLI)
	POSEDROP=$(CLI) tests/browser/check.sh

# The insulator cap's gallery, chart against the paper's physical tests and
# gauss-sphere map, and the cost-accuracy chart, into docs/figures/
# (docs/figures.md). CHART_ONLY=1 redraws the cost-accuracy chart from its
# kept CSV instead of rerunning its several minutes of drops.
figures: deps
	@$(MAKE) --no-print-directory all
	POSEDROP=$(CLI) scripts/figures.sh $(if $(CHART_ONLY),--chart-only)

# The paper's Tables 1-4 with posedrop's columns beside them (results/).
paper: deps
	@$(MAKE) --no-print-directory all
	scripts/paper.sh

# Re-pins the golden outcomes (tests/unit/test_golden.c) on purpose, printing each
# case whose hash moved; the commit that does it says why.
golden: $(TEST_BIN)
	PD_GOLDEN_WRITE=tests/golden.csv $(TEST_BIN) golden

bench: deps
	@$(MAKE) --no-print-directory $(BENCH_BIN) $(CLI)
	$(BENCH_BIN)

install: all
	install -d $(DESTDIR)$(PREFIX)/bin $(DESTDIR)$(PREFIX)/lib/pkgconfig \
	           $(DESTDIR)$(PREFIX)/include/posedrop
	install -m 755 $(CLI) $(DESTDIR)$(PREFIX)/bin/posedrop
	install -m 644 $(LIB) $(DESTDIR)$(PREFIX)/lib/libposedrop.a
	install -m 644 include/posedrop/*.h $(DESTDIR)$(PREFIX)/include/posedrop/
	sed -e 's|@PREFIX@|$(PREFIX)|' -e 's|@VERSION@|$(shell sed -n 's/.*PD_VERSION_STRING "\(.*\)"/\1/p' include/posedrop/posedrop.h)|' \
	    -e 's|@REQUIRES@|$(LIB_PKGS)|' scripts/posedrop.pc.in > $(DESTDIR)$(PREFIX)/lib/pkgconfig/posedrop.pc

uninstall:
	rm -f $(DESTDIR)$(PREFIX)/bin/posedrop $(DESTDIR)$(PREFIX)/lib/libposedrop.a \
	      $(DESTDIR)$(PREFIX)/lib/pkgconfig/posedrop.pc
	rm -rf $(DESTDIR)$(PREFIX)/include/posedrop

clean:
	rm -rf build

help:
	@echo "make            build libposedrop.a and the posedrop command ($(BUILD)/)"
	@echo "make demo       install missing packages, build, drop $(DEMO_PART) 2000 times"
	@echo "make check      install missing packages, build and run the tests"
	@echo "                (SUITES='hull static' runs only those suites)"
	@echo "make paper      the paper's Tables 1-4 with posedrop's columns beside them"
	@echo "make bench      speed figures, as ratios against reference runs"
	@echo "make lint       check that no layer of src/ includes one above it"
	@echo "make check-browser  the report and pictures in headless Chromium and rsvg-convert"
	@echo "make figures    the cap's pictures and the cost-accuracy chart in docs/figures/"
	@echo "make golden     re-pin the golden outcomes on purpose, printing what moved"
	@echo "make install    install to PREFIX=$(PREFIX) (DESTDIR honoured)"
	@echo "make clean      remove build/"
	@echo "switches: WERROR=1  SANITIZE=1 (address,undefined)  DEBUG=1"

-include $(LIB_OBJS:.o=.d) $(VIZ_OBJS:.o=.d) $(TEST_OBJS:.o=.d) $(BENCH_OBJS:.o=.d) $(BUILD)/src/cli/cli.d
