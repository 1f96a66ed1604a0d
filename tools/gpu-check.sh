#!/usr/bin/env bash
# tools/gpu-check.sh: splatfx on a real GPU driver (issue 26, item 5). Runs the
# GL test suite and `splatfx-bench table1 | fog | clouds | shadows |
# transparency` on an NVIDIA GPU through EGL's device platform
# (SPLATFX_EGL_DEVICE=nvidia, sdk/include/splatfx/context.hpp) and prints one
# table. Two halves, so that the GPU machine needs the NVIDIA driver and
# nothing else:
#
#   tools/gpu-check.sh --bundle-only   # a machine with tools/setup-deps.sh's packages: build, then
#                                      # copy the binaries and the shared libraries they need into
#                                      # BUILD/bundle (bin/, lib/; RPATH $ORIGIN/../lib)
#   tools/gpu-check.sh --run-only      # the GPU machine, in a copy of this checkout holding BUILD/bundle
#   tools/gpu-check.sh                 # both, on one machine
#
# The bundle's binaries are stripped, and it is packed as BUILD/bundle.tar.xz
# (xz -9) for the trip to the GPU machine. With --light it holds only the
# binaries that need no library beyond the driver's, libepoxy, libstdc++ and
# libgcc_s (most GL tests: a few MB packed); the others (splatfx-bench and the
# tests that read or write images through OpenImageIO, whose Debian build
# brings about 250 libraries, ffmpeg, GDAL, OpenCV, Qt 5 and OpenVDB among
# them) are left out and their rows say so (docs/BENCHMARKS.md, "A GPU check").
#
# Options:
#   --build-dir DIR     the build (default build-gpu); its bundle is DIR/bundle
#   --tests A,B         only these GL test binaries (default: every one registered with LABEL gl)
#   --benches A,B       only these benches (default: table1,fog,clouds,shadows,transparency)
#   --light             bundle only what needs no library beyond libepoxy, libstdc++ and libgcc_s
#   --quick             the benches' short settings (--quick / few frames): the script itself, not figures
#   --allow-software    without an NVIDIA device, run on whatever EGL gives (Mesa's llvmpipe), said
#                       in the table's title: for testing this script on a machine without a GPU
#   --budget S          seconds for the whole run half (default 540: under 10 minutes with the probe)
#   --jobs N            build parallelism (default 2)
#
# The bundle leaves out what the driver machine provides (libGL, libEGL, libGLX,
# libOpenGL, libGLdispatch, the NVIDIA and Mesa driver libraries, glibc and the
# dynamic loader): glibc on the GPU machine must be at least the build
# machine's (Debian 12: 2.36). Everything else a binary loads (libepoxy,
# libstdc++, OpenImageIO and its codecs, TBB, ...) is copied.
set -euo pipefail

repo="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
build="build-gpu"
mode="both"
tests=""
benches="table1,fog,clouds,shadows,transparency"
quick=0
light=0
software=0
budget=540
jobs=2

die() { echo "gpu-check: $*" >&2; exit 2; }
while [[ $# -gt 0 ]]; do
  case "$1" in
    --bundle-only) mode="bundle" ;;
    --run-only) mode="run" ;;
    --build-dir) build="${2:?--build-dir expects a folder}"; shift ;;
    --tests) tests="${2:?--tests expects a comma-separated list}"; shift ;;
    --benches) benches="${2:?--benches expects a comma-separated list}"; shift ;;
    --quick) quick=1 ;;
    --light) light=1 ;;
    --allow-software) software=1 ;;
    --budget) budget="${2:?--budget expects seconds}"; shift ;;
    --jobs) jobs="${2:?--jobs expects a number}"; shift ;;
    -h|--help) awk 'NR > 1 && /^#/ { sub(/^# ?/, ""); print; next } NR > 1 { exit }' "${BASH_SOURCE[0]}"; exit 0 ;;
    *) die "unknown option '$1' (see --help)" ;;
  esac
  shift
