#!/usr/bin/env bash
# Installs splatfx's build and test dependencies from Debian's archive.
# Idempotent and fast when everything is present (no apt-get update then).
# Needs root (or sudo) only when something is missing.
#   tools/setup-deps.sh          build and test dependencies
#   tools/setup-deps.sh --fuzz   ... and clang with libFuzzer (tools/fuzz.sh)
#   tools/setup-deps.sh --ogre   ... and OGRE 1.12 (sample 21, tests/ogre: splatfx inside an engine)
#   tools/setup-deps.sh --bake   ... and blender (tools/bake-smoke.py rebakes samples/20-vdb-smoke; not a build dependency)
set -euo pipefail

PACKAGES=(
  build-essential cmake pkg-config git
  libglm-dev libglfw3-dev libepoxy-dev libegl-dev libgl-dev
  libgl1-mesa-dri libegl-mesa0 libegl1
  libopenimageio-dev openimageio-tools python3-imath libopencv-dev nlohmann-json3-dev libgtest-dev
  libassimp-dev libimgui-dev
  glslang-tools libcli11-dev  # every shader variant compiled at build time; the tools' command lines
  gnuplot-nox xvfb xauth
  # OpenVDB import (splatfx::vdb, optional at configure: SPLATFX_VDB). Debian's
  # FindOpenVDB.cmake also needs Boost iostreams; python3-openvdb reads and
  # writes grids from scripts (the bake's provenance checks).
  libopenvdb-dev libboost-iostreams-dev python3-openvdb
)
# tools/fuzz.sh needs clang and its libFuzzer runtime; only it asks for them (--fuzz).
# Sample 21 (splatfx inside OGRE) is optional: configure skips it, with a message, without OGRE (--ogre).
# tools/bake-smoke.py needs Blender with mantaflow (Debian's build has it); only --bake asks for it.
for arg in "$@"; do
  case "$arg" in
    --fuzz) PACKAGES+=(clang libclang-rt-14-dev) ;;
    --ogre) PACKAGES+=(libogre-1.12-dev) ;;
    --bake) PACKAGES+=(blender) ;;
    *) echo "setup-deps: unknown option $arg (expected --fuzz, --ogre, --bake)" >&2; exit 2 ;;
  esac
done

missing=()
for p in "${PACKAGES[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$p")
  fi
done

if [ ${#missing[@]} -eq 0 ]; then
  echo "setup-deps: all ${#PACKAGES[@]} packages present"
  exit 0
fi

SUDO=""
if [ "$(id -u)" -ne 0 ]; then
  if command -v sudo >/dev/null; then SUDO="sudo"; else
    echo "setup-deps: missing packages: ${missing[*]}" >&2
    echo "setup-deps: run as root: apt-get install -y ${missing[*]}" >&2
    exit 1
  fi
fi
echo "setup-deps: installing ${missing[*]}"
export DEBIAN_FRONTEND=noninteractive
$SUDO apt-get update -qq
$SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}"
echo "setup-deps: done"
