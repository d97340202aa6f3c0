//! Speed/accuracy tables of the optics core (run: `cargo bench --bench optics`).
//! Single core throughout (no rayon). Each timing is reported twice: wall-clock and the CPU
//! time of this thread (Linux /proc), which stays meaningful on a busy machine.

use ocular::aberrations::preset;
use ocular::optics::{beta_from_alpha, compute_psf, split_wavefront, PsfRequest};
use std::time::Instant;

/// CPU seconds of this thread (user + system), or None off Linux.
fn cpu_seconds() -> Option<f64> {
    let s = std::fs::read_to_string("/proc/thread-self/stat").ok()?;
    let rest = &s[s.rfind(')')? + 2..];
    let f: Vec<&str> = rest.split_whitespace().collect();
    let ticks = f.get(11)?.parse::<f64>().ok()? + f.get(12)?.parse::<f64>().ok()?;
    Some(ticks / 100.0) // USER_HZ is 100 on Linux
}

/// Run `f` once to warm up, then until at least `min_s` of wall time has passed; returns the
/// last result, wall seconds per run and CPU seconds per run.
fn time<T>(min_s: f64, mut f: impl FnMut() -> T) -> (T, f64, f64) {
    let mut out = f();
    let c0 = cpu_seconds();
    let t = Instant::now();
    let mut reps = 0;
    while reps < 2 || t.elapsed().as_secs_f64() < min_s {
        out = f();
        reps += 1;
    }
    let wall = t.elapsed().as_secs_f64() / reps as f64;
    let cpu = match (c0, cpu_seconds()) {
        (Some(a), Some(b)) => (b - a) / reps as f64,
        _ => f64::NAN,
    };
    (out, wall, cpu)
}

fn main() {
    println!("# Zernike basis evaluation (all terms at one point, one core)");
    println!("| max order | terms | ns per call (values) | ns per call (values + gradients) |");
    println!("|---|---|---|---|");
    for order in [4u32, 6, 10, 20] {
        use ocular::optics::zernike::{basis_gradients, basis_values, num_terms};
        let nt = num_terms(order);
        let (mut z, mut gx, mut gy) = (vec![0.0; nt], vec![0.0; nt], vec![0.0; nt]);
        let calls = 200_000;
        let (_, wall_v, _) = time(0.2, || {
            let mut acc = 0.0;
            for i in 0..calls {
                let t = i as f64 * 1e-5;
                basis_values(order, 0.3 + t * 0.1, -0.5 + t * 0.2, &mut z);
                acc += z[nt - 1];
            }
            acc
        });
        let (_, wall_g, _) = time(0.2, || {
            let mut acc = 0.0;
            for i in 0..calls {
                let t = i as f64 * 1e-5;
                basis_values(order, 0.3 + t * 0.1, -0.5 + t * 0.2, &mut z);
                basis_gradients(order, 0.3 + t * 0.1, -0.5 + t * 0.2, &mut gx, &mut gy);
                acc += z[nt - 1] + gx[nt - 1];
            }
            acc
        });
        println!(
            "| {order} | {nt} | {:.0} | {:.0} |",
            wall_v / calls as f64 * 1e9,
            wall_g / calls as f64 * 1e9
        );
    }
    println!();
    println!("# beta expansion: degree vs truncation error vs time (one core)");
    println!(
        "| preset | wavelength nm | tolerance | degree | truncation error | wall ms | cpu ms |"
    );
    println!("|---|---|---|---|---|---|---|");
    for name in ["keratoconus", "astigmatism"] {
        let set = preset(name).unwrap();
        let split = split_wavefront(&set.coefficients, set.wavelength_nm, 0.0, true);
        for tol in [1e-2, 1e-3, 1e-4, 1e-6, 1e-8, 1e-10] {
            let (be, wall, cpu) = time(0.5, || {
                beta_from_alpha(
                    &split.alpha_um,
                    set.wavelength_nm,
                    set.pupil_diameter_mm,
                    None,
                    tol,
                    200,
                )
            });
            println!(
                "| {name} | {} | {tol:.0e} | {} | {:.2e} | {:.1} | {:.1} |",
                set.wavelength_nm,
                be.degree,
                be.truncation_error,
                wall * 1e3,
                cpu * 1e3
            );
        }
        // the seed paper's fixed cap
        let be = beta_from_alpha(
            &split.alpha_um,
            set.wavelength_nm,
            set.pupil_diameter_mm,
            None,
            1e-12,
            30,
        );
        println!(
            "| {name} | {} | cap 30 | {} | {:.2e} | | |",
            set.wavelength_nm, be.degree, be.truncation_error
        );
    }

    println!();
    println!("# one 256x256 PSF (one core): beta + radial coefficients/table + synthesis");
    println!("The preset's own c(2,0) is replaced by the f named; pitch spans the blur (|f|/pi) plus a margin.");
    println!("| preset | tolerance (degree) | f | pitch lambda/NA | radial evals (taps) | beta ms | coefficients ms | radial ms | synthesis ms | total wall ms | total cpu ms | energy in grid |");
    println!("|---|---|---|---|---|---|---|---|---|---|---|---|");
    // (preset, β tolerance, degree cap, include tilt)
    let cases: [(&str, f64, u32, bool); 6] = [
        ("healthy", 1e-8, 160, true),
        ("keratoconus", 1e-8, 160, true),
        ("keratoconus", 1e-8, 160, false),
        ("keratoconus", 1e-12, 30, false),
        ("astigmatism", 1e-8, 160, true),
        ("astigmatism", 1e-12, 30, true),
    ];
    for (name, tol, cap, tilt) in cases {
        let set = preset(name).unwrap();
        for f in [0.0, 100.0, 700.0] {
            let coeffs: Vec<_> = set
                .coefficients
                .iter()
                .cloned()
                .filter(|c| !(c.0 == 2 && c.1 == 0))
                .collect();
            let pitch = ((f / std::f64::consts::PI + 20.0) / 110.0).max(0.25);
            let mut req =
                PsfRequest::new(coeffs, set.pupil_diameter_mm, set.wavelength_nm, pitch, 256);
            req.defocus_f = f;
            req.beta_tolerance = tol;
            req.max_degree = cap;
            req.include_tilt = tilt;
            let (psf, wall, cpu) = time(1.0, || compute_psf(&req).unwrap());
            let mut label = if cap == 30 {
                "cap 30".to_string()
            } else {
                format!("{tol:.0e}")
            };
            if name == "keratoconus" && !tilt {
                label.push_str(", no tilt");
            }
            println!(
                "| {name} | {label} ({}) | {:.0} | {:.3} | {} ({}) | {:.1} | {:.1} | {:.1} | {:.1} | {:.1} | {:.1} | {:.4} |",
                psf.beta_degree,
                psf.defocus_f,
                pitch,
                psf.radial_nodes,
                psf.radial_taps,
                psf.seconds_beta * 1e3,
                psf.seconds_coefficients * 1e3,
                psf.seconds_table * 1e3,
                psf.seconds_synthesis * 1e3,
                wall * 1e3,
                cpu * 1e3,
                psf.energy_in_grid
            );
        }
    }
}