done
[[ "$budget" =~ ^[0-9]+$ ]] || die "--budget expects whole seconds, got '$budget'"
[[ "$jobs" =~ ^[0-9]+$ && "$jobs" -ge 1 ]] || die "--jobs expects a whole number >= 1, got '$jobs'"
cd "$repo"
[[ "$build" = /* ]] || build="$repo/$build"
bundle="$build/bundle"

# The GL test binaries: every splatfx_add_test(... LABEL gl ...) in tests/.
all_gl_tests() {
  grep -rhoE 'splatfx_add_test\([A-Za-z0-9_]+ LABEL gl' tests --include=CMakeLists.txt | sed -E 's/splatfx_add_test\(([A-Za-z0-9_]+).*/\1/' | sort
}
if [[ -z "$tests" ]]; then tests="$(all_gl_tests | paste -sd, -)"; fi
IFS=, read -r -a test_list <<<"$tests"
IFS=, read -r -a bench_list <<<"$benches"
for b in "${bench_list[@]}"; do
  case "$b" in table1|fog|clouds|shadows|transparency) ;; *) die "--benches: '$b' is not one of table1, fog, clouds, shadows, transparency" ;; esac
done

# Libraries the driver machine provides (or that must come from it): never copied.
provided='^(libGL|libEGL|libGLX|libGLESv[12]|libOpenGL|libGLdispatch|libEGL_mesa|libEGL_nvidia|libGLX_mesa|libGLX_nvidia|libnvidia-|libcuda|libgbm|libglapi|libc|libm|libdl|libpthread|librt|libutil|libresolv|ld-linux)[.-]'

