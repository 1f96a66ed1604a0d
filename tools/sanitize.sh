#!/usr/bin/env bash
# The whole test suite under AddressSanitizer + UndefinedBehaviorSanitizer (but the label parity, below), GL tests
# included (headless Mesa llvmpipe), on the instrumented build tools/fuzz.sh shares
# (tools/instrumented-build.sh: clang, build-asan/).
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
# UBSan stops at the first report (-fno-sanitize-recover), so a report fails its test.
# (GCC's sanitizers: configure any build dir with -DSPLATFX_SANITIZE=ON.)
set -euo pipefail
cd "$(dirname "$0")/.."
BUILD_DIR="${BUILD_DIR:-build-asan}"
JOBS="${JOBS:-$(nproc)}"
export BUILD_DIR JOBS
start=$(date +%s)
tools/instrumented-build.sh
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
# Not the label parity (the viewer against the render tool on each of the 22 other scene-file
# samples, 64x64): the same two programs run sanitized on the scenes held by viewer_matches_render*
# and viewer_conventions_*, and every scene is drawn sanitized by SamplesGL.EverySampleLoadsAndRendersAFrame;
# the plain build runs them all. Sanitized they took 170 of the suite's 2200 test-seconds (2026-12-03).
ASAN_OPTIONS="${ASAN_OPTIONS/detect_leaks=1/detect_leaks=0}" \
  ctest --test-dir "$BUILD_DIR" --output-on-failure -j"$JOBS" --timeout 1800 -LE "^(cpu|parity)$" ${CTEST_ARGS:-}
end=$(date +%s)
echo "sanitize: passed; build $((built - start)) s, tests $((end - built)) s"
