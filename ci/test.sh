#!/usr/bin/env bash
# Runs the whole test suite the way CI does: on Mesa lavapipe, with Vulkan validation required.
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/.."

# The loader lists several CPU drivers; pin lavapipe so that GPU tests run on the same
# implementation everywhere (set OCULAR_DEVICE or VK_DRIVER_FILES yourself to test another).
lvp=$(ls /usr/share/vulkan/icd.d/lvp_icd.*.json 2>/dev/null | head -n 1 || true)
if [ -z "${VK_DRIVER_FILES:-}${VK_ICD_FILENAMES:-}${OCULAR_DEVICE:-}" ] && [ -n "$lvp" ]; then
    export VK_DRIVER_FILES="$lvp"
fi
# A missing validation layer must fail the tests, not silently skip the checks.
export OCULAR_VALIDATION=required

# Library, binary and integration tests; benchmarks are built by clippy and run by `cargo bench`.
cargo test --release "$@"

# The live viewer in a real browser (Debian's chromium through playwright-core): the page, a
# focus click, a bad and a good prescription, a comparison, an export (docs/viewer.md).
if [ $# -eq 0 ]; then
    node tests/viewer/e2e.mjs
fi