bundle_step() {
  command -v cmake >/dev/null || die "cmake not found: the bundle half needs the build machine's packages (tools/setup-deps.sh)"
  command -v ldd >/dev/null || die "ldd not found"
  echo "gpu-check: configuring $build (Release, RPATH \$ORIGIN/../lib)"
  mkdir -p "$build"
  # The install RPATH, linked in as it is (a build RPATH is padded with empty entries, which
  # the loader reads as the current folder), as DT_RPATH (not RUNPATH): the loader then
  # searches it for the libraries' own dependencies too, which Debian's libraries look up
  # without a path of their own. The binaries then find no build-tree shared library
  # (splatfx_c): the bundle needs none.
  local launcher=()
  if command -v ccache >/dev/null; then launcher=(-DCMAKE_CXX_COMPILER_LAUNCHER=ccache -DCMAKE_C_COMPILER_LAUNCHER=ccache); fi
  cmake -S "$repo" -B "$build" -DCMAKE_BUILD_TYPE=Release -DSPLATFX_BUILD_TESTS=ON -DSPLATFX_BUILD_TOOLS=ON "${launcher[@]}" \
    -DCMAKE_BUILD_WITH_INSTALL_RPATH=ON '-DCMAKE_INSTALL_RPATH=$ORIGIN/../lib' -DCMAKE_EXE_LINKER_FLAGS=-Wl,--disable-new-dtags >"$build/gpu-check-configure.log" 2>&1 ||
    { tail -30 "$build/gpu-check-configure.log"; die "configure failed (log: $build/gpu-check-configure.log)"; }
  echo "gpu-check: building splatfx-bench, egl_probe and ${#test_list[@]} GL test binaries"
  cmake --build "$build" -j "$jobs" --target splatfx-bench egl_probe "${test_list[@]}" >"$build/gpu-check-build.log" 2>&1 ||
    { tail -30 "$build/gpu-check-build.log"; die "build failed (log: $build/gpu-check-build.log)"; }
  rm -rf "$bundle" "$build/bundle.tar.xz"
  mkdir -p "$bundle/bin" "$bundle/lib"
  local exe extra left_out=()
  for t in splatfx-bench egl_probe "${test_list[@]}"; do
    exe="$(find "$build" -path "$bundle" -prune -o -type f -name "$t" -perm -u+x -print | head -n 1)"
    [[ -n "$exe" ]] || die "built $t but cannot find it under $build"
    if [[ $light -eq 1 ]]; then
      # Every library it loads that the driver machine does not provide, less the light three.
      extra="$(ldd "$exe" | awk '$2 == "=>" {print $1}' | grep -Ev "$provided" | grep -Ev '^(libepoxy\.so|libstdc\+\+\.so|libgcc_s\.so)' || true)"
      if [[ -n "$extra" ]]; then left_out+=("$t"); continue; fi
    fi
    cp "$exe" "$bundle/bin/"
  done
  # Symbols are of no use on the GPU machine (a crash there is reported by its log).
  strip --strip-unneeded "$bundle"/bin/*
  if [[ ${#left_out[@]} -gt 0 ]]; then
    echo "gpu-check: --light: left out (they need more libraries): ${left_out[*]}"
    printf '%s\n' "${left_out[@]}" >"$bundle/left-out.txt"
  fi
  # Every shared library the binaries load, found by ldd here, less the provided ones.
  local copied=0 lib name
  while read -r lib; do
    name="$(basename "$lib")"
    if [[ "$name" =~ $provided ]]; then continue; fi
    if [[ ! -e "$bundle/lib/$name" ]]; then cp -L "$lib" "$bundle/lib/$name"; copied=$((copied + 1)); fi
  done < <(for f in "$bundle"/bin/*; do ldd "$f"; done | awk '$2 == "=>" && $3 ~ /^\// {print $3}' | sort -u)
  local missing
  missing="$(for f in "$bundle"/bin/*; do ldd "$f"; done | grep 'not found' | sort -u || true)"
  [[ -z "$missing" ]] || die "libraries not found while bundling:\n$missing"
  local rpath_of=splatfx-bench
  [[ -e "$bundle/bin/$rpath_of" ]] || rpath_of=egl_probe
  if ! readelf -d "$bundle/bin/$rpath_of" | grep -q 'RPATH.*\[\$ORIGIN/../lib\]'; then
    die "$rpath_of's RPATH is not exactly \$ORIGIN/../lib (readelf -d): the bundle would not find its libraries"
  fi
  XZ_OPT="-9 -T$jobs" tar -C "$build" -cJf "$build/bundle.tar.xz" bundle
  echo "gpu-check: bundle $bundle: $(ls "$bundle/bin" | wc -l) binaries, $copied libraries, $(du -sh "$bundle" | cut -f1); packed $build/bundle.tar.xz: $(du -h "$build/bundle.tar.xz" | cut -f1)"
}

# ---- the run half: nothing here needs a Debian package beyond bash, coreutils and the driver ----
rows=()
row() { rows+=("| $1 | $2 | $3 | $4 |"); }
start_s=$SECONDS
left() { echo $((budget - (SECONDS - start_s))); }

run_step() {
  [[ -d "$bundle/bin" ]] || die "no bundle in $bundle: run tools/gpu-check.sh --bundle-only on the build machine first"
  local logs="$build/gpu-check-logs"
  rm -rf "$logs"
  mkdir -p "$logs" "$build/gpu-check-output"
  export SPLATFX_SOURCE_DIR="$repo" SPLATFX_TEST_OUTPUT_DIR="$build/gpu-check-output" SPLATFX_EGL_PROBE="$bundle/bin/egl_probe"
  local bench="$bundle/bin/splatfx-bench" device where
  # The device table of splatfx-bench, or (a --light bundle) egl_probe's one line.
  probe() { if [[ -x "$bench" ]]; then "$bench" device 2>&1; else "$bundle/bin/egl_probe" 2>&1; fi; }
  export SPLATFX_EGL_DEVICE=nvidia
  if device="$(probe)"; then
    where="NVIDIA GPU through EGL's device platform (SPLATFX_EGL_DEVICE=nvidia)"
  else
    device="${device#device: }"
    echo "gpu-check: no NVIDIA device: ${device#error: }" >&2
    if [[ $software -eq 0 ]]; then
      echo "gpu-check: nothing run (pass --allow-software to test this script on Mesa's llvmpipe instead)" >&2
      exit 3
    fi
    unset SPLATFX_EGL_DEVICE
    device="$(probe)" || die "no OpenGL 4.5 context at all: ${device#device: }"
    where="NOT A GPU: --allow-software, EGL's default choice"
  fi
  local renderer
  renderer="$(sed -n -e 's/^| GL_RENDERER | \(.*\) |$/\1/p' -e 's/^ok: \(.*\) | vendor .*/\1/p' <<<"$device")"
  echo "$device" >"$logs/device.md"

  local t out rc s passed failed skipped limit
  for t in "${test_list[@]}"; do
    limit=$(left)
    if [[ ! -x "$bundle/bin/$t" ]]; then row "test $t" "not bundled" "-" "needs libraries beyond a --light bundle's"; continue; fi
    if [[ $limit -le 5 ]]; then row "test $t" "not run" "-" "the ${budget} s budget is spent"; continue; fi
    [[ $limit -gt 240 ]] && limit=240
    s=$SECONDS
    rc=0
    timeout "$limit" "$bundle/bin/$t" --gtest_brief=1 >"$logs/$t.log" 2>&1 || rc=$?
    out="$(cat "$logs/$t.log")"
    passed="$(sed -n 's/^\[  PASSED  \] \([0-9]*\) test.*/\1/p' <<<"$out" | tail -n 1)"
    failed="$(grep -c '^\[  FAILED  \] [A-Za-z]' <<<"$out" || true)" # one line per failed test (--gtest_brief prints no count)
    skipped="$(sed -n 's/^\[  SKIPPED \] \([0-9]*\) test.*/\1/p' <<<"$out" | tail -n 1)"
    if [[ $rc -eq 124 ]]; then
      row "test $t" "TIMEOUT" "$((SECONDS - s))" "killed after ${limit} s (log: gpu-check-logs/$t.log)"
    elif [[ $rc -eq 0 ]]; then
      row "test $t" "ok" "$((SECONDS - s))" "${passed:-0} passed, ${skipped:-0} skipped"
    else
      row "test $t" "FAIL ($rc)" "$((SECONDS - s))" "${passed:-0} passed, ${failed:-0} failed, ${skipped:-0} skipped (log: gpu-check-logs/$t.log)"
    fi
  done

  local b args
  for b in "${bench_list[@]}"; do
    limit=$(left)
    if [[ ! -x "$bench" ]]; then row "bench $b" "not bundled" "-" "splatfx-bench needs OpenImageIO's libraries: not in a --light bundle"; continue; fi
    if [[ $limit -le 5 ]]; then row "bench $b" "not run" "-" "the ${budget} s budget is spent"; continue; fi
    [[ $limit -gt 180 ]] && limit=180
    args=()
    if [[ $quick -eq 1 ]]; then
      case "$b" in
        table1|fog|shadows|transparency) args=(--quick) ;;
        clouds) args=(--frames 2 --pop-frames 4 --fog-frames 2 --streak-frames 2) ;;
      esac
    fi
    s=$SECONDS
    rc=0
    timeout "$limit" "$bench" "$b" "${args[@]}" >"$logs/bench-$b.md" 2>&1 || rc=$?
    if [[ $rc -eq 124 ]]; then
      row "bench $b ${args[*]}" "TIMEOUT" "$((SECONDS - s))" "killed after ${limit} s (partial: gpu-check-logs/bench-$b.md)"
    elif [[ $rc -eq 0 ]]; then
      row "bench $b ${args[*]}" "ok" "$((SECONDS - s))" "$(wc -l <"$logs/bench-$b.md") lines of tables in gpu-check-logs/bench-$b.md"
    else
      row "bench $b ${args[*]}" "FAIL ($rc)" "$((SECONDS - s))" "$(tail -n 1 "$logs/bench-$b.md" | tr '|' '/') (gpu-check-logs/bench-$b.md)"
    fi
  done

  echo
  echo "## gpu-check on ${renderer:-unknown} — $where"
  echo
  echo "| step | result | s | detail |"
  echo "|---|---|---|---|"
  printf '%s\n' "${rows[@]}"
  echo
  echo "Device: $logs/device.md; every step's output: $logs/. Run half: $((SECONDS - start_s)) s of the ${budget} s budget."
  local bad=0 r
  for r in "${rows[@]}"; do [[ "$r" == *"| FAIL"* || "$r" == *"| TIMEOUT"* ]] && bad=1; done
  return $bad
}

case "$mode" in
  bundle) bundle_step ;;
  run) run_step ;;
  both) bundle_step; run_step ;;
esac
