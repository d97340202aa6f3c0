#!/bin/bash
# The FLIP table of docs/validation-flip.md: `ocular compare` (reference truth, splat and depth
# slices) for the four eyes on primitives and colonnade, with PSNR, MSSIM and mean LDR-FLIP of
# the displayed images at FLIP's default 67.02 pixels per degree.
# Usage: tools/flip_table.sh [BINARY] [OUT_DIR] [SIZE]   (defaults: target/release/ocular, flip_out, 320x180)
set -euo pipefail
bin=${1:-target/release/ocular}
out=${2:-flip_out}
size=${3:-320x180}
mkdir -p "$out"
for scene in primitives colonnade; do
  for eye in healthy myopia astigmatism keratoconus; do
    if [ ! -s "$out/$scene-$eye.json" ]; then
      "$bin" compare --scene "$scene" --eye "$eye" --size "$size" \
        --json "$out/$scene-$eye.json" > "$out/$scene-$eye.txt"
    fi
  done
done
python3 - "$out" <<'PY'
import json, sys
out = sys.argv[1]
first = json.load(open(f"{out}/primitives-healthy.json"))
print(f"{first['width']}×{first['height']}, FLIP at {first['flip_ppd']:.2f} pixels per degree, on {first['device']}")
print()
print("| scene | eye | splat PSNR dB | splat MSSIM | splat FLIP | slices PSNR dB | slices MSSIM | slices FLIP |")
print("|---|---|---|---|---|---|---|---|")
for scene in ["primitives", "colonnade"]:
    for eye in ["healthy", "myopia", "astigmatism", "keratoconus"]:
        r = json.load(open(f"{out}/{scene}-{eye}.json"))
        ms = {m["method"]: m for m in r["methods"]}
        cells = []
        for name in ["splat", "slices"]:
            m = ms[name]
            db = "∞" if m["psnr_db"] is None else f"{m['psnr_db']:.2f}"
            cells += [db, f"{m['mssim']:.4f}", f"{m['flip_mean']:.4f}"]
        print(f"| {scene} | {eye} | " + " | ".join(cells) + " |")
PY
