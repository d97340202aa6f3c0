//! Field axes planned from a frame: only the range it shows, and the coarsest uniform steps
//! whose linear interpolation reproduces the measured wavefront within a tolerance.
//!
//! The criterion is measured, not assumed: for a candidate count of nodes the eye is traced
//! at every node and at every midpoint between neighbours (along each axis through the
//! centre, then at the centres of the 2-D cells), and the RMS of the difference between the
//! interpolated and the measured Zernike coefficients (orders 2 and up; piston and tilt only
//! move the image) must stay within the tolerance. The default, 0.04 µm, is λ/14 at 555 nm
//! (Maréchal's criterion for a wavefront that leaves the PSF essentially unchanged).

use super::axes::{GridAxes, Screen};
use super::defocus::distance_of;
use super::field::{frame_half_field_deg, FieldAxes};
use crate::eye::field::{measure_field, shrink_into_traced_field, MAX_FIELD_DEG};
use crate::eye::{accommodate, Eye, OpticalSystem};
use crate::{Error, Result};
use serde::Serialize;

/// Default interpolation tolerance (µm RMS).
pub const FIELD_TOLERANCE_UM: f64 = 0.04;
/// Most nodes per axis the planner tries.
pub const MAX_FIELD_NODES: usize = 31;

/// What the planner chose and measured.
#[derive(Clone, Debug, Serialize)]
pub struct FieldPlan {
    pub axes: FieldAxes,
    /// Largest interpolation error found at the midpoints checked (µm RMS).
    pub worst_error_um: f64,
    pub tolerance_um: f64,
    /// The frame's half-field (h, v) in degrees before any clamping to the traced field.
    pub frame_half_deg: [f64; 2],
    pub notes: Vec<String>,
}

/// The measurement the plan interpolates: how the eye is traced at one direction.
pub struct Probe<'a> {
    pub sys: &'a OpticalSystem,
    pub wavelength_nm: f64,
    pub pupil_mm: f64,
    pub object_distance_m: Option<f64>,
}

impl Probe<'_> {
    fn coefficients(&self, field: [f64; 2]) -> Result<Vec<f64>> {
        let m = measure_field(
            self.sys,
            self.wavelength_nm,
            self.pupil_mm,
            self.object_distance_m,
            field,
            6,
        )
        .map_err(|e| Error::input(format!("field plan at ({}, {})°: {e}", field[0], field[1])))?;
        let mut c = m.measurement.coefficients_um;
        c.iter_mut().take(3).for_each(|v| *v = 0.0);
        Ok(c)
    }
}

fn rms_difference(a: &[f64], b: &[f64]) -> f64 {
    a.iter()
        .zip(b)
        .map(|(x, y)| (x - y).powi(2))
        .sum::<f64>()
        .sqrt()
}

fn lerp(a: &[f64], b: &[f64], t: f64) -> Vec<f64> {
    a.iter().zip(b).map(|(x, y)| x + t * (y - x)).collect()
}

fn nodes(half: f64, n: usize) -> Vec<f64> {
    super::axes::linspace(-half, half, n)
}

/// Worst midpoint error of `n` nodes over [−half, half] along one axis (`dir` 0 = h, 1 = v).
fn axis_error(p: &Probe, half: f64, n: usize, dir: usize) -> Result<f64> {
    let at = |x: f64| if dir == 0 { [x, 0.0] } else { [0.0, x] };
    let xs = nodes(half, n);
    let cs = xs
        .iter()
        .map(|&x| p.coefficients(at(x)))
        .collect::<Result<Vec<_>>>()?;
    let mut worst = 0.0f64;
    for k in 0..n - 1 {
        let mid = p.coefficients(at(0.5 * (xs[k] + xs[k + 1])))?;
        worst = worst.max(rms_difference(&lerp(&cs[k], &cs[k + 1], 0.5), &mid));
    }
    Ok(worst)
}

