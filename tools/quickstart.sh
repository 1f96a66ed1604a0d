#!/usr/bin/env bash
# The README's two commands.
#   tools/quickstart.sh demo   install deps, build, render the campfire headless into out/
#   tools/quickstart.sh test   install deps, build, run the whole test suite
# Options come from the environment: BUILD_DIR (default build), JOBS (default nproc).
set -euo pipefail
cd "$(dirname "$0")/.."

BUILD_DIR="${BUILD_DIR:-build}"
JOBS="${JOBS:-$(nproc)}"

# Each step is announced so that a failure says where it happened (tools/clean-room.sh reports
# the last one announced).
step() { echo "quickstart: $*"; }

# demo builds the SDK, its tools and samples (half the build: the tests are the other
# half) with only the build dependencies; test also installs OGRE, so sample 21 and
# tests/ogre (splatfx inside an engine) run instead of being skipped, and builds the tests.
# Both configure with every dependency found, so a missing one fails either.
build() {
  local tests="$1"
  shift
  step "installing dependencies (tools/setup-deps.sh $*)"
  tools/setup-deps.sh "$@"
  step "configuring ($BUILD_DIR, tests $tests)"
  cmake -S . -B "$BUILD_DIR" -DCMAKE_BUILD_TYPE=Release -DSPLATFX_BUILD_TESTS="$tests" -DSPLATFX_BUILD_SAMPLES=ON -DSPLATFX_BUILD_TOOLS=ON >/dev/null
  step "building with $JOBS jobs"
  cmake --build "$BUILD_DIR" -j"$JOBS"
}

case "${1:-}" in
  demo)
    build OFF
    step "rendering the campfire into out/"
    "$BUILD_DIR"/samples/01-campfire/campfire --frames 48 --out out --size 640x480
    echo
    echo "Open out/campfire.gif (the animation), out/campfire_figure1.png (traditional vs textured splats)"
    echo "and out/campfire_NNNN.png (the frames). Windowed: $BUILD_DIR/samples/01-campfire/campfire"
    ;;
  test)
    build ON --ogre
    step "running the test suite"
    ctest --test-dir "$BUILD_DIR" --output-on-failure -j"$JOBS" --timeout 600
    ;;
  *)
    echo "usage: tools/quickstart.sh demo|test" >&2
    exit 2
    ;;
esac
