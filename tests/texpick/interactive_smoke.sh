#!/usr/bin/env bash
# Smoke test of `splatfx-texpick interactive` under Xvfb: opens the HighGUI
# window, clicks three positions through --events, saves (key s) and quits
# after 30 frames; then checks the folder it saved is a 3-texture set made
# by the positions mode.  Usage: interactive_smoke.sh TOOL IMAGE OUTDIR
set -euo pipefail
tool="$1" image="$2" out="$3"
rm -rf "$out"
xvfb-run -a -s "-screen 0 1280x900x24" "$tool" interactive "$image" --out "$out/set" --no-preview \
  --auto-quit-after 30 --events "click:110,200;click:120,300;click:90,380;key:s" --screenshot "$out/window.png"
test -f "$out/window.png" || { echo "no window screenshot written"; exit 1; }
grep -q '"method": "positions"' "$out/set/manifest.json" || { echo "manifest does not record the positions method"; exit 1; }
n=$(find "$out/set" -name 't[0-9][0-9][0-9].png' | wc -l)
[ "$n" -eq 3 ] || { echo "expected 3 textures in the saved set, found $n"; exit 1; }
echo "interactive smoke test: window opened, 3 clicks saved as a 3-texture set"
