//! The one depth policy of file input: what counts as background, what is invalid, and what
//! is nearer than ocular can render.
//!
//! - Background markers are "infinitely far" (stored as +∞, which every method reads as 0 D
//!   and sorts behind everything): +∞, 0, values ≥ 1e9 (Cycles writes 1e10), and 65504 in a
//!   half-float channel (the largest half, Eevee's background).
//! - Invalid values — NaN, −∞, negative — are far as well, but counted and reported with the
//!   first such pixel, since they usually mean a broken file or the wrong channel.
//! - After `--depth-scale`, depths nearer than [`nearest_supported_m`] (about 2 cm) are clamped
//!   to it, with one warning giving their count: the kernels cover vergences up to about 50 D.
//! - A depth map with a single value everywhere (Blender's "Z = 1" compositor trap) is
//!   accepted with a warning.

use crate::render::focus::nearest_supported_m;

/// Raw values from this far on mark the background (scene units, before `--depth-scale`).
pub const BACKGROUND_FROM: f32 = 1e9;

/// The largest finite half-float, which half-float depth passes write for the background.
pub const HALF_MAX: f32 = 65504.0;

/// What the policy found in a depth map.
#[derive(Clone, Debug, Default, PartialEq, serde::Serialize)]
pub struct DepthReport {
    /// Background markers read as infinitely far.
    pub background_px: usize,
    /// NaN, −∞ or negative values read as infinitely far.
    pub invalid_px: usize,
    /// The first invalid pixel (x, y).
    pub first_invalid: Option<(u32, u32)>,
    /// Depths nearer than the nearest supported distance, clamped to it.
    pub clamped_near_px: usize,
    /// The single depth (metres) of a constant map.
    pub constant_m: Option<f32>,
}

impl DepthReport {
    /// One line per thing a user should know, without the file name.
    pub fn warnings(&self) -> Vec<String> {
        let mut out = Vec::new();
        if self.invalid_px > 0 {
            let (x, y) = self.first_invalid.unwrap_or_default();
            out.push(format!(
                "{} pixel(s) have invalid depth (NaN, negative or -inf), first at ({x}, {y}); \
                 they are treated as infinitely far",
                self.invalid_px
            ));
        }
        if self.clamped_near_px > 0 {
            out.push(near_clamp_warning(self.clamped_near_px));
        }
        if let Some(d) = self.constant_m {
            out.push(format!(
                "the depth map is {d} m at every pixel: is it the right channel? (Blender writes \
                 Z = 1 everywhere when the compositor's Z socket is unlinked)"
            ));
        }
        out
    }
}

/// The warning for `count` depths clamped to the nearest supported distance.
pub fn near_clamp_warning(count: usize) -> String {
    let near = nearest_supported_m();
    format!(
        "{count} pixel(s) nearer than {near:.4} m were clamped to it (the nearest distance ocular \
         renders, {:.3} D)",
        1.0 / f64::from(near)
    )
}

/// Applies the policy to raw depth values of a `width`-wide map: background and invalid values
/// become +∞, the rest are scaled to metres by `scale` and clamped at the near limit.
pub fn apply(raw: &[f32], width: u32, half: bool, scale: f64) -> (Vec<f32>, DepthReport) {
    let mut report = DepthReport::default();
    let near = nearest_supported_m();
    let mut first: Option<f32> = None;
    let mut constant = true;
    let mut finite = 0usize;
    let out: Vec<f32> = raw
        .iter()
        .enumerate()
        .map(|(i, &v)| {
            let background =
                v == f32::INFINITY || v == 0.0 || v >= BACKGROUND_FROM || (half && v == HALF_MAX);
            if background {
                report.background_px += 1;
                return f32::INFINITY;
            }
            if v.is_nan() || v <= 0.0 || !v.is_finite() {
                report.invalid_px += 1;
                if report.first_invalid.is_none() {
                    let w = width.max(1) as usize;
                    report.first_invalid = Some(((i % w) as u32, (i / w) as u32));
                }
                return f32::INFINITY;
            }
            let metres = (f64::from(v) * scale) as f32;
            finite += 1;
            match first {
                None => first = Some(metres),
                Some(f) if f != metres => constant = false,
                _ => {}
            }
            if metres < near {
                report.clamped_near_px += 1;
                near
            } else {
                metres
            }
        })
        .collect();
    if constant && finite > 1 {
        report.constant_m = first;
    }
    (out, report)
}
