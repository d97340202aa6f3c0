//! Off axis at the boundary: `eye measure --field-deg` (JSON like on axis, plus the pupil it
//! used), its range checks, and the retina in eye files (old files load with the wide-angle
//! retina, a plane is accepted, bad radii and unknown shapes are refused).

use crate::common::{eye_measure, json_ok, ocular_run, ok, refused, temp_dir};
use ocular::eye::{Eye, Retina};
use std::process::Output;

fn measure_json(field: &str) -> serde_json::Value {
    json_ok(&eye_measure(
        "navarro-wide",
        "4",
        "555",
        &["--field-deg", field, "--json"],
    ))
}

#[test]
fn measure_off_axis_prints_the_on_axis_json_and_its_pupil() {
    let on = measure_json("0,0");
    let off = measure_json("-30,0");
    for key in [
        "coefficients",
        "refraction",
        "coefficients_um",
        "power_d",
        "rms_um",
    ] {
        assert!(off.get(key).is_some(), "{key} missing");
    }
    let j0 = off["refraction"]["j0"].as_f64().unwrap();
    assert!(j0 < -0.5, "30° horizontally: J0 {j0}");
    assert!(on["refraction"]["j0"].as_f64().unwrap().abs() < 1e-6);
    let axes = off["field"]["semi_axes_mm"].as_array().unwrap();
    let (t, s) = (axes[0].as_f64().unwrap(), axes[1].as_f64().unwrap());
    // Foreshortened tangentially (≈ cos 30° times a little magnification), not sagittally.
    assert!(t < 0.95 * s && t > 0.8 * s, "ellipse {t} × {s}");
    // A vertical field turns the astigmatism's axis: J0 changes sign.
    let up = measure_json("0,30");
    assert!((up["refraction"]["j0"].as_f64().unwrap() + j0).abs() < 1e-6);
}

#[test]
fn field_option_is_range_checked() {
    for bad in ["61,0", "0,-70", "55,55", "nan,0", "10", "a,b", "1,2,3"] {
        let out = eye_measure("navarro-wide", "4", "555", &["--field-deg", bad]);
        refused(&out, &["--field-deg"]);
    }
}

#[test]
fn eye_files_carry_a_retina_shape() {
    let old = Eye::navarro().to_toml_string();
    assert!(!old.contains("retina"), "the default retina is not written");
    assert_eq!(
        Eye::from_toml_str(&old).unwrap().retina,
        Retina::Sphere { radius_mm: 12.0 }
    );
    let plane = format!("{old}\n[retina]\nshape = \"plane\"\n");
    assert_eq!(Eye::from_toml_str(&plane).unwrap().retina, Retina::Plane);
    let sphere = format!("{old}\n[retina]\nshape = \"sphere\"\nradius_mm = 11.0\n");
    let e = Eye::from_toml_str(&sphere).unwrap();
    assert_eq!(e.retina, Retina::Sphere { radius_mm: 11.0 });
    assert!(Eye::from_toml_str(&e.to_toml_string()).unwrap() == e);
    let small = format!("{old}\n[retina]\nshape = \"sphere\"\nradius_mm = 2.0\n");
    let err = Eye::from_toml_str(&small).unwrap_err().to_string();
    assert!(err.contains("retina.radius_mm"), "{err}");
    let odd = format!("{old}\n[retina]\nshape = \"cone\"\n");
    assert!(Eye::from_toml_str(&odd).is_err());
    let extra = format!("{old}\n[retina]\nshape = \"plane\"\nradius_mm = 3.0\n");
    assert!(Eye::from_toml_str(&extra).is_err());
    // The wide-angle preset: 23.9203 mm long, the 12 mm sphere.
    let w = Eye::preset("navarro-wide").unwrap();
    assert!((w.axial_length_mm - 23.9203).abs() < 1e-9);
    assert_eq!(w.retina, Retina::Sphere { radius_mm: 12.0 });
}

fn kernels(dir: &std::path::Path, extra: &[&str]) -> Output {
    let mut args = vec![
        "kernels",
        "--eye",
        "navarro-wide",
        "--objects",
        "0..2:3",
        "--focus-d",
        "0",
        "--pupils-mm",
        "4",
        "--fov-y",
        "40",
        "--height",
        "180",
    ];
    args.extend_from_slice(extra);
    let cache = dir.join("cache");
    let cache = cache.to_str().unwrap().to_string();
    if !extra.contains(&"--no-cache") {
        args.extend_from_slice(&["--cache", &cache]);
    }
    ocular_run(&args)
}

