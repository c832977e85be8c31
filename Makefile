# Thin wrapper over CMake: `make demo` and `make check` do all set-up on a fresh Debian machine.
BUILD ?= build
JOBS ?= 2
BUILD_TYPE ?= Release
WERROR ?= OFF
DEMO ?= out/demo
FUZZ_SECONDS ?= 60
FUZZ_BUILD ?= $(BUILD)-fuzz
FUZZERS = obj ply off stl auto
DIST ?= dist
# The Blender add-on's wheels (blender/README.md): the manylinux wheels `make wheels` leaves in
# $(DIST), or any rsmooth wheels named here (WHEELS="a.whl b.whl"); found when the recipe runs
WHEELS ?= $(wildcard $(DIST)/rsmooth-*-manylinux*.whl)
ADDON_VERSION := $(shell sed -n 's/^\#define RSMOOTH_VERSION_[A-Z]* //p' lib/include/rsmooth.h | paste -sd.)
ADDON_ZIP ?= $(DIST)/rsmooth_blender-$(ADDON_VERSION).zip

.PHONY: all deps configure build demo experiments check train train-env wheels wheels-check python-check sanitize fuzz \
        docs install clean blender-addon blender-check format format-check

all: build

deps:
	@.ci/install-deps.sh

configure: deps
	cmake -S . -B $(BUILD) -DCMAKE_BUILD_TYPE=$(BUILD_TYPE) -DRSMOOTH_WERROR=$(WERROR)

build: configure
	cmake --build $(BUILD) -j $(JOBS)

# Makes a noisy shape with sharp edges, smooths it on the default device, writes the input, the
# result and a confidence mesh to $(DEMO), and prints the error before and after and the time.
# The first run on a machine compiles the kernels (PoCL: about 10 s, most of it inside the
# first filter call), so the demo runs the filter once quietly first: the filter time it prints
# is then a warm run's, as every later run is.
demo: build
	@mkdir -p $(DEMO)
	$(BUILD)/rsmooth-demo-shape make $(DEMO)/noisy.ply $(DEMO)/truth.ply --noise 0.3
	@echo "warming the kernel caches (the first run on a machine compiles the kernels: seconds)"
	@POCL_CACHE_DIR=$(abspath $(BUILD))/pocl-cache $(BUILD)/rsmooth $(DEMO)/noisy.ply \
	  -o $(DEMO)/smoothed.ply --confidence $(DEMO)/confidence.ply --force -q
	POCL_CACHE_DIR=$(abspath $(BUILD))/pocl-cache $(BUILD)/rsmooth $(DEMO)/noisy.ply \
	  -o $(DEMO)/smoothed.ply --confidence $(DEMO)/confidence.ply --force
	@echo "error before:" && $(BUILD)/rsmooth-demo-shape compare $(DEMO)/noisy.ply $(DEMO)/truth.ply
	@echo "error after: " && $(BUILD)/rsmooth-demo-shape compare $(DEMO)/smoothed.ply $(DEMO)/truth.ply

# Regenerates docs/experiments.md and docs/img/ from the benchmark meshes beside the checkout
# (../shared/data; about 20 minutes on 2 cores; reruns reuse out/experiments/cache.json).
experiments: build
	@.ci/install-deps.sh experiments
	POCL_CACHE_DIR=$(abspath $(BUILD))/pocl-cache python3 scripts/experiments.py

# The learned normals' model from ../shared/data (train/README.md; about an hour on 2 cores,
# resumable): out/train/model.rsnn and its left-out figures. It does not replace the shipped
# models/learned-normals.rsnn.
train: build
	train/run.sh $(BUILD) out/train

# The part of the training environment the test learned_training needs (JAX and numpy, pinned as
# in train/requirements.txt), in $(BUILD)/train-venv.
train-env:
	@.ci/install-deps.sh python
	@test -x $(BUILD)/train-venv/bin/python || python3 -m venv $(BUILD)/train-venv
	$(BUILD)/train-venv/bin/pip install -q $$(grep -E '^(numpy|jax|jaxlib|ml_dtypes|opt_einsum)==' train/requirements.txt)

