#!/usr/bin/env bash
# What a binocular frame costs against one eye: `ocular render` of a scene through one eye and
# through a pair (--binocular), warm kernel cache, the render time of each (seconds_render: the
# splat submission, scene drawing included) from --json, median of N runs.
#
#   tools/binocular_cost.sh [BIN] [SCENE] [SIZE] [EYE] [N]
set -euo pipefail
bin=${1:-target/release/ocular}
scene=${2:-primitives}
size=${3:-640x360}
eye=${4:-myopia}
n=${5:-5}
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
common=(render --scene "$scene" --size "$size" --eye "$eye" --focus-m 2 --pupil-mm 4 --json)
# warm: kernels of both eye states in the cache, shaders compiled
"$bin" "${common[@]}" -o "$out/one.png" >/dev/null
"$bin" "${common[@]}" --binocular -o "$out/two.png" >/dev/null
one=(); two=()
for _ in $(seq "$n"); do
    one+=("$("$bin" "${common[@]}" -o "$out/one.png" | python3 -c 'import json,sys; print(json.load(sys.stdin)["seconds_render"])')")
    two+=("$("$bin" "${common[@]}" --binocular -o "$out/two.png" | python3 -c 'import json,sys; e=json.load(sys.stdin)["eyes"]; print(e[0]["seconds_render"] + e[1]["seconds_render"])')")
done
python3 - "${one[*]}" "${two[*]}" "$scene" "$size" "$eye" <<'PY'
import statistics, sys
one = [float(v) for v in sys.argv[1].split()]
two = [float(v) for v in sys.argv[2].split()]
m1, m2 = statistics.median(one), statistics.median(two)
print(f"{sys.argv[3]} at {sys.argv[4]} through {sys.argv[5]}: one eye {m1*1000:.0f} ms, "
      f"both eyes {m2*1000:.0f} ms (median of {len(one)}): {m2/m1:.2f}x")
PY
