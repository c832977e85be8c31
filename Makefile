# Thin wrapper over CMake: `make demo` and `make check` do all set-up on a fresh Debian machine.
BUILD ?= build
JOBS ?= 2
BUILD_TYPE ?= Release
WERROR ?= OFF
DEMO ?= out/demo

.PHONY: all deps configure build demo check sanitize install clean

all: build

deps:
	@.ci/install-deps.sh

configure: deps
	cmake -S . -B $(BUILD) -DCMAKE_BUILD_TYPE=$(BUILD_TYPE) -DRSMOOTH_WERROR=$(WERROR)

build: configure
	cmake --build $(BUILD) -j $(JOBS)

# Makes a noisy shape with sharp edges, smooths it on the default device, writes the input, the
# result and a confidence mesh to $(DEMO), and prints the error before and after and the time.
demo: build
	@mkdir -p $(DEMO)
	$(BUILD)/rsmooth-demo-shape make $(DEMO)/noisy.ply $(DEMO)/truth.ply --noise 0.3
	POCL_CACHE_DIR=$(abspath $(BUILD))/pocl-cache $(BUILD)/rsmooth $(DEMO)/noisy.ply \
	  -o $(DEMO)/smoothed.ply --confidence $(DEMO)/confidence.ply --force
	@echo "error before:" && $(BUILD)/rsmooth-demo-shape compare $(DEMO)/noisy.ply $(DEMO)/truth.ply
	@echo "error after: " && $(BUILD)/rsmooth-demo-shape compare $(DEMO)/smoothed.ply $(DEMO)/truth.ply

check: build
	cd $(BUILD) && ctest --output-on-failure

# The whole suite again under AddressSanitizer and UndefinedBehaviorSanitizer (Debug build).
sanitize: deps
	cmake -S . -B $(BUILD)-sanitize -DCMAKE_BUILD_TYPE=Debug -DRSMOOTH_SANITIZE=ON \
	  -DRSMOOTH_INSTALL=OFF -DRSMOOTH_WERROR=$(WERROR)
	cmake --build $(BUILD)-sanitize -j $(JOBS)
	cd $(BUILD)-sanitize && ctest --output-on-failure

install: build
	cmake --install $(BUILD)

clean:
	rm -rf $(BUILD) $(BUILD)-sanitize out