# ctest -j $(JOBS): tests that use both cores themselves ask for them (tests/CMakeLists.txt).
# Then how many tests passed with checks skipped because their data is absent (the benchmark
# meshes of ../shared...), which ctest's "100% tests passed" does not show (scripts/skipped-checks.sh).
check: build
	cd $(BUILD) && ctest --output-on-failure -j $(JOBS); status=$$?; \
	  $(CURDIR)/scripts/skipped-checks.sh Testing/Temporary/LastTest.log || true; exit $$status

# The Python package (pyproject.toml, python/) as users get it: `make wheels` builds the manylinux
# wheels (cp311-abi3, cp39, cp310: each where that Python is installed) with Zig's C compiler for
# glibc 2.17, tags them with auditwheel and makes the sdist, all in $(DIST) (.ci/wheels.sh; its
# tools in $(BUILD)-wheels/venv from PyPI). `make wheels-check` installs each wheel into a fresh
# venv of every Python here it accepts and runs the pytest suite tests/python/ against the command
# just built, from outside the checkout, then installs the sdist (.ci/wheels-check.sh, in
# $(BUILD)-python). `make python-check` is both; PyPI must be reachable.
export WHEELS_WORK = $(BUILD)-wheels
wheels: deps
	@.ci/install-deps.sh python
	.ci/wheels.sh $(DIST) $(WERROR)

wheels-check: build wheels
	.ci/wheels-check.sh $(DIST) $(BUILD) $(WERROR)

python-check: wheels-check

# The whole suite again under AddressSanitizer and UndefinedBehaviorSanitizer (Debug build), on
# smaller cases of the same checks (RSMOOTH_TEST_SMALL), with the kernels PoCL compiled for
# $(BUILD) (its caches: RSMOOTH_TEST_CACHE_DIR in tests/CMakeLists.txt).
sanitize: deps
	mkdir -p $(BUILD)
	cmake -S . -B $(BUILD)-sanitize -DCMAKE_BUILD_TYPE=Debug -DRSMOOTH_SANITIZE=ON \
	  -DRSMOOTH_INSTALL=OFF -DRSMOOTH_WERROR=$(WERROR) -DRSMOOTH_TEST_CACHE_DIR=$(abspath $(BUILD))
	cmake --build $(BUILD)-sanitize -j $(JOBS)
	cd $(BUILD)-sanitize && ctest --output-on-failure -j $(JOBS); status=$$?; \
	  $(CURDIR)/scripts/skipped-checks.sh Testing/Temporary/LastTest.log || true; exit $$status

