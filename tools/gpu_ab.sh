#!/usr/bin/env bash
# Two builds of the engine on a GPU, alternated run by run in one session: the draw's A/B
# (run 14 timed the colour resolve in compute, the NEW build, against the render pass's, the
# OLD one). Give it two release binaries built elsewhere; loader notes are in
# tools/gpu_bench.sh's header.
#
#   tools/gpu_ab.sh OLD_BINARY NEW_BINARY OUT_DIR
#
# Runs `bench --quality fast` for primitives and colonnade through the myopic eye at
# 3840×2160 and 1280×720, old then new for each, then both eyes at the Vive Pro's panel
# (colonnade / astigmatism), new then old. One JSON per run, {old,new}_SCENE_SIZE and
# {old,new}_pair_vive-pro; OUT_DIR/table.md lists each run's raster, resolve, GPU total and
# host time.
#
# Environment: FRAMES (default 10), WARMUP (default 3), RUN_TIMEOUT_S (default 60), DEADLINE_S
# (default 200).
set -uo pipefail
old=${1:?usage: tools/gpu_ab.sh OLD_BINARY NEW_BINARY OUT_DIR}
new=${2:?usage: tools/gpu_ab.sh OLD_BINARY NEW_BINARY OUT_DIR}
out=${3:?usage: tools/gpu_ab.sh OLD_BINARY NEW_BINARY OUT_DIR}
mkdir -p "$out"
"$new" devices > "$out/devices.txt" 2>&1 || { cat "$out/devices.txt"; exit 2; }
frames=${FRAMES:-10}
warmup=${WARMUP:-3}
run_timeout=${RUN_TIMEOUT_S:-60}
deadline=${DEADLINE_S:-200}
start=$SECONDS
status=0
source "$(dirname "${BASH_SOURCE[0]}")/gpu_run.sh"

for size in 3840x2160 1280x720; do
    for scene in primitives colonnade; do
        run "old_${scene}_${size}" "$old" --scene "$scene" --eye myopia --size "$size" --quality fast
        run "new_${scene}_${size}" "$new" --scene "$scene" --eye myopia --size "$size" --quality fast
    done
done
run new_pair_vive-pro "$new" --binocular --headset vive-pro --scene colonnade --eye astigmatism \
    --quality fast
run old_pair_vive-pro "$old" --binocular --headset vive-pro --scene colonnade --eye astigmatism \
    --quality fast
python3 - "$out" > "$out/table.md" <<'PY'
import glob, json, os, sys
print("| run | raster ms | resolve ms | GPU total ms | host ms | pair GPU ms |")
print("|---|---|---|---|---|---|")
for f in sorted(glob.glob(os.path.join(sys.argv[1], "*.json"))):
    d = json.load(open(f))
    p = {x["name"]: x["mean_ms"] for x in d["passes"]}
    b = d.get("binocular")
    print(f"| {os.path.basename(f)[:-5]} | {p.get('raster', 0):.2f} | "
          f"{p.get('resolve', p.get('depth resolve', 0)):.2f} | {d['total']['mean_ms']:.2f} | "
          f"{d['host_ms_per_frame']['mean_ms']:.1f} | "
          f"{b['gpu_total']['mean_ms']:.2f} |" if b else
          f"| {os.path.basename(f)[:-5]} | {p.get('raster', 0):.2f} | "
          f"{p.get('resolve', p.get('depth resolve', 0)):.2f} | {d['total']['mean_ms']:.2f} | "
          f"{d['host_ms_per_frame']['mean_ms']:.1f} | — |")
PY
cat "$out/table.md"
echo "gpu_ab: $((SECONDS - start)) s"
exit $status
