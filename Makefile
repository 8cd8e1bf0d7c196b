# bumpbake: plain Makefile. `make` builds, `make test` builds and runs every
# test, `make demo` bakes a fixture into out/, `make bench` measures,
# `make install` installs (PREFIX=/usr/local, DESTDIR= for staging),
# `make fuzz` runs the libFuzzer targets of fuzz/ (`make fuzz-long` for longer).
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
# -MMD -MP: every compile also writes OBJ.d listing the headers it read, so
# touching a header recompiles exactly what includes it (included below).
DEPFLAGS:= -MMD -MP
# Include paths by family: the library sees its private headers (-Isrc:
# "core/internal.h", "trace/sweep.h"...); the CLI sees the public header and
# its own folder only, so the build proves it uses nothing but bumpbake.h
# (and the JSON writer it compiles into itself, below); tests and tools also
# see tests/ and src/ (internals they check).
CFLAGS  += -std=c11 -D_POSIX_C_SOURCE=200809L -pthread $(OPT) $(WARN)
CXXFLAGS+= -std=c++17 -pthread $(OPT) -Wall -Wextra -Wshadow
LIB_INCLUDES  := -Iinclude -Isrc
CLI_INCLUDES  := -Iinclude -Isrc/cli
# serve (src/serve/) sees the public header and its own folder; the CLI's
# printing and the JSON writer by their relative paths ("../cli/common.h").
SERVE_INCLUDES := -Iinclude
TEST_INCLUDES := -Iinclude -Isrc -Itests
# Library objects go into libbumpbake.so as well as libbumpbake.a, so they
# are position-independent. -fno-semantic-interposition keeps GCC inlining
# and calling the library's own global functions directly, as without -fPIC.
LIB_CFLAGS := -fPIC -fno-semantic-interposition
PKGS    := OpenImageIO criterion assimp Imath libpng libjpeg OpenEXR libmicrohttpd
OIIO_CFLAGS := $(shell pkg-config --cflags OpenImageIO 2>/dev/null)
OIIO_LIBS   := $(shell pkg-config --libs OpenImageIO 2>/dev/null)
# libpng: src/image/png_hooks.c sets quiet error handlers and bounded
# allocations on the libpng structs OpenImageIO makes.
PNG_CFLAGS  := $(shell pkg-config --cflags libpng 2>/dev/null)
PNG_LIBS    := $(shell pkg-config --libs libpng 2>/dev/null)
# libjpeg and OpenEXRCore read headers before OpenImageIO's readers do
# (src/image/header_probe.c), to refuse what they would allocate in open().
PROBE_CFLAGS := $(shell pkg-config --cflags libjpeg OpenEXR 2>/dev/null)
PROBE_LIBS   := $(shell pkg-config --libs libjpeg 2>/dev/null) \
                $(filter -lOpenEXRCore%,$(shell pkg-config --libs OpenEXR 2>/dev/null))
CRIT_LIBS   := $(shell pkg-config --libs criterion 2>/dev/null)
# Assimp reads and writes meshes (src/mesh/mesh_assimp.cpp only).
ASSIMP_CFLAGS := $(shell pkg-config --cflags assimp 2>/dev/null)
ASSIMP_LIBS   := $(shell pkg-config --libs assimp 2>/dev/null)
# Imath's half.h (C, header only) converts floats to half for VTF and DDS;
# the blocks of both are bumpbake's own codec (src/texture/bc1.c, bc4.c).
# libmicrohttpd: the HTTP server of `bumpbake serve` (src/serve/ only), not
# linked: serve loads it by its soname when it starts (src/serve/serve_mhd.h),
# so that it and GnuTLS's libraries are not in every process's global scope.
MHD_SONAME := $(shell objdump -p $$(pkg-config --variable=libdir libmicrohttpd 2>/dev/null)/libmicrohttpd.so \
                2>/dev/null | awk '/SONAME/ { print $$2 }')
MHD_CFLAGS := $(shell pkg-config --cflags libmicrohttpd 2>/dev/null) \
              $(if $(MHD_SONAME),-DBB_MHD_SONAME='"$(MHD_SONAME)"')
# OpenEXR's IlmThread: bumpbake's provider for its pool (src/image/exr_pool.cpp).
EXR_POOL_LIBS := $(filter -lIlmThread%,$(shell pkg-config --libs OpenEXR 2>/dev/null))
# The library's and the programs' libraries: OpenImageIO is not one of them.
# The module that calls it (libbumpbake-oiio.so, below) links it and
# OpenEXR's pool, and the library loads the module on its first image call.
LDLIBS  := $(ASSIMP_LIBS) $(PNG_LIBS) $(PROBE_LIBS) -lm -pthread
MODULE_LIBS := $(OIIO_LIBS) $(EXR_POOL_LIBS) -lm -pthread
ifeq ($(DEBUG),1)
LDFLAGS += -fsanitize=address,undefined
endif

# ---- version, soname and install layout ------------------------------------
# The version and the ABI's number live once, in the public header.
VERSION := $(shell sed -n 's/.*define BB_VERSION_STRING "\(.*\)"$$/\1/p' include/bumpbake.h)
ABI_VERSION := $(shell sed -n 's/^\#define BB_ABI_VERSION \([0-9]*\)$$/\1/p' include/bumpbake.h)
# The soname names the ABI, not the release: libbumpbake.so.0.N, N =
# BB_ABI_VERSION. As Debian does, it changes only when abidiff says it must:
# when a change breaks programs built against the last release (a function
# removed or changed, a public struct changed), `make check-abi` fails until
# BB_ABI_VERSION is raised (once between two releases), and fails as well on
# a raise nothing needs. A release that only adds functions keeps the
# soname. Each release stores its ABI (`make abi-dump`, abi/).
ifeq ($(ABI_VERSION),)
$(error include/bumpbake.h has no line "#define BB_ABI_VERSION N")
endif
SOVERSION := 0.$(ABI_VERSION)
SONAME    := libbumpbake.so.$(SOVERSION)
SHLIB_REAL:= libbumpbake.so.$(VERSION)

