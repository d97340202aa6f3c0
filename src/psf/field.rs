//! Kernels over the visual field: one kernel grid per field direction (h, v), each computed
//! like an on-axis grid from the eye traced for that direction ([`crate::eye::field`]); each
//! channel's pupil is an ellipse ([`super::field_shape`]) and its PSFs are
//! [`super::field_psf`]'s.

use super::axes::{GridAxes, KernelSettings, Screen};
use super::cache::{grid_key, key_of};
use super::defocus::ColumnOptics;
use super::grid::{kernels_from_columns, measure_columns, GridReport, Progress};
use super::kernels::KernelGrid;
use crate::eye::field::check_field_deg;
use crate::eye::Eye;
use crate::{Error, Result};
use std::time::Instant;

/// Accommodates `eye` for (pupil, focus) on axis and measures it at each wavelength for the
/// field direction `field_deg`, with the object at the focus distance.
pub fn field_column(
    eye: &Eye,
    pupil_mm: f64,
    focus_d: f64,
    wavelengths_nm: [f64; 3],
    settings: &KernelSettings,
    field_deg: [f64; 2],
) -> Result<ColumnOptics> {
    ColumnOptics::new_in_field(eye, pupil_mm, focus_d, wavelengths_nm, settings, field_deg)
}

/// A field axis: `count` angles from `lo` to `hi` degrees.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct FieldAxes {
    pub h_deg: Vec<f64>,
    pub v_deg: Vec<f64>,
}

impl FieldAxes {
    /// Every (h, v), h-major.
    pub fn nodes(&self) -> Vec<[f64; 2]> {
        self.h_deg
            .iter()
            .flat_map(|&h| self.v_deg.iter().map(move |&v| [h, v]))
            .collect()
    }

    /// Parses `H0..H1:N,V0..V1:M` (degrees; N, M in 1–31; a count of 1 takes H0).
    pub fn parse(text: &str) -> std::result::Result<FieldAxes, String> {
        let allowed = "H0..H1:N,V0..V1:M in degrees, each axis within ±60°, N and M 1 to 31, \
                       every node at most 60° from the axis";
        let bad = || format!("--field-deg {text:?} is not allowed; need {allowed}");
        let parts: Vec<&str> = text.split(',').collect();
        if parts.len() != 2 {
            return Err(bad());
        }
        let axis = |p: &str| -> Option<Vec<f64>> {
            let (range, n) = p.trim().split_once(':')?;
            let (lo, hi) = range.split_once("..")?;
            let (lo, hi): (f64, f64) = (lo.trim().parse().ok()?, hi.trim().parse().ok()?);
            let n: usize = n.trim().parse().ok()?;
            let ok = lo.is_finite() && hi.is_finite() && (1..=31).contains(&n);
            if !ok || (n > 1 && hi <= lo) {
                return None;
            }
            Some(super::axes::linspace(lo, hi, n))
        };
        let axes = FieldAxes {
            h_deg: axis(parts[0]).ok_or_else(bad)?,
            v_deg: axis(parts[1]).ok_or_else(bad)?,
        };
        if axes.nodes().iter().any(|&n| check_field_deg(n).is_err()) {
            return Err(bad());
        }
        Ok(axes)
    }
}

/// Half-extents (h, v) in degrees of the field a pinhole frame shows: v = fov_y/2 and
/// tan h = tan(fov_y/2)·width/height.
pub fn frame_half_field_deg(fov_y_deg: f64, width_px: u32, height_px: u32) -> [f64; 2] {
    let t = (0.5 * fov_y_deg).to_radians().tan();
    let aspect = width_px as f64 / height_px as f64;
    [(t * aspect).atan().to_degrees(), 0.5 * fov_y_deg]
}

/// The cache key of the grid of one field direction.
pub fn field_grid_key(
    eye: &Eye,
    axes: &GridAxes,
    screen: &Screen,
    settings: &KernelSettings,
    field_deg: [f64; 2],
) -> String {
    let base = grid_key(eye, axes, screen, settings);
    if field_deg == [0.0, 0.0] {
        return base;
    }
    key_of(&[&base, &format!("field {:?}", field_deg)])
}

/// The kernel grid of one field direction: the on-axis grid at (0, 0).
pub fn compute_field_grid(
    eye: &Eye,
    axes: &GridAxes,
    screen: &Screen,
    settings: &KernelSettings,
    field_deg: [f64; 2],
    progress: Progress,
) -> Result<(KernelGrid, GridReport)> {
    check_field_deg(field_deg).map_err(|e| Error::input(e.to_string()))?;
    axes.validate().map_err(Error::input)?;
    settings.validate().map_err(Error::input)?;
    let t0 = Instant::now();
    let columns = measure_columns(eye, axes, settings, field_deg, progress)?;
    let seconds_optics = t0.elapsed().as_secs_f64();
    let (grid, mut report) = kernels_from_columns(&columns, axes, screen, settings, progress)?;
    report.seconds_optics = seconds_optics;
    Ok((grid, report))
}
