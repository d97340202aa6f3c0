"""Shared fixtures: the Vulkan setup of ci/test.sh, one renderer for the session, the CLI."""

import glob
import os
import pathlib
import shutil

import pytest

REPO = pathlib.Path(__file__).resolve().parents[2]

# As ci/test.sh: pin Mesa's lavapipe unless a device is chosen, and make a missing validation
# layer fail rather than skip the checks. Set before the module opens any device.
if not any(os.environ.get(v) for v in ("VK_DRIVER_FILES", "VK_ICD_FILENAMES", "OCULAR_DEVICE")):
    lvp = sorted(glob.glob("/usr/share/vulkan/icd.d/lvp_icd.*.json"))
    if lvp:
        os.environ["VK_DRIVER_FILES"] = lvp[0]
os.environ.setdefault("OCULAR_VALIDATION", "required")

import ocular_render as oc  # noqa: E402


@pytest.fixture(scope="session")
def kernel_cache(tmp_path_factory):
    return tmp_path_factory.mktemp("kernels")


@pytest.fixture(scope="session")
def renderer(kernel_cache):
    return oc.Renderer(cache_dir=kernel_cache)


def ocular_binary():
    """The CLI built by `cargo build --release` / ci/test.sh, or $OCULAR_BIN."""
    candidates = [os.environ.get("OCULAR_BIN")]
    target = os.environ.get("CARGO_TARGET_DIR")
    if target:
        candidates.append(os.path.join(target, "release", "ocular"))
    candidates.append(str(REPO / "target" / "release" / "ocular"))
    candidates.append(shutil.which("ocular"))
    for c in candidates:
        if c and os.path.isfile(c) and os.access(c, os.X_OK):
            return c
    return None


@pytest.fixture(scope="session")
def cli():
    path = ocular_binary()
    if path is None:
        pytest.fail(
            "the ocular CLI is needed to compare with: build it (cargo build --release) or set "
            "OCULAR_BIN"
        )
    return path
