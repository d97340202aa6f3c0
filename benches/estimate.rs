//! Eye estimation on the seed paper's four test conditions: run time, RMS error of the achieved
//! coefficients and whether every parameter stays in bounds (no harness).
//!
//! `cargo bench --bench estimate` runs the default optimiser (hybrid);
//! `OCULAR_BENCH_GPS=1 cargo bench --bench estimate` adds the pattern-search reference, with
//! the time budgets (2 min, keratoconus 10 min) as its limits.
//! `OCULAR_BENCH_THREADS=N` sets the worker count (default: all cores).

use ocular::aberrations::preset;
use ocular::eye::{estimate, Method, Settings};
use std::sync::atomic::AtomicBool;

fn main() {
    let threads = std::env::var("OCULAR_BENCH_THREADS")
        .ok()
        .and_then(|t| t.parse().ok());
    let mut methods = vec![Method::Hybrid];
    if std::env::var_os("OCULAR_BENCH_GPS").is_some() {
        methods.push(Method::PatternSearch);
    }
    let only: Option<String> = std::env::args().skip(1).find(|a| !a.starts_with('-'));
    println!(
        "{:<12} {:<7} {:>8} {:>9} {:>11} {:>10} {:>10} {:>7} {:>9}",
        "condition",
        "method",
        "time s",
        "evals",
        "loss",
        "RMS µm",
        "given µm",
        "bounds",
        "converged"
    );
    for name in ["healthy", "myopia", "astigmatism", "keratoconus"] {
        if only.as_deref().is_some_and(|o| o != name) {
            continue;
        }
        let target = preset(name).expect("shipped preset");
        for &method in &methods {
            let budget = if name == "keratoconus" { 600.0 } else { 120.0 };
            let settings = Settings {
                method,
                threads,
                max_time_s: Some(budget),
                ..Settings::default()
            };
            let cancel = AtomicBool::new(false);
            let e = estimate(&target, &settings, &cancel, &mut |_| {}).expect("estimate runs");
            let r = &e.report;
            println!(
                "{:<12} {:<7} {:>8.2} {:>9} {:>11.4e} {:>10.5} {:>10.5} {:>7} {:>9}",
                name,
                r.method,
                r.time_s,
                r.evaluations,
                r.loss,
                r.rms_error_um,
                r.rms_error_given_um,
                if r.all_in_bounds { "yes" } else { "NO" },
                if r.converged { "yes" } else { "no" }
            );
        }
    }
    println!(
        "threads: {}; RMS over every term of orders 1-6 (absent terms target 0); \
         target: RMS <= 0.02 um, <= 120 s (keratoconus <= 600 s) on 2 cores",
        threads.unwrap_or_else(rayon::current_num_threads)
    );
}
