#!/usr/bin/env bash
# How the draw's time follows its samples per pixel on a GPU, and two eyes at a headset's
# panel: the GPU questions of issues #47 (the draw at 4K) and #50 (a pair within 11.1 ms)
# that tools/gpu_presets.sh ran out of time for. Give it a release binary built elsewhere;
# loader notes are in tools/gpu_bench.sh's header.
#
#   tools/gpu_draw.sh BINARY OUT_DIR
#
# Order: the draw at 2, 4 and 8 samples (`bench --draw-samples`, primitives and colonnade
# through the myopic eye, `fast`) at 3840×2160 then 1280×720; the same at 4 samples unshaded
# (`--draw-unshaded`) at 3840×2160, and with its colour in half floats (`--draw-half-colour`) at
# both sizes; then `bench --binocular --headset vive-pro|quest3
# --quality fast` for primitives / myopia and colonnade / astigmatism. One JSON per run:
# samplesN_SCENE_SIZE, half_SCENE_SIZE, unshaded_SCENE_SIZE, pair_HEADSET_SCENE_EYE. Summarise with
# `tools/gpu_draw_table.py OUT_DIR`.
#
# Environment: FRAMES (default 10), WARMUP (default 3), RUN_TIMEOUT_S (default 60), DEADLINE_S
# (start no run after this many seconds, default 0: none).
set -uo pipefail
bin=${1:?usage: tools/gpu_draw.sh BINARY OUT_DIR}
out=${2:?usage: tools/gpu_draw.sh BINARY OUT_DIR}
mkdir -p "$out"
"$bin" devices > "$out/devices.txt" 2>&1 || { cat "$out/devices.txt"; exit 2; }
cat "$out/devices.txt"
frames=${FRAMES:-10}
warmup=${WARMUP:-3}
run_timeout=${RUN_TIMEOUT_S:-60}
deadline=${DEADLINE_S:-0}
start=$SECONDS
status=0

# run NAME BINARY ARGS...: one bench run (tools/gpu_run.sh)
source "$(dirname "${BASH_SOURCE[0]}")/gpu_run.sh"

for size in 3840x2160 1280x720; do
    for scene in primitives colonnade; do
        for n in 4 2 8; do
            run "samples${n}_${scene}_${size}" "$bin" --scene "$scene" --eye myopia \
                --size "$size" --quality fast --draw-samples "$n"
        done
    done
done
# the multisampled colour in half floats (`--draw-half-colour`): 16 bytes a sample, not 24
for size in 3840x2160 1280x720; do
    for scene in primitives colonnade; do
        run "half_${scene}_${size}" "$bin" --scene "$scene" --eye myopia --size "$size" \
            --quality fast --draw-half-colour
    done
done
for scene in primitives colonnade; do
    run "unshaded_${scene}_3840x2160" "$bin" --scene "$scene" --eye myopia --size 3840x2160 \
        --quality fast --draw-unshaded
done
for headset in vive-pro quest3; do
    for c in "primitives myopia" "colonnade astigmatism"; do
        read -r scene eye <<<"$c"
        run "pair_${headset}_${scene}_${eye}" "$bin" --binocular --headset "$headset" \
            --scene "$scene" --eye "$eye" --quality fast
    done
done
echo "gpu_draw: $((SECONDS - start)) s"
exit $status
