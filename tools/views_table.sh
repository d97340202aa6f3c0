#!/bin/bash
# The partial-occlusion table (docs/validation.md): every method against the multi-view truth, whole frame
# and occlusion-edge band, for the four eyes on primitives and colonnade.
# Usage: tools/views_table.sh [BINARY] [OUT_DIR] [SIZE]   (defaults: target/release/ocular, views_out, 320x180)
set -euo pipefail
bin=${1:-target/release/ocular}
out=${2:-views_out}
size=${3:-320x180}
mkdir -p "$out"
for scene in primitives colonnade; do
  for eye in healthy myopia astigmatism keratoconus; do
    "$bin" compare --scene "$scene" --eye "$eye" --size "$size" --truth views --layers 2 \
      --json "$out/$scene-$eye.json" --maps "$out/$scene-$eye" > "$out/$scene-$eye.txt"
  done
done
python3 - "$out" <<'PY'
import json, sys, glob, os
out = sys.argv[1]
print("| scene | eye | views: 2× change dB | " + " | ".join(
    f"{m} frame / band dB (band SSIM)" for m in ["reference", "splat", "splat-layers", "slices"]) + " |")
print("|---|---|---|---|---|---|---|")
for scene in ["primitives", "colonnade"]:
    for eye in ["healthy", "myopia", "astigmatism", "keratoconus"]:
        r = json.load(open(f"{out}/{scene}-{eye}.json"))
        ms = {m["method"]: m for m in r["methods"]}
        cells = []
        for name in ["reference", "splat", "splat-layers", "slices"]:
            m = ms[name]
            cells.append(f"{m['psnr_db']:.2f} / {m['edge_band']['psnr_db']:.2f} ({m['edge_band']['mssim']:.4f})")
        print(f"| {scene} | {eye} | {r['views_convergence']['psnr_db']:.1f} | " + " | ".join(cells) + " |")
PY
# The SSIM maps of docs/validation.md (1280×720 run): one layer against two, primitives through the healthy
# eye and colonnade through the myopic one.
if [ "$size" = "1280x720" ]; then
  cp "$out/primitives-healthy/ssim_splat.png" tools/figures/ssim-primitives-healthy-splat.png
  cp "$out/primitives-healthy/ssim_splat-layers.png" tools/figures/ssim-primitives-healthy-splat-layers.png
  cp "$out/colonnade-myopia/ssim_splat.png" tools/figures/ssim-colonnade-myopia-splat.png
  cp "$out/colonnade-myopia/ssim_splat-layers.png" tools/figures/ssim-colonnade-myopia-splat-layers.png
fi
