//! The runtime looks a kernel up at the two radius levels around its radius and blends them.
//! Against the kernel drawn at its exact radius, the blend keeps r80 within 5 % wherever r80 is
//! at least half a pixel (quarter-pixel levels below 2 px); whole-pixel levels everywhere (the
//! old layout, the negative control) do not.

use crate::common;

use common::synthetic::SyntheticEye;
use ocular::psf::{kernel_side, level_block_radius, level_of_radius, level_radius_px};

/// A kernel as (block radius, values), normalised.
type Kernel = (u32, Vec<f64>);

fn draw(eye: &SyntheticEye, radius_px: f64) -> Kernel {
    let r = radius_px.ceil() as u32;
    let v = eye.kernel_values(1, 1.3, radius_px + 0.5, r);
    (r, v.into_iter().map(f64::from).collect())
}

/// Mix of two kernels drawn at radii `a` and `b` (b ≥ a), weights 1 − t and t.
fn mix(eye: &SyntheticEye, a: f64, b: f64, t: f64) -> Kernel {
    let (ka, kb) = (draw(eye, a), draw(eye, b));
    let r = kb.0.max(ka.0);
    let side = kernel_side(r);
    let mut out = vec![0.0; side * side];
    for (k, w) in [(ka, 1.0 - t), (kb, t)] {
        let inner = kernel_side(k.0);
        let off = (r - k.0) as usize;
        for (i, v) in k.1.iter().enumerate() {
            out[(i / inner + off) * side + i % inner + off] += w * v;
        }
    }
    (r, out)
}

/// Radius of the circle about the centroid holding 80 % of the energy, each pixel's energy
/// spread evenly over its area (12 × 12 sub-samples), interpolated between sub-sample distances.
fn r80(k: &Kernel) -> f64 {
    const SUB: usize = 12;
    let side = kernel_side(k.0);
    let c = k.0 as f64;
    let (mut mx, mut my) = (0.0, 0.0);
    for (i, v) in k.1.iter().enumerate() {
        mx += v * ((i % side) as f64 - c);
        my += v * ((i / side) as f64 - c);
    }
    let mut by_distance: Vec<(f64, f64)> = Vec::with_capacity(k.1.len() * SUB * SUB);
    for (i, v) in k.1.iter().enumerate() {
        for s in 0..SUB * SUB {
            let fx = ((s % SUB) as f64 + 0.5) / SUB as f64 - 0.5;
            let fy = ((s / SUB) as f64 + 0.5) / SUB as f64 - 0.5;
            let (x, y) = (
                (i % side) as f64 - c - mx + fx,
                (i / side) as f64 - c - my + fy,
            );
            by_distance.push((x.hypot(y), v / (SUB * SUB) as f64));
        }
    }
    by_distance.sort_by(|a, b| a.0.total_cmp(&b.0));
    let (mut acc, mut previous) = (0.0, 0.0);
    for (d, v) in by_distance {
        if acc + v >= 0.8 {
            let t = (0.8 - acc) / v;
            return previous + t * (d - previous);
        }
        acc += v;
        previous = d;
    }
    previous
}

#[test]
fn level_blends_keep_r80_within_5_percent() {
    let eye = SyntheticEye::new(0.0, 1.0);
    let (mut levels_worst, mut integer_worst) = (0.0f64, 0.0f64);
    let mut radius = 0.3;
    while radius <= 4.0 {
        let exact = r80(&draw(&eye, radius));
        if exact >= 0.5 {
            let l = level_of_radius(radius);
            let (l0, l1) = (l.floor() as u32, l.ceil() as u32);
            let levels = mix(
                &eye,
                level_radius_px(l0),
                level_radius_px(l1),
                l - l.floor(),
            );
            assert!(level_block_radius(l1) >= radius.ceil() as u32);
            let integers = mix(&eye, radius.floor(), radius.ceil(), radius.fract());
            levels_worst = levels_worst.max((r80(&levels) / exact - 1.0).abs());
            integer_worst = integer_worst.max((r80(&integers) / exact - 1.0).abs());
        }
        radius += 0.02;
    }
    eprintln!(
        "worst r80 error over radii 0.3–4 px: quarter-pixel levels {:.1} %, whole pixels {:.1} %",
        100.0 * levels_worst,
        100.0 * integer_worst
    );
    assert!(levels_worst < 0.05, "{levels_worst}");
    assert!(
        integer_worst > 0.05,
        "negative control: whole-pixel levels passed ({integer_worst})"
    );
}
