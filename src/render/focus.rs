//! Where the eye focuses: depth → vergence, distances too far to matter, and the far point
//! of an eye that cannot relax enough.

use crate::eye::measure::Measurer;
use crate::eye::Eye;
use crate::eye::{focus_within_range, FocusLimit};
use crate::optics::zernike::osa_index;
use crate::psf::axes::{GridAxes, KernelSettings};
use crate::{Error, Result};

/// The largest object vergence the kernels cover (the planner's limit), in dioptres.
pub const MAX_OBJECT_VERGENCE_D: f64 = 50.0;

/// The nearest depth ocular renders, in metres (about 2 cm): the reciprocal of the largest
/// object vergence on the reference grid's spacing within [`MAX_OBJECT_VERGENCE_D`], since the
/// planner brackets a scene's range with grid points. Depths nearer are clamped to it; it is
/// rounded up in f32 so that its vergence never exceeds that grid point.
pub fn nearest_supported_m() -> f32 {
    let o = GridAxes::default().objects;
    let top_d = o.min_d + o.step_d * ((MAX_OBJECT_VERGENCE_D - o.min_d) / o.step_d + 1e-9).floor();
    let m = (1.0 / top_d) as f32;
    if 1.0 / f64::from(m) > top_d {
        m.next_up()
    } else {
        m
    }
}

/// Focus distances from this far on are infinity: the vergence (≤ 1e-4 D) is far below any
/// eye's depth of field, and accommodating to it numerically is ill-posed.
pub const FAR_FOCUS_M: f64 = 1e4;

/// The object vergence (D) of a depth `depth_m` along the view axis, ignoring the pixel's
/// direction; background (+∞, 0, NaN, negative) is optical infinity. Per-pixel conversions go
/// through [`pixel_vergence_d`] (distance along the ray).
pub fn vergence_of_depth_d(depth_m: f32) -> f64 {
    if depth_m > 0.0 && depth_m.is_finite() {
        1.0 / f64::from(depth_m)
    } else {
        0.0
    }
}

/// Where a pixel lies on the screen, for conversions that depend on its ray.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PixelOnScreen {
    pub x: u32,
    pub y: u32,
    pub width: u32,
    pub height: u32,
    pub fov_y_deg: f64,
}

/// The object vergence (D) of the pixel `at` whose depth buffer holds `depth_m`: what
/// `--focus-at` and the default focus focus on. Light reaches the eye with the vergence of the
/// distance along the pixel's ray (see [`crate::render::projection`]), as every method uses.
pub fn pixel_vergence_d(depth_m: f32, at: PixelOnScreen) -> f64 {
    crate::render::projection::Projection {
        width: at.width,
        height: at.height,
        fov_y_deg: at.fov_y_deg,
    }
    .dioptre_at(at.x, at.y, depth_m)
}

/// The focus vergence (D) for a focus distance in metres: 0 (infinity) from
/// [`FAR_FOCUS_M`] on, and for +∞.
pub fn focus_d_of_distance_m(distance_m: f64) -> f64 {
    if distance_m >= FAR_FOCUS_M {
        0.0
    } else {
        1.0 / distance_m
    }
}

/// A focus vergence with vergences nearer infinity than [`FAR_FOCUS_M`] set to exactly 0.
pub fn normalised_focus_d(focus_d: f64) -> f64 {
    if focus_d < 1.0 / FAR_FOCUS_M {
        0.0
    } else {
        focus_d
    }
}

/// The focus asked for and the one the eye reaches.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct FocusOutcome {
    pub requested_d: f64,
    /// Where the eye actually focuses (D): the request, or the far (near) point when the
    /// request lies beyond (nearer than) it.
    pub actual_d: f64,
    /// The request lies beyond the eye's far point: the eye stays relaxed.
    pub beyond_far_point: bool,
    /// Reached, or clamped at the far or the near point.
    pub limit: FocusLimit,
}

impl FocusOutcome {
    pub fn clamped(&self) -> bool {
        self.limit != FocusLimit::Reached
    }
}

/// Object distance (m) of a vergence, `None` for infinity.
fn distance_of(focus_d: f64) -> Option<f64> {
    (focus_d > 0.0).then(|| 1.0 / focus_d)
}

/// Checks that `eye` can focus at `focus_d` with `pupil_mm` and, where the request lies
/// beyond the far point (a myopic eye asked to focus far) or nearer than the near point (an
/// eye with too little accommodation, or an IOL), finds where the limiting lens focuses — the
/// same criterion (c(2,0) = 0 at the accommodation wavelength) the kernels use. `what` names
/// the options that set the focus, for errors.
pub fn effective_focus(
    eye: &Eye,
    focus_d: f64,
    pupil_mm: f64,
    settings: &KernelSettings,
    what: &str,
) -> Result<FocusOutcome> {
    let fail = |e: &dyn std::fmt::Display| {
        let at = match distance_of(focus_d) {
            Some(m) => format!("{m:.4} m ({focus_d:.4} D)"),
            None => "infinity".into(),
        };
        Error::input(format!(
            "{what}: the eye cannot focus at {at} with a {pupil_mm} mm pupil (--pupil-mm): {e}"
        ))
    };
    let f = focus_within_range(
        eye,
        distance_of(focus_d),
        pupil_mm,
        settings.accommodation_nm,
        settings.far_point_limit,
    )
    .map_err(|e| fail(&e))?;
    if f.limit == FocusLimit::Reached {
        return Ok(FocusOutcome {
            requested_d: focus_d,
            actual_d: focus_d,
            beyond_far_point: false,
            limit: f.limit,
        });
    }
    let actual_d =
        far_point_d(&f.eye, pupil_mm, settings.accommodation_nm, focus_d).map_err(|e| fail(&e))?;
    Ok(FocusOutcome {
        requested_d: focus_d,
        actual_d,
        beyond_far_point: f.limit == FocusLimit::FarPoint,
        limit: f.limit,
    })
}