/// Grids over the field: an index and one grid per direction, each cached on its own (a
/// second run computes nothing); the centre is the on-axis grid, bit for bit; off axis the
/// in-focus kernel is larger (oblique astigmatism and coma).
#[test]
fn kernels_over_the_field_are_written_and_cached_per_direction() {
    use ocular::psf::read_grid;
    let dir = temp_dir("field");
    let index = dir.join("field.toml");
    let field = [
        "--field-deg",
        "-30..30:3,0..0:1",
        "-o",
        index.to_str().unwrap(),
    ];
    ok(&kernels(&dir, &field));
    let text = std::fs::read_to_string(&index).unwrap();
    assert_eq!(text.matches("[[node]]").count(), 3);
    assert_eq!(text.matches("cached = false").count(), 3);
    assert!(kernels(&dir, &field).status.success());
    let text = std::fs::read_to_string(&index).unwrap();
    assert_eq!(text.matches("cached = true").count(), 3, "{text}");
    let plain = dir.join("plain.bin");
    assert!(
        kernels(&dir, &["--no-cache", "-o", plain.to_str().unwrap()])
            .status
            .success()
    );
    let centre = read_grid(&dir.join("field.h1.v0.bin"), None).unwrap();
    let on_axis = read_grid(&plain, None).unwrap();
    assert!(centre.sets[0].texels == on_axis.sets[0].texels);
    let side = read_grid(&dir.join("field.h2.v0.bin"), None).unwrap();
    let mirror = read_grid(&dir.join("field.h0.v0.bin"), None).unwrap();
    let r = |g: &ocular::psf::KernelGrid| g.sets[0].radius_px[0][1];
    assert!(
        r(&side) > r(&centre) + 0.5,
        "{} vs {}",
        r(&side),
        r(&centre)
    );
    // mirror images up to the resampling grid's asymmetry (a few thousandths of a pixel)
    assert!((r(&side) - r(&mirror)).abs() < 0.02);
    // Bad ranges and options are refused at the parser.
    for bad in [
        vec!["--field-deg", "-61..0:2,0..0:1"],
        vec!["--field-deg", "0..10:40,0..0:1"],
        vec!["--field-deg", "0..10"],
    ] {
        let mut a = bad.clone();
        a.extend_from_slice(&["-o", index.to_str().unwrap()]);
        refused(&kernels(&dir, &a), &["--field-deg"]);
    }
    // auto: the frame's range (160 × 180 px at 40°) at measured steps.
    let auto = dir.join("auto.toml");
    let out = kernels(
        &dir,
        &[
            "--field-deg",
            "auto",
            "--width",
            "160",
            "-o",
            auto.to_str().unwrap(),
        ],
    );
    ok(&out);
    let idx: toml::Table = std::fs::read_to_string(&auto).unwrap().parse().unwrap();
    let first = |k: &str| idx[k].as_array().unwrap()[0].as_float().unwrap();
    let h = (20f64.to_radians().tan() * 160.0 / 180.0)
        .atan()
        .to_degrees();
    assert!((first("h_deg") + h).abs() < 1e-9 && (first("v_deg") + 20.0).abs() < 1e-9);
    assert!(String::from_utf8_lossy(&out.stderr).contains("field plan:"));
    refused(
        &kernels(
            &dir,
            &[
                "--width",
                "8",
                "--field-deg",
                "auto",
                "-o",
                auto.to_str().unwrap(),
            ],
        ),
        &["--width"],
    );
    let png = dir.join("p.png");
    let mut a = vec![
        "--field-deg",
        "0..10:2,0..0:1",
        "-o",
        index.to_str().unwrap(),
    ];
    a.extend_from_slice(&["--preview", png.to_str().unwrap()]);
    refused(&kernels(&dir, &a), &["--field-deg"]);
    let _ = std::fs::remove_dir_all(&dir);
}

/// `--off-axis` where it has no meaning is an input error before any kernel is computed:
/// the slice method and the views truth stay on axis.
#[test]
fn off_axis_is_refused_where_it_does_not_apply() {
    let dir = temp_dir("refused");
    let png = dir.join("x.png");
    let out = ocular_run(&[
        "render",
        "--scene",
        "primitives",
        "--size",
        "64x36",
        "--method",
        "slices",
        "--off-axis",
        "--no-cache",
        "-o",
        png.to_str().unwrap(),
    ]);
    refused(&out, &["--off-axis"]);
    assert!(!png.exists(), "no output for a refused render");
    let out = ocular_run(&[
        "compare",
        "--scene",
        "primitives",
        "--size",
        "64x36",
        "--truth",
        "views",
        "--off-axis",
        "--no-cache",
    ]);
    refused(&out, &["--off-axis"]);
    std::fs::remove_dir_all(&dir).ok();
}
