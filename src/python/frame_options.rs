//! One frame's options from Python, checked with the CLI's messages, and the focus, pupil and
//! accommodation resolved from them and the frame as `ocular render` resolves them.

use crate::eye::age::HofstetterLine;
use crate::eye::Eye;
use crate::render::frame::{HostFrame, Method};
use crate::render::frame_plan::{
    self, Correction, FocusAsked, Physiology, PupilAsked, PupilFallback, PupilModel,
};
use crate::{Error, Result};

use super::eye::check_pupil;

/// The options of one frame, already checked where Python gave them.
pub(super) struct Options {
    pub(super) focus_m: Option<f64>,
    pub(super) focus_d: Option<f64>,
    pub(super) focus_at: Option<(u32, u32)>,
    pub(super) pupil_mm: Option<f64>,
    pub(super) luminance_cdm2: Option<f64>,
    pub(super) age: f64,
    pub(super) method: Method,
    pub(super) layers: u32,
    pub(super) off_axis: bool,
    /// The exposure the image will be shown at (EV; None: the frame's automatic one).
    pub(super) exposure_ev: Option<f64>,
    /// The speed/accuracy preset (`--quality`).
    pub(super) quality: crate::render::splat::Quality,
}

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
) -> Result<Options> {
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
    Ok(Options {
        focus_m,
        focus_d,
        focus_at,
        pupil_mm,
        luminance_cdm2,
        age,
        method,
        layers,
        off_axis,
        exposure_ev,
        quality,
    })
}

/// The focus vergence and the words naming its source, as `ocular render` decides (a focus
/// nearer than ocular renders is refused).
pub(super) fn focus_dioptres(o: &Options, f: &HostFrame) -> Result<(f64, String)> {
    let asked = o
        .focus_m
        .map(FocusAsked::DistanceM)
        .or(o.focus_d.map(FocusAsked::Dioptres))
        .or(o.focus_at.map(|(x, y)| FocusAsked::AtPixel(x, y)));
    f.focus_d(asked)
}

/// The pupil as `ocular render` picks it: given, else Watson–Yellott at the luminance given,
/// the scene's pupil or luminance, or the frame's mean luminance.
pub(super) fn pupil_diameter(o: &Options, f: &HostFrame) -> Result<(f64, String)> {
    let asked = PupilAsked {
        given_mm: o.pupil_mm,
        luminance_cdm2: o.luminance_cdm2.map(|l| (l, "luminance_cdm2")),
        model: PupilModel::WatsonYellott,
        age_years: o.age,
        fallback: PupilFallback::Luminance,
    };
    f.pupil_mm(&asked)
}

/// The eye as the CLI renders it: with the age's amplitude of accommodation unless its file
/// sets one (a correction the eye carries stays).
pub(super) fn physiology(eye: &Eye, age: f64) -> Result<(Eye, Physiology)> {
    frame_plan::corrected_eye(
        eye,
        &Correction::default(),
        Some((age, HofstetterLine::Mean)),
    )
}
