#!/usr/bin/env bash
# Negative controls for tests/it/off_axis_kernels.rs: (1) the object's astigmatic defocus added
# with the wrong sign, (2) the disc's PSF used without resampling through the pupil stretch.
# Runs the elliptical-pupil test for each and restores the source; both runs must FAIL.
# Refuses to run over uncommitted changes in src/psf.
set -euo pipefail
cd "$(dirname "$0")/.."
if ! git diff --quiet -- src/psf; then
    echo "src/psf has uncommitted changes; commit or stash them first" >&2
    exit 2
fi
trap 'git checkout -- src/psf' EXIT
run() {
    if cargo test --release --test it off_axis_kernels::defocused -- --nocapture 2>&1 |
        grep -E "σ|^test |test result"; then :; fi
    git checkout -- src/psf
}
sub() {
    python3 - "$@" <<'PY'
import sys
path, old, new = sys.argv[1:4]
s = open(path).read()
assert old in s, (path, old)
open(path, 'w').write(s.replace(old, new))
PY
}
echo "== control 1: the object's astigmatism with the wrong sign"
sub src/psf/field_psf.rs 'alpha[osa_index(2, 2)] += c22;' 'alpha[osa_index(2, 2)] -= c22;'
run
echo "== control 2: no resampling through the stretch"
sub src/psf/field_psf.rs '*v = sample(s[0][0] * x + s[0][1] * y, s[1][0] * x + s[1][1] * y) * det;' \
    '*v = sample(x, y) * det;'
run
