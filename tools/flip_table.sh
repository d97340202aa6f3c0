#!/bin/bash
# The FLIP table of docs/validation-flip.md: `ocular compare` (reference truth, splat and depth
# slices) for the four eyes on primitives and colonnade, with PSNR, MSSIM and mean LDR-FLIP of
# the displayed images at FLIP's default 67.02 pixels per degree; and, for scale, the same
# metrics of the sharp frame (no eye) against the truth: what the eye's blur itself changes.
# Usage: tools/flip_table.sh [BINARY] [OUT_DIR] [SIZE]   (defaults: target/release/ocular, flip_out, 320x180)
# Runs that finished are kept: rerunning after an interruption resumes.
set -euo pipefail
bin=${1:-target/release/ocular}
out=${2:-flip_out}
size=${3:-320x180}
mkdir -p "$out"
for scene in primitives colonnade; do
  "$bin" raster --scene "$scene" --size "$size" -o "$out/sharp-$scene.exr" > /dev/null
  for eye in healthy myopia astigmatism keratoconus; do
    if [ ! -s "$out/$scene-$eye.json" ]; then
      "$bin" compare --scene "$scene" --eye "$eye" --size "$size" \
        --truth-out "$out/$scene-$eye-truth.exr" \
        --json "$out/$scene-$eye.json" > "$out/$scene-$eye.txt"
    fi
    if [ ! -s "$out/$scene-$eye-sharp.json" ]; then
      "$bin" compare --scene "$scene" --eye "$eye" --size "$size" --no-slices --no-warmup \
        --truth-in "$out/$scene-$eye-truth.exr" --judge "$out/sharp-$scene.exr" \
        --json "$out/$scene-$eye-sharp.json" > "$out/$scene-$eye-sharp.txt"
    fi
  done
done
python3 - "$out" <<'PY'
import json, sys
out = sys.argv[1]
first = json.load(open(f"{out}/primitives-healthy.json"))
print(f"{first['width']}×{first['height']}, FLIP at {first['flip_ppd']:.2f} pixels per degree, on {first['device']}")
print()
print("| scene | eye | splat PSNR dB | splat MSSIM | splat FLIP | slices PSNR dB | slices MSSIM | slices FLIP "
      "| no eye (sharp) PSNR dB | no eye MSSIM | no eye FLIP |")
print("|---|---|---|---|---|---|---|---|---|---|---|")
for scene in ["primitives", "colonnade"]:
    for eye in ["healthy", "myopia", "astigmatism", "keratoconus"]:
        r = json.load(open(f"{out}/{scene}-{eye}.json"))
        sharp = json.load(open(f"{out}/{scene}-{eye}-sharp.json"))
        ms = {m["method"]: m for m in r["methods"]}
        ms["sharp"] = next(m for m in sharp["methods"] if m["method"] == f"sharp-{scene}")
        cells = []
        for name in ["splat", "slices", "sharp"]:
            m = ms[name]
            db = "∞" if m["psnr_db"] is None else f"{m['psnr_db']:.2f}"
            cells += [db, f"{m['mssim']:.4f}", f"{m['flip_mean']:.4f}"]
        print(f"| {scene} | {eye} | " + " | ".join(cells) + " |")
PY
