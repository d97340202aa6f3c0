//! Accommodation: the lens diameter (at constant volume) that focuses a given distance.
//!
//! The criterion is c(2,0) = 0 over the given pupil at the given wavelength: with the other
//! terms fixed, Zernike defocus is the only second-order radially symmetric term, so its zero
//! is the focus of minimum RMS wavefront error, the same focus the PSF stage takes as its
//! reference (defocus relative to it goes into the ENZ defocus parameter). c(2,0) varies
//! smoothly and monotonically with the diameter, so a safeguarded secant converges in a few
//! steps, each a cheap 96-ray order-4 measurement.

use super::measure::Measurer;
use super::model::{Eye, EyeError};
use crate::optics::zernike::osa_index;
use std::sync::OnceLock;

/// Result of focusing an eye.
#[derive(Debug, Clone, PartialEq)]
pub struct Accommodation {
    pub eye: Eye,
    pub diameter_mm: f64,
    /// c(2,0) left at the target distance (µm), by the standard 1024-ray measurement.
    pub residual_c20_um: f64,
    /// The same as a refraction error (D).
    pub residual_d: f64,
    pub iterations: usize,
}

fn fast_measurer() -> &'static Measurer {
    static M: OnceLock<Measurer> = OnceLock::new();
    M.get_or_init(|| Measurer::new(4, 6, 16))
}

/// Focuses `eye` on an on-axis point at `object_distance_m` (from the corneal vertex; `None`
/// = infinity) for a `pupil_mm` entrance pupil at `wavelength_nm`.
pub fn accommodate(
    eye: &Eye,
    object_distance_m: Option<f64>,
    pupil_mm: f64,
    wavelength_nm: f64,
) -> Result<Accommodation, EyeError> {
    eye.validate()?;
    let meas = fast_measurer();
    let mut buf = [0.0; 15];
    let j20 = osa_index(2, 0);
    let mut c20 = |d: f64| -> Result<(f64, Eye), EyeError> {
        let e = eye.with_lens_diameter(d)?;
        let sys = e.system()?;
        meas.coefficients_um(&sys, wavelength_nm, pupil_mm, object_distance_m, &mut buf)?;
        Ok((buf[j20], e))
    };
    let d0 = eye.lens.diameter_mm;
    let (lo, hi) = (0.5 * d0, 1.6 * d0);
    let (mut x0, (mut g0, mut best)) = (d0, c20(d0)?);
    let mut x1 = d0 - 0.05;
    let (mut g1, mut e1) = c20(x1)?;
    let mut iterations = 2;
    let tol = 1e-6;
    while g1.abs() > tol {
        if iterations > 60 {
            return Err(EyeError::Invalid(format!(
                "accommodation did not converge (c(2,0) = {g1:.4} µm at lens diameter {x1:.4} mm)"
            )));
        }
        let slope = (g1 - g0) / (x1 - x0);
        if slope == 0.0 || !slope.is_finite() {
            break;
        }
        let mut x2 = (x1 - g1 / slope).clamp(lo, hi);
        // Halve the step until the lens can still be built at the new diameter.
        let mut trial = c20(x2);
        let mut halvings = 0;
        while trial.is_err() && halvings < 40 {
            x2 = 0.5 * (x1 + x2);
            trial = c20(x2);
            halvings += 1;
            iterations += 1;
        }
        let (g2, e2) = trial.map_err(|e| {
            EyeError::Invalid(format!(
                "cannot focus at {}: the lens cannot change enough ({e})",
                fmt_distance(object_distance_m)
            ))
        })?;
        iterations += 1;
        let stalled = (x2 - x1).abs() < 1e-12;
        x0 = x1;
        g0 = g1;
        x1 = x2;
        g1 = g2;
        e1 = e2;
        if stalled {
            break;
        }
    }
    best = if g1.abs() <= g0.abs() { e1 } else { best };
    let sys = best.system()?;
    let m = Measurer::standard().measure(&sys, wavelength_nm, pupil_mm, object_distance_m)?;
    let c = m.coefficient_um(2, 0);
    Ok(Accommodation {
        diameter_mm: best.lens.diameter_mm,
        eye: best,
        residual_c20_um: c,
        residual_d: -4.0 * 3f64.sqrt() * c / (pupil_mm / 2.0).powi(2),
        iterations,
    })
}

fn fmt_distance(d: Option<f64>) -> String {
    match d {
        Some(d) => format!("{d} m"),
        None => "infinity".into(),
    }
}
