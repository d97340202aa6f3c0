#!/usr/bin/env bash
# Negative controls for tests/it/psf_true_kernels.rs: puts back (1) the old β degree cap of 60
# with the ENZ series for every PSF, and (2) the old point sampling (retinal 4 µm pitch, 2
# samples per pixel) with the old resample (each sample a unit box), runs the test for each and
# restores the sources. Both runs must FAIL. Refuses to run over uncommitted changes in src/psf.
set -euo pipefail
cd "$(dirname "$0")/.."
if ! git diff --quiet -- src/psf; then
    echo "src/psf has uncommitted changes; commit or stash them first" >&2
    exit 2
fi
trap 'git checkout -- src/psf' EXIT
run() {
    if cargo test --release --test it psf_true_kernels:: 2>&1 | grep -E "^test |test result"; then :; fi
    git checkout -- src/psf
}
echo "== control 1: β degree cap 60, ENZ for every PSF"
sed -i 's/max_beta_degree: 120,/max_beta_degree: 60,/; s/method: MethodChoice::Auto,/method: MethodChoice::Enz,/' \
    src/psf/axes.rs
run
echo "== control 2: point sampling and the unit-box resample"
python3 - <<'PY'
def sub(path, old, new):
    s = open(path).read()
    assert old in s, (path, old)
    open(path, 'w').write(s.replace(old, new))
sub('src/psf/project.rs', '        .min(diffraction)\n', '')
sub('src/psf/axes.rs', 'samples_per_pixel: 4.0', 'samples_per_pixel: 2.0')
sub('src/psf/integrate.rs', '[g(-2.0), g(-1.0), g(0.0), g(1.0), g(2.0)]',
    '{ let _ = g; [0.0, 0.0, 1.0, 0.0, 0.0] }')
sub('src/psf/integrate.rs',
    'let t = tau - j0 as f64; // nodes at t = 0, 1, 2, 3\n            let l = [',
    'let t = tau - j0 as f64; // nodes at t = 0, 1, 2, 3\n            let l = [0.0, 2.0 - t, t - 1.0, 0.0];\n            let _ = [')
PY
run
