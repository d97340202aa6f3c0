#!/usr/bin/env bash
# Regenerates the pictures and tables of README.md and docs/: the main job's picture, the quality table
# (ground truth vs splatting vs depth slices for the four presets), the lavapipe/GPU timing
# table and the speed/accuracy sweep. Run from the repository root after `cargo build --release`.
# Results go to tools/figures/ (pictures) and $OUT (JSON, default /tmp/ocular-figures).
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/.."
bin=target/release/ocular
out=${OUT:-/tmp/ocular-figures}
size=${SIZE:-320x180}
mkdir -p "$out" tools/figures

# The main job, exactly as the README runs it (default scene, eye and size).
(cd "$out" && "$OLDPWD/$bin" render -o main.png) && cp "$out/main.png" tools/figures/ocular.png

# Presbyopia (docs/corrections.md): the chart scene's reading card at 0.4 m through a
# 60-year-old healthy eye (Hofstetter's mean amplitude, 0.5 D), with +2.00 D readers and without.
rm -rf "$out/presbyopia"
"$bin" video --scene tools/recipes/chart_card.toml --eye healthy --age 60 --correct "+2.00" \
    --side-by-side uncorrected --focus-sweep 0.4..0.4 --duration 0 --size 400x300 \
    -o "$out/presbyopia" && cp "$out/presbyopia/frame_000000.png" tools/figures/presbyopia.png

# Off axis (docs/off-axis.md): point lights across a 90° × 60° frame through the
# wide-angle eye, on-axis PSF against --off-axis.
python3 tools/field_figure.py --bin "$bin" --out tools/figures/off_axis_points.png

for eye in healthy myopia astigmatism keratoconus; do
    "$bin" compare --scene primitives --eye "$eye" --size "$size" --json "$out/compare-$eye.json" \
        --maps "$out/maps-$eye"
done
cp "$out/maps-keratoconus/splat.png" tools/figures/keratoconus-splat.png
cp "$out/maps-keratoconus/ssim_slices.png" tools/figures/keratoconus-ssim-slices.png

"$bin" bench --scene primitives --eye myopia --size "$size" --warmup 2 --frames 10 \
    --json "$out/bench-myopia-$size.json"

python3 tools/sweep.py --eye myopia --size "$size" --out "$out/sweep" && cp "$out/sweep/sweep.png" tools/figures/sweep.png
echo "figures in tools/figures/, tables in $out/"
