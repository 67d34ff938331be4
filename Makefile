# Two entry points for a fresh Debian 12 machine: `make demo` and `make test`.
BUILD_DIR ?= build
BUILD_TYPE ?= RelWithDebInfo
JOBS ?= $(shell nproc)
CMAKE_FLAGS ?=

.PHONY: all deps configure build demo test sanitize sanitize-cpu fuzz bench clean

all: build

deps:
	@scripts/bootstrap.sh

configure: deps
	@cmake -S . -B $(BUILD_DIR) -G Ninja -DCMAKE_BUILD_TYPE=$(BUILD_TYPE) $(CMAKE_FLAGS) > $(BUILD_DIR).configure.log 2>&1 || (cat $(BUILD_DIR).configure.log; exit 1)

build: configure
	@cmake --build $(BUILD_DIR) -j $(JOBS)

demo: build
	@$(BUILD_DIR)/tools/msm/msm demo

test: build
	@cd $(BUILD_DIR) && ctest --output-on-failure -j $(JOBS) --timeout 900

# The suite again under AddressSanitizer and UndefinedBehaviorSanitizer, halting on the first
# report (CI runs it after `make test`). Leak checking is off: the Khronos validation layer leaks.
SANITIZE_DIR ?= build-sanitize
sanitize: deps
	@cmake -S . -B $(SANITIZE_DIR) -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo -DMSM_SANITIZE=address,undefined \
		-DMSM_BUILD_BENCHMARKS=OFF "-DCMAKE_CXX_FLAGS=-fno-sanitize-recover=all" $(CMAKE_FLAGS) \
		> $(SANITIZE_DIR).configure.log 2>&1 || (cat $(SANITIZE_DIR).configure.log; exit 1)
	@cmake --build $(SANITIZE_DIR) -j $(JOBS)
	@cd $(SANITIZE_DIR) && ASAN_OPTIONS=detect_leaks=0:abort_on_error=1 UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1 \
		ctest --output-on-failure -j $(JOBS) --timeout 1800

# The CPU part of the suite under ASan + UBSan, as CI runs it (`.ci/run`; `make sanitize` is all of
# it, 20 min more): a build without Vulkan, so math, oracles, scene and import, images, the ray
# tracer, evaluate and the CLI's non-rendering commands (their error paths included) with the
# fuzz corpora and reproducers; the renderer's lavapipe tests are left out. Leak checking is off
# as in `make sanitize` (not yet tried over Open MPI and Embree); the fuzz runs check leaks.
SANITIZE_CPU_DIR ?= build-sanitize-cpu
SANITIZE_CPU_CTEST_ARGS ?=
sanitize-cpu: deps
	@cmake -S . -B $(SANITIZE_CPU_DIR) -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo -DMSM_SANITIZE=address,undefined \
		-DMSM_BUILD_VULKAN=OFF -DMSM_BUILD_BENCHMARKS=OFF "-DCMAKE_CXX_FLAGS=-fno-sanitize-recover=all" $(CMAKE_FLAGS) \
		> $(SANITIZE_CPU_DIR).configure.log 2>&1 || (cat $(SANITIZE_CPU_DIR).configure.log; exit 1)
	@cmake --build $(SANITIZE_CPU_DIR) -j $(JOBS)
	@cd $(SANITIZE_CPU_DIR) && ASAN_OPTIONS=detect_leaks=0:abort_on_error=1 \
		UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1 ctest --output-on-failure -j $(JOBS) --timeout 1800 $(SANITIZE_CPU_CTEST_ARGS)

# The libFuzzer targets (tests/fuzz; clang-16, ASan + UBSan, in build-fuzz), FUZZ_SECONDS each.
FUZZ_SECONDS ?= 60
fuzz: deps
	@scripts/fuzz.sh $(FUZZ_SECONDS)

bench: build
	@$(BUILD_DIR)/bench/msm_bench_cpu --benchmark_min_time=0.2

clean:
	rm -rf $(BUILD_DIR) $(BUILD_DIR).configure.log $(SANITIZE_DIR) $(SANITIZE_DIR).configure.log $(SANITIZE_CPU_DIR) $(SANITIZE_CPU_DIR).configure.log build-fuzz build-fuzz.configure.log
