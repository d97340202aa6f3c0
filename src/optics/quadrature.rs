//! Quadrature rules used by the ENZ engine and its tests.

use std::f64::consts::PI;

/// Gauss–Legendre nodes and weights mapped to [0, 1], nodes ascending. Exact for polynomials
/// of degree ≤ 2n − 1. Newton iteration on the Legendre recurrence from Tricomi-type starting
/// guesses; O(n²), fine up to several thousand nodes.
pub fn gauss_legendre_01(n: usize) -> (Vec<f64>, Vec<f64>) {
    let mut xs = vec![0.0; n];
    let mut ws = vec![0.0; n];
    let nf = n as f64;
    let half = n.div_ceil(2);
    for i in 0..half {
        let mut x = (PI * (i as f64 + 0.75) / (nf + 0.5)).cos();
        let mut dp = 1.0;
        for _ in 0..100 {
            let (mut p0, mut p1) = (1.0, x);
            for k in 2..=n {
                let kf = k as f64;
                let p2 = ((2.0 * kf - 1.0) * x * p1 - (kf - 1.0) * p0) / kf;
                p0 = p1;
                p1 = p2;
            }
            let (p, pm1) = if n == 1 { (x, 1.0) } else { (p1, p0) };
            dp = nf * (pm1 - x * p) / (1.0 - x * x);
            let dx = p / dp;
            x -= dx;
            if dx.abs() <= 1e-15 * x.abs().max(1e-3) {
                break;
            }
        }
        let w = 2.0 / ((1.0 - x * x) * dp * dp);
        // x is the i-th largest root; map to [0,1] ascending from both ends.
        xs[n - 1 - i] = 0.5 * (1.0 + x);
        ws[n - 1 - i] = 0.5 * w;
        xs[i] = 0.5 * (1.0 - x);
        ws[i] = 0.5 * w;
    }
    (xs, ws)
}

/// Nodes t_j = (1 + cos(π(K−j−½)/K))/2 on [0, 1] (ascending) and Fejér first-rule weights for
/// ∫₀¹ g(t) dt, exact for polynomials of degree < K. With t = ρ² these are the cosine-sampled
/// pupil radii ρ_j = cos(π(K−j−½)/(2K)), and ∫₀¹ G(ρ) ρ dρ = ½ ∫₀¹ G(√t) dt.
pub fn fejer1_01(k: usize) -> (Vec<f64>, Vec<f64>) {
    let kf = k as f64;
    let mut ts = vec![0.0; k];
    let mut ws = vec![0.0; k];
    for j in 0..k {
        let th = PI * (kf - j as f64 - 0.5) / kf;
        ts[j] = 0.5 * (1.0 + th.cos());
        let mut s = 0.0;
        for l in 1..=k / 2 {
            let lf = l as f64;
            s += (2.0 * lf * th).cos() / (4.0 * lf * lf - 1.0);
        }
        // Fejér weights on [−1,1] sum to 2; halve for [0,1].
        ws[j] = (1.0 / kf) * (1.0 - 2.0 * s);
    }
    (ts, ws)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn gauss_legendre_exact_for_polynomials() {
        for n in [1usize, 2, 5, 20, 101, 1500] {
            let (x, w) = gauss_legendre_01(n);
            let deg = (2 * n - 1).min(60) as i32;
            let s: f64 = x.iter().zip(&w).map(|(x, w)| w * x.powi(deg)).sum();
            assert!((s - 1.0 / (deg as f64 + 1.0)).abs() < 1e-13, "n={n}");
        }
    }

    #[test]
    fn fejer_exact() {
        let (t, w) = fejer1_01(12);
        for d in 0..12 {
            let s: f64 = t.iter().zip(&w).map(|(t, w)| w * t.powi(d)).sum();
            assert!((s - 1.0 / (d as f64 + 1.0)).abs() < 1e-14, "d={d}");
        }
    }
}
