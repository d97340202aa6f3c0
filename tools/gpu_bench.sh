#!/usr/bin/env bash
# The paper's Table 3 layout on whatever GPU the machine has, without building anything there:
# give it a release binary (cargo build --release elsewhere) and, if the machine has no Vulkan
# loader, a folder holding libvulkan.so.1 (Debian's libvulkan1 package, unpacked).
#
#   tools/gpu_bench.sh BINARY OUT_DIR [LOADER_DIR]
#
# Runs `ocular bench --baseline` for the primitives and colonnade scenes, the four estimated
# eyes and 1280×720, 1920×1080 and 3840×2160, one JSON per run in OUT_DIR, plus devices.txt.
# Sizes a device cannot render (memory, binding limits) are reported and skipped.
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
status=0
for scene in primitives colonnade; do
    for eye in healthy myopia astigmatism keratoconus; do
        for size in 1280x720 1920x1080 3840x2160; do
            name="$out/${scene}_${eye}_${size}.json"
            echo "== $scene $eye $size"
            if ! "$bin" bench --scene "$scene" --eye "$eye" --size "$size" --warmup 5 \
                --frames "$frames" --baseline --json "$name"; then
                echo "   (failed: see above)"
                status=1
            fi
        done
    done
done
exit $status
