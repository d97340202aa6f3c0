#!/usr/bin/env bash
# The paper's Table 3 layout on whatever GPU the machine has, without building anything there:
# give it a release binary (cargo build --release elsewhere) and, if the machine has no Vulkan
# loader, a folder holding libvulkan.so.1 (Debian's libvulkan1 package, unpacked). NVIDIA's
# Vulkan driver is libGLX_nvidia.so.0, which loads only beside glvnd: on the H100 of
# docs/validation.md, libvulkan1 alone gave "Could not get 'vkCreateInstance' ... for ICD
# libGLX_nvidia.so.0"; unpacking libvulkan1, libglvnd0, libglx0, libgl1, libegl1, libgles2 and
# libopengl0 (`apt-get download`, then `dpkg -x PKG.deb /; ldconfig`) made it load.
#
#   tools/gpu_bench.sh BINARY OUT_DIR [LOADER_DIR]
#
# Runs `ocular bench --baseline` for the primitives and colonnade scenes, the four estimated
# eyes and 1280×720, 1920×1080 and 3840×2160, one JSON per run in OUT_DIR, plus devices.txt
# and a log per run. Sizes a device cannot render (memory, binding limits) are reported and
# skipped. The smallest size runs first for every scene and eye, so a run cut short keeps the
# most comparable rows. Then, unless OFF_AXIS=0, colonnade at the first size with `--off-axis`
# for each eye (its on-axis row is the matching one above). Summarise with
# `tools/gpu_bench_table.py OUT_DIR`.
#
# Environment: FRAMES (timed frames, default 50), WARMUP (default 5), RUN_TIMEOUT_S (one run's
# limit, default 180), DEADLINE_S (start no run after this many seconds, default: none),
# SIZES, SCENES, EYES (space-separated lists), OFF_AXIS (1 or 0).
set -uo pipefail
bin=${1:?usage: tools/gpu_bench.sh BINARY OUT_DIR [LOADER_DIR]}
out=${2:?usage: tools/gpu_bench.sh BINARY OUT_DIR [LOADER_DIR]}
if [ -n "${3:-}" ]; then
    export LD_LIBRARY_PATH="$3${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}"
fi
mkdir -p "$out"
"$bin" devices > "$out/devices.txt" 2>&1 || { cat "$out/devices.txt"; exit 2; }
cat "$out/devices.txt"
frames=${FRAMES:-50}
warmup=${WARMUP:-5}
run_timeout=${RUN_TIMEOUT_S:-180}
deadline=${DEADLINE_S:-0}
sizes=${SIZES:-1280x720 1920x1080 3840x2160}
scenes=${SCENES:-primitives colonnade}
eyes=${EYES:-healthy myopia astigmatism keratoconus}
start=$SECONDS
status=0

# One bench run: NAME then bench arguments. Skipped once the deadline has passed.
run() {
    local name=$1
    shift
    if [ "$deadline" -gt 0 ] && [ $((SECONDS - start)) -ge "$deadline" ]; then
        echo "== $name skipped: past DEADLINE_S=$deadline"
        status=1
        return
    fi
    echo "== $name ($((SECONDS - start)) s)"
    if ! timeout "$run_timeout" "$bin" bench "$@" --warmup "$warmup" --frames "$frames" \
        --json "$out/$name.json" > "$out/$name.log" 2>&1; then
        echo "   (failed or over ${run_timeout} s:)"
        tail -n 3 "$out/$name.log" | sed 's/^/   /'
        status=1
    else
        grep -E '^  (total|wall per frame)|baseline|speed' "$out/$name.log" | sed 's/^/   /'
    fi
}

for size in $sizes; do
    for scene in $scenes; do
        for eye in $eyes; do
            run "${scene}_${eye}_${size}" --scene "$scene" --eye "$eye" --size "$size" --baseline
        done
    done
done
if [ "${OFF_AXIS:-1}" = 1 ]; then
    first=${sizes%% *}
    for eye in $eyes; do
        run "colonnade_${eye}_${first}_off-axis" --scene colonnade --eye "$eye" \
            --size "$first" --off-axis
    done
fi
echo "gpu_bench: $((SECONDS - start)) s"
exit $status
