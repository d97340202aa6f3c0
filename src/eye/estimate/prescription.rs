//! An eye from a spectacle prescription, the one convention `ocular eye estimate --rx` and the
//! Python module's `Eye.from_rx` share: "S C x A" is a spectacle `vertex_mm` in front of the
//! cornea (12 mm unless given, as `--correct` and `eye refract` read it), taken at 549 nm
//! unless given (the wavelength the renderer accommodates at). The wavefront the estimator
//! fits is the one at the eye's entrance pupil, so the lens is moved there first; where that
//! pupil lies depends on the eye being fitted, hence the refits in [`RxTarget::estimate`].
//!
//! Error messages name the CLI's options (`--rx`, `--vertex-mm`): the Python module reports
//! the same ones.

use std::sync::atomic::{AtomicBool, Ordering};

use super::{
    check_target, estimate, params::prior_centre, Estimate, EstimateError, Progress, Settings,
};
use crate::aberrations::ZernikeSet;
use crate::eye::correction::{DEFAULT_VERTEX_MM, VERTEX_RANGE_MM};
use crate::eye::error::EyeError;
use crate::eye::model::Eye;
use crate::eye::refract::{spectacle_to_pupil_rx, REFRACTION_WAVELENGTH_NM};
use crate::optics::zernike::Prescription;

/// How close (mm) the fitted eye's entrance pupil must come to the one the prescription was
/// moved to. A millimetre moves a −6 D meridian at the pupil by 0.04 D.
pub const RX_PUPIL_TOLERANCE_MM: f64 = 0.01;
/// The most fits one estimate of a prescription makes (each is a full estimate).
pub const RX_FITS: usize = 3;

/// A prescription ready to fit: read, range-checked and shown to be a refraction some eye
/// can have.
#[derive(Debug, Clone)]
pub struct RxTarget {
    prescription: Prescription,
    rx: String,
    pub pupil_mm: f64,
    pub wavelength_nm: f64,
    pub vertex_mm: f64,
    /// Higher-order terms (n, m, µm) added to the prescription's second-order ones.
    pub extra_terms: Vec<(u32, i32, f64)>,
    /// The estimator's start eye's entrance-pupil depth (mm behind the cornea): where the
    /// first fit assumes the pupil lies.
    start_pupil_depth_mm: f64,
}

/// The paraxial entrance-pupil depth (mm behind the cornea) of `eye` at `wavelength_nm`.
pub fn entrance_pupil_mm(eye: &Eye, wavelength_nm: f64) -> Result<f64, EyeError> {
    let sys = eye.system()?;
    Ok(crate::eye::paraxial::paraxial(&sys, wavelength_nm, 0.0).entrance_pupil_z_mm)
}

impl RxTarget {
    /// Reads "S C x A" over a `pupil_mm` pupil; `wavelength_nm` defaults to
    /// [`REFRACTION_WAVELENGTH_NM`] and `vertex_mm` to [`DEFAULT_VERTEX_MM`]. The pupil and
    /// wavelength are checked by [`RxTarget::start_target`] (after the prescription, so that a
    /// prescription's error comes first, as the CLI has always reported it).
    pub fn new(
        rx: &str,
        pupil_mm: f64,
        wavelength_nm: Option<f64>,
        vertex_mm: Option<f64>,
    ) -> Result<RxTarget, EstimateError> {
        let vertex_mm = vertex_mm.unwrap_or(DEFAULT_VERTEX_MM);
        let (lo, hi) = VERTEX_RANGE_MM;
        if !(vertex_mm.is_finite() && (lo..=hi).contains(&vertex_mm)) {
            return Err(EstimateError::Input(format!(
                "--vertex-mm: {vertex_mm} is outside {lo} to {hi} mm"
            )));
        }
        let wavelength_nm = wavelength_nm.unwrap_or(REFRACTION_WAVELENGTH_NM);
        // Out of range the start eye cannot be traced; the target's check reports the
        // wavelength then.
        let start_pupil_depth_mm = if crate::limits::WAVELENGTH_NM.contains(wavelength_nm) {
            entrance_pupil_mm(&prior_centre(), wavelength_nm)?
        } else {
            0.0
        };
        let prescription =
            Prescription::parse(rx).map_err(|e| EstimateError::Input(format!("--rx: {e}")))?;
        let target = RxTarget {
            prescription,
            rx: rx.to_string(),
            pupil_mm,
            wavelength_nm,
            vertex_mm,
            extra_terms: Vec::new(),
            start_pupil_depth_mm,
        };
        // A lens that focuses light before the eye is refused here, not after a fit.
        target.pupil_rx(start_pupil_depth_mm)?;
        Ok(target)
    }

    /// The prescription moved to an entrance pupil `pupil_behind_cornea_mm` behind the cornea.
    fn pupil_rx(&self, pupil_behind_cornea_mm: f64) -> Result<Prescription, EstimateError> {
        let p = &self.prescription;
        let (s, c, axis) = spectacle_to_pupil_rx(
            p.sphere_d,
            p.cylinder_d,
            p.axis_deg,
            self.vertex_mm,
            pupil_behind_cornea_mm,
        )
        .map_err(|e| EstimateError::Input(format!("--rx {:?}: {e}", self.rx)))?;
        Ok(Prescription::new(s, c, axis))
    }

    /// The wavefront over the pupil for an entrance pupil `pupil_behind_cornea_mm` behind the
    /// cornea, checked as [`check_target`] checks any target.
    pub fn target(&self, pupil_behind_cornea_mm: f64) -> Result<ZernikeSet, EstimateError> {
        let [cm, c0, cp] = self
            .pupil_rx(pupil_behind_cornea_mm)?
            .to_zernike(self.pupil_mm);
        let mut coefficients = vec![(2, -2, cm), (2, 0, c0), (2, 2, cp)];
        coefficients.extend_from_slice(&self.extra_terms);
        let set = ZernikeSet {
            pupil_diameter_mm: self.pupil_mm,
            wavelength_nm: self.wavelength_nm,
            coefficients,
        };
        check_target(&set)?;
        Ok(set)
    }

    /// The wavefront the first fit aims at (the start eye's pupil).
    pub fn start_target(&self) -> Result<ZernikeSet, EstimateError> {
        self.target(self.start_pupil_depth_mm)
    }

    /// Fits an eye, then fits again while the fitted eye's entrance pupil lies more than
    /// [`RX_PUPIL_TOLERANCE_MM`] from the one the wavefront assumed (at most [`RX_FITS`] fits;
    /// a cancelled fit is returned as it is).
    pub fn estimate(
        &self,
        settings: &Settings,
        cancel: &AtomicBool,
        progress: &mut (dyn FnMut(&Progress) + Send),
    ) -> Result<Estimate, EstimateError> {
        let mut pupil_depth_mm = self.start_pupil_depth_mm;
        let mut target = self.target(pupil_depth_mm)?;
        let mut fits = 0;
        loop {
            let est = estimate(&target, settings, cancel, progress)?;
            fits += 1;
            if fits == RX_FITS || cancel.load(Ordering::SeqCst) {
                return Ok(est);
            }
            let fitted_mm = entrance_pupil_mm(&est.eye, target.wavelength_nm)?;
            if (fitted_mm - pupil_depth_mm).abs() < RX_PUPIL_TOLERANCE_MM {
                return Ok(est);
            }
            pupil_depth_mm = fitted_mm;
            target = self.target(pupil_depth_mm)?;
        }
    }
}
