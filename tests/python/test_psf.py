"""psf(): normalised, centred, and diffraction-limited where the optics say it must be."""

import numpy as np
import pytest

import ocular_render as oc

# The Airy pattern's first dark ring: v = k·a·sin θ = 3.8317 (the first zero of J1).
FIRST_ZERO_V = 3.8317


def bessel(n, x):
    """J_n(x) by Bessel's integral (1/π) ∫₀^π cos(nτ − x sin τ) dτ, on a fine trapezoid."""
    tau = np.linspace(0.0, np.pi, 4001)
    f = np.cos(n * tau - x * np.sin(tau))
    return (f.sum() - 0.5 * (f[0] + f[-1])) * (tau[1] - tau[0]) / np.pi


def airy_encircled(v):
    """Energy of the Airy pattern within radius v (Rayleigh): 1 − J0(v)² − J1(v)²."""
    return 1.0 - bessel(0, v) ** 2 - bessel(1, v) ** 2


def encircled(psf, radius_px):
    n = psf.shape[0]
    y, x = np.mgrid[0:n, 0:n]
    r = np.hypot(x - n // 2, y - n // 2)
    return psf[r <= radius_px].sum()


def test_psf_of_a_small_pupil_is_the_airy_pattern():
    # A 1 mm pupil leaves a schematic eye diffraction-limited (its aberrations grow as the
    # pupil's square). The PSF is normalised over its finite grid, so the test compares the
    # energy inside the first dark ring with that inside the grid's inscribed circle.
    pupil_mm, wavelength_nm, pitch, size = 1.0, 550.0, 0.1, 256
    ring_px = np.degrees(1.22 * wavelength_nm * 1e-9 / (pupil_mm * 1e-3)) * 60 / pitch
    outer_px = size // 2 - 1
    p = oc.psf(oc.Eye.preset("navarro"), pupil_mm, wavelength_nm, size=size, pitch_arcmin=pitch)
    assert p.shape == (size, size) and p.dtype == np.float64
    assert p.sum() == pytest.approx(1.0, abs=1e-9)
    assert np.unravel_index(np.argmax(p), p.shape) == (size // 2, size // 2)
    want = airy_encircled(FIRST_ZERO_V) / airy_encircled(FIRST_ZERO_V * outer_px / ring_px)
    got = encircled(p, ring_px) / encircled(p, outer_px)
    assert got == pytest.approx(want, abs=0.01)
    # Negative control: 6 D of defocus (an object at 17 cm, the eye focused far) spreads it.
    blurred = oc.psf(
        oc.Eye.preset("navarro"), pupil_mm, wavelength_nm, object_d=6.0, size=size,
        pitch_arcmin=pitch,
    )
    assert encircled(blurred, ring_px) / encircled(blurred, outer_px) < want - 0.1


def test_psf_rejects_bad_arguments_with_the_cli_message():
    eye = oc.Eye.preset("myopia")
    with pytest.raises(ValueError, match=r"^--pupil-mm 10 is outside 1 to 9 mm$"):
        oc.psf(eye, 10.0, 555.0)
    with pytest.raises(ValueError, match=r"^--size 4 is outside 8–8192 pixels$"):
        oc.psf(eye, 3.0, 555.0, size=4)
    with pytest.raises(ValueError, match=r"^--focus-d -1 must be a vergence"):
        oc.psf(eye, 3.0, 555.0, focus_d=-1.0)
