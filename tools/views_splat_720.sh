#!/bin/bash
# One-layer splat against the multi-view truth at 1280×720 for both scenes and the four eyes
# (docs/validation.md, "Whole scenes at 1280×720", the re-run of the splat column), without the
# exact reference that tools/views_table.sh also renders (81 minutes for colonnade on 2 cores):
# the views truth is rendered by `ocular render --method views` at compare's focus and pupil
# (the same image as compare's views truth, byte for byte, checked at 320×180), then judged
# with `compare --truth-in`.
# Usage: tools/views_splat_720.sh [BINARY] [OUT_DIR]   (defaults: target/release/ocular, views720)
set -euo pipefail
B=$(realpath "${1:-target/release/ocular}")
mkdir -p "${2:-views720}" && cd "${2:-views720}"
for scene in primitives colonnade; do
  for eye in healthy myopia astigmatism keratoconus; do
    $B compare --scene $scene --eye $eye --size 64x36 --no-slices --json f-$scene-$eye.json > /dev/null 2>&1
    read F P <<< $(python3 -c "import json;d=json.load(open('f-$scene-$eye.json'));print(d['focus_d'],d['pupil_mm'])")
    $B render --scene $scene --eye $eye --size 1280x720 --method views --focus-d $F --pupil-mm $P -o views-$scene-$eye.exr > r-$scene-$eye.txt 2>&1
    $B compare --scene $scene --eye $eye --size 1280x720 --truth-in views-$scene-$eye.exr --no-slices --json $scene-$eye.json > $scene-$eye.txt 2>&1
    echo "$scene $eye F=$F: $(grep -E '^\s+splat' $scene-$eye.txt)"
  done
done
