//! One range per physical input, the same in every command and file format (`src/limits.rs`):
//! pupil 1–9 mm, wavelength 380–1000 nm, vertical field of view 0.1–170°. Each case is refused
//! just outside the bound with exit 2 and a message that names the option or field and states
//! the one shared range; a value on the bound passes the same check.

use crate::common::{ocular_run, ok, temp_dir};
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

/// `eye measure` of the Navarro eye: the cheapest command that traces.
fn measure<'a>(pupil_mm: &'a str, wavelength_nm: &'a str) -> [&'a str; 7] {
    [
        "eye",
        "measure",
        "navarro",
        "--pupil-mm",
        pupil_mm,
        "--wavelength-nm",
        wavelength_nm,
    ]
}

/// `kernels` of the Navarro eye with one option set, written to `grid`.
fn kernels<'a>(option: &'a str, value: &'a str, grid: &'a str) -> [&'a str; 7] {
    ["kernels", "--eye", "navarro", option, value, "-o", grid]
}

/// A Zernike file in `dir` with no terms, only its pupil and wavelength.
fn zernike_file(dir: &std::path::Path, pupil_mm: &str, wavelength_nm: &str) -> PathBuf {
    let path = dir.join("z.toml");
    std::fs::write(
        &path,
        format!("pupil_diameter_mm = {pupil_mm}\nwavelength_nm = {wavelength_nm}\n"),
    )
    .unwrap();
    path
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
        refused(&measure(p, "555"), "pupil", PUPIL);
        let grid = dir.join("g.bin");
        refused(
            &kernels("--pupils-mm", p, grid.to_str().unwrap()),
            "pupils-mm",
            PUPIL,
        );
        let zernike = zernike_file(&dir, p, "555");
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
    // On the bound: the same checks pass.
    ok(&ocular_run(&measure("9", "555")));
}

#[test]
fn wavelength_range_is_the_same_everywhere() {
    let dir = temp_dir("wavelength");
    let out = dir.join("x.exr");
    let out = out.to_str().unwrap();
    for w in ["379", "1001"] {
        refused(&measure("4", w), "wavelength", WAVELENGTH);
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
        let wavelengths = format!("{w},549,464");
        refused(
            &kernels("--wavelengths-nm", &wavelengths, grid.to_str().unwrap()),
            "wavelengths-nm",
            WAVELENGTH,
        );
        let zernike = zernike_file(&dir, "5", w);
        refused(
            &["psf", "--zernike", zernike.to_str().unwrap(), "-o", out],
            "wavelength",
            WAVELENGTH,
        );
    }
    ok(&ocular_run(&measure("4", "1000")));
}

#[test]
fn field_of_view_range_is_the_same_everywhere() {
    let dir = temp_dir("fov");
    let out = dir.join("x.exr");
    let out = out.to_str().unwrap();
    for f in ["0.09", "170.5"] {
        let grid = dir.join("g.bin");
        refused(&kernels("--fov-y", f, grid.to_str().unwrap()), "fov-y", FOV);
        let scene = primitives_with(&dir, "fov_y_deg = 60.0", &format!("fov_y_deg = {f}"));
        refused(
            &["raster", "--scene", scene.to_str().unwrap(), "-o", out],
            "fov_y_deg",
            FOV,
        );
    }
}
