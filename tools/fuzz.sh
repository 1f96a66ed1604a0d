#!/usr/bin/env bash
# Fuzz the SDK's input boundaries with libFuzzer (issue 13, item 7).
#   tools/fuzz.sh              build the fuzz targets in build-asan/ (the instrumented build
#                              tools/sanitize.sh shares: tools/instrumented-build.sh), run
#                              every target
#   FUZZ_SECONDS=600 tools/fuzz.sh        longer runs (default 60 s per target)
#   FUZZ_TARGETS="scene_file image" ...   a subset (default: all)
#   FUZZ_RUNS=20000 tools/fuzz.sh         a fixed number of inputs per target instead of
#                              a time: with the fixed seed the same inputs every run (CI
#                              uses this, so a finding there is a change's, not luck's)
#   FUZZ_RUNS_<t>=N                       that many for target <t> instead of FUZZ_RUNS;
#                              vdb defaults to half of FUZZ_RUNS (its inputs are slow:
#                              two imports of up to 30 KB each, 35-100 a second here)
# Each target starts from its seeds (tests/fuzz/corpus/<t>/) and past crashes
# (tests/fuzz/regressions/<t>/); the working corpus grows in build-asan/corpus/<t>/.
# Any finding (crash, sanitizer report, leak, timeout, out-of-memory) fails the
# script and leaves the input in build-asan/findings/<t>/: commit it under
# tests/fuzz/regressions/<t>/ with the fix, where fuzz_replay_<t> (a normal
# test) replays it from then on.
set -euo pipefail
cd "$(dirname "$0")/.."
BUILD_DIR="${BUILD_DIR:-build-asan}"
export BUILD_DIR
FUZZ_SECONDS="${FUZZ_SECONDS:-60}"
FUZZ_TARGETS="${FUZZ_TARGETS:-scene_file texture_set image mesh vdb}"
targets=()
for t in $FUZZ_TARGETS; do targets+=("fuzz_$t"); done
tools/instrumented-build.sh "${targets[@]}"

# Mesa/assimp/OpenImageIO are not instrumented; leaks inside them are not ours
# (the same suppressions as the sanitizer suite), and leak checks stay on for the rest.
export LSAN_OPTIONS="suppressions=$PWD/tools/lsan.supp:print_suppressions=0"
# fast_unwind_on_malloc=0: those libraries have no frame pointers, and a suppression
# only matches a frame the unwinder reached.
# quarantine_size_mb: freed blocks are held back to catch use-after-free; the default
# (256 MB, overshot in large blocks) counts against the 2 GB limit as if it were live.
export ASAN_OPTIONS="${ASAN_OPTIONS:-detect_leaks=1:fast_unwind_on_malloc=0:allocator_may_return_null=1:quarantine_size_mb=64}"
export UBSAN_OPTIONS="print_stacktrace=1:halt_on_error=1"

failed=()
for t in $FUZZ_TARGETS; do
  corpus="$BUILD_DIR/corpus/$t" findings="$BUILD_DIR/findings/$t" log="$BUILD_DIR/fuzz-$t.log"
  mkdir -p "$corpus" "$findings"
  runs_var="FUZZ_RUNS_$t"
  runs="${!runs_var:-${FUZZ_RUNS:-}}"
  if [ -n "${FUZZ_RUNS:-}" ] && [ -z "${!runs_var:-}" ] && [ "$t" = vdb ]; then runs=$(( (FUZZ_RUNS + 1) / 2 )); fi
  if [ -n "$runs" ]; then budget=(-runs="$runs"); what="$runs inputs"
  else budget=(-max_total_time="$FUZZ_SECONDS"); what="${FUZZ_SECONDS}s"; fi
  echo "fuzz: $t for $what (log $log)"
  # -timeout: one input taking 10 s is a hang; -rss_limit_mb: 2 GB is a memory bomb
  # (every loader has budgets far below it). Seeds and regressions are read-only inputs.
  if "$BUILD_DIR/tests/fuzz/fuzz_$t" "$corpus" "tests/fuzz/corpus/$t" "tests/fuzz/regressions/$t" \
       -seed="${FUZZ_SEED:-1}" "${budget[@]}" -timeout=10 -rss_limit_mb=2048 -malloc_limit_mb=2048 \
       -artifact_prefix="$findings/" -print_final_stats=1 >"$log" 2>&1; then
    cov=$(grep -o 'cov: [0-9]*' "$log" | tail -1 || true)
    runs=$(grep -o 'stat::number_of_executed_units: *[0-9]*' "$log" | grep -o '[0-9]*$' || true)
    echo "fuzz: $t: no finding ($cov, ${runs:-?} inputs)"
  else
    echo "fuzz: $t: FINDING; input(s) in $findings/:" >&2
    ls "$findings" >&2 || true
    grep -m1 -A25 -E 'ERROR: (AddressSanitizer|LeakSanitizer|libFuzzer)|runtime error|SUMMARY' "$log" >&2 || tail -40 "$log" >&2
    failed+=("$t")
  fi
done
if ((${#failed[@]})); then
  echo "fuzz: findings in: ${failed[*]}" >&2
  exit 1
fi
echo "fuzz: all targets ran with no finding (${FUZZ_TARGETS})"
