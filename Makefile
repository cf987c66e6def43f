# gonio: build, run, test, bench.
#   make [config=release|debug|sanitize]   -> build/$(config)/gonio, linked as build/gonio
#   make run | test | test-slow | test-full | mutants | check-layers | test-farm | bench | bench-peer
#   make bench-denoise | denoiser | docs-images | clean | install [PREFIX=/usr/local] [DESTDIR=]
#   make fuzz (libFuzzer targets, clang, in build/fuzz) | fuzz-run [FUZZ_TIME=60]
# Missing Debian packages are installed when run as root; otherwise the exact apt-get line
# is printed and make stops. What is fetched or installed is the scripts' of deps/ (below).

config ?= release
.DEFAULT_GOAL := all
PREFIX ?= /usr/local
BUILD := build/$(config)

CC ?= cc
CXX ?= c++
ifeq ($(origin CC),default)
CC := gcc
endif
ifeq ($(origin CXX),default)
CXX := g++
endif

PKGS := vulkan glfw3 OpenEXR tinygltf nlohmann_json libpng zlib stb draco libwebp libzstd
# meshoptimizer ships no pkg-config file (Debian 12), SPIRV-Tools only static libraries
# (src/core/spirv_specialise.cpp): linked by name.
LIBS_EXTRA := -lmeshoptimizer -lSPIRV-Tools-opt -lSPIRV-Tools
WARN := -Wall -Wextra -Wshadow -Werror
# The folders of the architecture (docs/architecture.md) are layers, lowest first: core
# (errors, images, Vulkan, plots), scene (glTF, meshes, camera, environment) and accel (the
# BVH) on it, render (the renderer, BRDFs, outputs), cli (the commands); glsl/lib (what the
# host and the kernels share) is below them all, glsl/kernels the program's kernels (their
# SPIR-V headers are the render and cli layers'), tests/kernels the unit tests' own.
# LAYER_x: the folders x may include from besides its own. Each source is compiled with the
# include paths of its layer only, so an upward #include does not compile, and make test
# checks the include graph (tests/tool/layers.sh: also includes that name a path).
LAYERS := core scene accel render cli
LAYER_core :=
LAYER_scene := core
LAYER_accel := core
LAYER_render := core scene accel
LAYER_cli := core scene accel render
SRC_DIRS := $(LAYERS:%=src/%)
layer_includes = $(patsubst %,-Isrc/%,$(1) $(LAYER_$(1))) -Iglsl/lib $(if $(filter render cli,$(1)),-I$(BUILD)/spv)
$(foreach l,$(LAYERS),$(eval $(BUILD)/src/$(l)/%.o: INCLUDES = $(call layer_includes,$(l))))
INCLUDES = $(SRC_DIRS:%=-I%) -Iglsl/lib -I$(BUILD)/spv # tests, tools and fuzz targets: every layer
CPPFLAGS += -MMD -MP
CFLAGS += -std=c11 -D_DEFAULT_SOURCE -pthread $(WARN)
CXXFLAGS += -std=c++14 -pthread -Wall -Wextra -Werror
LDFLAGS += -pthread

ifeq ($(config),release)
OPT := -O2 -g
else ifeq ($(config),debug)
OPT := -O0 -g
else ifeq ($(config),sanitize)
OPT := -O1 -g -fno-omit-frame-pointer -fsanitize=address,undefined -fno-sanitize-recover=undefined
LDFLAGS += -fsanitize=address,undefined
else ifeq ($(config),fuzz)
# make fuzz sets this config with CC=clang: libFuzzer's coverage hooks in every object,
# ASan+UBSan as in sanitize. Not -Werror: clang warns where gcc, the compiler of record, does not.
OPT := -O1 -g -fno-omit-frame-pointer -fsanitize=address,undefined,fuzzer-no-link -fno-sanitize-recover=undefined
LDFLAGS += -fsanitize=address,undefined
WARN := -Wall -Wextra -Wshadow
CXXFLAGS := $(filter-out -Werror,$(CXXFLAGS))
else
$(error config must be release, debug, sanitize or fuzz)
endif
CFLAGS += $(OPT)
CXXFLAGS += $(OPT)

