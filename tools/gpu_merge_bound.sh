#!/usr/bin/env bash
# What the wide-field merge bound (`--merge-scale-error`, docs/validation.md "Merging in the
# wide field") costs on a GPU: every scene × eye of the README table through one release binary
# (build it elsewhere; loader notes in tools/gpu_bench.sh's header), three ways in one session,
# one JSON per run:
#   default/   the default bound (0.02 px)
#   old_rule/  --merge-scale-error 1000 (the rule before the bound: merges off the centre too)
#   unmerged/  --merge-levels 0
# at 1280×720 first, then the default at 1920×1080, colonnade off axis at 1280×720, and the
# default and old rule at 3840×2160, so a run cut short keeps the most comparable rows.
# Summarise with `tools/gpu_merge_table.py OUT_DIR`.
#
#   tools/gpu_merge_bound.sh BINARY OUT_DIR [LOADER_DIR]
#
# Environment: FRAMES (timed frames, default 10; FRAMES_4K at 3840×2160, default 3, after one
# warm-up), WARMUP (default 2), RUN_TIMEOUT_S (one run's
# limit, default 60), DEADLINE_S (start no run after this many seconds, default 0: none).
set -uo pipefail
bin=${1:?usage: tools/gpu_merge_bound.sh BINARY OUT_DIR [LOADER_DIR]}
out=${2:?usage: tools/gpu_merge_bound.sh BINARY OUT_DIR [LOADER_DIR]}
if [ -n "${3:-}" ]; then
    export LD_LIBRARY_PATH="$3${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}"
fi
mkdir -p "$out/default" "$out/old_rule" "$out/unmerged"
"$bin" devices > "$out/devices.txt" 2>&1 || { cat "$out/devices.txt"; exit 2; }
cat "$out/devices.txt"
frames=${FRAMES:-10}
warmup=${WARMUP:-2}
run_timeout=${RUN_TIMEOUT_S:-60}
deadline=${DEADLINE_S:-0}
start=$SECONDS
status=0
scenes="primitives colonnade"
eyes="healthy myopia astigmatism keratoconus"

# One bench run: VARIANT, NAME, then bench arguments (the variant's own come first).
run() {
    local variant=$1 name=$2
    shift 2
    local extra=()
    case $variant in
        old_rule) extra=(--merge-scale-error 1000) ;;
        unmerged) extra=(--merge-levels 0) ;;
    esac
    if [ "$deadline" -gt 0 ] && [ $((SECONDS - start)) -ge "$deadline" ]; then
        echo "== $variant/$name skipped: past DEADLINE_S=$deadline"
        status=1
        return
    fi
    local log="$out/$variant/$name.log"
    if ! timeout "$run_timeout" "$bin" bench "$@" "${extra[@]}" --warmup "$warmup" \
        --frames "$frames" --json "$out/$variant/$name.json" > "$log" 2>&1; then
        echo "== $variant/$name failed or over ${run_timeout} s: $(tail -n 1 "$log")"
        rm -f "$out/$variant/$name.json"
        status=1
    else
        echo "== $variant/$name ($((SECONDS - start)) s): $(grep -E '^  total' "$log")"
    fi
}

each() {
    local size=$1
    shift
    for scene in $scenes; do
        for eye in $eyes; do
            for variant in "$@"; do
                run "$variant" "${scene}_${eye}_${size}" --scene "$scene" --eye "$eye" --size "$size"
            done
        done
    done
}

each 1280x720 default old_rule unmerged
each 1920x1080 default
for eye in $eyes; do
    run default "colonnade_${eye}_1280x720_off-axis" --scene colonnade --eye "$eye" \
        --size 1280x720 --off-axis
done
# A 4K frame takes seconds where the bound stops merging: fewer frames.
frames=${FRAMES_4K:-3}
warmup=1
each 3840x2160 default old_rule
echo "gpu_merge_bound: $((SECONDS - start)) s"
exit $status
