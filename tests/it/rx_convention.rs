//! One spectacle-vertex convention (issue 29, case 6): a prescription entered into
//! `eye estimate --rx` is a spectacle at the vertex distance `--correct` and `eye refract` use
//! (12 mm unless given), so the eye estimated from it, seen through it with `--correct`, is
//! emmetropic (M, J0, J45 within 0.12 D), and `eye refract` reads the same prescription back
//! (power vector within 0.06 D). The check is the traced system with the lens in it, not the
//! conversion formula. Negative control: an eye built with the prescription at the cornea (the
//! old convention, `--vertex-mm 0`), seen through the same lens at 12 mm, misses both bars.

use crate::common::{eye_measure, eye_refract, json_ok, ocular_run, temp_dir};

const CORRECTED_BAR_D: f64 = 0.12;
const REFRACT_BAR_D: f64 = 0.06;

/// Thibos power vector of sphere, cylinder and axis, written here for the test.
fn power_vector(s: f64, c: f64, a_deg: f64) -> [f64; 3] {
    let t = 2.0 * a_deg.to_radians();
    [s + 0.5 * c, -0.5 * c * t.cos(), -0.5 * c * t.sin()]
}

/// Largest |difference| of two power vectors.
fn distance(a: [f64; 3], b: [f64; 3]) -> f64 {
    (0..3).map(|k| (a[k] - b[k]).abs()).fold(0.0, f64::max)
}

/// The eye estimated from `rx` (with `extra` options), and what correcting it with `rx` at
/// 12 mm leaves (largest of |M|, |J0|, |J45|) and how far `eye refract` lands from `rx`.
fn round_trip(dir: &std::path::Path, rx: (f64, f64, f64), extra: &[&str]) -> (f64, f64) {
    let eye = dir.join("eye.toml");
    let eye = eye.to_str().unwrap();
    let text = format!("{} {} x {}", rx.0, rx.1, rx.2);
    let mut args = vec![
        "eye",
        "estimate",
        "--rx",
        &text,
        "--pupil-mm",
        "4",
        "--threads",
        "1",
        "-o",
        eye,
    ];
    args.extend(extra);
    let o = ocular_run(&args);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let m = json_ok(&eye_measure(
        eye,
        "4",
        "549",
        &["--correct", &text, "--json"],
    ));
    let residual = ["m", "j0", "j45"]
        .iter()
        .map(|k| m["refraction"][k].as_f64().unwrap().abs())
        .fold(0.0, f64::max);
    let r = json_ok(&eye_refract(eye, "4", &["--json"]));
    assert_eq!(r["vertex_mm"].as_f64(), Some(12.0));
    let back = power_vector(
        r["sphere_d"].as_f64().unwrap(),
        r["cylinder_d"].as_f64().unwrap(),
        r["axis_deg"].as_f64().unwrap(),
    );
    let refract_error = distance(back, power_vector(rx.0, rx.1, rx.2));
    eprintln!(
        "{text} {extra:?}: through it {residual:.4} D; eye refract {} ({refract_error:.4} D)",
        r["rx"]
    );
    (residual, refract_error)
}

#[test]
fn a_spectacle_prescription_round_trips_through_the_eye() {
    let dir = temp_dir("loop");
    // myopic, hyperopic, with-the-rule and oblique astigmatism, mixed
    for rx in [
        (-6.0, 0.0, 180.0),
        (4.0, 0.0, 180.0),
        (-2.25, -1.5, 35.0),
        (-3.0, -2.0, 60.0),
        (2.5, -1.75, 135.0),
    ] {
        let (residual, refract_error) = round_trip(&dir, rx, &[]);
        assert!(
            residual < CORRECTED_BAR_D,
            "{rx:?}: {residual} D left through its own prescription"
        );
        assert!(
            refract_error < REFRACT_BAR_D,
            "{rx:?}: eye refract is {refract_error} D from it"
        );
    }
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn the_vertex_of_the_prescription_is_an_option_and_the_cornea_plane_misses_the_bars() {
    let dir = temp_dir("vertex");
    // The old convention, the prescription taken at the cornea, fails both bars where the
    // vertex effect is large...
    for rx in [(-6.0, 0.0, 180.0), (-3.0, -2.0, 60.0)] {
        let (residual, refract_error) = round_trip(&dir, rx, &["--vertex-mm", "0"]);
        assert!(residual > CORRECTED_BAR_D, "{rx:?}: {residual}");
        assert!(refract_error > REFRACT_BAR_D, "{rx:?}: {refract_error}");
    }
    // ...and an explicit --vertex-mm 12 is the default.
    let (residual, refract_error) = round_trip(&dir, (-6.0, 0.0, 180.0), &["--vertex-mm", "12"]);
    assert!(residual < CORRECTED_BAR_D && refract_error < REFRACT_BAR_D);
    // A contact-lens prescription corrects as a contact lens.
    let eye = dir.join("eye.toml");
    let o = ocular_run(&[
        "eye",
        "estimate",
        "--rx",
        "-6",
        "--vertex-mm",
        "0",
        "--pupil-mm",
        "4",
        "--threads",
        "1",
        "-o",
        eye.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let through = json_ok(&eye_measure(
        eye.to_str().unwrap(),
        "4",
        "549",
        &["--correct", "-6", "--correct-contact", "--json"],
    ));
    let left = through["refraction"]["m"].as_f64().unwrap();
    assert!(left.abs() < CORRECTED_BAR_D, "contact lens: M = {left}");
    // Bad vertex distances are refused with the option named.
    for bad in ["17", "-1", "nan"] {
        let o = ocular_run(&[
            "eye",
            "estimate",
            "--rx",
            "-2",
            "--pupil-mm",
            "4",
            "--vertex-mm",
            bad,
            "-o",
            eye.to_str().unwrap(),
        ]);
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "{err}");
        assert!(err.lines().next().unwrap().contains("--vertex-mm"), "{err}");
    }
    let _ = std::fs::remove_dir_all(&dir);
}
