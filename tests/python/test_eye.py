"""Eyes from Python: presets, files, prescriptions and wavefronts, checked against closed forms."""

import json
import math
import subprocess

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
    assert r.pupil_m_d == pytest.approx(m, abs=0.03)
    assert r.pupil_j0_d == pytest.approx(j0, abs=0.03)
    assert r.pupil_j45_d == pytest.approx(j45, abs=0.03)
    # Seen through the same lens at 12 mm, the eye is emmetropic.
    c = eye.with_correction(text).refraction(pupil_mm=4.0, wavelength_nm=549.0)
    assert max(abs(c.pupil_m_d), abs(c.pupil_j0_d), abs(c.pupil_j45_d)) < 0.12
    # Negative controls: the lens taken at the cornea (vertex_mm=0) misses the pupil bar
    # (by about 0.11 D), and another prescription's eye misses it by far more.
    cornea = oc.Eye.from_rx(text, pupil_mm=4.0, vertex_mm=0.0).refraction(4.0, 549.0)
    assert abs(cornea.pupil_m_d - m) > 2 * 0.03
    other = oc.Eye.from_rx("-1.25 -1.50 x 80", pupil_mm=4.0).refraction(4.0, 549.0)
    assert abs(other.pupil_m_d - m) > 0.5 and abs(other.pupil_j0_d - j0) > 0.5


# Five prescriptions from -8 to +4 D with cylinder (issue 52): `refraction()` speaks the
# CLI's convention, a spectacle at a 12 mm vertex.
ROUND_TRIP_RX = [
    "-8.00 -2.00 x 170",
    "-6.00",
    "-2.25 -1.50 x 35",
    "+1.25 -0.75 x 120",
    "+3.50 -0.75 x 90",
]


def rx_numbers(text):
    parts = text.replace("x", " ").split()
    sphere = float(parts[0])
    cylinder = float(parts[1]) if len(parts) > 1 else 0.0
    axis = float(parts[2]) if len(parts) > 2 else 180.0
    return sphere, cylinder, axis


def rx_distance(a, b):
    """Largest difference of the two prescriptions' power vectors (D): axis-safe."""
    pa, pb = power_vector(*a), power_vector(*b)
    return max(abs(x - y) for x, y in zip(pa, pb))


@pytest.mark.parametrize("text", ROUND_TRIP_RX)
def test_refraction_returns_the_prescription_the_eye_was_fitted_to(tmp_path, cli, text):
    eye = oc.Eye.from_rx(text, pupil_mm=4.0)
    r = eye.refraction(pupil_mm=4.0, wavelength_nm=549.0)
    want = rx_numbers(text)
    got = (r.sphere_d, r.cylinder_d, r.axis_deg)
    assert r.vertex_mm == 12.0
    assert rx_distance(got, want) < 0.01, (text, r)
    # The CLI refracts the saved eye file to the same prescription.
    path = tmp_path / "eye.toml"
    eye.save(path)
    out = subprocess.run(
        [cli, "eye", "refract", str(path), "--json"],
        check=True, capture_output=True, text=True,
    )
    cli = json.loads(out.stdout)
    assert rx_distance(got, (cli["sphere_d"], cli["cylinder_d"], cli["axis_deg"])) < 0.005
    assert r.rx() == cli["rx"]
    # Negative control: the entrance-pupil power vector written as "S C x A" (the old
    # refraction()) misses the prescription once the eye is not weak.
    m, j0, j45 = r.pupil_m_d, r.pupil_j0_d, r.pupil_j45_d
    c = -2.0 * math.hypot(j0, j45)
    a = (0.5 * math.degrees(math.atan2(j45, j0))) % 180.0 or 180.0
    old = (m - c / 2.0, c, a)
    if abs(want[0]) >= 2.0:
        assert rx_distance(old, want) > 0.05, (text, old)
    # A contact lens needs its own prescription, and says so.
    cl = eye.refraction(pupil_mm=4.0, wavelength_nm=549.0, vertex_mm=0.0)
    assert cl.vertex_mm == 0.0
    if abs(want[0]) >= 2.0:
        assert rx_distance((cl.sphere_d, cl.cylinder_d, cl.axis_deg), want) > 0.03
    assert "at a 12 mm vertex" in repr(r)


def test_eye_from_zernike_defocus_has_the_closed_form_refraction(tmp_path):
    # M = -4 sqrt(3) c20 / r^2 (µm, mm → D): c20 for -3 D over a 5 mm pupil.
    pupil_mm, want_m = 5.0, -3.0
    c20 = -want_m * (pupil_mm / 2) ** 2 / (4 * math.sqrt(3))
    coefficients = np.zeros(6)
    coefficients[4] = c20
    eye = oc.Eye.from_zernike(coefficients, pupil_mm, 555.0)
    r = eye.refraction(pupil_mm=pupil_mm, wavelength_nm=555.0)
    assert r.pupil_m_d == pytest.approx(want_m, abs=0.03)
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
    assert abs(off.pupil_j0_d - on.pupil_j0_d) > 0.3
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
