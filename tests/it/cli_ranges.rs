//! One range per physical input, the same in every command and file format (`src/limits.rs`):
//! pupil 1–9 mm, wavelength 380–1000 nm, vertical field of view 0.1–170°. Each case is refused
//! just outside the bound with exit 2 and a message that names the option or field and states
//! the one shared range; a value on the bound passes the same check.

use crate::common::{ocular_run, temp_dir};
use std::path::PathBuf;

/// The primitives scene with one line replaced, written into `dir`.
fn primitives_with(dir: &std::path::Path, line: &str, by: &str) -> PathBuf {
    let text = std::fs::read_to_string(
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/primitives.toml"),
    )
    .unwrap();
    assert!(text.contains(line), "{line}");
    let path = dir.join("s.toml");
    std::fs::write(&path, text.replace(line, by)).unwrap();
    path
}

fn refused(args: &[&str], names: &str, allowed: &str) {
    let out = ocular_run(args);
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{args:?}: {err}");
    assert!(
        err.contains(names) && err.contains(allowed),
        "{args:?} should name {names:?} and {allowed:?}: {err}"
    );
    assert_eq!(err.trim().lines().count(), 1, "{args:?}: {err}");
}

const PUPIL: &str = "1 to 9 mm";
const WAVELENGTH: &str = "380 to 1000 nm";
const FOV: &str = "0.1 to 170 degrees";

#[test]
fn pupil_range_is_the_same_everywhere() {
    let dir = temp_dir("pupil");
    let png = dir.join("x.png");
    let png = png.to_str().unwrap();
    let exr = dir.join("x.exr");
    let out = exr.to_str().unwrap();
    for p in ["0.99", "9.01"] {
        refused(&["render", "--pupil-mm", p, "-o", png], "--pupil-mm", PUPIL);
        refused(
            &[
                "eye",
                "measure",
                "navarro",
                "--pupil-mm",
                p,
                "--wavelength-nm",
                "555",
            ],
            "pupil",
            PUPIL,
        );
        let grid = dir.join("g.bin");
        refused(
            &[
                "kernels",
                "--eye",
                "navarro",
                "--pupils-mm",
                p,
                "-o",
                grid.to_str().unwrap(),
            ],
            "pupils-mm",
            PUPIL,
        );
        let zernike = dir.join("z.toml");
        std::fs::write(
            &zernike,
            format!("pupil_diameter_mm = {p}\nwavelength_nm = 555\n"),
        )
        .unwrap();
        refused(
            &["psf", "--zernike", zernike.to_str().unwrap(), "-o", out],
            "pupil diameter",
            PUPIL,
        );
        let scene = primitives_with(
            &dir,
            "focus_m = 7.5",
            &format!("focus_m = 7.5\npupil_mm = {p}"),
        );
        refused(
            &["raster", "--scene", scene.to_str().unwrap(), "-o", out],
            "pupil_mm",
            PUPIL,
        );
    }
    // On the bound: the same checks pass (eye measure is the cheapest command that traces).
    let ok = ocular_run(&[
        "eye",
        "measure",
        "navarro",
        "--pupil-mm",
        "9",
        "--wavelength-nm",
        "555",
    ]);
    assert!(
        ok.status.success(),
        "{}",
        String::from_utf8_lossy(&ok.stderr)
    );
}

#[test]
fn wavelength_range_is_the_same_everywhere() {
    let dir = temp_dir("wavelength");
    let out = dir.join("x.exr");
    let out = out.to_str().unwrap();
    for w in ["379", "1001"] {
        refused(
            &[
                "eye",
                "measure",
                "navarro",
                "--pupil-mm",
                "4",
                "--wavelength-nm",
                w,
            ],
            "wavelength",
            WAVELENGTH,
        );
        refused(
            &[
                "psf",
                "--preset",
                "healthy",
                "--wavelength-nm",
                w,
                "-o",
                out,
            ],
            "--wavelength-nm",
            WAVELENGTH,
        );
        let grid = dir.join("g.bin");
        refused(
            &[
                "kernels",
                "--eye",
                "navarro",
                "--wavelengths-nm",
                &format!("{w},549,464"),
                "-o",
                grid.to_str().unwrap(),
            ],
            "wavelengths-nm",
            WAVELENGTH,
        );
        let zernike = dir.join("z.toml");
        std::fs::write(
            &zernike,
            format!("pupil_diameter_mm = 5\nwavelength_nm = {w}\n"),
        )
        .unwrap();
        refused(
            &["psf", "--zernike", zernike.to_str().unwrap(), "-o", out],
            "wavelength",
            WAVELENGTH,
        );
    }
    let ok = ocular_run(&[
        "eye",
        "measure",
        "navarro",
        "--pupil-mm",
        "4",
        "--wavelength-nm",
        "1000",
    ]);
    assert!(
        ok.status.success(),
        "{}",
        String::from_utf8_lossy(&ok.stderr)
    );
}

#[test]
fn field_of_view_range_is_the_same_everywhere() {
    let dir = temp_dir("fov");
    let out = dir.join("x.exr");
    let out = out.to_str().unwrap();
    for f in ["0.09", "170.5"] {
        let grid = dir.join("g.bin");
        refused(
            &[
                "kernels",
                "--eye",
                "navarro",
                "--fov-y",
                f,
                "-o",
                grid.to_str().unwrap(),
            ],
            "fov-y",
            FOV,
        );
        let scene = primitives_with(&dir, "fov_y_deg = 60.0", &format!("fov_y_deg = {f}"));
        refused(
            &["raster", "--scene", scene.to_str().unwrap(), "-o", out],
            "fov_y_deg",
            FOV,
        );
    }
}