# pkg-config is only asked once the packages are known to be there (see deps below).
PKG_CFLAGS = $(shell pkg-config --cflags $(PKGS) 2>/dev/null)
PKG_LIBS = $(shell pkg-config --libs $(PKGS) 2>/dev/null)

SRC_C := $(filter-out src/cli/main.c,$(wildcard $(SRC_DIRS:%=%/*.c)))
SRC_CXX := $(wildcard $(SRC_DIRS:%=%/*.cpp))
LIB_OBJ := $(SRC_C:%.c=$(BUILD)/%.o) $(SRC_CXX:%.cpp=$(BUILD)/%.o)
MAIN_OBJ := $(BUILD)/src/cli/main.o
TEST_SRC := $(wildcard tests/unit/*.c)
TEST_OBJ := $(TEST_SRC:%.c=$(BUILD)/%.o)
TOOL_OBJ := $(patsubst %.c,$(BUILD)/%.o,$(wildcard tests/tool/*.c)) \
	$(patsubst %.cpp,$(BUILD)/%.o,$(wildcard tests/tool/*.cpp))
SHADERS := $(wildcard glsl/kernels/*.comp tests/kernels/*.comp)
SPV_HDR := $(patsubst %.comp,$(BUILD)/spv/%.h,$(notdir $(SHADERS)))
vpath %.comp glsl/kernels tests/kernels

# ---- dependencies: deps/*.sh ------------------------------------------------------------
# One script a dependency; each does nothing where it is there already and says what it did:
#   deps/debian.sh GROUP   Debian's packages of a group, checked and installed (as root; else
#                          it prints the apt-get line and fails): build (deps), test
#                          (test-deps), fuzz (fuzz-deps), farm (test-farm), peer (bench-peer),
#                          oidn (denoiser)
#   deps/basisu.sh DIR     Basis Universal's sources (below)
#   deps/oidn.sh DIR       Open Image Denoise's libraries (denoiser, below)
#   deps/mitsuba.sh VENV   Mitsuba 3 for bench-peer (tests/peer/run.sh runs it)

# The build's packages (and the pkg-config modules of PKGS); make test's; make fuzz's.
deps:
	@PKGS='$(PKGS)' deps/debian.sh build
test-deps: deps
	@deps/debian.sh test
fuzz-deps: deps
	@deps/debian.sh fuzz

# ---- Basis Universal (KHR_texture_basisu's KTX2 textures) --------------------------------
# No Debian package has it: deps/basisu.sh fetches its C++ sources once into build/basisu/src
# (shared by every config) and writes gonio_basisu.mk, which make includes and re-reads once
# made (BASISU is 1 when the sources are there), and gonio_basisu.h: without them gonio builds
# without KTX2 support and says why. The sources compile into $(BUILD)/basisu: the transcoder
# into every program, the encoder (the tests' writer of KTX2 files, testtool ktx2) into
# testtool only.
BASISU_DIR := build/basisu
ifeq ($(filter clean,$(MAKECMDGOALS)),)
-include $(BASISU_DIR)/gonio_basisu.mk
endif
$(BASISU_DIR)/gonio_basisu.mk: deps/basisu.sh
	@deps/basisu.sh $(BASISU_DIR)
CPPFLAGS += -I$(BASISU_DIR)
BASISU_LIB :=
BASISU_ENC_LIB :=
ifeq ($(BASISU),1)
# KTX2 with Zstandard (Debian's libzstd), neither SSE kernels nor OpenCL (the encoder's
# options, unused by the transcoder), and UASTC's bits read a byte at a time: the vendor's
# x86 default reads 16-bit words at odd addresses, undefined behaviour that UBSan stops on
# (its own switch for this knows clang's UBSan, not GCC's). NDEBUG: the vendor's assert(0)s
# sit on paths that then return an error, which hostile files reach; asserting would turn
# them into aborts.
BASISU_DEFS := -DBASISD_SUPPORT_KTX2=1 -DBASISD_SUPPORT_KTX2_ZSTD=1 -DBASISU_SUPPORT_SSE=0 -DBASISU_SUPPORT_OPENCL=0 \
	-DBASISD_USE_UNALIGNED_WORD_READS=0
# -isystem: the vendor headers' warnings are not the project's (see BASISU_CXXFLAGS).
CPPFLAGS += $(BASISU_DEFS) -isystem $(BASISU_DIR)/src/transcoder -isystem $(BASISU_DIR)/src/encoder
# The project's flags less -Werror and -Wextra, and less the warnings GCC 12 finds in the
# vendor's code (unused values and parameters, memsets of classes, misleading indentation,
# sign comparisons and an enum in a conditional in its miniz copy, a maybe-uninitialized;
# -Wno-unknown-warning-option: clang, make fuzz's compiler, lacks two of these options):
# the code is not ours to change, and they would stop or flood the build. Strict aliasing off
# as the vendor's build has it: its block code type-puns.
BASISU_CXXFLAGS = $(filter-out -Werror -Wextra,$(CXXFLAGS)) -Wno-unused-local-typedefs -Wno-unused-value \
	-Wno-unused-variable -Wno-class-memaccess -Wno-misleading-indentation -Wno-sign-compare \
	-Wno-maybe-uninitialized -Wno-unknown-warning-option -fno-strict-aliasing -DNDEBUG
BASISU_LIB := $(BUILD)/basisu/libbasisu_transcoder.a
BASISU_ENC_LIB := $(BUILD)/basisu/libbasisu_encoder.a
BASISU_ENC_OBJ := $(patsubst $(BASISU_DIR)/src/%.cpp,$(BUILD)/basisu/%.o,$(wildcard $(BASISU_DIR)/src/encoder/*.cpp))
$(BUILD)/basisu/%.o: $(BASISU_DIR)/src/%.cpp | deps
	@mkdir -p $(dir $@)
	$(CXX) $(BASISU_DEFS) $(BASISU_CXXFLAGS) -c -o $@ $<
$(BASISU_LIB): $(BUILD)/basisu/transcoder/basisu_transcoder.o
	ar rcs $@ $^
$(BASISU_ENC_LIB): $(BASISU_ENC_OBJ)
	ar rcs $@ $^
endif

GONIO := $(BUILD)/gonio
UNIT := $(BUILD)/unit_tests
TESTTOOL := $(BUILD)/testtool

.PHONY: all deps test-deps run test test-build test-slow test-full mutants check-layers unit regress \
	bench clean install shaders docs-images fuzz fuzz-deps fuzz-targets fuzz-run fuzz-partials test-farm \
	bench-peer denoiser denoiser-if-possible bench-denoise device-check
all: $(GONIO) build/gonio

build/gonio: $(GONIO)
	@ln -sf $(config)/gonio build/gonio

$(GONIO): $(MAIN_OBJ) $(LIB_OBJ) $(BASISU_LIB) | deps
	$(CXX) $(LDFLAGS) -o $@ $^ $(PKG_LIBS) $(LIBS_EXTRA) -lm

$(UNIT): $(TEST_OBJ) $(LIB_OBJ) $(BASISU_LIB) | deps
	$(CXX) $(LDFLAGS) -o $@ $^ $(PKG_LIBS) $(LIBS_EXTRA) -lm

$(TESTTOOL): $(TOOL_OBJ) $(LIB_OBJ) $(BASISU_ENC_LIB) $(BASISU_LIB) | deps
	$(CXX) $(LDFLAGS) -o $@ $^ $(PKG_LIBS) $(LIBS_EXTRA) -lm

$(BUILD)/%.o: %.c | deps $(SPV_HDR)
	@mkdir -p $(dir $@)
	$(CC) $(INCLUDES) $(CPPFLAGS) $(PKG_CFLAGS) $(CFLAGS) -c -o $@ $<

$(BUILD)/%.o: %.cpp | deps
	@mkdir -p $(dir $@)
	$(CXX) $(INCLUDES) $(CPPFLAGS) $(PKG_CFLAGS) $(CXXFLAGS) -c -o $@ $<

# Shaders: GLSL -> SPIR-V (checked by spirv-val) -> C array in a generated header.
$(BUILD)/spv/%.h: %.comp | deps
	@mkdir -p $(dir $@)
	glslangValidator -V --target-env vulkan1.1 -Iglsl/lib --depfile $(BUILD)/spv/$*.d -o $(BUILD)/spv/$*.spv $< >/dev/null || { glslangValidator -V --target-env vulkan1.1 -Iglsl/lib -o /dev/null $<; exit 1; }
	spirv-val --target-env vulkan1.1 $(BUILD)/spv/$*.spv
	glslangValidator -V --target-env vulkan1.1 -Iglsl/lib --vn spv_$(subst -,_,$*) -o $@ $< >/dev/null
	@sed -i 's|\.spv:|.h:|' $(BUILD)/spv/$*.d
	@# (and, as -MP does for C, an empty rule per included file: a file renamed or removed is no error)
	@sed -n 's|^[^:]*: [^ ]*||p' $(BUILD)/spv/$*.d | tr ' ' '\n' | sed -n 's|^\(..*\)$$|\1:|p' >>$(BUILD)/spv/$*.d
shaders: $(SPV_HDR)

run: all
	@mkdir -p out
	$(GONIO) render scenes/cornell.gltf -o out/cornell.exr --png out/cornell.png

# The tests in two tiers (tests/README.md): make test is the fast one (at most 5 minutes on
# 2 cores), test-slow the rest, test-full both. TESTS=NAME... runs only the jobs whose names
# contain a NAME (unit/brdf, regress/path.sh, ...); TEST_JOBS=N runs N at once (default: the CPUs).
TEST_ENV = GONIO=$(GONIO) UNIT=$(UNIT) TESTTOOL=$(TESTTOOL) CONFIG=$(config)
test-build: check-layers all $(UNIT) $(TESTTOOL) test-deps denoiser-if-possible
test: test-build
	@$(TEST_ENV) tests/run.sh --tier fast $(TESTS)
test-slow: test-build
	@$(TEST_ENV) tests/run.sh --tier slow $(TESTS)
test-full: test-build
	@$(TEST_ENV) tests/run.sh --tier full $(TESTS)
# Deliberate bugs, each built in a scratch copy, that the fast tier must catch (tests/mutants.sh).
mutants: test-build
	@config=$(config) tests/mutants.sh $(TESTS)

# Intel Open Image Denoise 2 for `render --denoise` and `gonio denoise` (src/core/denoise.h,
# docs/denoise.md): its CPU libraries, from a pip wheel (deps/oidn.sh; pip: deps/debian.sh
# oidn), in build/oidn/lib, where gonio loads them at run time. A plain `make` fetches
# nothing. `make test` fetches them where it can (its denoise tests skip, saying so, where
# not); `make denoiser` fails where it cannot.
OIDN_LIB := build/oidn/lib/libOpenImageDenoise.so.2
denoiser: $(OIDN_LIB)
$(OIDN_LIB):
	@deps/debian.sh oidn
	@deps/oidn.sh build/oidn
# The denoiser's figures of docs/performance.md: quality against high-spp references and
# the time to an RMSE with and without it (tests/denoise/quality.sh; about half an hour).
bench-denoise: all $(TESTTOOL) denoiser
	@tests/denoise/quality.sh $(GONIO) $(TESTTOOL) build/denoise
denoiser-if-possible:
	@[ -e $(OIDN_LIB) ] || $(MAKE) --no-print-directory denoiser || \
		echo "gonio: note: no Open Image Denoise; the denoise tests will skip (make denoiser says why)"

# A one-node Slurm cluster on localhost runs farm/slurm-tiles.sh (tests/farm/slurm.sh);
# it skips, saying why, where slurm-wlm and munge cannot be installed (deps/debian.sh farm)
# or started.
test-farm: all $(TESTTOOL)
	@deps/debian.sh farm || true
	@GONIO=$(GONIO) TESTTOOL=$(TESTTOOL) tests/farm/slurm.sh; rc=$$?; [ $$rc = 0 ] || [ $$rc = 77 ]

# The include graph against LAYERS (also run by make test).
check-layers:
	@tests/tool/layers.sh $(foreach l,$(LAYERS),"$(l):$(LAYER_$(l))")

unit: $(UNIT)
	$(UNIT) $(T)

bench: all
	@tests/bench.sh $(GONIO)

# On a machine with a real Vulkan GPU: a short regression subset on it and its benchmarks,
# in one call (tests/device/run.sh; DEVICE=N picks the device).
device-check:
	@tests/device/run.sh

# gonio beside Mitsuba 3 on scenes it did not shape (tests/peer, docs/performance.md):
# Mitsuba, Dr.Jit and a libLLVM for it come by pip into build/peer/venv (deps/mitsuba.sh,
# which tests/peer/run.sh runs), a venv python3-venv makes (deps/debian.sh peer). It skips,
# saying why, where they cannot be installed.
bench-peer: all
	@deps/debian.sh peer || true
	@tests/peer/run.sh $(GONIO) $(PEER_ARGS)

# libFuzzer targets over scene_load, image_read_exr, gonio merge and the WebP and KTX2
# decoders (tests/fuzz); fuzz-run runs each for FUZZ_TIME seconds from seeds of
# $GONIO_ASSETS, EXRs gonio writes and textures the tests' encoders write (tests/fuzz/run.sh).
FUZZ_TARGETS := build/fuzz/fuzz_scene build/fuzz/fuzz_exr build/fuzz/fuzz_merge build/fuzz/fuzz_image
FUZZ_TIME ?= 60
fuzz: fuzz-deps
	@$(MAKE) --no-print-directory config=fuzz CC=clang CXX=clang++ fuzz-targets
fuzz-targets: $(FUZZ_TARGETS)
.SECONDARY: $(FUZZ_TARGETS:build/fuzz/%=$(BUILD)/tests/fuzz/%.o)
build/fuzz/fuzz_%: $(BUILD)/tests/fuzz/fuzz_%.o $(LIB_OBJ) $(BASISU_LIB) | deps
	$(CXX) $(LDFLAGS) -fsanitize=fuzzer -o $@ $^ $(PKG_LIBS) $(LIBS_EXTRA) -lm
fuzz-run: fuzz all $(TESTTOOL) test-deps
	@GONIO=$(GONIO) TESTTOOL=$(TESTTOOL) FUZZ_TIME=$(FUZZ_TIME) tests/fuzz/run.sh $(FUZZ_TARGETS)

# PARTIALS damaged resumable partials and tiles through the sanitizer build's gonio
# (tests/fuzz/partials.sh): no crash, hang, sanitizer report, or NaN written with exit 0.
PARTIALS ?= 2000
fuzz-partials:
	@$(MAKE) --no-print-directory config=sanitize all
	@GONIO=build/sanitize/gonio tests/fuzz/partials.sh $(PARTIALS)

# The figures of docs/ (docs/make-images.sh lists them).
docs-images: all $(TESTTOOL)
	GONIO=$(GONIO) TESTTOOL=$(TESTTOOL) docs/make-images.sh

# The man page is help2man's reading of every command's --help (docs/make-man.sh).
$(BUILD)/gonio.1: $(GONIO) docs/make-man.sh
	GONIO=$(GONIO) docs/make-man.sh $@

install: all $(BUILD)/gonio.1
	install -d $(DESTDIR)$(PREFIX)/bin $(DESTDIR)$(PREFIX)/share/man/man1 \
		$(DESTDIR)$(PREFIX)/share/bash-completion/completions
	install -m 755 $(GONIO) $(DESTDIR)$(PREFIX)/bin/gonio
	install -m 644 $(BUILD)/gonio.1 $(DESTDIR)$(PREFIX)/share/man/man1/gonio.1
	install -m 644 completion/gonio $(DESTDIR)$(PREFIX)/share/bash-completion/completions/gonio

clean:
	rm -rf build out

-include $(LIB_OBJ:.o=.d) $(MAIN_OBJ:.o=.d) $(TEST_OBJ:.o=.d) $(TOOL_OBJ:.o=.d) $(wildcard $(BUILD)/spv/*.d) \
	$(wildcard $(BUILD)/tests/fuzz/*.d)
