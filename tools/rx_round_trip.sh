#!/bin/bash
# Issue 29, case 6: a spectacle prescription → `eye estimate --rx` → the eye seen through the
# same prescription with `--correct` (its residual power vector) and `eye refract` (the
# prescription it reads back), all at the default vertex distance, 4 mm pupil, 549 nm.
#   OCULAR=path/to/ocular tools/rx_round_trip.sh [RX ...]
set -euo pipefail
bin=${OCULAR:-target/release/ocular}
dir=$(mktemp -d)
trap 'rm -rf "$dir"' EXIT
if [ $# -eq 0 ]; then
  set -- "-6.00 0.00 x 180" "-2.25 -1.50 x 35" "+4.00 0.00 x 180" "-3.00 -2.00 x 60" "+2.50 -1.75 x 135"
fi
echo "| Rx | through it with --correct: M / J0 / J45 (D) | eye refract | largest power-vector difference (D) |"
echo "|---|---|---|---|"
for rx in "$@"; do
  "$bin" eye estimate --rx "$rx" --pupil-mm 4 --threads 1 -o "$dir/eye.toml" >/dev/null
  m=$("$bin" eye measure "$dir/eye.toml" --pupil-mm 4 --wavelength-nm 549 --correct "$rx" --json)
  rc=0
  r=$("$bin" eye refract "$dir/eye.toml" --pupil-mm 4 --json 2>"$dir/err") || rc=$?
  if [ "$rc" -ne 0 ]; then
    echo "| $rx | $(echo "$m" | jq -r '"\(.refraction.m*1000|round/1000) / \(.refraction.j0*1000|round/1000) / \(.refraction.j45*1000|round/1000)"') | exit $rc: $(sed 's/.*: cannot/cannot/' "$dir/err" | cut -c1-80) | |"
    continue
  fi
  # the refracted prescription against the entered one, as power vectors
  diff=$(jq -n --arg rx "$rx" --argjson r "$r" '
    def pv(s; c; a): [s + c/2, -(c/2) * ((2*a*3.141592653589793/180)|cos), -(c/2) * ((2*a*3.141592653589793/180)|sin)];
    ($rx | gsub("x"; " ") | split(" ") | map(select(length > 0) | tonumber)) as $p
    | pv($p[0]; $p[1]; $p[2]) as $a
    | pv($r.sphere_d; $r.cylinder_d; $r.axis_deg) as $b
    | [range(0; 3) | ($a[.] - $b[.]) | fabs] | max * 1000 | round / 1000 | if . == 0 then 0 else . end')
  echo "$m" | jq -r --arg rx "$rx" --arg back "$(echo "$r" | jq -r .rx)" --arg diff "$diff" \
    'def f: (. * 1000 | round / 1000) | if . == 0 then 0 else . end;
     "| \($rx) | \(.refraction.m|f) / \(.refraction.j0|f) / \(.refraction.j45|f) | \($back) | \($diff) |"'
done