PREFIX     ?= /usr/local
DESTDIR    ?=
BINDIR     ?= $(PREFIX)/bin
LIBDIR     ?= $(PREFIX)/lib
INCLUDEDIR ?= $(PREFIX)/include
MANDIR     ?= $(PREFIX)/share/man
PKGCONFIGDIR ?= $(LIBDIR)/pkgconfig
# The Python package goes where Debian's python3 looks for a prefix's
# packages: PREFIX/lib/python3/dist-packages (on its path for /usr; other
# prefixes need PYTHONPATH), except /usr/local, whose directory Debian names
# by the interpreter's version (/usr/local/lib/python3.11/dist-packages).
PYTHON_VERSION := $(shell /usr/bin/python3 -c 'import sys; print("%d.%d" % sys.version_info[:2])' 2>/dev/null)
PYTHONDIR  ?= $(if $(and $(filter /usr/local,$(PREFIX)),$(PYTHON_VERSION)),$(PREFIX)/lib/python$(PYTHON_VERSION)/dist-packages,$(PREFIX)/lib/python3/dist-packages)
# bumpbake.pc: an rpath for a LIBDIR the dynamic loader does not search by
# itself (Debian's: /lib, /usr/lib, /usr/local/lib and their multiarch
# folders), and the static link's libraries (LDLIBS, Libs.private).
MULTIARCH  := $(shell $(CC) -dumpmachine 2>/dev/null)
LOADER_DIRS:= /lib /usr/lib /usr/local/lib $(addsuffix /$(MULTIARCH),/lib /usr/lib /usr/local/lib)
PC_RPATH    = $(if $(filter $(patsubst %/,%,$(LIBDIR)),$(LOADER_DIRS)),, -Wl$(comma)-rpath$(comma)$${libdir})
PC_LIBS_PRIVATE = $(LDLIBS) -lstdc++
# Refreshes the loader's cache after a real (DESTDIR-less) install as root;
# `make install LDCONFIG=:` skips it (the install check does).
LDCONFIG   ?= ldconfig

# ---- start-up: the OpenImageIO module and its early link ---------------------
# OpenImageIO on Debian 12 loads about 260 shared libraries, and loading
# them was most of a bumpbake process's start-up (bumpbake --version: 0.2 s
# of CPU; each Criterion test, a process of its own: 0.33 s). Its calls are
# built into a module of their own, $(MODULE) (src/image/oiio_module.h),
# which the library dlopen()s on the first call that reads or writes an
# image or draws text (src/image/oiio_load.c): a process that does neither
# never loads OpenImageIO. libbumpbake.so finds the module in its own folder,
# a program linking libbumpbake.a in the folder compiled into it
# (src/image/oiio_module_dir.c: $(BUILD) for the build's, LIBDIR for the
# installed ones); `make install` puts the module beside the library.
#
# When the module is loaded, most of that time is the dynamic linker looking
# up symbols: each lookup walks the libraries in load order up to the one
# defining it, and a few large C++ libraries deep in that order (OpenVDB,
# Xerces, GDAL...) look up tens of thousands of their own symbols. The
# module names every library the probe loads first on its link line, the
# one the most lookups end in first ($(BUILD)/link-order.txt, written by
# tools/link_order.sh at build time): they are loaded anyway, and the walks
# are short. `make EARLY_LINK=0` links them plainly.
EARLY_LINK ?= 1
LINK_ORDER := $(BUILD)/link-order.txt
MODULE_EARLY = $(if $(filter 1,$(EARLY_LINK)),-Wl$(comma)--push-state$(comma)--no-as-needed \
  $$(cat $(LINK_ORDER)) -Wl$(comma)--pop-state)
EARLY_DEPS = $(if $(filter 1,$(EARLY_LINK)),$(LINK_ORDER))
comma := ,

# ---- sources and products ----------------------------------------------------
# The library's families, each using only the ones before it: the order of
# docs/how-it-works.md ("Layers"), which `make check-layers` holds them to.
FAMILIES := core files texture image trace bake maps render mesh job cmd
# The OpenImageIO module's sources (src/image/oiio_module.h): every file
# that calls OpenImageIO, OpenEXR's pool, its entry and its calls back into
# the library; the library's side is src/image/oiio_load.c.
MODULE_CXX := $(addprefix src/image/,oiio_read.cpp oiio_write.cpp oiio_mips.cpp oiio_gif.cpp \
                oiio_guard.cpp exr_pool.cpp) src/render/oiio_text.cpp
