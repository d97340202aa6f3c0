#!/usr/bin/env bash
# Runs the video recipes of docs/video.md (tools/recipes/: GNU parallel, a Slurm array, a Kubernetes
# Indexed Job) as written on tiny frames, and checks that every split export is byte-identical
# to one run, in PNG and in EXR, and that docs/video.md shows the recipes verbatim.
#
#   tools/video_recipes.sh [path/to/ocular]     (default: target/release/ocular)
#
# Slurm and Kubernetes are not needed: the Slurm script runs once per array index with
# SLURM_ARRAY_TASK_ID set, and the Job's container command once per index with
# JOB_COMPLETION_INDEX set, all at the same time, as the schedulers would. GNU parallel must be
# installed (apt-get install parallel). Size: --size 96x54 is appended to every ocular call.
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
repo=$(dirname "$here")
real=$(realpath "${1:-$repo/target/release/ocular}")
recipes=$here/recipes
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT

fail() { echo "FAIL: $*" >&2; exit 1; }

# docs/video.md must show each of the three recipes exactly (the other files in tools/recipes/
# are scenes for figures, not video recipes).
python3 - "$repo/docs/video.md" "$recipes" <<'PY'
import sys, pathlib
page = pathlib.Path(sys.argv[1]).read_text()
for name in ["parallel.sh", "slurm.sbatch", "k8s-job.yaml"]:
    text = (pathlib.Path(sys.argv[2]) / name).read_text().strip()
    if text not in page:
        sys.exit(f"FAIL: docs/video.md does not show {name} verbatim")
PY

# `ocular` on PATH: the real binary with tiny frames (and one shared kernel cache).
mkdir -p "$work/bin" "$work/cache"
cat > "$work/bin/ocular" <<SH
#!/bin/sh
exec "$real" "\$@" --size 96x54 --cache "$work/cache" \${OCULAR_EXTRA:-}
SH
chmod +x "$work/bin/ocular"
export PATH="$work/bin:$PATH"

same() { # folder folder: identical frame files
  local a=$1 b=$2
  local na nb
  na=$(cd "$a" && ls frame_* | wc -l)
  nb=$(cd "$b" && ls frame_* | wc -l)
  [ "$na" = "$nb" ] || fail "$b has $nb frames, $a has $na"
  for f in "$a"/frame_*; do
    cmp -s "$f" "$b/$(basename "$f")" || fail "$b/$(basename "$f") differs from one run"
  done
  # The recorded digests check out with the standard tool.
  (cd "$b" && cat ocular-video.sums/*.sha256 | sort -u | sha256sum --quiet -c -) \
    || fail "$b: sha256sum -c disagrees with the recorded digests"
  echo "ok: $b = one run ($na frames)"
}

for format in png exr; do
  export OCULAR_EXTRA="--format $format"
  dir=$work/$format
  mkdir -p "$dir"
  (cd "$dir" && ocular video --scene walk --eye myopia -o whole/ >/dev/null)

  command -v parallel >/dev/null || fail "GNU parallel is not installed (apt-get install parallel)"
  (cd "$dir" && bash -e "$recipes/parallel.sh" >/dev/null)
  same "$dir/whole" "$dir/frames"

  pids=()
  for i in 0 1 2 3 4 5; do
    SLURM_ARRAY_TASK_ID=$i FRAMES=$dir/slurm bash "$recipes/slurm.sbatch" >/dev/null &
    pids+=($!)
  done
  for p in "${pids[@]}"; do wait "$p" || fail "a Slurm array task failed"; done
  same "$dir/whole" "$dir/slurm"

  # The Job's container command, with the shared volume at $dir/k8s instead of /frames.
  cmd=$(grep -- '- ocular video' "$recipes/k8s-job.yaml" | sed 's/^ *- //; s#-o /frames#-o '"$dir"'/k8s#')
  pids=()
  for i in 0 1 2 3 4 5; do
    JOB_COMPLETION_INDEX=$i sh -c "$cmd" >/dev/null &
    pids+=($!)
  done
  for p in "${pids[@]}"; do wait "$p" || fail "a Kubernetes Job index failed"; done
  same "$dir/whole" "$dir/k8s"
done
echo "all recipes ran and every split is byte-identical to one run (PNG and EXR)"