# Each reader, and automatic detection (fuzz_auto), under libFuzzer with ASan and UBSan for
# $(FUZZ_SECONDS) s each, from the seed corpus make_seed_corpus writes (each run on a copy); each
# target writes what it read back and compares the values. All run, and any crash, leak, sanitizer
# report or changed value fails the target. Inputs that fail are left in $(FUZZ_BUILD)/artifacts.
fuzz:
	@.ci/install-deps.sh fuzz
	CC=clang cmake -S . -B $(FUZZ_BUILD) -DCMAKE_BUILD_TYPE=RelWithDebInfo -DRSMOOTH_SANITIZE=ON \
	  -DRSMOOTH_BUILD_FUZZERS=ON -DRSMOOTH_INSTALL=OFF -DRSMOOTH_BUILD_TESTS=OFF \
	  -DRSMOOTH_BUILD_TOOLS=OFF -DRSMOOTH_WERROR=$(WERROR)
	cmake --build $(FUZZ_BUILD) -j $(JOBS)
	rm -rf $(FUZZ_BUILD)/corpus $(FUZZ_BUILD)/grown
	mkdir -p $(FUZZ_BUILD)/artifacts
	$(FUZZ_BUILD)/fuzz/make_seed_corpus $(FUZZ_BUILD)/corpus
	failed=""; for f in $(FUZZERS); do \
	  mkdir -p $(FUZZ_BUILD)/grown/$$f && cp $(FUZZ_BUILD)/corpus/$$f/* $(FUZZ_BUILD)/grown/$$f/ \
	    || exit 1; \
	  echo "fuzz_$$f: $(FUZZ_SECONDS) s"; \
	  $(FUZZ_BUILD)/fuzz/fuzz_$$f -max_total_time=$(FUZZ_SECONDS) -rss_limit_mb=2048 \
	    -max_len=65536 -print_final_stats=1 -artifact_prefix=$(FUZZ_BUILD)/artifacts/$$f- \
	    $(FUZZ_BUILD)/grown/$$f || failed="$$failed fuzz_$$f"; \
	done; \
	if [ -n "$$failed" ]; then echo "fuzzing failed:$$failed (inputs in $(FUZZ_BUILD)/artifacts)"; \
	  exit 1; fi

# The API reference in $(BUILD)/docs: the C headers through Doxygen (docs/api/Doxyfile: every public
# name documented, any warning an error) into html/, and the Python module's docstrings through pdoc
# into python/, from the package `make python-check` installed in $(BUILD)-python/venv (pdoc is
# added there from PyPI; without that venv only the C part is built, and this says so).
docs:
	@.ci/install-deps.sh
	rm -rf $(BUILD)/docs && mkdir -p $(BUILD)/docs
	RSMOOTH_DOCS_OUT=$(abspath $(BUILD))/docs doxygen docs/api/Doxyfile
	@echo "C API reference: $(BUILD)/docs/html/index.html"
	@if $(BUILD)-python/venv/bin/python -c "import rsmooth" 2>/dev/null; then \
	  $(BUILD)-python/venv/bin/python -c "import pdoc" 2>/dev/null \
	    || $(BUILD)-python/venv/bin/pip install -q pdoc || exit 1; \
	  $(BUILD)-python/venv/bin/python -m pdoc rsmooth -o $(BUILD)/docs/python || exit 1; \
	  echo "Python reference: $(BUILD)/docs/python/index.html"; \
	else echo "no $(BUILD)-python/venv with rsmooth (make python-check): Python reference not built"; fi

# The Blender add-on (blender/): $(ADDON_ZIP), the rsmooth package unpacked from $(WHEELS) inside
# it (blender/make_addon.py prints its size and what each extension module needs of glibc).
blender-addon:
	@test -n "$(strip $(WHEELS))" || { echo "blender-addon: no wheels: dist/ has no" \
	  "rsmooth-*-manylinux*.whl (make wheels), or name some: make blender-addon WHEELS=..." >&2; \
	  exit 1; }
	python3 blender/make_addon.py $(WHEELS) -o $(ADDON_ZIP)

# The add-on in headless Blender (tests/blender/run.sh): installed from $(ADDON_ZIP), it must give
# the command's result on the same file (paper and best, PoCL's CPU device), and undo it. Needs
# Blender on PATH (`.ci/install-deps.sh blender`; BLENDER=PATH for another), else it says it
# skipped. About 5 s with the kernels in $(BUILD)/pocl-cache, 12 s without.
blender-check: build blender-addon
	tests/blender/run.sh $(BUILD) $(ADDON_ZIP)

# Every tracked C, header and OpenCL C file through clang-format with the repository's
# .clang-format: `make format` rewrites them in place, `make format-check` (in CI) names each file
# that differs and fails.
FORMAT_FILES = git ls-files '*.c' '*.h' '*.cl'
# one version: another clang-format may lay the same code out differently
CLANG_FORMAT ?= clang-format-14
format:
	@.ci/install-deps.sh format
	$(FORMAT_FILES) | xargs $(CLANG_FORMAT) -i

format-check:
	@.ci/install-deps.sh format
	@bad=$$($(FORMAT_FILES) | xargs $(CLANG_FORMAT) --dry-run 2>&1 | sed -n 's/^\([^:]*\):[0-9]*:[0-9]*: warning:.*/\1/p' | sort -u); \
	if [ -n "$$bad" ]; then echo "not formatted (make format):"; echo "$$bad"; exit 1; fi; \
	echo "format-check: $$($(FORMAT_FILES) | wc -l) files formatted"

# `make install PREFIX=/opt/rsmooth` installs the command (bin/rsmooth), the libraries, headers,
# CMake package and pkg-config files under PREFIX (without PREFIX: CMAKE_INSTALL_PREFIX, by
# default /usr/local). The installed command finds its libraries relative to itself.
install: build
	cmake --install $(BUILD)$(if $(PREFIX), --prefix $(abspath $(PREFIX)))

clean:
	rm -rf $(BUILD) $(BUILD)-sanitize $(BUILD)-python $(BUILD)-wheels $(FUZZ_BUILD) out $(DIST)
