//! PSF grid precomputation timings (run: `cargo bench --bench kernels`; `-- --quick` skips
//! the full grids, and so does `cargo test`, which runs this without `--bench` as a smoke
//! test; `-- --methods` times the two PSF methods against their cost estimates). The seed
//! paper's grid: 41 objects × 5 focus × 4 pupils × 3 wavelengths = 2460 PSFs, Rmax 48 (here
//! 720 px over a 30° field: the natural radii reach past 48 and are capped, as the paper's 48
//! is at 720p), and a single-frame column of 123 PSFs. Eyes: the shipped `keratoconus` preset
//! (estimated from the seed paper's measured keratoconus) and the hand-derived stand-ins of
//! `eye::hand_made_eyes`.

use ocular::eye::resolve;
use ocular::optics::{fft_cost, psf_by_fft, psf_from_pupil, PsfRequest};
use ocular::psf::{
    compute_grid, enz_cost, no_progress, psf_grid, ColumnOptics, GridAxes, GridReport,
    KernelSettings, Screen,
};
use std::time::Instant;

fn screen() -> Screen {
    Screen {
        fov_y_deg: 30.0,
        height_px: 720,
    }
}

fn settings() -> KernelSettings {
    KernelSettings {
        max_radius_cap: 48,
        ..KernelSettings::default()
    }
}

/// CPU seconds this process has used (user + system; Linux /proc), for figures that other
/// jobs on a shared machine do not inflate.
fn cpu_seconds() -> Option<f64> {
    let stat = std::fs::read_to_string("/proc/self/stat").ok()?;
    // fields after the parenthesised command name; utime and stime are the 12th and 13th
    let rest = stat.rsplit_once(')')?.1;
    let f: Vec<&str> = rest.split_whitespace().collect();
    let ticks: f64 = f.get(11)?.parse::<f64>().ok()? + f.get(12)?.parse::<f64>().ok()?;
    Some(ticks / 100.0)
}

fn run(eye_name: &str, axes: &GridAxes) -> (f64, Option<f64>, GridReport) {
    let eye = resolve(eye_name).expect("eye").eye;
    let t = Instant::now();
    let c = cpu_seconds();
    let (grid, report) = compute_grid(&eye, axes, &screen(), &settings(), &no_progress).unwrap();
    let s = t.elapsed().as_secs_f64();
    let cpu = cpu_seconds().zip(c).map(|(b, a)| b - a);
    drop(grid);
    (s, cpu, report)
}

/// Both methods on a few PSFs of the keratoconus eye whose β expansion converges: measured
/// seconds against the cost estimates that choose between them.
fn methods() {
    println!("| pupil mm | object D | β degree | grid side | ENZ s | FFT s | ENZ est / FFT est | measured ratio |");
    println!("|---|---|---|---|---|---|---|---|");
    let eye = resolve("keratoconus").expect("eye").eye;
    let s = settings();
    for pupil in [2.0, 3.0, 3.67] {
        let col = ColumnOptics::new(&eye, pupil, 0.125, [612.0, 549.0, 464.0], &s).unwrap();
        let ch = &col.channels[1];
        for object_d in [0.125, 2.0, 6.0] {
            let f = ch.defocus_f(object_d);
            let (pitch, half) = psf_grid(ch, f, &screen(), &s);
            let size = 2 * half + 1;
            let mut req = PsfRequest::new(Vec::new(), pupil, ch.wavelength_nm, pitch, size);
            req.include_tilt = false;
            req.radial_tolerance = s.radial_tolerance;
            req.defocus_f = f;
            let t = Instant::now();
            psf_from_pupil(&ch.pupil, &req).unwrap();
            let enz = t.elapsed().as_secs_f64();
            let t = Instant::now();
            psf_by_fft(&ch.alpha_um, ch.wavelength_nm, f, pitch, size).unwrap();
            let fft = t.elapsed().as_secs_f64();
            let degree = ch.pupil.beta.degree;
            println!(
                "| {pupil} | {object_d} | {degree} | {size} | {enz:.3} | {fft:.3} | {:.2} | {:.2} |",
                enz_cost(degree, size) / fft_cost(pitch, size),
                enz / fft
            );
        }
    }
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    if args.iter().any(|a| a == "--methods") {
        methods();
        return;
    }
    let quick = args.iter().any(|a| a == "--quick") || !args.iter().any(|a| a == "--bench");
    println!(
        "# PSF grid precomputation ({} threads, {})",
        rayon::current_num_threads(),
        std::env::consts::ARCH
    );
    println!("| eye | grid | PSFs | by FFT | seconds | CPU s | optics s | PSFs s | kernels s | Rmax (natural) | MiB per (focus, pupil) | worst missed energy |");
    println!("|---|---|---|---|---|---|---|---|---|---|---|---|");
    for eye in ["keratoconus", "myopia-like", "keratoconus-like"] {
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
            let (s, cpu, r) = run(eye, &axes);
            println!(
                "| {eye} | {label} | {} | {} | {s:.1} | {} | {:.1} | {:.1} | {:.1} | {} ({:.1}) | {:.1} | {:.1e} |",
                r.psfs_computed,
                r.psfs_fft,
                cpu.map_or("n/a".into(), |c| format!("{c:.1}")),
                r.seconds_optics,
                r.seconds_psfs,
                r.seconds_kernels,
                r.max_radius_px,
                r.natural_max_radius_px,
                r.bytes_per_set as f64 / (1 << 20) as f64,
                r.worst_missed_energy,
            );
            for w in &r.warnings {
                println!("warning: {w}");
            }
        }
    }
    if let Ok(load) = std::fs::read_to_string("/proc/loadavg") {
        println!("(load average at the end: {})", load.trim());
    }
    println!(
        "(paper: 196–622 s for the 2460 PSFs on 8 cores; 74 MB per (focus, pupil) pair at Rmax 48)"
    );
}
