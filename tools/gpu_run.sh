# Sourced by the GPU scripts that time many `ocular bench` runs (tools/gpu_vs_old.sh,
# tools/gpu_presets.sh): `run NAME BINARY ARGS...` runs one bench into "$out/NAME.json" and
# "$out/NAME.log", or skips it past DEADLINE_S, and prints one line. The caller sets out,
# frames, warmup, run_timeout, deadline (0: none), start (a $SECONDS) and status (set to 1 when
# a run fails or is skipped).
run() {
    local name=$1 bin=$2
    shift 2
    if [ "$deadline" -gt 0 ] && [ $((SECONDS - start)) -ge "$deadline" ]; then
        echo "== $name skipped: past DEADLINE_S=$deadline"
        status=1
        return
    fi
    if ! timeout "$run_timeout" "$bin" bench "$@" --warmup "$warmup" --frames "$frames" \
        --json "$out/$name.json" > "$out/$name.log" 2>&1; then
        echo "== $name failed or over ${run_timeout} s: $(tail -n 1 "$out/$name.log")"
        rm -f "$out/$name.json"
        status=1
    else
        # the runtime total (mean, median, p95 ms), not the precomputation's "total (with I/O)"
        echo "== $name ($((SECONDS - start)) s): $(grep -E '^  total +[0-9]' "$out/$name.log")"
    fi
}
