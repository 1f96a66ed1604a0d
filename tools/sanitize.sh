#!/usr/bin/env bash
# The whole test suite under AddressSanitizer + UndefinedBehaviorSanitizer
# (GCC; issue 13, item 8), GL tests included (headless Mesa llvmpipe).
#   tools/sanitize.sh                 configure build-asan/, build everything, run ctest
#   CTEST_ARGS="-L cpu" tools/sanitize.sh   a subset
# Leak checking stays on. Mesa, LLVM (llvmpipe's JIT), EGL/glvnd and epoxy keep
# allocations alive until exit by design; tools/lsan.supp suppresses leaks
# whose allocation stack passes through those libraries only, so a leak in
# splatfx, the tools or the tests still fails the run.
# UBSan stops at the first report (halt_on_error), so a report fails its test.
set -euo pipefail
cd "$(dirname "$0")/.."
BUILD_DIR="${BUILD_DIR:-build-asan}"
JOBS="${JOBS:-$(nproc)}"
start=$(date +%s)
tools/setup-deps.sh
echo "sanitize: configuring $BUILD_DIR (GCC, SPLATFX_SANITIZE=ON)"
cmake -S . -B "$BUILD_DIR" -DSPLATFX_SANITIZE=ON -DCMAKE_BUILD_TYPE=RelWithDebInfo \
  -DSPLATFX_BUILD_TESTS=ON -DSPLATFX_BUILD_TOOLS=ON -DSPLATFX_BUILD_SAMPLES=ON >/dev/null
echo "sanitize: building with $JOBS jobs"
cmake --build "$BUILD_DIR" -j"$JOBS"
built=$(date +%s)
# Fast unwinding on malloc (the default): with fast_unwind_on_malloc=0 llvmpipe's
# allocations make one GL test take over 5 minutes. The fuzz replays, whose
# suppressions need full stacks, set it for themselves (tests/fuzz/CMakeLists.txt).
export ASAN_OPTIONS="detect_leaks=1:strict_string_checks=1:detect_stack_use_after_return=1"
export LSAN_OPTIONS="suppressions=$PWD/tools/lsan.supp:print_suppressions=0"
export UBSAN_OPTIONS="print_stacktrace=1:halt_on_error=1"
echo "sanitize: running the suite (ASAN_OPTIONS=$ASAN_OPTIONS)"
# Sanitized code runs a few times slower: the per-test timeout is widened to match.
ctest --test-dir "$BUILD_DIR" --output-on-failure -j"$JOBS" --timeout 1800 ${CTEST_ARGS:-}
end=$(date +%s)
echo "sanitize: passed; build $((built - start)) s, tests $((end - built)) s"