/// Worst error at the centres of the 2-D cells (bilinear interpolation of the four corners).
fn cell_error(p: &Probe, hs: &[f64], vs: &[f64]) -> Result<f64> {
    let mut worst = 0.0f64;
    for i in 0..hs.len().saturating_sub(1) {
        for j in 0..vs.len().saturating_sub(1) {
            let c = |a: usize, b: usize| p.coefficients([hs[a], vs[b]]);
            let (c00, c01, c10, c11) = (c(i, j)?, c(i, j + 1)?, c(i + 1, j)?, c(i + 1, j + 1)?);
            let want = lerp(&lerp(&c00, &c01, 0.5), &lerp(&c10, &c11, 0.5), 0.5);
            let mid = p.coefficients([0.5 * (hs[i] + hs[i + 1]), 0.5 * (vs[j] + vs[j + 1])])?;
            worst = worst.max(rms_difference(&want, &mid));
        }
    }
    Ok(worst)
}

/// Plans the field axes of a `width_px` × `height_px` frame with vertical field `fov_y_deg`.
pub fn plan_field_axes(
    probe: &Probe,
    fov_y_deg: f64,
    width_px: u32,
    height_px: u32,
    tolerance_um: f64,
) -> Result<FieldPlan> {
    if !(tolerance_um.is_finite() && tolerance_um > 0.0) {
        return Err(Error::input(format!(
            "field tolerance {tolerance_um} µm must be positive"
        )));
    }
    let frame = frame_half_field_deg(fov_y_deg, width_px, height_px);
    let mut notes = Vec::new();
    // The corners must stay inside the traced field: shrink both half-fields alike.
    let half = shrink_into_traced_field(frame);
    if half != frame {
        notes.push(format!(
            "the frame shows ±{:.1}° × ±{:.1}°; the grid stops at ±{:.1}° × ±{:.1}° (corners \
             {MAX_FIELD_DEG}° off axis), farther pixels use its edge",
            frame[0], frame[1], half[0], half[1]
        ));
    }
    let mut count = [2usize, 2];
    let mut worst = 0.0f64;
    for dir in 0..2 {
        loop {
            let e = axis_error(probe, half[dir], count[dir], dir)?;
            if e <= tolerance_um {
                worst = worst.max(e);
                break;
            }
            if count[dir] >= MAX_FIELD_NODES {
                notes.push(format!(
                    "{} axis: {MAX_FIELD_NODES} nodes still leave {e:.3} µm",
                    ["horizontal", "vertical"][dir]
                ));
                worst = worst.max(e);
                break;
            }
            count[dir] += 1;
        }
    }
    // The oblique cells: refine the axis whose step is larger until their centres pass.
    loop {
        let (hs, vs) = (nodes(half[0], count[0]), nodes(half[1], count[1]));
        let e = cell_error(probe, &hs, &vs)?;
        if e <= tolerance_um || count.iter().all(|&c| c >= MAX_FIELD_NODES) {
            worst = worst.max(e);
            break;
        }
        let step = |d: usize| 2.0 * half[d] / (count[d] - 1) as f64;
        let d = if (step(0) >= step(1) && count[0] < MAX_FIELD_NODES) || count[1] >= MAX_FIELD_NODES
        {
            0
        } else {
            1
        };
        count[d] += 1;
    }
    Ok(FieldPlan {
        axes: FieldAxes {
            h_deg: nodes(half[0], count[0]),
            v_deg: nodes(half[1], count[1]),
        },
        worst_error_um: worst,
        tolerance_um,
        frame_half_deg: frame,
        notes,
    })
}

/// The directions a frame needs ([`crate::psf::field_plan`]), measured with the grid's
/// largest pupil at its green wavelength, the eye focused at its first focus state.
pub fn plan_for_frame(
    eye: &Eye,
    axes: &GridAxes,
    screen: &Screen,
    width_px: u32,
) -> Result<FieldPlan> {
    let pupil_mm = axes.pupils_mm.last().copied().unwrap_or(4.0);
    let focus = distance_of(axes.focus_d.first().copied().unwrap_or(0.0));
    let wavelength_nm = axes.wavelengths_nm[1];
    let focused = match focus {
        None => eye.clone(),
        Some(_) => accommodate(eye, focus, pupil_mm, wavelength_nm)?.eye,
    };
    let sys = focused.system()?;
    let probe = Probe {
        sys: &sys,
        wavelength_nm,
        pupil_mm,
        object_distance_m: focus,
    };
    plan_field_axes(
        &probe,
        screen.fov_y_deg,
        width_px,
        screen.height_px,
        FIELD_TOLERANCE_UM,
    )
}
