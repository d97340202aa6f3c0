#!/bin/bash
# The off-axis scene table (docs/validation.md): `--off-axis` splat against the off-axis reference (every
# pixel's own vergence and 1° direction, no lattice), with the on-axis PSF judged against the
# same truth as the negative control; then the truth's own dioptre bin, measured (a 0.02 D
# truth judged against a 0.001 D one, colonnade through the myopic eye at 640×360, on axis
# where both are affordable; the bin's effect in pixels grows linearly with the frame size).
# Usage: tools/off_axis_scene_table.sh [BINARY] [OUT_DIR] [SIZE] [PAIRS]
#   defaults: target/release/ocular, off_axis_out, 1280x720, and PAIRS = every scene:eye of
#   chart and colonnade × healthy, myopia, astigmatism, keratoconus. BIN_CHECK=0 skips the
#   bin check; WARMUP=0 renders the off-axis splat frame once and times it (compare
#   --no-warmup: the same image, minutes less per pair).
# Chart's truth keeps the seed paper's 0.001 D bins; colonnade's rounds vergences to 0.02 D:
# off axis every (vergence bin, direction) pair costs its own FFT PSFs, far more pairs in a
# deep scene at 0.001 D than in a flat one. On 2 CPU cores one chart pair
# takes about 30 minutes (reference 18 min, the off-axis splat frame 5 min, rendered twice
# unless WARMUP=0).
set -euo pipefail
bin=${1:-target/release/ocular}
out=${2:-off_axis_out}
size=${3:-1280x720}
pairs=${4:-}
if [ -z "$pairs" ]; then
  for scene in chart colonnade; do
    for eye in healthy myopia astigmatism keratoconus; do pairs="$pairs $scene:$eye"; done
  done
fi
mkdir -p "$out"
for pair in $pairs; do
  scene=${pair%%:*}
  eye=${pair##*:}
  case $scene in colonnade) truth_bin=0.02 ;; *) truth_bin=0.001 ;; esac
  stem="$out/$scene-$eye"
  warmup=()
  if [ "${WARMUP:-1}" = 0 ]; then warmup=(--no-warmup); fi
  "$bin" compare --scene "$scene" --eye "$eye" --size "$size" --off-axis --no-slices "${warmup[@]}" \
    --truth-bin-d "$truth_bin" --truth-out "$stem-truth.exr" --json "$stem.json" \
    --maps "$stem" > "$stem.txt"
  "$bin" compare --scene "$scene" --eye "$eye" --size "$size" --no-slices \
    --truth-in "$stem-truth.exr" --json "$stem-onaxis.json" > "$stem-onaxis.txt"
done
if [ "${BIN_CHECK:-1}" = 1 ]; then
  check=${BIN_CHECK_SIZE:-640x360}
  "$bin" compare --scene colonnade --eye myopia --size "$check" --no-slices \
    --truth-out "$out/colonnade-fine.exr" --json "$out/bin-colonnade-fine.json" > /dev/null
  "$bin" compare --scene colonnade --eye myopia --size "$check" --no-slices --truth-bin-d 0.02 \
    --judge "$out/colonnade-fine.exr" --json "$out/bin-colonnade.json" > "$out/bin-colonnade.txt"
fi
python3 - "$out" $pairs <<'PY'
import json, os, sys
out, pairs = sys.argv[1], sys.argv[2:]
def rows(path):
    r = json.load(open(path))
    return r, {m["method"]: m for m in r["methods"]}
def cell(m):
    return f"{m['psnr_db']:.2f} / {m['edge_band']['psnr_db']:.2f} ({m['mssim']:.4f})"
print("| scene | eye | truth bin | `--off-axis` splat: frame / band dB (MSSIM) | on-axis PSF (control) | splat s | truth s |")
print("|---|---|---|---|---|---|---|")
for pair in pairs:
    scene, eye = pair.split(":")
    r, m = rows(f"{out}/{scene}-{eye}.json")
    _, c = rows(f"{out}/{scene}-{eye}-onaxis.json")
    print(f"| {scene} | {eye} | {r.get('truth_bin_d') or 0.001} D | {cell(m['splat'])} | {cell(c['splat'])} "
          f"| {m['splat']['seconds']:.0f} | {m['reference']['seconds']:.0f} |")
path = f"{out}/bin-colonnade.json"
if os.path.exists(path):
    r, m = rows(path)
    f = m["colonnade-fine"]
    print(f"colonnade/myopia at {r['width']}x{r['height']}, on axis: the 0.001 D truth against the 0.02 D one: "
          f"{f['psnr_db']:.2f} dB (band {f['edge_band']['psnr_db']:.2f} dB, MSSIM {f['mssim']:.6f}); "
          f"splat against each: {rows(f'{out}/bin-colonnade-fine.json')[1]['splat']['psnr_db']:.2f} / "
          f"{m['splat']['psnr_db']:.2f} dB")
PY
