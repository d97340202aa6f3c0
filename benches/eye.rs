//! Prints the cost of one aberration measurement and one accommodation (no harness).
//! Run with `cargo bench --bench eye`.

use ocular::eye::{accommodate, ElevationTerm, Eye, Measurer};
use std::hint::black_box;
use std::time::Instant;

/// Nanoseconds this process has spent on a CPU (Linux), so that a busy shared machine
/// inflates the wall time but not this figure.
fn cpu_ns() -> Option<u64> {
    let s = std::fs::read_to_string("/proc/self/schedstat").ok()?;
    s.split_whitespace().next()?.parse().ok()
}

/// Prints wall and CPU time per call; returns the CPU time (wall where unavailable), seconds.
fn time<F: FnMut()>(label: &str, reps: usize, mut f: F) -> f64 {
    for _ in 0..reps.min(20) {
        f();
    }
    let c0 = cpu_ns();
    let t = Instant::now();
    for _ in 0..reps {
        f();
    }
    let wall = t.elapsed().as_secs_f64() / reps as f64;
    let cpu = match (c0, cpu_ns()) {
        (Some(a), Some(b)) => (b - a) as f64 * 1e-9 / reps as f64,
        _ => wall,
    };
    println!(
        "{label:<58} {:>9.1} µs wall {:>9.1} µs cpu",
        wall * 1e6,
        cpu * 1e6
    );
    cpu
}

fn main() {
    let m = Measurer::standard();
    println!(
        "measurement: {} rays, order {} fit, one core",
        m.rays(),
        m.max_order()
    );
    let plain = Eye::navarro().system().unwrap();
    let mut complex = Eye::population_mean();
    complex.cornea.anterior.radius_mm = [7.7, 7.9];
    complex.cornea.anterior.axis_deg = 20.0;
    complex.cornea.anterior.elevation = (1..=6u32)
        .flat_map(|n| (0..=n).map(move |k| (n, 2 * k as i32 - n as i32)))
        .map(|(n, mm)| ElevationTerm {
            n,
            m: mm,
            mm: 0.001,
        })
        .collect();
    complex.lens.decentration_mm = [0.2, -0.1];
    complex.lens.tilt_deg = [2.0, -1.0];
    let complex_sys = complex.system().unwrap();
    time("measure, Navarro eye, 6 mm, infinity", 2000, || {
        black_box(m.measure(&plain, 555.0, 6.0, None).unwrap());
    });
    let per = time(
        "measure, toric + order-6 elevation + tilted lens, 0.5 m",
        2000,
        || {
            black_box(m.measure(&complex_sys, 555.0, 6.0, Some(0.5)).unwrap());
        },
    );
    time("build system from parameters", 20000, || {
        black_box(complex.system().unwrap());
    });
    time(
        "accommodate Navarro eye to 0.2 m (4 mm, 555 nm)",
        200,
        || {
            black_box(accommodate(&Eye::navarro(), Some(0.2), 4.0, 555.0).unwrap());
        },
    );
    let hi = Measurer::for_order(10);
    time(
        &format!("measure order 10 ({} rays)", hi.rays()),
        300,
        || {
            black_box(hi.measure(&complex_sys, 555.0, 6.0, None).unwrap());
        },
    );
    println!(
        "target ≤ 1000 µs (cpu) per measurement: {}",
        if per <= 1e-3 { "met" } else { "MISSED" }
    );
}
