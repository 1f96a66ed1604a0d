#!/usr/bin/env bash
# The whole test suite under AddressSanitizer + UndefinedBehaviorSanitizer
# (GCC; issue 13, item 8), GL tests included (headless Mesa llvmpipe).
#   tools/sanitize.sh                 configure build-asan/, build everything, run ctest
#   CTEST_ARGS="-L cpu" tools/sanitize.sh   a subset
# Leak checking is on for every test that does not create a GL context (label
# cpu), with tools/lsan.supp suppressing what third-party libraries keep alive
# (OpenImageIO, Mesa, LLVM, EGL/glvnd, epoxy), so a leak in splatfx, the tools
# or the tests fails the run. Tests that create a context (labels gl, package)
# run with ASan and UBSan but without leak checking: llvmpipe's JIT allocates
# from code LSan cannot name (an "<unknown module>" frame), so no suppression
# can match those allocations. Measured on 2026-12-01: with leak checking on,
# every process that made a context reported the same 128 + 112 bytes from
# that frame and nothing else.
#   SPLATFX_SANITIZE_TOOLS=OFF tools/sanitize.sh   the SDK and its tests only (faster)
# UBSan stops at the first report (halt_on_error), so a report fails its test.
set -euo pipefail
cd "$(dirname "$0")/.."
BUILD_DIR="${BUILD_DIR:-build-asan}"
JOBS="${JOBS:-$(nproc)}"
start=$(date +%s)
tools/setup-deps.sh
echo "sanitize: configuring $BUILD_DIR (GCC, SPLATFX_SANITIZE=ON)"
# -O1 -g1 (line tables: every report still names file and line): the sanitized build is the
# longest step of CI, and these flags compile in 0.58 of the time of -O2 -g (measured on
# tests/render/renderer_gl_test.cpp, 10.9 s against 18.9 s). The GLSL is the same as the
# plain build's, which checks every variant: no second check here.
cmake -S . -B "$BUILD_DIR" -DSPLATFX_SANITIZE=ON -DCMAKE_BUILD_TYPE=RelWithDebInfo -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O1 -g1 -DNDEBUG" \
  -DCMAKE_C_FLAGS_RELWITHDEBINFO="-O1 -g1 -DNDEBUG" -DSPLATFX_CHECK_GLSL=OFF -DSPLATFX_BUILD_TESTS=ON -DSPLATFX_BUILD_TOOLS="${SPLATFX_SANITIZE_TOOLS:-ON}" -DSPLATFX_BUILD_SAMPLES="${SPLATFX_SANITIZE_TOOLS:-ON}" >/dev/null
echo "sanitize: building with $JOBS jobs"
cmake --build "$BUILD_DIR" -j"$JOBS"
built=$(date +%s)
# Fast unwinding on malloc (the default): with fast_unwind_on_malloc=0 llvmpipe's
# allocations make one GL test take over 5 minutes. The fuzz replays, whose
# suppressions need full stacks, set it for themselves (tests/fuzz/CMakeLists.txt).
# No strict_string_checks: libxkbcommon (under Qt, texpick's interactive mode) strndup()s
# buffers that are not NUL-terminated, which is legal and which that check reports.
export ASAN_OPTIONS="detect_leaks=1:detect_stack_use_after_return=1"
export LSAN_OPTIONS="suppressions=$PWD/tools/lsan.supp:print_suppressions=0"
export UBSAN_OPTIONS="print_stacktrace=1:halt_on_error=1"
echo "sanitize: the CPU tests, leak checking on (ASAN_OPTIONS=$ASAN_OPTIONS)"
# Sanitized code runs a few times slower: the per-test timeout is widened to match.
ctest --test-dir "$BUILD_DIR" --output-on-failure -j"$JOBS" --timeout 1800 -L cpu ${CTEST_ARGS:-}
echo "sanitize: the tests that create a GL context, leak checking off (llvmpipe's JIT)"
ASAN_OPTIONS="${ASAN_OPTIONS/detect_leaks=1/detect_leaks=0}" \
  ctest --test-dir "$BUILD_DIR" --output-on-failure -j"$JOBS" --timeout 1800 -LE cpu ${CTEST_ARGS:-}
end=$(date +%s)
echo "sanitize: passed; build $((built - start)) s, tests $((end - built)) s"
