//! `ocular psf` end to end: the EXR is normalised with the optical axis at (N/2, N/2), the
//! sidecar carries the inputs and accuracy figures, and bad input is exit 2 with no file.

use crate::common::{ocular, ok, temp_dir};

#[test]
fn healthy_psf_is_normalised_and_centred() {
    let dir = temp_dir("ok");
    let exr = dir.join("psf.exr");
    let png = dir.join("psf.png");
    let out = ocular()
        .args([
            "psf",
            "--preset",
            "healthy",
            "--pupil-mm",
            "3",
            "--wavelength-nm",
            "550",
            "--size",
            "65",
            "--pitch-arcmin",
            "0.2",
        ])
        .arg("-o")
        .arg(&exr)
        .arg("--png")
        .arg(&png)
        .output()
        .unwrap();
    ok(&out);
    let image = ocular::image_io::read_exr_depth(&exr).unwrap();
    assert_eq!((image.width, image.height), (65, 65));
    let total: f64 = image.pixels.iter().map(|&v| f64::from(v)).sum();
    assert!((total - 1.0).abs() < 1e-5, "sum {total}");
    let (argmax, _) = image
        .pixels
        .iter()
        .enumerate()
        .fold((0, 0.0f32), |b, (i, &v)| if v > b.1 { (i, v) } else { b });
    assert_eq!(
        (argmax % 65, argmax / 65),
        (32, 32),
        "peak not on the optical axis"
    );
    // Diffraction-limited Airy pattern: symmetric about the axis.
    let at = |x: usize, y: usize| image.pixels[y * 65 + x];
    assert!((at(32 + 5, 32) - at(32 - 5, 32)).abs() < 1e-6 * at(32, 32).max(1e-3));
    let sidecar: serde_json::Value =
        serde_json::from_slice(&std::fs::read(dir.join("psf.json")).unwrap()).unwrap();
    assert_eq!(sidecar["pupil_mm"], 3.0);
    assert_eq!(sidecar["optical_axis_pixel"], serde_json::json!([32, 32]));
    assert!(sidecar["strehl"].as_f64().unwrap() > 0.95);
    assert!(sidecar["beta_truncation_error"].as_f64().unwrap() <= 1e-8);
    assert!(png.exists());
}

#[test]
fn bad_inputs_fail_with_exit_2_and_write_nothing() {
    let dir = temp_dir("bad");
    let exr = dir.join("psf.exr");
    let nan_file = dir.join("nan.toml");
    std::fs::write(
        &nan_file,
        "pupil_diameter_mm = 5.0\nwavelength_nm = 550.0\n[[terms]]\nn = 2\nm = 0\num = nan\n",
    )
    .unwrap();
    let bad_term = dir.join("bad.abp");
    std::fs::write(&bad_term, "Ap = 5\nWa = 550\nZ[2, 1] = 0.3\n").unwrap();
    let cases: Vec<Vec<String>> = vec![
        vec![
            "--preset".into(),
            "healthy".into(),
            "--pupil-mm".into(),
            "0".into(),
        ],
        vec![
            "--preset".into(),
            "healthy".into(),
            "--pupil-mm".into(),
            "-3".into(),
        ],
        vec![
            "--preset".into(),
            "healthy".into(),
            "--wavelength-nm".into(),
            "200".into(),
        ],
        vec!["--preset".into(), "nope".into()],
        vec!["--zernike".into(), nan_file.display().to_string()],
        vec!["--zernike".into(), bad_term.display().to_string()],
        vec![
            "--zernike".into(),
            dir.join("missing.abp").display().to_string(),
        ],
    ];
    for case in cases {
        let out = ocular()
            .arg("psf")
            .args(&case)
            .arg("-o")
            .arg(&exr)
            .output()
            .unwrap();
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{case:?}: {stderr}");
        assert!(
            stderr.starts_with("error:") && stderr.trim().lines().count() == 1,
            "{case:?}: {stderr}"
        );
        assert!(!exr.exists(), "{case:?} left an output file");
    }
}
