//! Pupil sampling and the precomputed Zernike least-squares operator used by measurement.
//!
//! The pupil is sampled on Gauss–Legendre rings in ρ² (equal-area radial quadrature) times
//! uniform azimuths, so the weighted least-squares fit coincides with the exact projection onto
//! the orthonormal Zernikes for every term the fit holds, and aliasing from higher orders is
//! only what the quadrature leaves. The operator (BᵀWB)⁻¹BᵀW is built once per pattern; a
//! fit is then one matrix–vector product.

use crate::optics::zernike::{basis_values, num_terms};
use nalgebra::DMatrix;

/// Gauss–Legendre nodes and weights on [0, 1].
pub fn gauss_legendre_01(n: usize) -> Vec<(f64, f64)> {
    let mut out = Vec::with_capacity(n);
    for i in 0..n {
        let mut x = (std::f64::consts::PI * (i as f64 + 0.75) / (n as f64 + 0.5)).cos();
        let mut dp = 1.0;
        for _ in 0..100 {
            let (mut p0, mut p1) = (1.0, x);
            for k in 2..=n {
                let p2 = ((2 * k - 1) as f64 * x * p1 - (k - 1) as f64 * p0) / k as f64;
                p0 = p1;
                p1 = p2;
            }
            let pn = if n == 0 { 1.0 } else { p1 };
            let pn1 = if n == 0 { 0.0 } else { p0 };
            dp = n as f64 * (x * pn - pn1) / (x * x - 1.0);
            let dx = pn / dp;
            x -= dx;
            if dx.abs() < 1e-15 {
                break;
            }
        }
        let w = 2.0 / ((1.0 - x * x) * dp * dp);
        out.push(((1.0 - x) / 2.0, w / 2.0));
    }
    out.sort_by(|a, b| a.0.partial_cmp(&b.0).unwrap());
    out
}

/// Weighted least-squares operator for `points` (unit disk) and `weights`: a terms × points
/// row-major matrix P with c = P·w. `None` if the points do not determine every term.
pub fn fit_operator(order: u32, points: &[[f64; 2]], weights: &[f64]) -> Option<Vec<f64>> {
    let nt = num_terms(order);
    let np = points.len();
    let mut b = vec![0.0; nt * np];
    let mut z = vec![0.0; nt];
    for (i, p) in points.iter().enumerate() {
        basis_values(order, p[0], p[1], &mut z);
        for j in 0..nt {
            b[j * np + i] = z[j];
        }
    }
    // BᵀWB; the factorisation reads its lower triangle only
    let mut a = DMatrix::<f64>::zeros(nt, nt);
    for j in 0..nt {
        for l in 0..=j {
            a[(j, l)] = (0..np)
                .map(|i| b[j * np + i] * b[l * np + i] * weights[i])
                .sum();
        }
    }
    // None when BᵀWB is not positive definite: the points do not determine every term
    let chol = a.cholesky()?;
    let mut rhs = DMatrix::from_fn(nt, np, |j, i| b[j * np + i] * weights[i]);
    chol.solve_mut(&mut rhs);
    // nalgebra stores column-major; the operator is row-major
    Some(rhs.transpose().as_slice().to_vec())
}

/// A fixed pupil sampling with its fit operator.
#[derive(Debug, Clone)]
pub struct PupilPattern {
    pub order: u32,
    pub points: Vec<[f64; 2]>,
    pub weights: Vec<f64>,
    pub operator: Vec<f64>,
}

impl PupilPattern {
    /// `rings` Gauss–Legendre rings in ρ², `spokes` azimuths each (offset by half a step on
    /// alternate rings to spread the samples).
    pub fn new(order: u32, rings: usize, spokes: usize) -> PupilPattern {
        let mut points = Vec::with_capacity(rings * spokes);
        let mut weights = Vec::with_capacity(rings * spokes);
        for (r, (s, w)) in gauss_legendre_01(rings).into_iter().enumerate() {
            let rho = s.sqrt();
            let off = if r % 2 == 1 { 0.5 } else { 0.0 };
            for k in 0..spokes {
                let th = 2.0 * std::f64::consts::PI * (k as f64 + off) / spokes as f64;
                points.push([rho * th.cos(), rho * th.sin()]);
                weights.push(w / spokes as f64);
            }
        }
        let operator = fit_operator(order, &points, &weights)
            .expect("ring pattern must determine every Zernike term of its order");
        PupilPattern {
            order,
            points,
            weights,
            operator,
        }
    }

    pub fn terms(&self) -> usize {
        num_terms(self.order)
    }

    /// Coefficients from wavefront samples at `points` (same units).
    pub fn fit(&self, values: &[f64], out: &mut [f64]) {
        let np = self.points.len();
        for (j, o) in out.iter_mut().enumerate().take(self.terms()) {
            let row = &self.operator[j * np..(j + 1) * np];
            *o = row.iter().zip(values).map(|(a, b)| a * b).sum();
        }
    }

    /// Fit from the samples flagged valid only (slow path for partly vignetted pupils).
    pub fn fit_subset(&self, values: &[f64], valid: &[bool], out: &mut [f64]) -> bool {
        let mut pts = Vec::new();
        let mut ws = Vec::new();
        let mut vs = Vec::new();
        for i in 0..self.points.len() {
            if valid[i] {
                pts.push(self.points[i]);
                ws.push(self.weights[i]);
                vs.push(values[i]);
            }
        }
        let Some(op) = fit_operator(self.order, &pts, &ws) else {
            return false;
        };
        let np = pts.len();
        for (j, o) in out.iter_mut().enumerate().take(self.terms()) {
            *o = (0..np).map(|i| op[j * np + i] * vs[i]).sum();
        }
        true
    }
}
