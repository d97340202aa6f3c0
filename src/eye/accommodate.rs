//! Accommodation: the lens diameter (at constant volume) that focuses a given distance.
//!
//! The criterion is c(2,0) = 0 over the given pupil at the given wavelength: with the other
//! terms fixed, Zernike defocus is the only second-order radially symmetric term, so its zero
//! is the focus of minimum RMS wavefront error, the same focus the PSF stage takes as its
//! reference (defocus relative to it goes into the ENZ defocus parameter). c(2,0) varies
//! smoothly and monotonically with the diameter, so a safeguarded secant converges in a few
//! steps, each a cheap 96-ray order-4 measurement.

use super::error::EyeError;
use super::measure::Measurer;
use super::model::Eye;
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
    if eye.iol.is_some() {
        // An IOL has a fixed focus: the eye stays as it is.
        let sys = eye.system()?;
        let m = Measurer::standard().measure(&sys, wavelength_nm, pupil_mm, object_distance_m)?;
        let c = m.coefficient_um(2, 0);
        return Ok(Accommodation {
            diameter_mm: eye.lens.diameter_mm,
            eye: eye.clone(),
            residual_c20_um: c,
            residual_d: -4.0 * 3f64.sqrt() * c / (pupil_mm / 2.0).powi(2),
            iterations: 0,
        });
    }
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

/// Whether a focus request was met.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum FocusLimit {
    /// The eye focuses where asked.
    Reached,
    /// The request lies beyond the far point: the relaxed lens is kept.
    FarPoint,
    /// The request lies nearer than the near point (the amplitude of accommodation, or a
    /// fixed-focus IOL): the most accommodated lens is kept.
    NearPoint,
}

/// An eye focused as far as its range allows.
#[derive(Debug, Clone, PartialEq)]
pub struct Focused {
    pub eye: Eye,
    pub limit: FocusLimit,
}

/// Focuses `eye` on `object_distance_m` (from the corneal vertex; `None` = infinity) within
/// its range: not beyond the relaxed lens when `far_point_limit`, not past
/// `eye.accommodation_max_d` of accommodation, and not at all with an IOL.
pub fn focus_within_range(
    eye: &Eye,
    object_distance_m: Option<f64>,
    pupil_mm: f64,
    wavelength_nm: f64,
    far_point_limit: bool,
) -> Result<Focused, EyeError> {
    if eye.iol.is_some() {
        let error_d = focus_error_d(eye, object_distance_m, pupil_mm, wavelength_nm)?;
        let limit = if error_d.abs() < 0.01 {
            FocusLimit::Reached
        } else if error_d > 0.0 {
            FocusLimit::FarPoint
        } else {
            FocusLimit::NearPoint
        };
        return Ok(Focused {
            eye: eye.clone(),
            limit,
        });
    }
    let d0 = eye.lens.diameter_mm;
    let near_limit = match eye.accommodation_max_d {
        Some(a) => Some(near_limit_diameter_mm(eye, pupil_mm, wavelength_nm, a)?),
        None => None,
    };
    let acc = match accommodate(eye, object_distance_m, pupil_mm, wavelength_nm) {
        Ok(acc) => acc,
        // A lens that cannot change enough is past any amplitude limit anyway.
        Err(_) if near_limit.is_some() && object_distance_m.is_some() => {
            let d = near_limit.unwrap_or(d0);
            return Ok(Focused {
                eye: eye.with_lens_diameter(d)?,
                limit: FocusLimit::NearPoint,
            });
        }
        Err(e) => return Err(e),
    };
    if far_point_limit && acc.diameter_mm > d0 {
        // Within 0.01 D of the far point (a prescription rounded to 0.01 D) counts as reached.
        let limit = if focus_error_d(eye, object_distance_m, pupil_mm, wavelength_nm)?.abs() < 0.01
        {
            FocusLimit::Reached
        } else {
            FocusLimit::FarPoint
        };
        return Ok(Focused {
            eye: eye.clone(),
            limit,
        });
    }
    if let Some(d_min) = near_limit {
        if acc.diameter_mm < d_min {
            return Ok(Focused {
                eye: eye.with_lens_diameter(d_min)?,
                limit: FocusLimit::NearPoint,
            });
        }
    }
    Ok(Focused {
        eye: acc.eye,
        limit: FocusLimit::Reached,
    })
}

