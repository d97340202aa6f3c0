"""psnr and ssim against their closed forms; flip against the CLI and its bounds."""

import json
import subprocess

import numpy as np
import pytest

import ocular_render as oc


def test_psnr_of_a_constant_offset_is_its_closed_form():
    rng = np.random.default_rng(1)
    a = rng.random((24, 32, 3), dtype=np.float32) * 0.8
    b = a + np.float32(0.1)
    # MSE = 0.01 → PSNR = 10 log10(1 / 0.01) = 20 dB.
    assert oc.psnr(b, a) == pytest.approx(20.0, abs=1e-4)
    assert oc.psnr(a, a) == float("inf")


def test_ssim_is_one_for_identical_images_and_lower_for_noise():
    rng = np.random.default_rng(2)
    a = rng.random((40, 40, 3), dtype=np.float32)
    assert oc.ssim(a, a) == pytest.approx(1.0, abs=1e-9)
    noisy = (a + rng.normal(0, 0.2, a.shape)).astype(np.float32)
    mean, full_map = oc.ssim(noisy, a, full=True)
    assert mean < 0.9 and full_map.shape == (40, 40)


def test_metrics_refuse_mismatched_images():
    a = np.zeros((8, 8, 3), np.float32)
    with pytest.raises(ValueError, match="they must match"):
        oc.psnr(a, np.zeros((8, 9, 3), np.float32))
    with pytest.raises(ValueError, match="float32 is required"):
        oc.psnr(a.astype(np.float64), a)


def _pair(seed=3):
    rng = np.random.default_rng(seed)
    a = rng.random((48, 64, 3), dtype=np.float32) * 0.9
    b = np.clip(a + rng.normal(0, 0.15, a.shape), 0.0, 1.0).astype(np.float32)
    return a, b


def test_flip_is_zero_for_identical_images_and_grows_with_the_difference():
    a, b = _pair()
    assert oc.flip(a, a) == 0.0
    small = oc.flip(np.clip(a + 0.02, 0, 1).astype(np.float32), a)
    large, fmap = oc.flip(b, a, full=True)
    assert 0.0 < small < large <= 1.0
    assert fmap.shape == (48, 64) and fmap.dtype == np.float32
    assert float(fmap.mean()) == pytest.approx(large, rel=1e-5)


def test_hdr_flip_equals_the_clis(tmp_path, cli):
    a, b = _pair(4)
    a, b = a * 20.0, b * 20.0
    oc.write_exr(tmp_path / "ref.exr", a)
    oc.write_exr(tmp_path / "test.exr", b)
    out = subprocess.run(
        [cli, "metrics", str(tmp_path / "ref.exr"), str(tmp_path / "test.exr"), "--json"],
        check=True, capture_output=True, text=True,
    )
    report = json.loads(out.stdout)
    assert report["flip"]["metric"] == "HDR-FLIP"
    assert oc.flip(b, a, hdr=True) == pytest.approx(report["flip"]["mean"], rel=1e-6)


def test_flip_refuses_bad_arguments():
    a, b = _pair()
    with pytest.raises(ValueError, match="pixels per degree"):
        oc.flip(b, a, ppd=0.0)
    nan = a.copy()
    nan[0, 0, 0] = np.nan
    with pytest.raises(ValueError, match="finite"):
        oc.flip(nan, a)
    with pytest.raises(ValueError, match="non-negative"):
        oc.flip(b - 0.5, a, hdr=True)
    with pytest.raises(ValueError, match="they must match"):
        oc.flip(a, a[:, :-1])
