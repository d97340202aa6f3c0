//! Object samples get a PSF of their own only where the kernels need it
//! (src/psf/object_knots.rs): the rest are the blend of the computed samples around them.
//! Judged against every sample computed directly (tolerance 0), which shares the PSF and
//! pixel integration but not the choice of knots or the blend. The negative control is the
//! same rule with a tolerance so loose that the first knots, a dioptre apart, are kept.
//! Figures: `cargo test --release --test it object_knots:: -- --nocapture`.

use ocular::eye::resolve;
use ocular::psf::{
    compute_grid, level_count, level_of_radius, no_progress, DioptreAxis, GridAxes, KernelGrid,
    KernelSettings, Screen, DEFAULT_OBJECT_TOLERANCE, DEFAULT_WAVELENGTHS_NM,
};

const OBJECTS: usize = 161;

fn grid(eye: &str, pupil_mm: f64, focus_d: f64, tolerance: f64) -> (KernelGrid, usize) {
    let axes = GridAxes {
        // the default axis: 0–10 D in 1/16 D steps
        objects: DioptreAxis::spanning(0.0, 10.0, OBJECTS),
        focus_d: vec![focus_d],
        pupils_mm: vec![pupil_mm],
        wavelengths_nm: DEFAULT_WAVELENGTHS_NM,
    };
    let screen = Screen {
        fov_y_deg: 30.0,
        height_px: 360,
    };
    let settings = KernelSettings {
        object_tolerance: tolerance,
        ..KernelSettings::default()
    };
    let eye = resolve(eye).unwrap().eye;
    let (g, report) = compute_grid(&eye, &axes, &screen, &settings, &no_progress).unwrap();
    assert_eq!(report.psfs_computed + report.psfs_filled, OBJECTS * 3);
    (g, report.psfs_computed)
}

/// Worst L1 distance over objects and channels between two grids' kernels, each object at
/// the radius level around its own radius where a fragment at that distance reads it (both
/// levels around it), and the worst radius difference (px).
fn worst_distance(test: &KernelGrid, truth: &KernelGrid) -> (f64, f64, usize) {
    let (a, b) = (&test.sets[0], &truth.sets[0]);
    assert_eq!(test.max_radius_px, truth.max_radius_px);
    let (mut worst, mut worst_radius, mut at) = (0.0f64, 0.0f64, 0);
    for o in 0..a.objects.count {
        for c in 0..3 {
            let r = f64::from(b.radius_px[o][c]);
            worst_radius = worst_radius.max((f64::from(a.radius_px[o][c]) - r).abs());
            let l = level_of_radius(r).floor() as u32;
            for level in [l, l + 1] {
                if level >= level_count(test.max_radius_px) {
                    continue;
                }
                let d: f64 = a
                    .kernel(level, o)
                    .iter()
                    .zip(b.kernel(level, o))
                    .map(|(x, y)| f64::from((x[c] - y[c]).abs()))
                    .sum();
                if d > worst {
                    (worst, at) = (d, o);
                }
            }
        }
    }
    (worst, worst_radius, at)
}

#[test]
fn blended_samples_stay_within_the_tolerance_of_their_own_kernels() {
    for (eye, pupil_mm, focus_d) in [("healthy", 6.0, 0.5), ("keratoconus-like", 5.0, 0.5)] {
        let (dense, all) = grid(eye, pupil_mm, focus_d, 0.0);
        let (knots, computed) = grid(eye, pupil_mm, focus_d, DEFAULT_OBJECT_TOLERANCE);
        let (coarse, few) = grid(eye, pupil_mm, focus_d, 0.5);
        let (d, dr, at) = worst_distance(&knots, &dense);
        let (dc, drc, at_c) = worst_distance(&coarse, &dense);
        println!(
            "{eye}, {pupil_mm} mm, focus {focus_d} D: {computed} of {all} PSFs computed, worst \
             L1 {d:.4} at {:.3} D, radius {dr:.3} px; control (knots a dioptre apart, {few} \
             PSFs): L1 {dc:.4} at {:.3} D, radius {drc:.3} px",
            dense.objects.value_d(at),
            dense.objects.value_d(at_c)
        );
        assert_eq!(all, OBJECTS * 3);
        assert!(computed < all, "{eye}: nothing saved");
        // the rule holds the interval's midpoint to the tolerance; elsewhere the blend's
        // error is no larger to second order
        assert!(d <= 1.5 * DEFAULT_OBJECT_TOLERANCE, "{eye}: L1 {d}");
        assert!(
            dc > 1.5 * DEFAULT_OBJECT_TOLERANCE,
            "{eye}: control L1 {dc}"
        );
    }
}

#[test]
fn kernels_checks_the_tolerance() {
    let bin = env!("CARGO_BIN_EXE_ocular");
    for bad in ["0.9", "-1", "nan"] {
        let out = std::process::Command::new(bin)
            .args([
                "kernels",
                "--eye",
                "healthy",
                "--object-tolerance",
                bad,
                "-o",
            ])
            .arg(std::env::temp_dir().join("ocular-object-knots-bad.bin"))
            .output()
            .unwrap();
        assert_eq!(out.status.code(), Some(2), "{bad}");
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(
            err.contains("--object-tolerance") && err.lines().count() == 1,
            "{bad}: {err}"
        );
    }
}