/// How far (D) `eye` as it is focuses nearer than the object: positive when the object lies
/// beyond its focus (c(2,0) > 0), negative when nearer.
fn focus_error_d(
    eye: &Eye,
    object_distance_m: Option<f64>,
    pupil_mm: f64,
    wavelength_nm: f64,
) -> Result<f64, EyeError> {
    let sys = eye.system()?;
    let mut buf = [0.0; 15];
    fast_measurer().coefficients_um(&sys, wavelength_nm, pupil_mm, object_distance_m, &mut buf)?;
    Ok(4.0 * 3f64.sqrt() * buf[osa_index(2, 0)] / (pupil_mm / 2.0).powi(2))
}

/// The bare eye's refraction (D) for a distant object at lens diameter `diameter_mm`.
fn bare_refraction_d(
    bare: &Eye,
    diameter_mm: f64,
    pupil_mm: f64,
    wavelength_nm: f64,
) -> Result<f64, EyeError> {
    let sys = bare.with_lens_diameter(diameter_mm)?.system()?;
    let mut buf = [0.0; 15];
    fast_measurer().coefficients_um(&sys, wavelength_nm, pupil_mm, None, &mut buf)?;
    Ok(-4.0 * 3f64.sqrt() * buf[osa_index(2, 0)] / (pupil_mm / 2.0).powi(2))
}

/// The accommodation (D) `eye` exerts with lens diameter `diameter_mm`: how far the bare
/// eye's distance refraction has moved from the relaxed lens's.
pub fn exerted_accommodation_d(
    eye: &Eye,
    diameter_mm: f64,
    pupil_mm: f64,
    wavelength_nm: f64,
) -> Result<f64, EyeError> {
    let bare = eye.without_corrections();
    let relaxed = bare_refraction_d(&bare, bare.lens.diameter_mm, pupil_mm, wavelength_nm)?;
    Ok(relaxed - bare_refraction_d(&bare, diameter_mm, pupil_mm, wavelength_nm)?)
}

/// The lens diameter (mm) at which `eye` exerts `amplitude_d` of accommodation.
pub fn near_limit_diameter_mm(
    eye: &Eye,
    pupil_mm: f64,
    wavelength_nm: f64,
    amplitude_d: f64,
) -> Result<f64, EyeError> {
    let bare = eye.without_corrections();
    let d0 = bare.lens.diameter_mm;
    if amplitude_d <= 0.0 {
        return Ok(d0);
    }
    let relaxed = bare_refraction_d(&bare, d0, pupil_mm, wavelength_nm)?;
    let g = |d: f64| -> Result<f64, EyeError> {
        Ok(relaxed - bare_refraction_d(&bare, d, pupil_mm, wavelength_nm)? - amplitude_d)
    };
    let (mut x0, mut g0) = (d0, -amplitude_d);
    let mut x1 = d0 - 0.05;
    let mut g1 = g(x1)?;
    for _ in 0..40 {
        if g1.abs() < 1e-5 || g1 == g0 {
            break;
        }
        let mut x2 = (x1 - g1 * (x1 - x0) / (g1 - g0)).clamp(0.5 * d0, d0);
        let mut trial = g(x2);
        let mut halvings = 0;
        while trial.is_err() && halvings < 40 {
            x2 = 0.5 * (x1 + x2);
            trial = g(x2);
            halvings += 1;
        }
        let g2 = trial?;
        (x0, g0) = (x1, g1);
        (x1, g1) = (x2, g2);
    }
    // Where the lens cannot accommodate that much, its own limit is the near point.
    Ok(x1)
}
