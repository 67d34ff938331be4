#!/usr/bin/env bash
# Builds the libFuzzer targets (tests/fuzz) with clang-16 under ASan + UBSan in build-fuzz and
# fuzzes each for SECONDS (default 60), one process each, from the committed seed corpus.
#   scripts/fuzz.sh [SECONDS] [TARGET...]
# New inputs go to build-fuzz/corpus/<target> (the committed corpus is only read); a crash stops
# that target's run, leaves its reproducer in build-fuzz/crashes/<target>/ and makes the script
# exit 1 after all targets ran. Commit a reproducer to tests/fuzz/crashes/<target>/ with its fix:
# `make test` then replays it (msm_fuzz_replay_<target>). Figures: build-fuzz/fuzz-<target>.log.
# FUZZ_RUNS="target:runs,..." (with FUZZ_SEED, default 1) replaces the time budget of the named
# targets by a fixed number of runs from a fixed seed: the same inputs on every machine, so that
# CI's fuzzing (.ci/run) is repeatable and a local .ci/run predicts it; timed runs stay random.
set -euo pipefail
cd "$(dirname "$0")/.."
seconds=${1:-60}
shift || true
targets=("$@")
[ ${#targets[@]} -gt 0 ] || targets=(scene_json mesh_import image compare)
build=${FUZZ_BUILD_DIR:-build-fuzz}
launcher=()
# ccache where present, its cache inside the build folder unless CCACHE_DIR says otherwise: nothing
# is written under $HOME (a fresh clone's CI run checks that HOME stays empty).
if command -v ccache > /dev/null; then
  export CCACHE_DIR=${CCACHE_DIR:-$PWD/$build/ccache}
  launcher=(-DCMAKE_CXX_COMPILER_LAUNCHER=ccache)
fi
cmake -S . -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo -DCMAKE_CXX_COMPILER=clang++-16 \
  "${launcher[@]}" -DMSM_BUILD_FUZZERS=ON -DMSM_SANITIZE=address,undefined -DMSM_BUILD_TESTS=OFF \
  -DMSM_BUILD_VULKAN=OFF -DMSM_BUILD_TOOLS=OFF -DMSM_BUILD_BENCHMARKS=OFF \
  "-DCMAKE_CXX_FLAGS=-fno-sanitize-recover=all" > "$build.configure.log" 2>&1 || { cat "$build.configure.log"; exit 1; }
cmake --build "$build" -j "${JOBS:-$(nproc)}" --target "${targets[@]/#/msm_fuzz_}"
export UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1
export LSAN_OPTIONS=suppressions=$PWD/tests/lsan.supp
failed=0
for t in "${targets[@]}"; do
  mkdir -p "$build/corpus/$t" "$build/crashes/$t"
  dict=()
  [ -f "tests/fuzz/$t.dict" ] && dict=("-dict=tests/fuzz/$t.dict")
  budget=(-max_total_time="$seconds") corpus=$build/corpus/$t spent="${seconds} s"
  runs=$(tr ',' '\n' <<< "${FUZZ_RUNS:-}" | sed -n "s/^$t:\([0-9]*\)$/\1/p")
  if [ -n "$runs" ]; then # from the committed corpus alone (what earlier runs found changes the inputs)
    budget=(-runs="$runs" -seed="${FUZZ_SEED:-1}") corpus=$build/corpus-fixed/$t spent="seed ${FUZZ_SEED:-1}"
    rm -rf "$corpus" && mkdir -p "$corpus"
  fi
  # -rss_limit_mb: the process (ASan's shadow memory included); -timeout: seconds per input.
  if "$build/tests/fuzz/msm_fuzz_$t" "$corpus" "tests/fuzz/corpus/$t" "${dict[@]}" \
    "${budget[@]}" -timeout=20 -rss_limit_mb=2560 -print_final_stats=1 \
    -artifact_prefix="$build/crashes/$t/" > "$build/fuzz-$t.log" 2>&1; then
    echo "fuzz $t: $(grep -E "^#[0-9]+[[:space:]]+DONE" "$build/fuzz-$t.log" | tail -1) ($(grep -E 'stat::number_of_executed_units' "$build/fuzz-$t.log" | awk '{print $2}') runs, $spent)"
  else
    failed=1
    echo "fuzz $t: FAILED, reproducer in $build/crashes/$t/:"
    grep -E 'ERROR|SUMMARY|fuzz check failed|uncaught|Test unit written' "$build/fuzz-$t.log" | head -8
  fi
done
exit $failed
