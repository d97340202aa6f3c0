//! Box-constrained Levenberg–Marquardt on the loss's residual vector.
//!
//! The loss is a sum of squares whose coefficient part is smooth in the eye parameters, so a
//! Gauss–Newton model predicts it far better than the axis-by-axis probing of pattern search:
//! a handful of Jacobians (N + 1 evaluations each, in parallel) brings the loss down by orders
//! of magnitude. Bounds are handled by an active set: a variable sitting on a bound whose
//! gradient pushes it outwards is frozen for that step; steps are projected onto the box.
//! Variables the residuals do not see (flat Jacobian column) get a small ridge so the normal
//! equations stay solvable; the damping λ scales with diag(JᵀJ) (Marquardt's form).

use super::pattern_search::{Limits, Outcome, Stop};
use nalgebra::{DMatrix, DVector};
use rayon::prelude::*;

#[derive(Debug, Clone, Copy)]
pub struct LmSettings {
    pub max_iterations: usize,
    /// Finite-difference step in normalised units.
    pub step: f64,
    /// Stop when an accepted step lowers the loss by less than this fraction…
    pub rel_tolerance: f64,
    /// …or the loss falls below this.
    pub abs_tolerance: f64,
}

impl Default for LmSettings {
    fn default() -> Self {
        LmSettings {
            max_iterations: 60,
            step: 1e-6,
            rel_tolerance: 1e-3,
            abs_tolerance: 1e-12,
        }
    }
}

/// Minimises Σ r(x)² over [lower, upper]; `r` writes `m` residuals and returns false where
/// the point is infeasible.
#[allow(clippy::too_many_arguments)]
pub fn levenberg_marquardt<R>(
    r: &R,
    m: usize,
    x0: &[f64],
    lower: &[f64],
    upper: &[f64],
    settings: &LmSettings,
    limits: &Limits,
    progress: &mut dyn FnMut(&Outcome),
) -> Outcome
where
    R: Fn(&[f64], &mut [f64]) -> bool + Sync,
{
    let n = x0.len();
    let mut x = x0.to_vec();
    let mut res = vec![0.0; m];
    let mut out = Outcome {
        x: x.clone(),
        f: f64::INFINITY,
        evaluations: 1,
        iterations: 0,
        mesh: 1e-3,
        stop: Stop::Converged,
    };
    if !r(&x, &mut res) {
        out.stop = Stop::Infeasible;
        return out;
    }
    let sq = |v: &[f64]| v.iter().map(|a| a * a).sum::<f64>();
    let mut f = sq(&res);
    out.f = f;
    let mut lambda = 1e-3;
    let mut stalls = 0;
    for _ in 0..settings.max_iterations {
        if let Some(stop) = limits.check(out.evaluations) {
            out.stop = stop;
            return out;
        }
        if f <= settings.abs_tolerance {
            break;
        }
        // Forward differences, backwards where the forward point leaves the box or the
        // feasible set.
        let cols: Vec<(Option<Vec<f64>>, usize)> = (0..n)
            .into_par_iter()
            .map(|i| {
                let mut xi = x.clone();
                let mut buf = vec![0.0; m];
                let mut evals = 0;
                for h in [settings.step, -settings.step] {
                    let v = x[i] + h;
                    if v < lower[i] || v > upper[i] {
                        continue;
                    }
                    xi[i] = v;
                    evals += 1;
                    if r(&xi, &mut buf) {
                        let col = buf.iter().zip(&res).map(|(a, b)| (a - b) / h).collect();
                        return (Some(col), evals);
                    }
                }
                (None, evals)
            })
            .collect();
        out.evaluations += cols.iter().map(|c| c.1).sum::<usize>();
        let cols: Vec<Option<Vec<f64>>> = cols.into_iter().map(|c| c.0).collect();
        let mut j = DMatrix::<f64>::zeros(m, n);
        for (i, c) in cols.iter().enumerate() {
            if let Some(c) = c {
                for (k, v) in c.iter().enumerate() {
                    j[(k, i)] = *v;
                }
            }
        }
        let rv = DVector::from_column_slice(&res);
        let g = j.transpose() * &rv;
        let jtj = j.transpose() * &j;
        let free: Vec<usize> = (0..n)
            .filter(|&i| {
                cols[i].is_some()
                    && !(x[i] <= lower[i] && g[i] > 0.0)
                    && !(x[i] >= upper[i] && g[i] < 0.0)
            })
            .collect();
        if free.is_empty() {
            break;
        }
        let scale = (0..n)
            .map(|i| jtj[(i, i)])
            .fold(0.0f64, f64::max)
            .max(1e-30);
        let mut accepted = false;
        for _ in 0..12 {
            let k = free.len();
            let mut a = DMatrix::<f64>::zeros(k, k);
            let mut b = DVector::<f64>::zeros(k);
            for (p, &i) in free.iter().enumerate() {
                b[p] = -g[i];
                for (q, &l) in free.iter().enumerate() {
                    a[(p, q)] = jtj[(i, l)];
                }
                a[(p, p)] += lambda * jtj[(i, i)] + 1e-12 * scale;
            }
            let Some(chol) = a.cholesky() else {
                lambda *= 10.0;
                continue;
            };
            let d = chol.solve(&b);
            let mut xn = x.clone();
            for (p, &i) in free.iter().enumerate() {
                xn[i] = (x[i] + d[p]).clamp(lower[i], upper[i]);
            }
            let mut rn = vec![0.0; m];
            out.evaluations += 1;
            if r(&xn, &mut rn) {
                let fn_ = sq(&rn);
                if fn_ < f {
                    let gain = (f - fn_) / f;
                    x = xn;
                    res = rn;
                    f = fn_;
                    lambda = (lambda / 3.0).max(1e-12);
                    accepted = true;
                    stalls = if gain < settings.rel_tolerance {
                        stalls + 1
                    } else {
                        0
                    };
                    break;
                }
            }
            lambda *= 4.0;
            if let Some(stop) = limits.check(out.evaluations) {
                out.stop = stop;
                out.x = x;
                out.f = f;
                return out;
            }
        }
        out.iterations += 1;
        out.x.clone_from(&x);
        out.f = f;
        out.mesh = lambda;
        progress(&out);
        if !accepted || stalls >= 3 {
            break;
        }
    }
    out.x = x;
    out.f = f;
    out.stop = Stop::Converged;
    out
}
