//! The seed paper's loss: L = Σ_k (w_f·f_k·(α̂_k − α_k))² + Σ_l (w_a·a_l·max(|x̄_l − x_l| − σ_l, 0))²,
//! kept as a residual vector so that least-squares refinement can use its structure.
//!
//! An eye the model cannot build (a lens that cannot close, a vignetted measurement) has an
//! infinite loss: the search treats it as outside the feasible set, which is how the
//! impossible corners of Table 1's box are excluded.

use super::params::ParamMap;
use crate::eye::measure::Measurer;
use crate::eye::model::Eye;
use crate::optics::zernike::{num_terms, osa_nm};
use std::cell::RefCell;

/// Weights of Zernike orders n = 1…6 (the authors' framework); higher orders reuse the last.
pub const ORDER_WEIGHTS: [f64; 6] = [0.5, 1.0, 1.0, 2.0, 4.0, 4.0];

/// What the eye must reproduce and how residuals are weighted.
#[derive(Debug, Clone)]
pub struct Objective {
    pub pupil_mm: f64,
    pub wavelength_nm: f64,
    /// Highest fitted order.
    pub order: u32,
    /// Target coefficients in OSA order (piston included but never fitted), µm.
    pub target_um: Vec<f64>,
    /// w_f·f_k for each OSA index (0 for piston).
    pub term_weight: Vec<f64>,
    pub w_a: f64,
}

impl Objective {
    pub fn new(
        pupil_mm: f64,
        wavelength_nm: f64,
        order: u32,
        target_um: Vec<f64>,
        w_f: f64,
        w_a: f64,
        order_weights: &[f64],
    ) -> Objective {
        let nt = num_terms(order);
        let mut target = target_um;
        target.resize(nt, 0.0);
        let term_weight = (0..nt)
            .map(|j| {
                let (n, _) = osa_nm(j);
                if n == 0 {
                    0.0
                } else {
                    let k = (n as usize - 1).min(order_weights.len() - 1);
                    w_f * order_weights[k]
                }
            })
            .collect();
        Objective {
            pupil_mm,
            wavelength_nm,
            order,
            target_um: target,
            term_weight,
            w_a,
        }
    }

    /// Fitted terms (piston excluded).
    pub fn terms(&self) -> usize {
        self.target_um.len() - 1
    }
}

/// Evaluates the loss for normalised parameter vectors; safe to share between threads (each
/// thread keeps its own eye and coefficient buffers).
pub struct Evaluator<'a> {
    pub map: &'a ParamMap,
    pub objective: &'a Objective,
    measurer: &'a Measurer,
}

struct Scratch {
    eye: Option<Eye>,
    coeffs: Vec<f64>,
    residuals: Vec<f64>,
}

thread_local! {
    static SCRATCH: RefCell<Scratch> = const {
        RefCell::new(Scratch { eye: None, coeffs: Vec::new(), residuals: Vec::new() })
    };
}

impl<'a> Evaluator<'a> {
    pub fn new(map: &'a ParamMap, objective: &'a Objective) -> Evaluator<'a> {
        Evaluator {
            map,
            objective,
            measurer: Measurer::for_order(objective.order),
        }
    }

    /// Length of the residual vector: fitted terms, then one per parameter.
    pub fn residual_len(&self) -> usize {
        self.objective.terms() + self.map.len()
    }

    /// Measured coefficients (µm, OSA order up to the objective's order) of the eye at
    /// `unit` into `coeffs`; false when the eye cannot be built or measured.
    pub fn coefficients(&self, unit: &[f64], coeffs: &mut [f64]) -> bool {
        SCRATCH.with(|s| {
            let s = &mut *s.borrow_mut();
            let eye = s.eye.get_or_insert_with(|| self.map.eye(unit));
            self.map.write_eye(unit, eye);
            let Ok(sys) = eye.system() else {
                return false;
            };
            let o = self.objective;
            let nm = num_terms(self.measurer.max_order());
            s.coeffs.resize(nm, 0.0);
            if self
                .measurer
                .coefficients_um(&sys, o.wavelength_nm, o.pupil_mm, None, &mut s.coeffs)
                .is_err()
            {
                return false;
            }
            let n = coeffs.len().min(nm);
            coeffs[..n].copy_from_slice(&s.coeffs[..n]);
            s.coeffs[..n].iter().all(|c| c.is_finite())
        })
    }

    /// Residuals at `unit` into `out` (length [`Self::residual_len`]); false when infeasible.
    pub fn residuals(&self, unit: &[f64], out: &mut [f64]) -> bool {
        let o = self.objective;
        let nt = o.target_um.len();
        let mut coeffs = [0.0; 66];
        if !self.coefficients(unit, &mut coeffs[..nt]) {
            return false;
        }
        for j in 1..nt {
            out[j - 1] = o.term_weight[j] * (coeffs[j] - o.target_um[j]);
        }
        let k = o.terms();
        for (i, (spec, &u)) in self.map.specs.iter().zip(unit).enumerate() {
            out[k + i] = spec.prior_residual(spec.denormalise(u), o.w_a);
        }
        true
    }

    /// The loss at `unit` (+∞ when infeasible).
    pub fn loss(&self, unit: &[f64]) -> f64 {
        let len = self.residual_len();
        let r = SCRATCH.with(|s| std::mem::take(&mut s.borrow_mut().residuals));
        let mut r = r;
        r.resize(len, 0.0);
        let value = if self.residuals(unit, &mut r) {
            r.iter().map(|v| v * v).sum::<f64>()
        } else {
            f64::INFINITY
        };
        SCRATCH.with(|s| s.borrow_mut().residuals = r);
        if value.is_finite() {
            value
        } else {
            f64::INFINITY
        }
    }

    /// Coefficient and prior parts of the loss at `unit`.
    pub fn loss_parts(&self, unit: &[f64]) -> (f64, f64) {
        let mut r = vec![0.0; self.residual_len()];
        if !self.residuals(unit, &mut r) {
            return (f64::INFINITY, f64::INFINITY);
        }
        let k = self.objective.terms();
        let sq = |v: &[f64]| v.iter().map(|x| x * x).sum::<f64>();
        (sq(&r[..k]), sq(&r[k..]))
    }
}
