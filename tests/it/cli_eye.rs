//! `ocular eye …` end to end: estimation from a prescription (eye file, JSON, plot), an
//! interrupted run, presets, measurement JSON, drawing, and bad input refused with exit 2.

use crate::common::{self, eye_measure, json_ok, ocular, ocular_run, ok, temp_dir};
use std::path::PathBuf;
use std::process::{Command, Output};

/// Exit code 2, one line on stderr that starts `error:` and contains `word`.
fn refused(out: &Output, word: &str) {
    let err = common::refused(out, &[word]);
    assert!(err.starts_with("error:"), "expected {word:?} in {err}");
}

#[test]
fn estimate_from_prescription_writes_eye_json_and_plot() {
    let d = temp_dir("rx");
    let eye = d.join("eye.toml");
    let json = d.join("report.json");
    let svg = d.join("fit.svg");
    let png = d.join("fit.png");
    let s = |p: &PathBuf| p.to_str().unwrap().to_string();
    let out = ocular_run(&[
        "eye",
        "estimate",
        "--rx",
        "-3 -1 x 20",
        "--pupil-mm",
        "4",
        "-o",
        &s(&eye),
        "--json",
        &s(&json),
        "--plot",
        &s(&svg),
    ]);
    let text = ok(&out);
    assert!(text.contains("converged"), "{text}");
    let file = ocular::eye::load(&eye).unwrap();
    let r = file.estimate.expect("estimate record");
    assert!(r.converged && r.all_in_bounds);
    assert!(r.rms_error_um < 0.02);
    let j: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap();
    assert_eq!(j["estimate"]["converged"], true);
    assert!(j["eye"]["axial_length_mm"].as_f64().unwrap() > 20.0);
    assert!(std::fs::read_to_string(&svg).unwrap().contains("<svg"));
    // The file is an eye like any other.
    let shown = ok(&ocular_run(&["eye", "show", &s(&eye)]));
    assert!(shown.contains("estimated from a 4 mm"), "{shown}");
    let m = json_ok(&eye_measure(&s(&eye), "4", "549", &["--json"]));
    // "-3 -1 x 20" is a spectacle 12 mm in front of the cornea (taken at 549 nm): its
    // meridians −3 and −4 D reach the entrance pupil as P/(1 − dP), d = 12 mm + the pupil's
    // depth (which `eye refract` reports).
    let r: serde_json::Value =
        serde_json::from_str(&ok(&ocular_run(&["eye", "refract", &s(&eye), "--json"]))).unwrap();
    let d = (12.0 + r["eye_entrance_pupil_z_mm"].as_f64().unwrap()) * 1e-3;
    let at_pupil = |p: f64| p / (1.0 - d * p);
    let expected = 0.5 * (at_pupil(-3.0) + at_pupil(-4.0));
    let mm = m["refraction"]["m"].as_f64().unwrap();
    assert!(
        (mm - expected).abs() < 0.05,
        "M = {mm}, expected {expected}"
    );
    // PNG plot of the same run.
    ok(&ocular_run(&[
        "eye",
        "estimate",
        "--rx",
        "-1",
        "--pupil-mm",
        "4",
        "-o",
        &s(&eye),
        "--plot",
        &s(&png),
    ]));
    let bytes = std::fs::read(&png).unwrap();
    assert_eq!(&bytes[1..4], b"PNG");
}

#[test]
fn time_limit_writes_best_eye_marked_not_converged() {
    let d = temp_dir("limit");
    let eye = d.join("k.toml");
    let out = ocular_run(&[
        "eye",
        "estimate",
        "--preset",
        "keratoconus",
        "--max-time-s",
        "0.3",
        "-o",
        eye.to_str().unwrap(),
    ]);
    let text = ok(&out);
    assert!(text.contains("NOT converged"), "{text}");
    let file = ocular::eye::load(&eye).unwrap();
    assert!(!file.estimate.unwrap().converged);
    assert!(std::fs::read_to_string(&eye)
        .unwrap()
        .contains("NOT CONVERGED"));
}

