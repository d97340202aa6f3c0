#!/usr/bin/env bash
# One engine's settings side by side on a GPU, in one session: every scene × eye of the README
# table at each size, once per named variant (bench arguments), one `ocular bench --json` per
# run in a folder per variant. The binary is built elsewhere (loader notes in
# tools/gpu_bench.sh's header). Summarise with `tools/gpu_merge_table.py OUT_DIR`.
#
#   tools/gpu_variants.sh BINARY OUT_DIR NAME='BENCH ARGS' [NAME='BENCH ARGS' ...]
#   e.g. tools/gpu_variants.sh .gpu/ocular out default='' k2='--merge-blur-per-block 2'
#
# Environment: SIZES (default "1280x720 1920x1080 3840x2160"), FRAMES (default 10), WARMUP
# (default 2), FRAMES_4K (default 3, one warm-up), RUN_TIMEOUT_S (default 60), DEADLINE_S
# (default 0: none). Runs go size by size, scene by scene, every variant of a row together,
# so a deadline cuts whole rows off the largest size first.
set -uo pipefail
bin=${1:?usage: tools/gpu_variants.sh BINARY OUT_DIR NAME='ARGS' ...}
out=${2:?usage: tools/gpu_variants.sh BINARY OUT_DIR NAME='ARGS' ...}
shift 2
[ $# -gt 0 ] || { echo "gpu_variants: name at least one variant, NAME='ARGS'" >&2; exit 2; }
names=()
declare -A args
for v in "$@"; do
    name=${v%%=*}
    case $name in
        ''|*[!A-Za-z0-9_-]*) echo "gpu_variants: variant '$v' is not NAME='ARGS'" >&2; exit 2 ;;
    esac
    names+=("$name")
    args[$name]=${v#*=}
    mkdir -p "$out/$name"
done
"$bin" devices > "$out/devices.txt" 2>&1 || { cat "$out/devices.txt"; exit 2; }
cat "$out/devices.txt"
run_timeout=${RUN_TIMEOUT_S:-60}
deadline=${DEADLINE_S:-0}
start=$SECONDS
status=0
for size in ${SIZES:-1280x720 1920x1080 3840x2160}; do
    frames=${FRAMES:-10} warmup=${WARMUP:-2}
    if [ "$size" = 3840x2160 ]; then frames=${FRAMES_4K:-3} warmup=1; fi
    for scene in primitives colonnade; do
        for eye in healthy myopia astigmatism keratoconus; do
            for name in "${names[@]}"; do
                run="${scene}_${eye}_${size}"
                if [ "$deadline" -gt 0 ] && [ $((SECONDS - start)) -ge "$deadline" ]; then
                    echo "== $name/$run skipped: past DEADLINE_S=$deadline"
                    status=1
                    continue
                fi
                log="$out/$name/$run.log"
                # shellcheck disable=SC2086 # a variant's arguments split on spaces
                if ! timeout "$run_timeout" "$bin" bench --scene "$scene" --eye "$eye" \
                    --size "$size" ${args[$name]} --warmup "$warmup" --frames "$frames" \
                    --json "$out/$name/$run.json" > "$log" 2>&1; then
                    echo "== $name/$run failed or over ${run_timeout} s: $(tail -n 1 "$log")"
                    rm -f "$out/$name/$run.json"
                    status=1
                else
                    echo "== $name/$run ($((SECONDS - start)) s): $(grep -E '^  total  ' "$log")"
                fi
            done
        done
    done
done
echo "gpu_variants: $((SECONDS - start)) s"
exit $status
