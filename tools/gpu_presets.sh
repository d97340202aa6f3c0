#!/usr/bin/env bash
# The quality presets on a GPU, against an older engine, in one session on one device: what
# issues #47 (presets) and #50 (two eyes) ask of a GPU. Give it two release binaries built
# elsewhere (`cargo build --release` here; the old one in a worktree of the old commit, as
# tools/speed_vs_old.sh does). Loader notes (NVIDIA needs glvnd beside libvulkan1) are in
# tools/gpu_bench.sh's header.
#
#   tools/gpu_presets.sh NEW_BINARY OLD_BINARY OUT_DIR
#
# Order, so that a run cut short keeps what the bars need first: both eyes at 1440×1600
# (`bench --binocular --quality fast`); `fast` at 3840×2160 and 1920×1080 for primitives and
# colonnade through the four preset eyes; `balanced` at 1280×720, then the old engine's default
# there; colonnade off axis at 1280×720 (both presets); `fast` at 1280×720; `balanced` at
# 1920×1080 and 3840×2160; the old engine at 3840×2160 (astigmatism, keratoconus); the draw
# unshaded (`--draw-unshaded`, myopia, `fast`) at 3840×2160 and 1280×720, then at 2 and 8
# samples per pixel (`--draw-samples`). One JSON per
# run, named SCENE_EYE_SIZE[_off-axis]_{fast,balanced,old}; pairs are bin_SCENE_EYE_SIZE_fast,
# the unshaded draws probe_SCENE_myopia_SIZE_fast, the others samplesN_SCENE_myopia_SIZE_fast.
# Summarise with `tools/gpu_presets_table.py OUT_DIR`.
#
# Environment: FRAMES (timed frames, default 10), WARMUP (default 3), RUN_TIMEOUT_S (one run's
# limit, default 45), DEADLINE_S (start no run after this many seconds, default 0: none).
set -uo pipefail
new=${1:?usage: tools/gpu_presets.sh NEW_BINARY OLD_BINARY OUT_DIR}
old=${2:?usage: tools/gpu_presets.sh NEW_BINARY OLD_BINARY OUT_DIR}
out=${3:?usage: tools/gpu_presets.sh NEW_BINARY OLD_BINARY OUT_DIR}
mkdir -p "$out"
"$new" devices > "$out/devices.txt" 2>&1 || { cat "$out/devices.txt"; exit 2; }
cat "$out/devices.txt"
frames=${FRAMES:-10}
warmup=${WARMUP:-3}
run_timeout=${RUN_TIMEOUT_S:-45}
deadline=${DEADLINE_S:-0}
start=$SECONDS
status=0
eyes="healthy myopia astigmatism keratoconus"

# run NAME BINARY ARGS...: one bench run (tools/gpu_run.sh)
source "$(dirname "${BASH_SOURCE[0]}")/gpu_run.sh"

# NAME_SUFFIX QUALITY|old SIZES SCENES [EYES] [extra bench arguments...]
sweep() {
    local which=$1 sizes=$2 scenes=$3 es=$4
    shift 4
    for size in $sizes; do
        for scene in $scenes; do
            for eye in $es; do
                local tag="${scene}_${eye}_${size}"
                if [ "$which" = old ]; then
                    run "${tag}_old" "$old" --scene "$scene" --eye "$eye" --size "$size" "$@"
                else
                    run "${tag}_${which}" "$new" --scene "$scene" --eye "$eye" --size "$size" \
                        --quality "$which" "$@"
                fi
            done
        done
    done
}

for c in "primitives myopia" "colonnade astigmatism" "primitives keratoconus"; do
    read -r scene eye <<<"$c"
    run "bin_${scene}_${eye}_1440x1600_fast" "$new" --binocular --scene "$scene" --eye "$eye" \
        --size 1440x1600 --quality fast
done
sweep fast "3840x2160 1920x1080" "primitives colonnade" "$eyes"
sweep balanced 1280x720 "primitives colonnade" "$eyes"
sweep old 1280x720 "primitives colonnade" "$eyes"
for q in balanced fast; do
    for eye in healthy astigmatism; do
        run "colonnade_${eye}_1280x720_off-axis_${q}" "$new" --scene colonnade --eye "$eye" \
            --size 1280x720 --quality "$q" --off-axis
    done
done
sweep fast 1280x720 "primitives colonnade" "$eyes"
sweep balanced "1920x1080 3840x2160" "primitives colonnade" "$eyes"
sweep old 3840x2160 "primitives colonnade" "astigmatism keratoconus"
# The draw with no shading (`--draw-unshaded`): what its fragment work costs.
for size in 3840x2160 1280x720; do
    for scene in primitives colonnade; do
        run "probe_${scene}_myopia_${size}_fast" "$new" --scene "$scene" --eye myopia \
            --size "$size" --quality fast --draw-unshaded
    done
done
# The draw at 2 and 8 samples per pixel (`--draw-samples`): how its time follows the samples.
for size in 3840x2160 1280x720; do
    for scene in primitives colonnade; do
        for n in 2 8; do
            run "samples${n}_${scene}_myopia_${size}_fast" "$new" --scene "$scene" --eye myopia \
                --size "$size" --quality fast --draw-samples "$n"
        done
    done
done
echo "gpu_presets: $((SECONDS - start)) s"
exit $status
