//! One frame's options from Python, checked with the CLI's messages, and the focus, pupil and
//! accommodation resolved from them and the frame as `ocular render` resolves them.

use crate::cli::correction::{CorrectionArgs, Physiology};
use crate::eye::age::HofstetterLine;
use crate::eye::Eye;
use crate::render::frame::Method;
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
}

/// A frame on the host: what the methods read, and what focus and pupil are resolved from.
#[derive(Clone)]
pub(super) struct HostFrame {
    pub(super) width: u32,
    pub(super) height: u32,
    pub(super) fov_y_deg: f64,
    pub(super) color: Vec<[f32; 4]>,
    pub(super) depth_m: Vec<f32>,
    pub(super) hidden: Vec<(Vec<[f32; 4]>, Vec<f32>)>,
    /// A scene's own focus (m; ≤ 0 or ∞ = infinity), pupil and luminance.
    pub(super) scene_focus_m: Option<f64>,
    pub(super) scene_pupil_mm: Option<f64>,
    pub(super) scene_luminance_cdm2: Option<f64>,
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
) -> Result<Options> {
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
    crate::cli::render::parse_age_years(&age.to_string())
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
    })
}

/// The focus vergence asked for and the words naming its source, as `ocular render` decides.
pub(super) fn focus_dioptres(o: &Options, f: &HostFrame) -> Result<(f64, String)> {
    use crate::render::focus::{
        focus_d_of_distance_m, normalised_focus_d, pixel_vergence_d, PixelOnScreen,
    };
    if let Some(m) = o.focus_m {
        if m.is_nan() || m <= 0.0 {
            return Err(Error::input(format!(
                "--focus-m {m} must be a positive distance in metres (or inf)"
            )));
        }
        return Ok((focus_d_of_distance_m(m), "--focus-m".into()));
    }
    if let Some(d) = o.focus_d {
        if !(d.is_finite() && d >= 0.0) {
            return Err(Error::input(format!(
                "--focus-d {d} must be a non-negative vergence in dioptres"
            )));
        }
        return Ok((normalised_focus_d(d), "--focus-d".into()));
    }
    let vergence_at = |x: u32, y: u32| {
        let at = PixelOnScreen {
            x,
            y,
            width: f.width,
            height: f.height,
            fov_y_deg: f.fov_y_deg,
        };
        normalised_focus_d(pixel_vergence_d(f.depth_m[(y * f.width + x) as usize], at))
    };
    if let Some((x, y)) = o.focus_at {
        if x >= f.width || y >= f.height {
            return Err(Error::input(format!(
                "--focus-at {x},{y} is outside the {}×{} frame",
                f.width, f.height
            )));
        }
        return Ok((vergence_at(x, y), format!("--focus-at {x},{y}")));
    }
    if let Some(m) = f.scene_focus_m {
        let d = if m > 0.0 {
            focus_d_of_distance_m(m)
        } else {
            0.0
        };
        return Ok((d, "the scene's focus".into()));
    }
    let (x, y) = (f.width / 2, f.height / 2);
    Ok((
        vergence_at(x, y),
        format!("the default focus (depth at the frame centre {x},{y}; or use --focus-m)"),
    ))
}

/// The pupil as `ocular render` picks it: given, else Watson–Yellott at the luminance given,
/// the scene's pupil or luminance, or the frame's mean luminance.
pub(super) fn pupil_diameter(o: &Options, f: &HostFrame) -> (f64, String) {
    use crate::optics::pupil::{watson_yellott_mm, Viewing};
    if let Some(p) = o.pupil_mm {
        return (p, "given".into());
    }
    let (luminance, source) = if let Some(l) = o.luminance_cdm2 {
        (l, "luminance_cdm2")
    } else if let Some(p) = f.scene_pupil_mm {
        return (p, "scene".into());
    } else if let Some(l) = f.scene_luminance_cdm2 {
        (l, "scene luminance")
    } else {
        let sum: f64 = f
            .color
            .iter()
            .map(|p| f64::from(crate::image_io::luminance([p[0], p[1], p[2]])))
            .sum();
        (sum / f.color.len().max(1) as f64, "frame mean luminance")
    };
    let aspect = f64::from(f.width) / f64::from(f.height);
    let field_deg2 = f.fov_y_deg * f.fov_y_deg * aspect;
    let mm = watson_yellott_mm(luminance, field_deg2, o.age, Viewing::OneEye);
    (
        mm,
        format!("Watson–Yellott at {luminance:.3} cd/m² ({source})"),
    )
}

/// The eye as the CLI renders it: with the age's amplitude of accommodation unless its file
/// sets one (a correction the eye carries stays).
pub(super) fn physiology(eye: &Eye, age: f64) -> Result<(Eye, Physiology)> {
    CorrectionArgs::default().apply(eye, Some((age, HofstetterLine::Mean)))
}
