#!/bin/bash
# The default frame before and after the silhouette fix (docs/validation.md, "Silhouettes"):
# `ocular render` with no arguments from two binaries, the images' PSNR against each other, the
# raster's own edge pixels, and full-size crops of the red sphere's lower edge (4× enlarged,
# nearest neighbour) side by side. Needs ImageMagick's `convert`.
# Usage: tools/silhouette_figure.sh OLD_BINARY [NEW_BINARY] [OUT_DIR]
set -euo pipefail
old=${1:?usage: tools/silhouette_figure.sh OLD_BINARY [NEW_BINARY] [OUT_DIR]}
new=${2:-target/release/ocular}
out=${3:-silhouette_out}
mkdir -p "$out"
for which in old new; do
  bin=$old; [ "$which" = new ] && bin=$new
  "$bin" render -o "$out/$which.exr" > "$out/$which.txt"
  "$bin" render -o "$out/$which.png" > /dev/null
  "$bin" raster --scene primitives --size 640x360 -o "$out/$which-raster.exr" --depth-out "$out/$which-depth.exr"
done
echo "splat, default frame, before against after:"
"$new" metrics "$out/old.exr" "$out/new.exr"
# the red sphere's lower edge at 1280x720 (centre about (484, 438), radius 78 px)
crop=170x80+400+470
for which in old new; do
  convert "$out/$which.png" -crop "$crop" +repage -filter point -resize 400% "$out/$which-edge.png"
done
convert "$out/old-edge.png" "$out/new-edge.png" -background white -splice 8x0 +append \
  tools/figures/silhouette-before-after.png
echo "wrote tools/figures/silhouette-before-after.png (left: before, right: after)"
