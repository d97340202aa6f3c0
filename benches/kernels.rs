//! PSF grid precomputation timings (run: `cargo bench --bench kernels`; `-- --quick` skips
//! the full grids, and so does `cargo test`, which runs this without `--bench` as a smoke
//! test). The seed paper's grid: 41 objects × 5 focus × 4 pupils × 3 wavelengths =
//! 2460 PSFs, Rmax 48 (here 720 px over a 30° field: the natural radii reach past 48 and are
//! capped, as the paper's 48 is at 720p), and a single-frame column of 123 PSFs.
//! The eyes are the hand-derived stand-ins of `eye::test_eyes` (no estimated presets yet).

use ocular::eye::test_eyes::test_eye;
use ocular::psf::axes::{GridAxes, KernelSettings, Screen};
use ocular::psf::grid::{compute_grid, no_progress, GridReport};
use std::time::Instant;

fn run(eye_name: &str, axes: &GridAxes) -> (f64, GridReport) {
    let eye = test_eye(eye_name).expect("test eye");
    let screen = Screen {
        fov_y_deg: 30.0,
        height_px: 720,
    };
    let settings = KernelSettings {
        max_radius_cap: 48,
        ..KernelSettings::default()
    };
    let t = Instant::now();
    let (grid, report) = compute_grid(&eye, axes, &screen, &settings, &no_progress).unwrap();
    let s = t.elapsed().as_secs_f64();
    drop(grid);
    (s, report)
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let quick = args.iter().any(|a| a == "--quick") || !args.iter().any(|a| a == "--bench");
    println!(
        "# PSF grid precomputation ({} threads, {})",
        rayon::current_num_threads(),
        std::env::consts::ARCH
    );
    println!("| eye | grid | PSFs | seconds | optics s | PSFs s | kernels s | Rmax (natural) | MiB per (focus, pupil) | worst β truncation |");
    println!("|---|---|---|---|---|---|---|---|---|---|");
    for eye in ["myopia-like", "keratoconus-like"] {
        let mut cases = vec![(
            "column, pupil 4 mm, focus 0.125 D",
            GridAxes {
                focus_d: vec![0.125],
                pupils_mm: vec![4.0],
                ..GridAxes::default()
            },
        )];
        if !quick {
            cases.push((
                "column, pupil 7 mm, focus 0.125 D",
                GridAxes {
                    focus_d: vec![0.125],
                    pupils_mm: vec![7.0],
                    ..GridAxes::default()
                },
            ));
            cases.push(("full (paper)", GridAxes::default()));
        }
        for (label, axes) in cases {
            let (s, r) = run(eye, &axes);
            let worst = r
                .columns
                .iter()
                .flat_map(|c| c.beta_truncation_error)
                .fold(0.0f64, f64::max);
            println!(
                "| {eye} | {label} | {} | {s:.1} | {:.1} | {:.1} | {:.1} | {} ({:.1}) | {:.1} | {worst:.1e} |",
                r.psfs_computed,
                r.seconds_optics,
                r.seconds_psfs,
                r.seconds_kernels,
                r.max_radius_px,
                r.natural_max_radius_px,
                r.bytes_per_set as f64 / (1 << 20) as f64,
            );
        }
    }
    println!(
        "(paper: 196–622 s for the 2460 PSFs on 8 cores; 74 MB per (focus, pupil) pair at Rmax 48)"
    );
}
