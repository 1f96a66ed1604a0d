#!/usr/bin/env bash
# The one instrumented build that tools/sanitize.sh and tools/fuzz.sh share (build-asan/):
# clang with ASan + UBSan on everything (the SDK, tests, tools and samples) and libFuzzer's
# coverage counters (cmake/fuzz.cmake), -O1 -g1 (line tables: every report still names file
# and line). One build serves both: the whole suite runs on it sanitized, and the fuzz
# targets are built in it. Configuring with the same options each time keeps it incremental.
#   tools/instrumented-build.sh [TARGET...]   configure, then build TARGETs (default: all)
# Environment: BUILD_DIR (default build-asan), JOBS (default nproc).
set -euo pipefail
cd "$(dirname "$0")/.."
BUILD_DIR="${BUILD_DIR:-build-asan}"
JOBS="${JOBS:-$(nproc)}"
tools/setup-deps.sh --fuzz
echo "instrumented build: configuring $BUILD_DIR (clang, ASan + UBSan + libFuzzer coverage, -O1 -g1)"
# The GLSL is the plain build's, which compiles every variant: no second check here.
cmake -S . -B "$BUILD_DIR" -DCMAKE_CXX_COMPILER=clang++ -DCMAKE_C_COMPILER=clang -DSPLATFX_FUZZ=ON \
  -DCMAKE_BUILD_TYPE=RelWithDebInfo -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O1 -g1" -DCMAKE_C_FLAGS_RELWITHDEBINFO="-O1 -g1" \
  -DSPLATFX_CHECK_GLSL=OFF -DSPLATFX_BUILD_TESTS=ON -DSPLATFX_BUILD_TOOLS=ON -DSPLATFX_BUILD_SAMPLES=ON >/dev/null
targets=()
for t in "$@"; do targets+=(--target "$t"); done
echo "instrumented build: building ${*:-everything} with $JOBS jobs"
cmake --build "$BUILD_DIR" -j"$JOBS" "${targets[@]}"
