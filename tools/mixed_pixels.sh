#!/bin/bash
# Does splitting a pixel a silhouette crosses move the image toward the multi-view truth?
# (issue 51, docs/validation.md "Mixed pixels"). The reference is rendered twice from the same
# raster, eye state and kernels: reading each pixel whole (one fragment: mean colour at the
# nearest depth, what every method does) and split (the nearest surface over its share of the
# pixel's 4 samples, what lies behind over the rest, each with its own depth's kernel). Only the
# reference changes, so the difference isolates the split. Both are judged against `--truth
# views`, over the frame and over the occlusion-edge band.
# Usage: tools/mixed_pixels.sh [BINARY] [OUT_DIR] [SIZE]   (defaults: target/release/ocular, mixed_out, 320x180)
set -euo pipefail
bin=${1:-target/release/ocular}
out=${2:-mixed_out}
size=${3:-320x180}
here=$(cd "$(dirname "$0")/.." && pwd)
mkdir -p "$out"
# primitives focused far (blurred silhouettes before a sharp background) and near (the other
# way round), and a flat card before a wall (no grazing rims), focused on the wall and on the card
sed 's/^focus_m = .*/focus_m = 0.2/' "$here/scenes/primitives.toml" > "$out/primitives-near.toml"
card() {
  cat <<TOML
name = "card"
description = "a flat card at 0.5 m before a wall at 5 m, turned 17 degrees"
focus_m = $1
[camera]
position = [0.0, 0.0, 0.0]
look_at = [0.0, 0.0, -1.0]
fov_y_deg = 40.0
near_m = 0.02
far_m = 50.0
[background]
color = [0.8, 0.9, 1.0]
luminance_cd_m2 = 40.0
[[light]]
kind = "ambient"
illuminance_lux = 400.0
[[object]]
kind = "plane"
size_m = 0.12
translate = [0.0, 0.0, -0.5]
rotate_deg = [0.0, 0.0, 17.0]
color = [0.9, 0.2, 0.1]
[[object]]
kind = "plane"
size_m = [24.0, 14.0]
translate = [0.0, 0.0, -5.0]
color = [0.1, 0.3, 0.6]
TOML
}
card 5.0 > "$out/card-far.toml"
card 0.5 > "$out/card-near.toml"
cases=("primitives healthy" "primitives myopia" "$out/primitives-near.toml healthy"
       "$out/primitives-near.toml myopia" "$out/card-far.toml healthy" "$out/card-near.toml healthy"
       "$out/card-far.toml keratoconus")
for c in "${cases[@]}"; do
  read -r scene eye <<< "$c"
  name=$(basename "$scene" .toml)-$eye
  for mode in whole split; do
    "$bin" compare --scene "$scene" --eye "$eye" --size "$size" --truth views --no-slices \
      --edge-pixels "$mode" --json "$out/$name-$mode.json" > "$out/$name-$mode.txt"
  done
done
python3 - "$out" "${cases[@]}" <<'PY'
import json, os, sys
out, cases = sys.argv[1], sys.argv[2:]
print("| scene | eye | frame dB: whole → split | edge band dB: whole → split | band px |")
print("|---|---|---|---|---|")
for c in cases:
    scene, eye = c.split()
    name = os.path.basename(scene).removesuffix(".toml") + "-" + eye
    r = {m: {x["method"]: x for x in json.load(open(f"{out}/{name}-{m}.json"))["methods"]}["reference"]
         for m in ["whole", "split"]}
    w, s = r["whole"], r["split"]
    print(f"| {os.path.basename(scene).removesuffix('.toml')} | {eye} | {w['psnr_db']:.2f} → {s['psnr_db']:.2f} | "
          f"{w['edge_band']['psnr_db']:.2f} → {s['edge_band']['psnr_db']:.2f} | {w['edge_band'].get('pixels', '')} |")
PY
