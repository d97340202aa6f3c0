#!/usr/bin/env bash
# Times this engine against an older one on a GPU, both given as release binaries (build them
# elsewhere: `cargo build --release` here, and for the old one a worktree of the old commit, as
# tools/speed_vs_old.sh does), run in the same session on the same device, one JSON per run.
# Loader notes (NVIDIA needs glvnd beside libvulkan1) are in tools/gpu_bench.sh's header.
#
#   tools/gpu_vs_old.sh NEW_BINARY OLD_BINARY OUT_DIR
#
# Order (a run cut short keeps the most comparable rows): 1280×720 for primitives and colonnade
# through the four preset eyes, new, new with 2×2 merging only (`--merge-levels 1`, the
# previous default) and old; 1920×1080 and 3840×2160 for the astigmatic and keratoconic eyes,
# new and old; colonnade off axis at 1280×720, new and old. Summarise with
# `tools/gpu_vs_old_table.py OUT_DIR`.
#
# Environment: FRAMES (timed frames, default 20), WARMUP (default 3), RUN_TIMEOUT_S (one run's
# limit, default 90), DEADLINE_S (start no run after this many seconds, default 0: none).
set -uo pipefail
new=${1:?usage: tools/gpu_vs_old.sh NEW_BINARY OLD_BINARY OUT_DIR}
old=${2:?usage: tools/gpu_vs_old.sh NEW_BINARY OLD_BINARY OUT_DIR}
out=${3:?usage: tools/gpu_vs_old.sh NEW_BINARY OLD_BINARY OUT_DIR}
mkdir -p "$out"
"$new" devices > "$out/devices.txt" 2>&1 || { cat "$out/devices.txt"; exit 2; }
cat "$out/devices.txt"
frames=${FRAMES:-20}
warmup=${WARMUP:-3}
run_timeout=${RUN_TIMEOUT_S:-90}
deadline=${DEADLINE_S:-0}
start=$SECONDS
status=0

# run NAME BINARY ARGS...: one bench run (tools/gpu_run.sh)
source "$(dirname "${BASH_SOURCE[0]}")/gpu_run.sh"

pair() {
    local tag=$1
    shift
    run "${tag}_new" "$new" "$@"
    run "${tag}_old" "$old" "$@"
}

for scene in primitives colonnade; do
    for eye in healthy myopia astigmatism keratoconus; do
        tag="${scene}_${eye}_1280x720"
        run "${tag}_new" "$new" --scene "$scene" --eye "$eye" --size 1280x720
        run "${tag}_l1" "$new" --scene "$scene" --eye "$eye" --size 1280x720 --merge-levels 1
        run "${tag}_old" "$old" --scene "$scene" --eye "$eye" --size 1280x720
    done
done
for eye in healthy astigmatism; do
    pair "colonnade_${eye}_1280x720_off-axis" --scene colonnade --eye "$eye" --size 1280x720 \
        --off-axis
done
for size in 1920x1080 3840x2160; do
    for scene in primitives colonnade; do
        for eye in astigmatism keratoconus; do
            pair "${scene}_${eye}_${size}" --scene "$scene" --eye "$eye" --size "$size"
        done
    done
done
echo "gpu_vs_old: $((SECONDS - start)) s"
exit $status
