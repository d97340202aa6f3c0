"""psnr and ssim against their closed forms."""

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
