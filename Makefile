# bumpbake: plain Makefile. `make` builds, `make test` builds and runs every
# test, `make demo` bakes a fixture into out/, `make bench` measures.
# `make DEBUG=1 ...` builds with assertions and ASan/UBSan into build/debug.

DEBUG ?= 0
ifeq ($(DEBUG),1)
BUILD   := build/debug
OPT     := -O1 -g -fsanitize=address,undefined -fno-omit-frame-pointer
else
BUILD   := build
OPT     := -O3 -g -DNDEBUG
endif

CC      ?= cc
CXX     ?= g++
WARN    := -Wall -Wextra -Wshadow -Wconversion -Wstrict-prototypes -Wmissing-prototypes
CFLAGS  += -std=c11 -D_POSIX_C_SOURCE=200809L -pthread $(OPT) $(WARN) -Iinclude -Isrc
CXXFLAGS+= -std=c++17 -pthread $(OPT) -Wall -Wextra -Wshadow -Iinclude -Isrc
PKGS    := OpenImageIO criterion
OIIO_CFLAGS := $(shell pkg-config --cflags OpenImageIO 2>/dev/null)
OIIO_LIBS   := $(shell pkg-config --libs OpenImageIO 2>/dev/null)
CRIT_LIBS   := $(shell pkg-config --libs criterion 2>/dev/null)
LDLIBS  := $(OIIO_LIBS) -lm -pthread

# Start-up. OpenImageIO on Debian 12 loads 261 shared libraries, and most of
# bumpbake's ~0.2 s start-up is the dynamic linker looking up symbols: each
# lookup walks the libraries in load order up to the one defining it, and a
# few large C++ libraries deep in that order (OpenVDB, GDAL, Xerces, GEOS...)
# look up tens of thousands of their own symbols. Naming them first on the
# CLI's link line (they are loaded anyway) makes those walks short: `bumpbake
# --version` drops from 0.20 to 0.14 s. Only those OpenImageIO already brings
# in are named (none elsewhere: no change); `make EARLY_LIBS=` turns it off.
# Deferred (=), so ldd runs only when the CLI is linked.
EARLY_LIB_PATTERN := ^lib(openvdb|xerces-c|gdal|geos|crypto|proj|poppler|dcmdata|gdcmMSFF|rsvg-2)[.-]
EARLY_LIBS = $(shell ldd "$$(pkg-config --variable=libdir OpenImageIO)/libOpenImageIO.so" \
  2>/dev/null | awk '$$1 ~ /$(EARLY_LIB_PATTERN)/ && $$3 ~ /^\// {print $$3}')
EARLY_LINK = $(if $(strip $(EARLY_LIBS)),-Wl$(comma)--push-state$(comma)--no-as-needed $(EARLY_LIBS) -Wl$(comma)--pop-state)
comma := ,
ifeq ($(DEBUG),1)
LDFLAGS += -fsanitize=address,undefined
endif

LIB_C    := $(filter-out src/cli%.c,$(wildcard src/*.c))
LIB_CXX  := $(wildcard src/*.cpp)
CLI_C    := $(wildcard src/cli*.c)
TEST_C   := $(wildcard tests/test_*.c)
TOOL_C   := $(wildcard tools/*.c)

LIB_OBJ  := $(LIB_C:%.c=$(BUILD)/%.o) $(LIB_CXX:%.cpp=$(BUILD)/%.o)
CLI_OBJ  := $(CLI_C:%.c=$(BUILD)/%.o)
TEST_OBJ := $(TEST_C:%.c=$(BUILD)/%.o)
LIB      := $(BUILD)/libbumpbake.a
BIN      := $(BUILD)/bumpbake
TESTBIN  := $(BUILD)/bb_tests
TOOLS    := $(TOOL_C:tools/%.c=$(BUILD)/tools/%)

.PHONY: all deps ensure-deps demo test check bench goldens clean format
all: $(BIN) $(TOOLS)

# ---- dependencies (Debian packages) ----------------------------------------
SUDO := $(shell [ "$$(id -u)" = 0 ] || echo sudo)
DEB_PKGS := libopenimageio-dev libcriterion-dev pkg-config g++ make
deps:
	$(SUDO) apt-get update
	DEBIAN_FRONTEND=noninteractive $(SUDO) apt-get install -y --no-install-recommends $(DEB_PKGS)

ensure-deps:
	@if command -v pkg-config >/dev/null 2>&1 && pkg-config --exists $(PKGS) \
	    && command -v $(CXX) >/dev/null 2>&1; then :; \
	 else echo "bumpbake: installing missing build dependencies (make deps)"; $(MAKE) --no-print-directory deps; fi

# ---- build ------------------------------------------------------------------
$(BUILD)/%.o: %.c include/bumpbake.h src/internal.h
	@mkdir -p $(dir $@)
	$(CC) $(CFLAGS) -c $< -o $@

$(BUILD)/src/%.o: src/%.cpp include/bumpbake.h src/internal.h
	@mkdir -p $(dir $@)
	$(CXX) $(CXXFLAGS) $(OIIO_CFLAGS) -c $< -o $@

$(LIB): $(LIB_OBJ)
	@rm -f $@
	ar rcs $@ $^

$(BIN): $(CLI_OBJ) $(LIB)
	$(CXX) $(LDFLAGS) -o $@ $(CLI_OBJ) $(LIB) $(EARLY_LINK) $(LDLIBS)

$(BUILD)/tools/%: tools/%.c $(wildcard tools/*.h) $(LIB) include/bumpbake.h
	@mkdir -p $(dir $@)
	$(CC) $(CFLAGS) -o $@ $< $(LIB) $(LDFLAGS) $(LDLIBS) -lstdc++

$(TESTBIN): $(TEST_OBJ) $(LIB)
	$(CXX) $(LDFLAGS) -o $@ $(TEST_OBJ) $(LIB) $(CRIT_LIBS) $(LDLIBS)

# ---- the README's commands ---------------------------------------------------
demo: ensure-deps
	@$(MAKE) --no-print-directory all
	@./tools/demo.sh $(BIN)

test: ensure-deps
	@$(MAKE) --no-print-directory check

# Criterion suite (unit, property, CLI and golden tests); the CLI tests run
# the binary named by BB_BIN.
check: $(BIN) $(TESTBIN) $(TOOLS)
	BB_BIN=$(BIN) BB_FIXTURES=fixtures ./$(TESTBIN) --jobs 2

bench: ensure-deps
	@$(MAKE) --no-print-directory all
	@./tools/bench.sh $(BIN)

goldens: ensure-deps
	@$(MAKE) --no-print-directory all
	@./tools/goldens.sh $(BIN) regenerate

format:
	clang-format -i include/*.h src/*.c src/*.h src/*.cpp tests/*.c tools/*.c

clean:
	rm -rf build out
