#!/usr/bin/env bash
# Regenerates the texture sets shipped in textures/ with splatfx-texpick.
#
#   tools/texpick/make-shipped-sets.sh [BUILD_DIR]     (default BUILD_DIR: build)
#
# Turbulence sets need nothing but the tool. The photo sets use the fire
# photograph kept in textures/sources/ and the smoke photograph from Debian's
# tuxpaint-stamps-default; the faces set uses two photographs from Debian's
# python3-skimage. Those packages are fetched with `apt-get download` into a
# temporary folder and unpacked there (nothing is installed; nothing from them
# is committed except the derived sets). Each set's manifest.json records its
# source, credit, licence and the exact parameters below.
set -euo pipefail

root="$(cd "$(dirname "$0")/../.." && pwd)"
build="${1:-$root/build}"
tool="$build/tools/texpick/splatfx-texpick"
[ -x "$tool" ] || { echo "make-shipped-sets: no $tool; build the splatfx-texpick target first" >&2; exit 1; }
out="$root/textures"
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT

echo "== turbulence sets (procedural)"
for count in 8 16; do
  for size in 32 64; do
    "$tool" turbulence --out "$out/turbulence-${count}x${size}" --count "$count" --size "$size" --seed 1 \
      --preview-colors fire --preview-size 96
  done
done

echo "== photo sets"
# The Tux Paint stamps have translucent (soft) alpha, which --alpha auto reads
# as a sprite's density; these sets were cut with the alpha as a cut-out.
# The shipped photo sets predate the straight-alpha read (issue 18): rerun
# now, the fire sets get the same patches with brighter translucent texels,
# and the smoke set other patches (its patch statistics changed with them).
tux_credit="Tux Paint stamps (tuxpaint-stamps-default 2022.06.04, Debian), stamps/naturalforces; (c) 2002-2022 Bill Kendrick and the Tux Paint contributors"
fire="$root/textures/sources/fire.png"
"$tool" random "$fire" --out "$out/photo-fire-8x32" --count 8 --patch 48 --seed 3 --min-std 0.12 --order \
  --alpha coverage --source-name "tuxpaint-stamps-default: stamps/naturalforces/fire.png" --credit "$tux_credit" --license GPL-2.0-or-later \
  --preview-colors fire --preview-size 96
"$tool" path "$fire" --out "$out/photo-fire-path-16x32" --path 112,420:112,60 --step 6 --count 16 --patch 64 \
  --alpha coverage --source-name "tuxpaint-stamps-default: stamps/naturalforces/fire.png" --credit "$tux_credit" --license GPL-2.0-or-later \
  --preview-colors fire --preview-size 96

(cd "$work" && apt-get download -q tuxpaint-stamps-default python3-skimage >/dev/null)
dpkg-deb -x "$work"/tuxpaint-stamps-default_*.deb "$work/tux"
dpkg-deb -x "$work"/python3-skimage_*.deb "$work/sk"
smoke="$work/tux/usr/share/tuxpaint/stamps/naturalforces/explosion.png"
# --absolute-thresholds: this set's --min-std was chosen in luminance units, before thresholds were relative.
"$tool" random "$smoke" --out "$out/photo-smoke-8x32" --count 8 --patch 96 --seed 5 --min-std 0.08 --order \
  --alpha coverage --absolute-thresholds --source-name "tuxpaint-stamps-default: stamps/naturalforces/explosion.png" --credit "$tux_credit" --license GPL-2.0-or-later \
  --preview-colors smoke --preview-size 96

echo "== faces set (the paper's ghosts, Fig. 10)"
skdata="$work/sk/usr/lib/python3/dist-packages/skimage/data"
"$tool" positions "$skdata/astronaut.png" --out "$work/faces-a-4x32" --no-preview \
  --at 226,115,110 --at 226,112,128 --at 224,118,96 --at 230,115,116 \
  --source-name "python3-skimage 0.19.3: skimage/data/astronaut.png" \
  --credit "Eileen Collins, NASA (NASA Great Images database, via scikit-image)" --license "public domain"
"$tool" positions "$skdata/camera.png" --out "$work/faces-c-4x32" --no-preview \
  --at 238,145,72 --at 236,143,84 --at 240,147,64 --at 234,141,96 \
  --source-name "python3-skimage 0.19.3: skimage/data/camera.png" \
  --credit "Lav Varshney (photographer), via scikit-image" --license CC0-1.0
"$tool" merge "$work/faces-a-4x32" "$work/faces-c-4x32" --out "$out/faces-8x32" --preview-colors steam --preview-size 96

echo "== done: $(ls -d "$out"/*-*x*/ | wc -l) sets in $out"