MODULE_C   := src/image/oiio_host.c src/image/oiio_host_table.c src/render/oiio_entry.c
MODULE_DIR_C := src/image/oiio_module_dir.c
LIB_C    := $(filter-out $(MODULE_C),$(foreach f,$(FAMILIES),$(wildcard src/$(f)/*.c)))
LIB_CXX  := $(filter-out $(MODULE_CXX),$(foreach f,$(FAMILIES),$(wildcard src/$(f)/*.cpp)))
# `bumpbake serve` (src/serve/): a client of its own above the CLI (it
# prints as the CLI does), the program's only HTTP server, linked into the
# program by src/cli/main.c and left out of the test binary and the fuzz
# targets.
SERVE_C  := $(wildcard src/serve/*.c)
# The program's sources: the CLI and serve.
CLI_C    := $(wildcard src/cli/*.c) $(SERVE_C)
# The page it serves, embedded into serve_page.o at build time.
SERVE_ASSETS := $(wildcard share/serve/*) shaders/ssbump_relief.glsl
TEST_C   := $(wildcard tests/*/test_*.c)
TOOL_C   := $(filter-out tools/link_probe.c,$(wildcard tools/*.c))

LIB_OBJ  := $(LIB_C:%.c=$(BUILD)/%.o) $(LIB_CXX:%.cpp=$(BUILD)/%.o)
# The JSON writer is no part of the library's ABI: the CLI compiles its one
# source, src/core/json.c (which includes nothing of the library), into
# itself as cli/json.o for serve, which includes src/core/json.h by its
# relative path (compare and info print the library's report, which the
# library writes).
CLI_JSON_OBJ := $(BUILD)/src/cli/json.o
CLI_OBJ  := $(CLI_C:%.c=$(BUILD)/%.o) $(CLI_JSON_OBJ)
TEST_OBJ := $(TEST_C:%.c=$(BUILD)/%.o)
TOOL_OBJ := $(TOOL_C:%.c=$(BUILD)/%.o)
# The fuzz targets' code, compiled into the test binary to replay the saved
# regression inputs (tests/test_fuzz.c), with the CLI minus main().
FUZZ_REPLAY_OBJ := $(patsubst fuzz/%.c,$(BUILD)/fuzz/%.o,$(wildcard fuzz/fuzz_*.c))
CLI_LIB_OBJ := $(filter-out $(BUILD)/src/cli/main.o $(SERVE_C:%.c=$(BUILD)/%.o),$(CLI_OBJ))
MODULE_OBJ := $(MODULE_C:%.c=$(BUILD)/%.o) $(MODULE_CXX:%.cpp=$(BUILD)/%.o)
MODULE   := $(BUILD)/libbumpbake-oiio.so.$(VERSION)
# The module exports its entry only (src/image/oiio_module.map).
MODULE_MAP := src/image/oiio_module.map
ALL_OBJ  := $(LIB_OBJ) $(CLI_OBJ) $(TEST_OBJ) $(TOOL_OBJ) $(FUZZ_REPLAY_OBJ) $(MODULE_OBJ)
LIB      := $(BUILD)/libbumpbake.a
SHLIB    := $(BUILD)/$(SHLIB_REAL)
# The symbols libbumpbake.so exports: bb_* (the public API) and nothing else.
LIB_MAP  := src/libbumpbake.map
BIN      := $(BUILD)/bumpbake
TESTBIN  := $(BUILD)/bb_tests
TOOLS    := $(TOOL_C:tools/%.c=$(BUILD)/tools/%)
# The CLI linked other ways, for `make bench`'s start-up comparison, and the
# Criterion suite, whose trench test section 10 (tools/bench_bounce.sh) reads.
BENCH_BINS := $(BUILD)/bench/bumpbake-shared $(TESTBIN)

.PHONY: all lib deps ensure-deps demo test check check-unit check-install \
        check-python check-serve check-report check-circles check-layers check-docs check-abi abi-dump api-report \
        bench bench-cluster bench-check goldens docs docs-reference install check-others \
        uninstall clean format FORCE \
        fuzz fuzz-long fuzz-deps ensure-fuzz-deps hostile
all: $(BIN) lib $(TOOLS) $(MODULE)
lib: $(LIB) $(SHLIB) $(BUILD)/$(SONAME) $(BUILD)/libbumpbake.so $(MODULE)

# ---- dependencies (Debian packages) ----------------------------------------
SUDO := $(shell [ "$$(id -u)" = 0 ] || echo sudo)
# Python: Debian's /usr/bin/python3 with its cffi, numpy and pytest.
# fonts-dejavu-core: the labels of `sheet` and `render --compare` (drawn
# through OpenImageIO's FreeType text; without a font they are left out).
PYTHON   := /usr/bin/python3
# openimageio-tools: idiff, which a test runs beside `bumpbake compare` to
# check their exit codes agree; ninja-build: a test has ninja read a bake's
# --depfile. Both tests skip without them, so ensure-deps installs them.
# python3-distributed and python3-dask: bumpbake.dask, batches and big maps on
# a Dask cluster (its tests run a LocalCluster). python3-junitparser: a test
# reads `bumpbake check --junit`'s file as CI servers do; python3-yaml: a test
# runs docs/goldens.md's CI jobs. strace: a test (and make
# hostile) delivers a signal in the middle of a commit; time: make hostile's
# peak memory (GNU time's %M). abigail-tools: abidw and abidiff, the ABI
# check.
DEB_PKGS := libopenimageio-dev libcriterion-dev libassimp-dev libimath-dev \
            libpng-dev libjpeg-dev libopenexr-dev pkg-config g++ make \
            python3 python3-cffi python3-numpy python3-pytest fonts-dejavu-core \
            openimageio-tools ninja-build python3-distributed python3-dask strace time \
            libmicrohttpd-dev chromium chromium-driver python3-selenium python3-junitparser \
            python3-yaml abigail-tools
LABEL_FONT := /usr/share/fonts/truetype/dejavu/DejaVuSans.ttf
deps:
	$(SUDO) apt-get update
	DEBIAN_FRONTEND=noninteractive $(SUDO) apt-get install -y --no-install-recommends $(DEB_PKGS)

ensure-deps:
	@if command -v pkg-config >/dev/null 2>&1 && pkg-config --exists $(PKGS) \
	    && command -v $(CXX) >/dev/null 2>&1 && [ -f $(LABEL_FONT) ] \
	    && command -v idiff >/dev/null 2>&1 && command -v ninja >/dev/null 2>&1 \
	    && $(PYTHON) -c 'import cffi, numpy, pytest, dask, distributed, selenium, junitparser, yaml' >/dev/null 2>&1 \
	    && command -v chromium >/dev/null 2>&1 && command -v chromedriver >/dev/null 2>&1 \
	    && command -v abidw >/dev/null 2>&1 && command -v abidiff >/dev/null 2>&1; then :; \
	 else echo "bumpbake: installing missing build dependencies (make deps)"; $(MAKE) --no-print-directory deps; fi

# libFuzzer needs clang and its runtimes (Debian 12: clang 14); only `make
# fuzz` asks for them.
FUZZ_DEB_PKGS := clang libclang-rt-14-dev
fuzz-deps:
	$(SUDO) apt-get update
	DEBIAN_FRONTEND=noninteractive $(SUDO) apt-get install -y --no-install-recommends $(FUZZ_DEB_PKGS)

# Linking an empty fuzzer proves clang, libFuzzer and the sanitizer runtimes.
ensure-fuzz-deps: ensure-deps
	@if command -v clang >/dev/null 2>&1 && printf 'int LLVMFuzzerTestOneInput(const char *d, unsigned long n) { (void)d; (void)n; return 0; }\n' \
	    | clang -x c -fsanitize=fuzzer,address,undefined -o /dev/null - >/dev/null 2>&1; then :; \
	 else echo "bumpbake: installing clang and libFuzzer (make fuzz-deps)"; $(MAKE) --no-print-directory fuzz-deps; fi

# ---- build ------------------------------------------------------------------
# Objects and binaries also depend on a record of the flags they were made
# with, rewritten only when those change: a changed CFLAGS, DEBUG or
# EARLY_LINK rebuilds what it affects, and stale objects from before a
# Makefile change (non-PIC ones, say) are never linked into the .so.
COMPILE_FLAGS := $(CC) $(CFLAGS) $(DEPFLAGS) | $(CXX) $(CXXFLAGS) $(OIIO_CFLAGS) $(ASSIMP_CFLAGS) | $(LIB_CFLAGS) $(PNG_CFLAGS) $(PROBE_CFLAGS)
LINK_FLAGS    := $(CXX) $(LDFLAGS) $(LDLIBS) $(MODULE_LIBS) $(CRIT_LIBS) EARLY_LINK=$(EARLY_LINK) $(SONAME)
$(BUILD)/compile.flags: FORCE
	@mkdir -p $(@D)
	@echo '$(COMPILE_FLAGS)' | cmp -s - $@ || echo '$(COMPILE_FLAGS)' >$@
$(BUILD)/link.flags: FORCE
	@mkdir -p $(@D)
	@echo '$(LINK_FLAGS)' | cmp -s - $@ || echo '$(LINK_FLAGS)' >$@

$(LIB_OBJ) $(MODULE_OBJ): EXTRA_CFLAGS := $(LIB_CFLAGS) $(LIB_INCLUDES) $(PNG_CFLAGS) $(PROBE_CFLAGS)
# The folder a static link finds the module in: this build's.
$(BUILD)/$(MODULE_DIR_C:.c=.o): EXTRA_CFLAGS += -DBB_OIIO_MODULE_DIR='"$(abspath $(BUILD))"'
$(CLI_OBJ): EXTRA_CFLAGS := $(CLI_INCLUDES)
$(SERVE_C:%.c=$(BUILD)/%.o): EXTRA_CFLAGS := $(SERVE_INCLUDES) $(MHD_CFLAGS)
$(BUILD)/src/serve/serve_page.o: $(SERVE_ASSETS)
$(TEST_OBJ) $(TOOL_OBJ): EXTRA_CFLAGS := $(TEST_INCLUDES)

$(CLI_JSON_OBJ): src/core/json.c $(BUILD)/compile.flags
	@mkdir -p $(@D)
	$(CC) $(CFLAGS) $(CLI_INCLUDES) $(DEPFLAGS) -c $< -o $@

$(BUILD)/%.o: %.c $(BUILD)/compile.flags
	@mkdir -p $(@D)
	$(CC) $(CFLAGS) $(EXTRA_CFLAGS) $(DEPFLAGS) -c $< -o $@

$(BUILD)/src/%.o: src/%.cpp $(BUILD)/compile.flags
	@mkdir -p $(@D)
	$(CXX) $(CXXFLAGS) $(EXTRA_CFLAGS) $(DEPFLAGS) $(OIIO_CFLAGS) $(ASSIMP_CFLAGS) -c $< -o $@

-include $(ALL_OBJ:.o=.d)

$(LIB): $(LIB_OBJ)
	@rm -f $@
	ar rcs $@ $^

# The shared library: soname libbumpbake.so.MAJOR[.MINOR], the real file
# carries the full version, symlinks as ldconfig and -lbumpbake expect.
$(SHLIB): $(LIB_OBJ) $(LIB_MAP) $(BUILD)/link.flags | $(MODULE)
	$(CXX) -shared $(LDFLAGS) -Wl,-soname,$(SONAME) -Wl,--version-script=$(LIB_MAP) \
	  -Wl,-z,defs -Wl,-Bsymbolic-functions -o $@ $(LIB_OBJ) $(LDLIBS)
# The OpenImageIO module: loaded by file name, no soname; the library's own
# functions it calls come through the table the library hands it
# (src/image/oiio_host.c), so it needs nothing of the library at link time.
$(MODULE): $(MODULE_OBJ) $(MODULE_MAP) $(BUILD)/link.flags $(EARLY_DEPS)
	$(CXX) -shared $(LDFLAGS) -Wl,--version-script=$(MODULE_MAP) -Wl,-z,defs \
	  -o $@ $(MODULE_OBJ) $(MODULE_EARLY) $(MODULE_LIBS)
$(BUILD)/$(SONAME): $(SHLIB)
	ln -sf $(SHLIB_REAL) $@
$(BUILD)/libbumpbake.so: $(BUILD)/$(SONAME)
	ln -sf $(SONAME) $@

# The CLI links the static library: it starts as fast as with the shared one
# (`make bench` measures both) and the installed binary finds no library at
# run time but OpenImageIO's.
$(BIN): $(CLI_OBJ) $(LIB) $(BUILD)/link.flags | $(MODULE)
	$(CXX) $(LDFLAGS) -o $@ $(CLI_OBJ) $(LIB) $(LDLIBS)

# The probe and the order it gives (tools/link_order.sh; empty where the
# loader ignores LD_DEBUG, and the link is then the plain one).
$(BUILD)/tools/link_probe: tools/link_probe.c $(BUILD)/link.flags
	@mkdir -p $(@D)
	$(CXX) $(LDFLAGS) -o $@ -x c $< -Wl,--no-as-needed $(MODULE_LIBS)
$(LINK_ORDER): $(BUILD)/tools/link_probe tools/link_order.sh
	tools/link_order.sh $< >$@.tmp && mv $@.tmp $@

$(BUILD)/bench/bumpbake-shared: $(CLI_OBJ) $(BUILD)/libbumpbake.so $(BUILD)/link.flags
	@mkdir -p $(@D)
	$(CXX) $(LDFLAGS) -o $@ $(CLI_OBJ) -L$(BUILD) -lbumpbake -Wl,-rpath,'$$ORIGIN/..' $(LDLIBS)

# The tools print JSON with the library's one writer (bb__json, src/core/json.h).
$(TOOLS): $(BUILD)/tools/%: $(BUILD)/tools/%.o $(LIB) $(BUILD)/link.flags | $(MODULE)
	$(CXX) $(LDFLAGS) -o $@ $< $(LIB) $(LDLIBS)

$(FUZZ_REPLAY_OBJ): $(BUILD)/fuzz/%.o: fuzz/%.c $(BUILD)/compile.flags
	@mkdir -p $(@D)
	$(CC) $(CFLAGS) $(TEST_INCLUDES) $(DEPFLAGS) -DLLVMFuzzerTestOneInput=bb_$* -c $< -o $@

$(TESTBIN): $(TEST_OBJ) $(FUZZ_REPLAY_OBJ) $(CLI_LIB_OBJ) $(LIB) $(BUILD)/link.flags | $(MODULE)
	$(CXX) $(LDFLAGS) -o $@ $(TEST_OBJ) $(FUZZ_REPLAY_OBJ) $(CLI_LIB_OBJ) $(LIB) \
	  $(CRIT_LIBS) $(LDLIBS)

# ---- install ----------------------------------------------------------------
# The installed program: the CLI with src/cli/installed_dirs.c compiled
# again with the install's PYTHONDIR, where `bumpbake bake --scheduler`
# finds the Python package (src/cli/cluster.c); build/bumpbake finds its
# source tree instead. Relinked when PYTHONDIR changes.
INSTALL_BIN := $(BUILD)/install/bumpbake
INSTALL_LIB := $(BUILD)/install/libbumpbake.a
$(BUILD)/install/dirs.flags: FORCE
	@mkdir -p $(@D)
	@echo '$(PYTHONDIR)' | cmp -s - $@ || echo '$(PYTHONDIR)' >$@
$(BUILD)/install/installed_dirs.o: src/cli/installed_dirs.c $(BUILD)/install/dirs.flags \
                                   $(BUILD)/compile.flags
	$(CC) $(CFLAGS) $(CLI_INCLUDES) -DBB_PYTHONDIR='"$(PYTHONDIR)"' -c $< -o $@
$(INSTALL_BIN): $(filter-out $(BUILD)/src/cli/installed_dirs.o,$(CLI_OBJ)) \
                $(BUILD)/install/installed_dirs.o $(INSTALL_LIB) $(BUILD)/link.flags
	$(CXX) $(LDFLAGS) -o $@ $(filter %.o,$^) $(INSTALL_LIB) $(LDLIBS)
# The installed archive: the build's with the module's folder LIBDIR
# (src/image/oiio_module_dir.c), for the installed program and for programs
# linking it (pkg-config --static). Remade when LIBDIR changes.
$(BUILD)/install/libdir.flags: FORCE
	@mkdir -p $(@D)
	@echo '$(LIBDIR)' | cmp -s - $@ || echo '$(LIBDIR)' >$@
$(BUILD)/install/oiio_module_dir.o: $(MODULE_DIR_C) $(BUILD)/install/libdir.flags \
                                    $(BUILD)/compile.flags
	$(CC) $(CFLAGS) $(LIB_CFLAGS) -DBB_OIIO_MODULE_DIR='"$(LIBDIR)"' -c $< -o $@
$(INSTALL_LIB): $(LIB) $(BUILD)/install/oiio_module_dir.o
	cp $(LIB) $@.tmp && ar rs $@.tmp $(BUILD)/install/oiio_module_dir.o && mv $@.tmp $@

# The public headers: bumpbake.h, and bumpbake_cluster.h beside it (the
# advanced calls of drivers that spread the work over machines).
PUBLIC_HEADERS := include/bumpbake.h include/bumpbake_cluster.h
# bumpbake.pc is made from bumpbake.pc.in with the install's own paths; the
# Python package gets bumpbake/_install.py, the path of the library it loads
# (LIBDIR's, where it will be at run time, also when staged with DESTDIR).
install: $(INSTALL_BIN) $(INSTALL_LIB) lib
	install -d $(DESTDIR)$(BINDIR) $(DESTDIR)$(LIBDIR) $(DESTDIR)$(INCLUDEDIR) \
	  $(DESTDIR)$(MANDIR)/man1 $(DESTDIR)$(PKGCONFIGDIR)
	install -m 755 $(INSTALL_BIN) $(DESTDIR)$(BINDIR)/bumpbake
	install -m 755 $(SHLIB) $(DESTDIR)$(LIBDIR)/$(SHLIB_REAL)
	ln -sf $(SHLIB_REAL) $(DESTDIR)$(LIBDIR)/$(SONAME)
	ln -sf $(SONAME) $(DESTDIR)$(LIBDIR)/libbumpbake.so
	install -m 755 $(MODULE) $(DESTDIR)$(LIBDIR)/$(notdir $(MODULE))
	install -m 644 $(INSTALL_LIB) $(DESTDIR)$(LIBDIR)/libbumpbake.a
	install -m 644 $(PUBLIC_HEADERS) $(DESTDIR)$(INCLUDEDIR)/
	install -m 644 docs/bumpbake.1 $(DESTDIR)$(MANDIR)/man1/bumpbake.1
	sed -e 's|@PREFIX@|$(PREFIX)|; s|@LIBDIR@|$(LIBDIR)|; s|@INCLUDEDIR@|$(INCLUDEDIR)|' \
	  -e 's|@VERSION@|$(VERSION)|; s|@RPATH@|$(PC_RPATH)|; s|@LIBS_PRIVATE@|$(PC_LIBS_PRIVATE)|' \
	  bumpbake.pc.in >$(DESTDIR)$(PKGCONFIGDIR)/bumpbake.pc
	install -d $(DESTDIR)$(PYTHONDIR)/bumpbake $(DESTDIR)$(PYTHONDIR)/bumpbake/dask
	install -m 644 $(filter-out python/bumpbake/_install.py,$(wildcard python/bumpbake/*.py)) \
	  $(DESTDIR)$(PYTHONDIR)/bumpbake/
	install -m 644 $(wildcard python/bumpbake/dask/*.py) $(DESTDIR)$(PYTHONDIR)/bumpbake/dask/
	printf '%s\n' '# Written by make install: the library this installed package loads.' \
	  'LIBRARY = "$(LIBDIR)/$(SONAME)"' >$(DESTDIR)$(PYTHONDIR)/bumpbake/_install.py
	@if [ -z "$(DESTDIR)" ] && [ "$$(id -u)" = 0 ]; then $(LDCONFIG) || true; fi

uninstall:
	rm -f $(DESTDIR)$(BINDIR)/bumpbake $(DESTDIR)$(LIBDIR)/$(SHLIB_REAL) \
	  $(DESTDIR)$(LIBDIR)/$(SONAME) $(DESTDIR)$(LIBDIR)/libbumpbake.so \
	  $(DESTDIR)$(LIBDIR)/libbumpbake.a $(DESTDIR)$(LIBDIR)/$(notdir $(MODULE)) $(addprefix $(DESTDIR)$(INCLUDEDIR)/,$(notdir $(PUBLIC_HEADERS))) \
	  $(DESTDIR)$(MANDIR)/man1/bumpbake.1 $(DESTDIR)$(PKGCONFIGDIR)/bumpbake.pc
	rm -rf $(DESTDIR)$(PYTHONDIR)/bumpbake

# ---- the README's commands ---------------------------------------------------
# The demo builds only the command it runs, on every core.
demo: ensure-deps
	@$(MAKE) --no-print-directory -j$(NPROC) $(BIN)
	@./tools/demo.sh $(BIN)

# The build runs on every core (a fresh clone compiles ~70 files); the checks
# then run one after another, the Criterion suite on 2 jobs of its own.
NPROC := $(shell nproc 2>/dev/null || echo 2)
test: ensure-deps
	@$(MAKE) --no-print-directory -j$(NPROC) all $(TESTBIN)
	@$(MAKE) --no-print-directory check

# Everything `make test` runs: the Criterion suite, the install check, the
# Python tests, serve's page in a browser, the check that no two files need
# each other, the check that no family reaches up to a later one, the
# check that the command reference and the man page say what --help says
# and the check of the ABI against the last release's.
# The unit tests take both cores; the other checks mostly wait (on Dask's
# workers, on Chromium, on installs: about 70 s of CPU in 180 s), so they
# run side by side with the unit tests and with each other, their output
# kept (build/check-others.log) and printed whole once the unit tests end.
# A command the shell starts with & ignores SIGINT; the tests of Ctrl-C
# need it as a terminal delivers it, so env gives it back its default.
CHECK_OTHERS_LOG := $(BUILD)/check-others.log
check: $(BIN) $(TESTBIN) $(TOOLS) lib
	@echo "test: the install, the Python package, the serve and report pages in Chromium and the docs,"
	@echo "test: ABI and layer checks start beside the unit tests; their output follows the unit tests'"
	@env --default-signal=INT,QUIT $(MAKE) --no-print-directory -j$(NPROC) --output-sync=target check-others \
	  >$(CHECK_OTHERS_LOG) 2>&1 & others=$$!; \
	$(MAKE) --no-print-directory check-unit; unit=$$?; \
	echo "test: the unit tests are done; waiting for the other checks"; \
	wait $$others; status=$$?; cat $(CHECK_OTHERS_LOG); \
	if [ $$unit -ne 0 ] || [ $$status -ne 0 ]; then \
	  echo "test: FAILED ($$([ $$unit -ne 0 ] && echo 'unit tests ')$$([ $$status -ne 0 ] && echo 'other checks'))"; \
	  exit 1; fi
check-others: check-install check-python check-serve check-report check-circles check-layers \
              check-docs check-abi

# docs/commands/*.md's option tables and docs/bumpbake.1 are generated from
# each command's --help (tools/gen_docs.py): `make docs-reference` rewrites
# them, `make check-docs` fails, naming the command, when they differ.
docs-reference: $(BIN)
	$(PYTHON) tools/gen_docs.py $(BIN)
check-docs: $(BIN)
	@$(PYTHON) tools/gen_docs.py --check $(BIN)

# Object files that use each other's symbols in a circle fail the build's
# checks (tools/check_circles.py): one of them has two jobs.
# The OpenImageIO module is a link of its own (the library's functions it
# calls are its own calls through the host table): checked apart.
check-circles: $(LIB_OBJ) $(MODULE_OBJ) $(CLI_OBJ)
	@./tools/check_circles.py $(LIB_OBJ) $(CLI_OBJ)
	@./tools/check_circles.py $(MODULE_OBJ)

# Families that include or call a later family in the order of
# docs/how-it-works.md ("Layers") fail (tools/check_layers.py); its test
# (tests/tools/test_check_layers.py) shows it refuses an upward include,
# a relative one and an upward call in a tree of its own.
check-layers: $(LIB_OBJ) $(MODULE_OBJ) $(CLI_OBJ)
	@$(PYTHON) tools/check_layers.py --families '$(FAMILIES)' $(LIB_OBJ) $(CLI_OBJ)
	@$(PYTHON) tools/check_layers.py --families '$(FAMILIES)' $(MODULE_OBJ)
	@$(PYTHON) tests/tools/test_check_layers.py

# The shared library's ABI against the last release's, stored in abi/
# (tools/check_abi.sh, libabigail): additions pass; a function removed or
# changed, or a public struct changed, fails, naming it, unless
# BB_ABI_VERSION (the soname) was raised since; a soname raised for nothing
# fails too. abi/bumpbake.abignore lists the changes that break no program.
# Its test (tests/tools/test_check_abi.py) shows the check on a small
# library built against this header and changed copies of it.
# `make abi-dump`, at a release only (after setting its BB_VERSION_STRING):
# stores the release's ABI, what check-abi compares with until the next.
ABI_STORED       := abi/libbumpbake.abi
ABI_SUPPRESSIONS := abi/bumpbake.abignore
check-abi: lib
	@./tools/check_abi.sh check $(ABI_STORED) $(SHLIB) include $(ABI_SUPPRESSIONS)
	@$(PYTHON) tests/tools/test_check_abi.py
abi-dump: check-abi
	@./tools/check_abi.sh dump $(SHLIB) include $(ABI_STORED)

# Who uses which export (tools/api_uses.py): the exports and the public
# header's lines, how many exports the CLI, serve, Python and the installed
# C client each use, and what no client uses; one row per export in
# build/api_uses.tsv. A report, never part of `make test`.
SERVE_OBJ := $(SERVE_C:%.c=$(BUILD)/%.o)
api-report: lib $(CLI_OBJ) $(TEST_OBJ) $(TOOL_OBJ) $(FUZZ_REPLAY_OBJ)
	@$(PYTHON) tools/api_uses.py --shared $(BUILD)/libbumpbake.so --header $(wildcard include/*.h) \
	  --library $(LIB_OBJ) --client cli $(filter-out $(SERVE_OBJ),$(CLI_OBJ)) \
	  --client serve $(SERVE_OBJ) --python python/bumpbake \
	  --source install_client tests/install_client.c \
	  --tests tests $(TEST_OBJ) --tests tools $(TOOL_OBJ) --tests fuzz $(FUZZ_REPLAY_OBJ) \
	  --together program cli serve --both program python --table $(BUILD)/api_uses.tsv

# Criterion suite (unit, property, CLI and golden tests); the CLI tests run
# the binary named by BB_BIN.
check-unit: $(BIN) $(TESTBIN) $(TOOLS)
	@BB_BIN=$(BIN) BB_FIXTURES=fixtures ./tools/run_tests.sh ./$(TESTBIN)

# Installs into a temporary prefix, builds tests/install_client.c with
# pkg-config and runs it; checks the exported symbols and the man page.
check-install: $(BIN) lib
	@MAKE="$(MAKE)" DEBUG=$(DEBUG) BUILD=$(BUILD) ./tools/check_install.sh

# The Python package over the shared library (python/bumpbake), against this
# build's library. A sanitized (DEBUG=1) library needs the sanitizer runtimes
# preloaded into the (uninstrumented) interpreter.
# (Python's own allocations are not freed at exit: no leak report.) BB_BIN is
# the CLI the results are compared with.
PY_PRELOAD := $(if $(filter 1,$(DEBUG)),$(shell $(CC) -print-file-name=libasan.so) $(shell $(CC) -print-file-name=libubsan.so))
PY_SANITIZE := $(if $(PY_PRELOAD),LD_PRELOAD="$(PY_PRELOAD)" ASAN_OPTIONS=detect_leaks=0 UBSAN_OPTIONS=halt_on_error=1:print_stacktrace=1)
check-python: $(BIN) lib
	cd python && BUMPBAKE_LIBRARY=$(abspath $(BUILD)/$(SONAME)) BB_BIN=$(abspath $(BIN)) \
	  BB_CC="$(CC)" PYTHONDONTWRITEBYTECODE=1 $(PY_SANITIZE) \
	  $(PYTHON) -m pytest -q -p no:cacheprovider --durations=10 tests

# `bumpbake serve` in headless Chromium (tests/serve/): the page draws, relights,
# re-bakes on a save by rename and on a control, keeps the last maps after a
# broken save, writes what `bumpbake bake` writes. Skipped, saying why,
# without chromium, chromium-driver or python3-selenium. Screenshots:
# build/serve-test/.
check-serve: $(BIN) lib
	@echo "serve: the page in headless Chromium (tests/serve)"
	@cd tests/serve && BB_BIN=$(abspath $(BIN)) BB_SERVE_SHOTS=$(abspath $(BUILD))/serve-test \
	  PYTHONDONTWRITEBYTECODE=1 $(PYTHON) -m pytest -q -rs -p no:cacheprovider .

# `bumpbake check --html`'s report in headless Chromium (tests/report/): every
# picture loads from the folder and nothing else, the flip and the slider
# work, a failure shows golden, new and difference. Skipped, saying why,
# without chromium, chromium-driver or python3-selenium. Screenshots:
# build/report-test/.
check-report: $(BIN) lib
	@echo "report: check --html's page in headless Chromium (tests/report)"
	@cd tests/report && BB_BIN=$(abspath $(BIN)) BB_REPORT_SHOTS=$(abspath $(BUILD))/report-test \
	  PYTHONPATH=$(abspath python) BUMPBAKE_LIBRARY=$(abspath $(BUILD)/$(SONAME)) \
	  PYTHONDONTWRITEBYTECODE=1 $(PYTHON) -m pytest -q -rs -p no:cacheprovider .

bench: ensure-deps
	@$(MAKE) --no-print-directory all $(BENCH_BINS)
	@./tools/bench.sh $(BIN)

# A golden suite of 200 maps from the fixtures checked three ways
# (tools/bench_check.sh, for docs/performance.md "Golden checks"): the bake
# alone, check --bake (the same bake, writing nothing) and the bake then
# compare once per map; wall, CPU and peak memory, medians of 3 rounds.
bench-check: ensure-deps
	@$(MAKE) --no-print-directory all lib
	@BUMPBAKE_LIBRARY=$(abspath $(BUILD)/$(SONAME)) ./tools/bench_check.sh $(BIN)

# bumpbake on a Dask cluster of this machine (2 worker processes) against
# one process, with cmp of their files (tools/bench_cluster.sh, for
# docs/cluster.md); BENCH_CLUSTER picks sizes and sections, e.g.
# BENCH_CLUSTER="-n 60 -r 2 batch big". Every section by default: a long
# run (about 3 GB of work files in build/bench/cluster), never in `make test`.
bench-cluster: ensure-deps
	@$(MAKE) --no-print-directory all
	@PYTHON=$(PYTHON) ./tools/bench_cluster.sh $(BENCH_CLUSTER) $(BIN)

# The README's pictures (docs/*.png, committed); never part of `make test`.
docs: ensure-deps
	@$(MAKE) --no-print-directory all
	@./tools/docs.sh $(BIN)

goldens: ensure-deps
	@$(MAKE) --no-print-directory all
	@./tools/goldens.sh $(BIN) regenerate

# `make hostile` reruns the reproductions of hostile files (models reading
# outside their directory, FIFOs, huge headers, outputs over inputs, links at
# temporaries, signals in a commit, depfile names, escapes, JSON, address
# space; code from the working directory, outputs that are not regular
# files, a memory cgroup, renders too large; `bumpbake serve` as a server:
# slow clients, 1,000 connections, stalled downloads, concurrent writes,
# malformed HTTP, tools/hostile_serve.py) against the binary, a line per
# case, in about five minutes (tools/hostile_repro.sh; not part of make test:
# its bounds are wall-clock).
hostile: $(BIN)
	@./tools/hostile_repro.sh $(BIN)

# ---- fuzzing (libFuzzer, ASan + UBSan) ---------------------------------------
# `make fuzz FUZZ_SECONDS=N` builds fuzz/fuzz_*.c with clang against a copy of
# the library instrumented for coverage and runs each target N seconds,
# seeded by fuzz/make_seeds.c (the fixtures, and a small valid file of every
# image format OpenImageIO writes here) and from the corpus earlier runs left
# in build/fuzz/corpus, after replaying fuzz/regressions/. A crash, a leak, a
# failed property, an input slower than FUZZ_TIMEOUT seconds, one allocation
# over FUZZ_MALLOC_MB or a process over FUZZ_RSS_MB fails the run
# (fuzz/run.sh); the input lands in build/fuzz/crashes/, and each one found
# becomes a regression input under fuzz/regressions/NAME/, replayed by `make
# test` (tests/cli/test_fuzz.c) and by every `make fuzz`.
# CI runs `make fuzz FUZZ_SECONDS=15`; `make fuzz-long` runs each target
# FUZZ_LONG_SECONDS (1800) seconds, for a machine left to it.
FUZZ_SECONDS ?= 60
FUZZ_LONG_SECONDS ?= 1800
FUZZ_TIMEOUT   ?= 10
FUZZ_MALLOC_MB ?= 1100
FUZZ_RSS_MB    ?= 2560
FUZZ_BUILD   := build/fuzz
FUZZ_SAN     := -fsanitize=address,undefined -fno-sanitize-recover=undefined
FUZZ_OPT     := -O1 -g -fno-omit-frame-pointer $(FUZZ_SAN)
FUZZ_CFLAGS  := -std=c11 -D_POSIX_C_SOURCE=200809L -pthread $(FUZZ_OPT) $(TEST_INCLUDES) -Isrc/cli
FUZZ_CXXFLAGS:= -std=c++17 -pthread $(FUZZ_OPT) -Iinclude -Isrc
FUZZ_TARGETS := $(patsubst fuzz/%.c,$(FUZZ_BUILD)/%,$(wildcard fuzz/fuzz_*.c))
# The targets link the OpenImageIO module's objects with the library's,
# less its calls back through the host table (oiio_host.c): built with
# BB_OIIO_LINKED, src/image/oiio_load.c calls the module's entry itself, and
# it and src/render/text_calls.c define no wrappers (the module's own
# definitions are the program's).
FUZZ_LIB_OBJ := $(LIB_C:%.c=$(FUZZ_BUILD)/%.o) $(LIB_CXX:%.cpp=$(FUZZ_BUILD)/%.o) \
                $(FUZZ_BUILD)/src/image/oiio_host_table.o $(FUZZ_BUILD)/src/render/oiio_entry.o \
                $(MODULE_CXX:%.cpp=$(FUZZ_BUILD)/%.o)
$(FUZZ_BUILD)/src/image/oiio_load.o $(FUZZ_BUILD)/src/render/text_calls.o: FUZZ_CFLAGS += -DBB_OIIO_LINKED
$(FUZZ_BUILD)/src/image/oiio_module_dir.o: FUZZ_CFLAGS += -DBB_OIIO_MODULE_DIR='""'
FUZZ_CLI_OBJ := $(patsubst %.c,$(FUZZ_BUILD)/%.o,$(filter-out src/cli/main.c $(SERVE_C),$(CLI_C)))
# Per target: libFuzzer options beyond time and corpus.
FUZZ_ARGS_fuzz_cli        := -dict=fuzz/cli.dict
FUZZ_ARGS_fuzz_provenance := -max_len=65536
FUZZ_ARGS_fuzz_program    := -dict=fuzz/program.dict
FUZZ_ARGS_fuzz_mesh       := -dict=fuzz/mesh.dict -max_len=16384

# Objects are kept between runs (make would delete them as intermediates).
.SECONDARY: $(FUZZ_LIB_OBJ) $(FUZZ_CLI_OBJ)

$(FUZZ_BUILD)/src/%.o: src/%.c
	@mkdir -p $(@D)
	clang $(FUZZ_CFLAGS) $(PNG_CFLAGS) $(PROBE_CFLAGS) -MMD -MP -fsanitize=fuzzer-no-link -c $< -o $@

$(FUZZ_BUILD)/src/%.o: src/%.cpp
	@mkdir -p $(@D)
	clang++ $(FUZZ_CXXFLAGS) -MMD -MP $(OIIO_CFLAGS) $(ASSIMP_CFLAGS) \
	  $(PNG_CFLAGS) $(PROBE_CFLAGS) -fsanitize=fuzzer-no-link -c $< -o $@

-include $(FUZZ_LIB_OBJ:.o=.d) $(FUZZ_CLI_OBJ:.o=.d)

$(FUZZ_BUILD)/%: fuzz/%.c fuzz/fuzz_common.h $(FUZZ_LIB_OBJ) $(FUZZ_CLI_OBJ)
	@mkdir -p $(@D)
	clang++ -x c $(FUZZ_CFLAGS) -fsanitize=fuzzer -o $@ $< -x none $(FUZZ_CLI_OBJ) \
	  $(FUZZ_LIB_OBJ) $(LDLIBS) $(MODULE_LIBS)

$(FUZZ_BUILD)/seed_formats.o: fuzz/seed_formats.cpp
	@mkdir -p $(@D)
	clang++ $(FUZZ_CXXFLAGS) $(OIIO_CFLAGS) -c $< -o $@

$(FUZZ_BUILD)/make_seeds: fuzz/make_seeds.c $(FUZZ_BUILD)/seed_formats.o $(FUZZ_LIB_OBJ)
	clang++ -x c $(FUZZ_CFLAGS) -fsanitize=fuzzer-no-link -o $@ $< -x none \
	  $(FUZZ_BUILD)/seed_formats.o $(FUZZ_LIB_OBJ) $(LDLIBS) $(MODULE_LIBS)

fuzz: ensure-fuzz-deps
	@$(MAKE) --no-print-directory $(FUZZ_TARGETS) $(FUZZ_BUILD)/make_seeds
	@FUZZ_TIMEOUT=$(FUZZ_TIMEOUT) FUZZ_MALLOC_MB=$(FUZZ_MALLOC_MB) FUZZ_RSS_MB=$(FUZZ_RSS_MB) \
	  ./fuzz/run.sh $(FUZZ_BUILD) $(FUZZ_SECONDS) \
	  $(foreach t,$(FUZZ_TARGETS),"$(notdir $(t)) $(FUZZ_ARGS_$(notdir $(t)))")

fuzz-long:
	@$(MAKE) --no-print-directory fuzz FUZZ_SECONDS=$(FUZZ_LONG_SECONDS)

format:
	clang-format -i include/*.h src/*/*.c src/*/*.h src/*/*.cpp tests/*.h tests/*/*.c tools/*.c fuzz/*.c

clean:
	rm -rf build out
