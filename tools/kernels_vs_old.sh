#!/bin/bash
# Times `ocular kernels` for the paper's full grid (fov 30°, 720 px, Rmax 48; the default axes:
# 161 objects × 5 focus × 4 pupils × 3 colours) of each preset eye, this build against an older
# one, in the same run and on the same machine, and prints a Markdown table: wall seconds,
# PSFs computed and the ratio. Usage: OLD_BIN=/path/to/old/ocular tools/kernels_vs_old.sh [EYES...]
# (default eyes: keratoconus healthy myopia astigmatism). No cache is read or written.
set -euo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
new_bin="$here/target/release/ocular"
old_bin=${OLD_BIN:?set OLD_BIN to the ocular binary of the older build}
eyes=("$@")
[ ${#eyes[@]} -eq 0 ] && eyes=(keratoconus healthy myopia astigmatism)
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
grid=(--fov-y 30 --height 720 --rmax-cap 48 --no-cache --json)
seconds() {
  python3 - "$1" <<'PY'
import json, sys
r = json.load(open(sys.argv[1]))
print(f"{r['seconds']:.1f} {r['report']['psfs_computed']}")
PY
}
echo "| eye | old s | old PSFs | new s | new PSFs | old / new |"
echo "|---|---|---|---|---|---|"
for eye in "${eyes[@]}"; do
  "$old_bin" kernels --eye "$eye" "${grid[@]}" -o "$tmp/old.bin" >"$tmp/old.json"
  "$new_bin" kernels --eye "$eye" "${grid[@]}" -o "$tmp/new.bin" >"$tmp/new.json"
  read -r so po <<<"$(seconds "$tmp/old.json")"
  read -r sn pn <<<"$(seconds "$tmp/new.json")"
  ratio=$(awk -v a="$so" -v b="$sn" 'BEGIN { printf "%.2fx", a / b }')
  echo "| $eye | $so | $po | $sn | $pn | $ratio |"
done
