#!/bin/bash
# The speed/accuracy trade of the --quality presets (docs/quality.md): per scene and eye, kernel
# evaluations and texture reads per pixel and wall time per frame (`ocular bench --json`, one
# run, lavapipe unless OCULAR_DEVICE says otherwise) at two sizes, and PSNR / HDR-FLIP against
# the exact CPU reference at the smaller size (`ocular compare`, the reference computed once
# per case and read back for the other presets).
# Usage: tools/quality_table.sh [BINARY] [OUT_DIR] [SMALL] [LARGE]
set -euo pipefail
bin=${1:-target/release/ocular}
out=${2:-quality_out}
small=${3:-320x180}
large=${4:-640x360}
mkdir -p "$out"
cases="colonnade:astigmatism primitives:keratoconus chart:myopia"
for c in $cases; do
  scene=${c%%:*}; eye=${c#*:}
  for q in exact balanced fast; do
    for size in "$small" "$large"; do
      "$bin" bench --scene "$scene" --eye "$eye" --size "$size" --quality "$q" --warmup 1 --frames 1 \
        --json "$out/bench-$scene-$eye-$q-$size.json" > /dev/null
    done
    truth=(--truth-out "$out/truth-$scene-$eye.exr")
    [ -f "$out/truth-$scene-$eye.exr" ] && truth=(--truth-in "$out/truth-$scene-$eye.exr")
    "$bin" compare --scene "$scene" --eye "$eye" --size "$small" --quality "$q" --no-slices \
      "${truth[@]}" --json "$out/compare-$scene-$eye-$q.json" > /dev/null
  done
done
python3 - "$out" "$small" "$large" "$cases" <<'PY'
import json, sys
out, small, large, cases = sys.argv[1], sys.argv[2], sys.argv[3], sys.argv[4].split()
print(f"| scene / eye | preset | evaluations / px {small} → {large} | texture reads / px {small} → {large} | ms / frame {small} → {large} | PSNR dB vs exact reference ({small}) | HDR-FLIP mean |")
print("|---|---|---|---|---|---|---|")
for c in cases:
    scene, eye = c.split(":")
    for q in ["exact", "balanced", "fast"]:
        b = [json.load(open(f"{out}/bench-{scene}-{eye}-{q}-{s}.json")) for s in (small, large)]
        r = json.load(open(f"{out}/compare-{scene}-{eye}-{q}.json"))
        m = [m for m in r["methods"] if m["method"] == "splat"][0]
        flip = f"{m['flip_mean']:.4f}"
        ev = " → ".join(f"{x['evaluations_per_pixel']:.1f}" for x in b)
        rd = " → ".join(f"{x['texture_reads_per_pixel']:.1f}" for x in b)
        ms = " → ".join(f"{x['wall_ms_per_frame']['mean_ms']:.0f}" for x in b)
        print(f"| {scene} / {eye} | {q} | {ev} | {rd} | {ms} | {m['psnr_db']:.2f} | {flip} |")
PY
