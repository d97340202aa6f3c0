//! One frame's options from Python, checked with the CLI's messages; `render::live` resolves
//! focus, pupil and accommodation from them as `ocular render` does.

use crate::render::frame::Method;
use crate::render::frame_plan::{self, FocusAsked};
use crate::render::live::LiveOptions;
use crate::{Error, Result};

use super::eye::check_pupil;

fn parse_quality(name: &str) -> Result<crate::render::splat::Quality> {
    // the CLI's own parser of `--quality`, case-insensitive
    <crate::render::splat::Quality as clap::ValueEnum>::from_str(name.trim(), true).map_err(|_| {
        Error::input(format!(
            "--quality {name:?} is not one of exact, balanced, fast"
        ))
    })
}

fn parse_method(name: &str) -> Result<Method> {
    match name.trim().to_ascii_lowercase().as_str() {
        "splat" => Ok(Method::Splat),
        "reference" => Ok(Method::Reference),
        "slices" => Ok(Method::Slices),
        "views" => Err(Error::input(
            "--method views is not available from Python yet; use splat, reference or slices",
        )),
        _ => Err(Error::input(format!(
            "--method {name:?} is not allowed; need splat, reference or slices"
        ))),
    }
}

#[allow(clippy::too_many_arguments)]
pub(super) fn options(
    focus_m: Option<f64>,
    focus_d: Option<f64>,
    focus_at: Option<(u32, u32)>,
    pupil_mm: Option<f64>,
    luminance_cdm2: Option<f64>,
    age: f64,
    method: &str,
    layers: u32,
    off_axis: bool,
    exposure_ev: Option<f64>,
    quality: &str,
) -> Result<LiveOptions> {
    let quality = parse_quality(quality)?;
    let given = [focus_m.is_some(), focus_d.is_some(), focus_at.is_some()];
    if given.iter().filter(|g| **g).count() > 1 {
        return Err(Error::input(
            "give one of focus_m, focus_d and focus_at (--focus-m, --focus-d, --focus-at)",
        ));
    }
    if pupil_mm.is_some() && luminance_cdm2.is_some() {
        return Err(Error::input(
            "give pupil_mm or luminance_cdm2, not both (--pupil-mm conflicts with \
             --luminance-cdm2)",
        ));
    }
    if let Some(p) = pupil_mm {
        check_pupil("--pupil-mm", p)?;
    }
    if let Some(l) = luminance_cdm2 {
        if !(l.is_finite() && l >= 0.0) {
            return Err(Error::input(format!(
                "luminance {l} cd/m² must be a non-negative number"
            )));
        }
    }
    frame_plan::parse_age_years(&age.to_string())
        .map_err(|e| Error::input(format!("--age: {e}")))?;
    let method = parse_method(method)?;
    let most = crate::inputs::layered::MAX_LAYERS as u32;
    if !(1..=most).contains(&layers) {
        return Err(Error::input(format!(
            "--layers {layers} is not a whole number of layers from 1 to {most}"
        )));
    }
    if layers > 1 && method != Method::Splat {
        return Err(Error::input(
            "--layers applies to --method splat (reference and slices see the visible layer only)",
        ));
    }
    if off_axis && method == Method::Slices {
        return Err(Error::input(
            "--off-axis applies to --method splat and reference (slices and views use the \
             on-axis PSF)",
        ));
    }
    if let Some(ev) = exposure_ev {
        if !(ev.is_finite() && ev.abs() <= 64.0) {
            return Err(Error::input(format!(
                "exposure_ev {ev} must be a number of EV in [-64, 64]"
            )));
        }
    }
    let focus = focus_m
        .map(FocusAsked::DistanceM)
        .or(focus_d.map(FocusAsked::Dioptres))
        .or(focus_at.map(|(x, y)| FocusAsked::AtPixel(x, y)));
    Ok(LiveOptions {
        focus,
        pupil_mm,
        luminance_cdm2,
        age,
        method,
        layers,
        off_axis,
        exposure_ev,
        quality,
        correction: Default::default(),
    })
}