#[test]
fn list_show_measure_draw() {
    let list = ok(&ocular_run(&["eye", "list"]));
    for name in [
        "navarro",
        "healthy",
        "myopia",
        "astigmatism",
        "keratoconus",
        "myopia3",
    ] {
        assert!(list.contains(name), "{name} missing from {list}");
    }
    for name in ["healthy", "myopia", "astigmatism", "keratoconus"] {
        let f = ocular::eye::preset(name).unwrap();
        let r = f.estimate.expect("estimated preset");
        assert!(r.converged && r.all_in_bounds, "{name}");
        assert!(r.rms_error_um <= 0.02, "{name}: {}", r.rms_error_um);
    }
    ok(&ocular_run(&["eye", "show", "myopia"]));
    let m = json_ok(&eye_measure("navarro", "6", "555", &["--json"]));
    let c40 = m["coefficients"]
        .as_array()
        .unwrap()
        .iter()
        .find(|c| c["n"] == 4 && c["m"] == 0)
        .unwrap()["um"]
        .as_f64()
        .unwrap();
    assert!((c40 - 0.239).abs() < 0.005, "c40 {c40}");
    assert!(m["power_d"].as_f64().unwrap() > 55.0);
    let d = temp_dir("draw");
    let svg = d.join("eye.svg");
    ok(&ocular_run(&[
        "eye",
        "draw",
        "navarro",
        "-o",
        svg.to_str().unwrap(),
    ]));
    assert!(std::fs::read_to_string(&svg).unwrap().starts_with("<svg"));
}

#[test]
fn bad_input_is_refused_with_exit_code_2() {
    let d = temp_dir("bad");
    let out = d.join("never.toml");
    let o = out.to_str().unwrap();
    let nan = d.join("nan.toml");
    std::fs::write(
        &nan,
        "pupil_diameter_mm = 5.0\nwavelength_nm = 555.0\n\n[[term]]\nn = 2\nm = 0\num = nan\n",
    )
    .unwrap();
    let unknown = d.join("unknown.toml");
    std::fs::write(
        &unknown,
        "pupil_diameter_mm = 5.0\nwavelength_nm = 555.0\n\n[[term]]\nn = 2\nm = 1\num = 0.1\n",
    )
    .unwrap();
    let bad_eye = d.join("bad_eye.toml");
    std::fs::write(&bad_eye, "axial_length_mm = 24.0\n").unwrap();
    let cases: Vec<(Vec<&str>, &str)> = vec![
        (vec!["--zernike", nan.to_str().unwrap()], "nan.toml"),
        (vec!["--zernike", unknown.to_str().unwrap()], "(2, 1)"),
        (
            vec!["--rx", "-2 -1 x 30", "--pupil-mm", "0.5"],
            "--pupil-mm",
        ),
        (
            vec!["--rx", "-2 -1 x 30", "--pupil-mm", "9.5"],
            "--pupil-mm",
        ),
        (
            vec!["--rx", "-2 -1 x 30", "--pupil-mm", "nan"],
            "--pupil-mm",
        ),
        (vec!["--rx", "-2 -1 x 30"], "--pupil-mm"),
        (vec!["--rx", "-2 -1", "--pupil-mm", "4"], "axis"),
        (vec!["--rx", "minus two", "--pupil-mm", "4"], "--rx"),
        (vec!["--rx", "-2 x 400", "--pupil-mm", "4"], "--rx"),
        (
            vec!["--rx", "-2", "--pupil-mm", "4", "--wavelength-nm", "nan"],
            "--wavelength-nm",
        ),
        (
            vec!["--rx", "-2", "--pupil-mm", "4", "--term", "2,1,0.1"],
            "--term",
        ),
        (
            vec!["--rx", "-2", "--pupil-mm", "4", "--max-time-s", "-1"],
            "time limit",
        ),
        (vec!["--preset", "nosuch"], "nosuch"),
    ];
    for (args, word) in cases {
        let mut all = vec!["eye", "estimate", "-o", o];
        all.extend(args.iter());
        refused(&ocular_run(&all), word);
        assert!(!out.exists(), "a refused run wrote {o}");
    }
    refused(
        &ocular_run(&["eye", "show", bad_eye.to_str().unwrap()]),
        "bad_eye.toml",
    );
    refused(&ocular_run(&["eye", "show", "no-such-eye"]), "no-such-eye");
    refused(&eye_measure("navarro", "12", "555", &[]), "--pupil-mm");
    refused(
        &eye_measure("navarro", "4", "555", &["--focus-m", "-1"]),
        "--focus-m",
    );
}

#[test]
fn ctrl_c_writes_best_eye_marked_not_converged() {
    let d = temp_dir("sigint");
    let eye = d.join("k.toml");
    let child = ocular()
        .args(["eye", "estimate", "--preset", "keratoconus", "-o"])
        .arg(&eye)
        .stdout(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    std::thread::sleep(std::time::Duration::from_millis(1500));
    let status = Command::new("kill")
        .args(["-INT", &child.id().to_string()])
        .status()
        .unwrap();
    assert!(status.success());
    let out = child.wait_with_output().unwrap();
    // Cancelled is not converged: the status is 128 + SIGINT, after the eye is written.
    assert_eq!(out.status.code(), Some(130));
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(
        text.contains("NOT converged (stopped: cancelled)"),
        "{text}"
    );
    let r = ocular::eye::load(&eye).unwrap().estimate.unwrap();
    assert!(!r.converged);
    assert_eq!(r.stop, "cancelled");
}
