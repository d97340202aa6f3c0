#!/usr/bin/env bash
# The wide field's block reads against the merge bound they replace, on a GPU, in one session:
# this engine's release binary and the one before (f548bb2, the bound), both built elsewhere
# (loader notes in tools/gpu_bench.sh's header), every scene × eye of the README table, one
# JSON per run in a folder per variant:
#   default/   this engine's default
#   unmerged/  this engine with --merge-levels 0
#   bound/     the previous binary's default (merges only where the bound allows)
#   old_rule/  the previous binary with --merge-scale-error 1000 (merges with misplaced reads)
# 1280×720 all four; 1920×1080 default and bound; 3840×2160 default and old rule (the bound
# takes seconds a frame there: tools/figures/gpu_h200/run9_merge_bound). Summarise with
# `tools/gpu_merge_table.py OUT_DIR`.
#
#   tools/gpu_vs_bound.sh NEW_BINARY PREVIOUS_BINARY OUT_DIR
#
# Environment: FRAMES (default 10), WARMUP (default 2), FRAMES_4K (default 3, one warm-up),
# RUN_TIMEOUT_S (default 60), DEADLINE_S (default 0: none).
set -uo pipefail
new=${1:?usage: tools/gpu_vs_bound.sh NEW_BINARY PREVIOUS_BINARY OUT_DIR}
old=${2:?usage: tools/gpu_vs_bound.sh NEW_BINARY PREVIOUS_BINARY OUT_DIR}
out=${3:?usage: tools/gpu_vs_bound.sh NEW_BINARY PREVIOUS_BINARY OUT_DIR}
mkdir -p "$out"/{default,unmerged,bound,old_rule}
"$new" devices > "$out/devices.txt" 2>&1 || { cat "$out/devices.txt"; exit 2; }
cat "$out/devices.txt"
frames=${FRAMES:-10}
warmup=${WARMUP:-2}
run_timeout=${RUN_TIMEOUT_S:-60}
deadline=${DEADLINE_S:-0}
start=$SECONDS
status=0

# One bench run: VARIANT, NAME, then bench arguments.
run() {
    local variant=$1 name=$2
    shift 2
    local bin=$new extra=()
    case $variant in
        unmerged) extra=(--merge-levels 0) ;;
        bound) bin=$old ;;
        old_rule) bin=$old extra=(--merge-scale-error 1000) ;;
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
        echo "== $variant/$name ($((SECONDS - start)) s): $(grep -E '^  total  ' "$log")"
    fi
}

each() {
    local size=$1
    shift
    for scene in primitives colonnade; do
        for eye in healthy myopia astigmatism keratoconus; do
            for variant in "$@"; do
                run "$variant" "${scene}_${eye}_${size}" --scene "$scene" --eye "$eye" --size "$size"
            done
        done
    done
}

each 1280x720 default bound old_rule unmerged
each 1920x1080 default bound
frames=${FRAMES_4K:-3}
warmup=1
each 3840x2160 default old_rule
echo "gpu_vs_bound: $((SECONDS - start)) s"
exit $status