/// The far point of `eye` as it is (no accommodation), signed (D of object vergence): positive
/// for a myopic eye (a real point before it), 0 for an emmetropic one, negative for a
/// hyperopic one or one over-corrected with a minus lens, whose relaxed focus lies beyond
/// infinity. Beyond infinity the tracer has no object to trace (light arriving converged), so
/// c(2,0), close to linear in the object vergence, is extrapolated from 0, 1 and 2 D by the
/// parabola through them.
pub fn signed_far_point_d(eye: &Eye, pupil_mm: f64, settings: &KernelSettings) -> Result<f64> {
    let fail = |e: &dyn std::fmt::Display| {
        Error::input(format!(
            "the far point: the eye cannot be measured with a {pupil_mm} mm pupil (--pupil-mm): {e}"
        ))
    };
    let sys = eye.system().map_err(|e| fail(&e))?;
    let meas = Measurer::new(4, 6, 16);
    let j20 = osa_index(2, 0);
    let mut buf = [0.0; 15];
    let mut c20 = |v: f64| -> Result<f64> {
        meas.coefficients_um(
            &sys,
            settings.accommodation_nm,
            pupil_mm,
            distance_of(v),
            &mut buf,
        )
        .map_err(|e| fail(&e))?;
        Ok(buf[j20])
    };
    let g = [c20(0.0)?, c20(1.0)?, c20(2.0)?];
    if g[0] >= 0.0 {
        return far_point_d(eye, pupil_mm, settings.accommodation_nm, 0.0).map_err(|e| fail(&e));
    }
    // g(v) = g0 + b·v + c·v² through the three samples; its root nearest 0 on the negative side.
    let c = 0.5 * (g[2] - 2.0 * g[1] + g[0]);
    let b = g[1] - g[0] - c;
    let linear = -g[0] / b;
    let v = if c.abs() * linear * linear < 1e-9 * g[0].abs() {
        linear
    } else {
        let disc = b * b - 4.0 * c * g[0];
        if disc < 0.0 {
            linear
        } else {
            // The root of smaller magnitude, written to avoid cancellation.
            let q = -0.5 * (b + b.signum() * disc.sqrt());
            let (r1, r2) = (q / c, g[0] / q);
            if r1.abs() < r2.abs() {
                r1
            } else {
                r2
            }
        }
    };
    if !(v.is_finite() && v <= 0.0 && v > -MAX_OBJECT_VERGENCE_D) {
        return Err(fail(&format!(
            "the relaxed eye's focus beyond infinity was not found (c(2,0) = {:.2e} µm at 0 D)",
            g[0]
        )));
    }
    Ok(v)
}

/// The vergence (D) at which `eye` (as it is, no further accommodation) has no Zernike
/// defocus, found by the secant method from `start_d` (c(2,0) is close to linear in the object
/// vergence); 0 where that point lies beyond infinity.
fn far_point_d(eye: &Eye, pupil_mm: f64, wavelength_nm: f64, start_d: f64) -> Result<f64> {
    let sys = eye.system()?;
    let meas = Measurer::new(4, 6, 16);
    let j20 = osa_index(2, 0);
    let mut buf = [0.0; 15];
    let mut c20 = |v: f64| -> Result<f64> {
        meas.coefficients_um(&sys, wavelength_nm, pupil_mm, distance_of(v), &mut buf)?;
        Ok(buf[j20])
    };
    let (mut v0, mut v1) = (start_d, start_d + 0.5);
    let (mut g0, mut g1) = (c20(v0)?, c20(v1)?);
    for _ in 0..30 {
        if g1.abs() < 1e-7 || g1 == g0 {
            break;
        }
        let v2 = (v1 - g1 * (v1 - v0) / (g1 - g0)).clamp(0.0, MAX_OBJECT_VERGENCE_D);
        (v0, g0) = (v1, g1);
        v1 = v2;
        g1 = c20(v1)?;
    }
    // c(2,0) < 0 at vergence 0: even a distant object is focused behind the retina's
    // conjugate, so the eye's focus lies beyond infinity.
    if v1 == 0.0 && g1 < 0.0 {
        return Ok(0.0);
    }
    if g1.abs() > 1e-4 {
        return Err(Error::input(format!(
            "the eye's focus was not found (c(2,0) = {g1:.2e} µm at {v1:.3} D)"
        )));
    }
    Ok(v1)
}
