"""Eyes from Python: presets, files, prescriptions and wavefronts, checked against closed forms."""

import math

import numpy as np
import pytest

import ocular_render as oc


def power_vector(sphere_d, cylinder_d, axis_deg):
    """Thibos et al. (1997), written here independently of the library."""
    a = math.radians(2 * axis_deg)
    return (sphere_d + cylinder_d / 2, -cylinder_d / 2 * math.cos(a), -cylinder_d / 2 * math.sin(a))


def test_presets_are_listed_and_load():
    names = oc.eye_presets()
    assert {"healthy", "myopia", "astigmatism", "keratoconus", "navarro"} <= set(names)
    assert oc.Eye.preset("myopia") == oc.Eye.preset("MYOPIA")
    assert oc.Eye.preset("myopia") != oc.Eye.preset("healthy")


def test_unknown_preset_is_a_value_error_naming_the_presets():
    with pytest.raises(ValueError, match=r'^eye "nope" is not a preset; the presets are .*myopia'):
        oc.Eye.preset("nope")


def pupil_power_vector(sphere_d, cylinder_d, axis_deg, distance_mm):
    """A spectacle's principal meridians F carried distance_mm to the eye's pupil: F / (1 - dF)."""
    d = distance_mm * 1e-3
    k1 = sphere_d / (1 - d * sphere_d)
    k2 = (sphere_d + cylinder_d) / (1 - d * (sphere_d + cylinder_d))
    return power_vector(k1, k2 - k1, axis_deg)


def test_eye_from_rx_measures_back_its_prescription():
    rx, text = (-2.25, -1.50, 35.0), "-2.25 -1.50 x 35"
    eye = oc.Eye.from_rx(text, pupil_mm=4.0)
    assert eye.converged
    # A spectacle 12 mm in front of the cornea, as `eye estimate --rx` reads it: at the
    # entrance pupil (about 3 mm behind the cornea; a millimetre moves this one by 0.01 D) and
    # the fitting wavelength, the traced refraction is the lens carried 15 mm.
    r = eye.refraction(pupil_mm=4.0, wavelength_nm=549.0)
    m, j0, j45 = pupil_power_vector(*rx, 12.0 + 3.0)
    assert r.m == pytest.approx(m, abs=0.03)
    assert r.j0 == pytest.approx(j0, abs=0.03)
    assert r.j45 == pytest.approx(j45, abs=0.03)
    # Seen through the same lens at 12 mm, the eye is emmetropic.
    c = eye.with_correction(text).refraction(pupil_mm=4.0, wavelength_nm=549.0)
    assert max(abs(c.m), abs(c.j0), abs(c.j45)) < 0.12
    # Negative controls: the lens taken at the cornea (vertex_mm=0) misses the pupil bar
    # (by about 0.11 D), and another prescription's eye misses it by far more.
    cornea = oc.Eye.from_rx(text, pupil_mm=4.0, vertex_mm=0.0).refraction(4.0, 549.0)
    assert abs(cornea.m - m) > 2 * 0.03
    other = oc.Eye.from_rx("-1.25 -1.50 x 80", pupil_mm=4.0).refraction(4.0, 549.0)
    assert abs(other.m - m) > 0.5 and abs(other.j0 - j0) > 0.5


def test_eye_from_zernike_defocus_has_the_closed_form_refraction(tmp_path):
    # M = -4 sqrt(3) c20 / r^2 (µm, mm → D): c20 for -3 D over a 5 mm pupil.
    pupil_mm, want_m = 5.0, -3.0
    c20 = -want_m * (pupil_mm / 2) ** 2 / (4 * math.sqrt(3))
    coefficients = np.zeros(6)
    coefficients[4] = c20
    eye = oc.Eye.from_zernike(coefficients, pupil_mm, 555.0)
    r = eye.refraction(pupil_mm=pupil_mm, wavelength_nm=555.0)
    assert r.m == pytest.approx(want_m, abs=0.03)
    assert abs(r.cylinder_d) < 0.05
    w = eye.wavefront(pupil_mm=pupil_mm, wavelength_nm=555.0)
    assert w.shape == (28,) and w.dtype == np.float64
    assert w[4] == pytest.approx(c20, abs=0.02)
    # saved and loaded, it is the same eye
    path = tmp_path / "eye.toml"
    eye.save(path)
    assert oc.Eye.load(path) == eye
    assert "[estimate]" in path.read_text()


def test_off_axis_refraction_differs_from_on_axis():
    eye = oc.Eye.preset("navarro")
    on = eye.refraction(pupil_mm=4.0)
    off = eye.refraction(pupil_mm=4.0, field_deg=(20.0, 0.0))
    # Oblique astigmatism of a schematic eye at 20°: about a dioptre of J0.
    assert abs(off.j0 - on.j0) > 0.3
    assert off.field_deg == (20.0, 0.0)


@pytest.mark.parametrize(
    "call, message",
    [
        (lambda: oc.Eye.from_rx("-2 -1 x 30", pupil_mm=0.5), r"^--pupil-mm 0.5 is outside 1 to 9 mm$"),
        (lambda: oc.Eye.from_rx("banana", pupil_mm=4.0), r"^--rx: "),
        (lambda: oc.Eye.preset("myopia").refraction(pupil_mm=12.0), r"^--pupil-mm 12 is outside 1 to 9 mm$"),
        (lambda: oc.Eye.preset("myopia").wavefront(wavelength_nm=200.0), r"^--wavelength-nm 200 is outside 380 to 1000 nm$"),
        (lambda: oc.Eye.preset("myopia").refraction(field_deg=(70.0, 0.0)), r"^--field-deg "),
        (lambda: oc.Eye.from_zernike([], 4.0, 555.0), r"^coefficients_um: 0 values"),
    ],
)
def test_bad_eye_arguments_raise_value_error_with_the_cli_message(call, message):
    with pytest.raises(ValueError, match=message):
        call()


def test_missing_eye_file_and_wrong_types():
    with pytest.raises(FileNotFoundError):
        oc.Eye.load("/nonexistent/eye.toml")
    with pytest.raises(TypeError):
        oc.Eye.from_rx(42)
