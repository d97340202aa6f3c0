#!/bin/bash
# Times this engine against an older commit's (default f59341e, the engine before level of
# detail by blur), both built from source here and run in the same session on the same device,
# and prints the per-frame table of issue #30: wall ms per frame, list entries and kernel
# evaluations per pixel (the old engine reports no evaluations: "—").
# Usage: tools/speed_vs_old.sh [OLD_COMMIT] [OUT_DIR] [FRAMES]
#   defaults: f59341e, speed_out, 2 frames after 1 warm-up.
# The old commit is checked out in a git worktree under OUT_DIR and built there (its own
# target folder: the first run takes minutes), unless OLD_BIN names a binary already built
# from it. QUALITY=fast (or exact) runs the new engine at that --quality preset, the old one
# at its defaults. Set VK_DRIVER_FILES to pick a driver.
set -euo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
old=${1:-f59341e}
out=${2:-speed_out}
frames=${3:-2}
mkdir -p "$out"
out="$(cd "$out" && pwd)"
new_bin="$here/target/release/ocular"
(cd "$here" && cargo build --release --quiet)
if [ -n "${OLD_BIN:-}" ]; then
  old_bin=$OLD_BIN
else
  tree="$out/old-$old"
  if [ ! -d "$tree" ]; then
    git -C "$here" worktree add --detach "$tree" "$old" >/dev/null
  fi
  ln -sfn "$here/.deps" "$tree/.deps"
  (cd "$tree" && cargo build --release --quiet --bin ocular)
  old_bin="$tree/target/release/ocular"
fi
preset=()
[ -n "${QUALITY:-}" ] && preset=(--quality "$QUALITY")

cases=("colonnade astigmatism 320x180" "colonnade astigmatism 640x360" "primitives keratoconus 640x360" "chart myopia 640x360")
for c in "${cases[@]}"; do
  read -r scene eye size <<<"$c"
  for which in old new; do
    bin=$old_bin
    extra=()
    if [ "$which" = new ]; then bin=$new_bin; extra=("${preset[@]}"); fi
    "$bin" bench --scene "$scene" --eye "$eye" --size "$size" --warmup 1 --frames "$frames" \
      "${extra[@]}" --json "$out/$scene-$eye-$size-$which.json" > "$out/$scene-$eye-$size-$which.txt"
  done
done
# the growth from 320×180 to 640×360 and `ocular render` with no arguments (warm cache: the
# first, untimed render fills the kernel cache if it is cold)
"$new_bin" render "${preset[@]}" -o "$out/default.png" > /dev/null
start=$(date +%s.%N)
"$new_bin" render "${preset[@]}" -o "$out/default.png" > /dev/null
end=$(date +%s.%N)

python3 - "$out" "$(echo "$end - $start" | bc)" <<'PY'
import json, sys
out, render_s = sys.argv[1], float(sys.argv[2])
cases = [("colonnade", "astigmatism", "320x180"), ("colonnade", "astigmatism", "640x360"),
         ("primitives", "keratoconus", "640x360"), ("chart", "myopia", "640x360")]
print("| scene | eye | size | old ms/frame | new ms/frame | speed-up | old entries | new entries | new evaluations/pixel | new texture reads/pixel |")
print("|---|---|---|---|---|---|---|---|---|---|")
walls = {}
for s, e, z in cases:
    o = json.load(open(f"{out}/{s}-{e}-{z}-old.json"))
    n = json.load(open(f"{out}/{s}-{e}-{z}-new.json"))
    ow, nw = o["wall_ms_per_frame"]["mean_ms"], n["wall_ms_per_frame"]["mean_ms"]
    walls[(s, e, z)] = nw
    ev = n.get("evaluations_per_pixel")
    print(f"| {s} | {e} | {z} | {ow:.0f} | {nw:.0f} | {ow / nw:.2f}× | {o['list_entries']} | "
          f"{n['list_entries']} | {ev:.1f} | {n.get('texture_reads_per_pixel', 0):.1f} |")
g = walls[("colonnade", "astigmatism", "640x360")] / walls[("colonnade", "astigmatism", "320x180")]
print(f"\ngrowth 320×180 → 640×360 (colonnade, astigmatism, new engine): {g:.2f}×")
print(f"`ocular render` with no arguments (warm cache): {render_s:.1f} s")
PY
