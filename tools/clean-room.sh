#!/usr/bin/env bash
# The README's commands on a machine that has nothing but Debian 12 and what the project installs.
#
#   tools/clean-room.sh           clean clone of HEAD -> minimal Debian 12 root -> tools/quickstart.sh demo
#   tools/clean-room.sh --test    the same, then tools/quickstart.sh test in that root
#
# Why: CI runs on the machine that submitted the change, where anything installed by hand is
# still present, so a missing package in tools/setup-deps.sh can pass CI and fail for a newcomer.
# This builds a fresh minbase root with mmdebstrap (it reuses this machine's apt sources, so no
# mirror is named here), copies in a clean clone of the committed tree (not the working tree:
# an uncommitted file would fool it the same way), and runs the README's commands there as root.
# Nothing is cached between runs; the root lives in a temporary folder removed on exit.
#
# Needs: root, mmdebstrap (installed here if missing), git. Environment: KEEP_ROOT=1 keeps the
# root for inspection, JOBS (default nproc) is passed to the build.
set -euo pipefail
cd "$(dirname "$0")/.."
repo="$(pwd)"

run_test=0
for arg in "$@"; do
  case "$arg" in
    --test) run_test=1 ;;
    -h|--help) sed -n '2,16p' "$0" | sed 's/^# \{0,1\}//'; exit 0 ;;
    *) echo "clean-room: unknown option '$arg' (use --test or nothing)" >&2; exit 2 ;;
  esac
done

if [ "$(id -u)" -ne 0 ]; then
  echo "clean-room: must run as root (mmdebstrap's root mode and chroot need it)" >&2
  exit 1
fi
if ! command -v mmdebstrap >/dev/null; then
  echo "clean-room: installing mmdebstrap"
  DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends mmdebstrap >/dev/null \
    || { apt-get update -qq && DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends mmdebstrap >/dev/null; }
fi

work="$(mktemp -d /tmp/splatfx-clean-room.XXXXXX)"
cleanup() {
  # The root's /proc, /dev and /sys are bind mounts while a hook runs; mmdebstrap unmounts them,
  # but a killed run can leave them, so never rm -rf through a mount.
  if [ "${KEEP_ROOT:-0}" = 1 ]; then echo "clean-room: kept $work"; return; fi
  for m in proc sys dev/pts dev; do
    mountpoint -q "$work/root/$m" 2>/dev/null && umount -l "$work/root/$m" || true
  done
  rm -rf --one-file-system "$work"
}
trap cleanup EXIT

echo "clean-room: cloning $(git rev-parse --short HEAD) (committed tree only)"
git clone -q --no-local --no-hardlinks "$repo" "$work/src"
git -C "$work/src" checkout -q "$(git rev-parse HEAD)"

# This machine's apt sources, one MIRROR argument per file (mmdebstrap pastes each into the root).
sources=()
[ -s /etc/apt/sources.list ] && grep -q '^[[:space:]]*deb' /etc/apt/sources.list && sources+=(/etc/apt/sources.list)
for f in /etc/apt/sources.list.d/*.list /etc/apt/sources.list.d/*.sources; do
  [ -s "$f" ] && sources+=("$f")
done
if [ ${#sources[@]} -eq 0 ]; then
  echo "clean-room: this machine has no apt sources to reuse" >&2
  exit 1
fi

steps="tools/quickstart.sh demo"
[ "$run_test" = 1 ] && steps="$steps && tools/quickstart.sh test"
inner="cd /root/splatfx && export JOBS=${JOBS:-$(nproc)} && $steps"
log="$work/run.log"

echo "clean-room: minimal Debian 12 root, then: $steps"
start=$(date +%s)
set +e
mmdebstrap --variant=minbase --mode=root --quiet \
  --customize-hook='mkdir -p "$1/root/splatfx"' \
  --customize-hook="sync-in $work/src /root/splatfx" \
  --customize-hook="chroot \"\$1\" /bin/bash -c '$inner' > '$log' 2>&1" \
  bookworm "$work/root" "${sources[@]}"
rc=$?
set -e
elapsed=$(( $(date +%s) - start ))

if [ $rc -ne 0 ]; then
  echo "clean-room: FAILED after ${elapsed}s (exit $rc)" >&2
  if [ -s "$log" ]; then
    # quickstart.sh announces each step; the last one announced is where it stopped.
    last_step="$(grep '^quickstart: ' "$log" | tail -n 1 || true)"
    echo "clean-room: the last step reached inside the clean root: ${last_step:-none (before quickstart.sh started)}" >&2
    echo "clean-room: last 40 lines of its output:" >&2
    tail -n 40 "$log" | sed 's/^/  | /' >&2
  else
    echo "clean-room: the root itself could not be built (mmdebstrap's messages are above)" >&2
  fi
  exit 1
fi
grep '^quickstart: ' "$log" | sed 's/^/  /'
echo "clean-room: passed in ${elapsed}s: '$steps' works on a fresh Debian 12 root"
