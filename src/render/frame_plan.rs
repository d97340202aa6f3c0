//! The eye a frame is rendered through and its state (focus, pupil), decided once for every
//! front door: `ocular render`, `video`, `compare`, `bench` and the Python bindings each
//! gather plain values and call these functions, so one scene gives one eye state whichever
//! door it came through. Messages name the command-line options; the Python bindings name
//! their own where they differ (the luminance's label).

use crate::eye::age::{hofstetter_amplitude_d, HofstetterLine};
use crate::eye::correction::{Iol, Spectacle, DEFAULT_VERTEX_MM};
use crate::eye::refract::emmetropic_iol_power_d;
use crate::eye::Eye;
use crate::optics::pupil::{moon_spencer_mm, watson_yellott_mm, Viewing};
use crate::render::focus::{
    focus_d_of_distance_m, normalised_focus_d, pixel_vergence_d, PixelOnScreen,
    MAX_OBJECT_VERGENCE_D,
};
use crate::{Error, Result};

/// Pupil and wavelength at which `--iol-d auto` makes the eye emmetropic: a photopic pupil
/// at the accommodation wavelength.
pub const AUTO_IOL_PUPIL_MM: f64 = 3.0;
pub const AUTO_IOL_WAVELENGTH_NM: f64 = 549.0;

/// The eye named by `option` (`--eye`, `--side-by-side`): a preset or a file.
pub fn load_eye(option: &str, spec: &str) -> Result<Eye> {
    match crate::eye::file::resolve(spec) {
        Ok(file) => Ok(file.eye),
        Err(Error::Input(message)) => Err(Error::Input(format!("{option}: {message}"))),
        Err(other) => Err(other),
    }
}

/// `--iol-d`: a power, or the emmetropic one.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum IolPower {
    Dioptres(f64),
    Auto,
}

impl IolPower {
    /// `--iol-d`'s text: a power in D within the IOL range, or `auto`. The error says what is
    /// allowed; the caller names the option.
    pub fn parse(text: &str) -> std::result::Result<IolPower, String> {
        if text.trim().eq_ignore_ascii_case("auto") {
            return Ok(IolPower::Auto);
        }
        let v = text
            .trim()
            .parse::<f64>()
            .ok()
            .filter(|v| v.is_finite())
            .ok_or_else(|| format!("{text:?} is not a number; a power in D or auto"))?;
        let (lo, hi) = crate::eye::correction::IOL_RANGE_D;
        if (lo..=hi).contains(&v) {
            Ok(IolPower::Dioptres(v))
        } else {
            Err(format!("{v} is outside {lo} to {hi} D"))
        }
    }
}

/// A spectacle's vertex distance as `--vertex-mm` takes it (lens to cornea, mm).
pub fn check_vertex_mm(vertex_mm: f64) -> std::result::Result<f64, String> {
    let (lo, hi) = crate::eye::correction::VERTEX_RANGE_MM;
    if vertex_mm.is_finite() && (lo..=hi).contains(&vertex_mm) {
        Ok(vertex_mm)
    } else {
        Err(format!("{vertex_mm} is outside {lo} to {hi} mm"))
    }
}

/// What is put in front of (or into) the eye and how far it accommodates, as asked.
#[derive(Debug, Clone, Default)]
pub struct Correction {
    pub spectacle: Option<Spectacle>,
    /// The vertex distance of the spectacle (mm; default [`DEFAULT_VERTEX_MM`]).
    pub vertex_mm: Option<f64>,
    /// The spectacle sits on the cornea (vertex distance 0).
    pub contact: bool,
    pub iol: Option<IolPower>,
    pub accommodation_max_d: Option<f64>,
}

/// Where the amplitude of accommodation came from, for reports.
#[derive(Debug, Clone, serde::Serialize)]
pub struct Physiology {
    /// Amplitude of accommodation (D); null = unlimited.
    pub accommodation_max_d: Option<f64>,
    pub accommodation_source: String,
    /// The correction in `--correct` form, with its vertex distance.
    pub correction: Option<String>,
    pub iol_d: Option<f64>,
    /// How the spectacle maps directions (2×2 on tangents, x right, y up; see
    /// `Spectacle::angular_magnification`): what the renderer warps scenes by.
    pub spectacle_magnification: Option<[[f64; 2]; 2]>,
}

/// The amplitude of accommodation: the one asked, else the eye file's, else the age's.
fn accommodation(eye: &mut Eye, asked: Option<f64>, age: Option<(f64, HofstetterLine)>) -> String {
    if let Some(a) = asked {
        eye.accommodation_max_d = Some(a);
        "--accommodation-max-d".to_string()
    } else if eye.accommodation_max_d.is_some() {
        "the eye file's accommodation_max_d".to_string()
    } else if let Some((years, line)) = age {
        eye.accommodation_max_d = Some(hofstetter_amplitude_d(years, line));
        format!(
            "Hofstetter's {} line at {years} years",
            format!("{line:?}").to_lowercase()
        )
    } else {
        "unlimited".to_string()
    }
}

/// `eye` with `correction` applied and its accommodation limited (by `age` on the given
/// Hofstetter line where neither the correction nor the eye file sets an amplitude).
pub fn corrected_eye(
    eye: &Eye,
    correction: &Correction,
    age: Option<(f64, HofstetterLine)>,
) -> Result<(Eye, Physiology)> {
    let mut e = eye.clone();
    let source = accommodation(&mut e, correction.accommodation_max_d, age);
    if let Some(mut s) = correction.spectacle {
        s.vertex_mm = if correction.contact {
            0.0
        } else {
            correction.vertex_mm.unwrap_or(DEFAULT_VERTEX_MM)
        };
        e.correction = Some(s);
    }
    if let Some(p) = correction.iol {
        let power_d = match p {
            IolPower::Dioptres(d) => d,
            IolPower::Auto => emmetropic_iol_power_d(&e, AUTO_IOL_PUPIL_MM, AUTO_IOL_WAVELENGTH_NM)
                .map_err(|err| Error::input(format!("--iol-d auto: {err}")))?,
        };
        e.iol = Some(Iol { power_d });
    }
    e.validate()
        .map_err(|err| Error::input(format!("--correct/--iol-d: {err}")))?;
    // An IOL has no accommodation whatever the amplitude asked.
    let (accommodation_max_d, accommodation_source) = match e.iol {
        Some(_) => (Some(0.0), "an IOL does not accommodate".to_string()),
        None => (e.accommodation_max_d, source),
    };
    let physiology = Physiology {
        accommodation_max_d,
        accommodation_source,
        correction: e.correction.map(|s| describe_spectacle(&s)),
        iol_d: e.iol.map(|i| i.power_d),
        spectacle_magnification: spectacle_magnification(&e)?,
    };
    Ok((e, physiology))
}

/// `-6.50 +0.00 x 180 at 12 mm` (or `as a contact lens`).
pub fn describe_spectacle(s: &Spectacle) -> String {
    if s.vertex_mm == 0.0 {
        format!("{} (contact lens)", s.notation())
    } else {
        format!("{} at {} mm", s.notation(), s.vertex_mm)
    }
}

/// The angular magnification of `eye`'s spectacle, seen from the bare eye's entrance pupil
/// (paraxial, at the renderer's green wavelength).
pub fn spectacle_magnification(eye: &Eye) -> Result<Option<[[f64; 2]; 2]>> {
    let Some(spectacle) = eye.correction else {
        return Ok(None);
    };
    let mut bare = eye.clone();
    bare.correction = None;
    let sys = bare
        .system()
        .map_err(|err| Error::input(format!("--correct: {err}")))?;
    let pupil_mm = crate::eye::paraxial::paraxial(&sys, 549.0, 0.0).entrance_pupil_z_mm;
    Ok(Some(spectacle.angular_magnification(pupil_mm)))
}

/// The pixels focus and pupil may be read from.
#[derive(Clone, Copy)]
pub struct FrameView<'a> {
    pub width: u32,
    pub height: u32,
    pub fov_y_deg: f64,
    pub color: &'a [[f32; 4]],
    pub depth_m: &'a [f32],
}

/// What a scene says about the eye at one time (all absent for colour + depth files).
#[derive(Clone, Copy, Debug, Default)]
pub struct SceneEye {
    /// The scene's focus distance (m; ≤ 0 or ∞ = infinity).
    pub focus_m: Option<f64>,
    pub pupil_mm: Option<f64>,
    pub luminance_cdm2: Option<f64>,
}

impl SceneEye {
    pub fn of(state: &crate::scene::FrameState<'_>) -> SceneEye {
        SceneEye {
            focus_m: Some(state.focus_m),
            pupil_mm: state.pupil_mm,
            luminance_cdm2: state.luminance_cd_m2,
        }
    }
}

/// A focus the user asked for.
#[derive(Clone, Copy, Debug)]
pub enum FocusAsked {
    /// `--focus-m` (∞ = infinity).
    DistanceM(f64),
    /// `--focus-d`.
    Dioptres(f64),
    /// `--focus-at X,Y`: the depth under that pixel.
    AtPixel(u32, u32),
}

/// The vergence (D) of a scene's focus distance: far distances (and ≤ 0) are infinity, since
/// accommodating to 1e-10 D is ill-posed.
pub fn scene_focus_d(focus_m: f64) -> f64 {
    if focus_m > 0.0 {
        focus_d_of_distance_m(focus_m)
    } else {
        0.0
    }
}

/// The focus vergence (D) and the words naming where it came from: the focus asked, else the
/// scene's, else the depth at the frame's centre. A focus nearer than ocular renders is
/// refused.
pub fn focus_d(
    asked: Option<FocusAsked>,
    scene: &SceneEye,
    frame: &FrameView<'_>,
) -> Result<(f64, String)> {
    let (focus_d, from) = asked_focus_d(asked, scene, frame)?;
    if focus_d > MAX_OBJECT_VERGENCE_D {
        return Err(Error::input(format!(
            "{from}: a focus at {:.4} m ({focus_d:.1} D) is nearer than ocular renders \
             (at most {MAX_OBJECT_VERGENCE_D} D, 2 cm)",
            1.0 / focus_d,
        )));
    }
    Ok((focus_d, from))
}

fn asked_focus_d(
    asked: Option<FocusAsked>,
    scene: &SceneEye,
    frame: &FrameView<'_>,
) -> Result<(f64, String)> {
    let vergence_at = |x: u32, y: u32| {
        let depth_m = frame.depth_m[(y * frame.width + x) as usize];
        let at = PixelOnScreen {
            x,
            y,
            width: frame.width,
            height: frame.height,
            fov_y_deg: frame.fov_y_deg,
        };
        normalised_focus_d(pixel_vergence_d(depth_m, at))
    };
    match asked {
        Some(FocusAsked::DistanceM(m)) => {
            if m.is_nan() || m <= 0.0 {
                return Err(Error::input(format!(
                    "--focus-m {m} must be a positive distance in metres (or inf)"
                )));
            }
            Ok((focus_d_of_distance_m(m), "--focus-m".into()))
        }
        Some(FocusAsked::Dioptres(d)) => {
            if !(d.is_finite() && d >= 0.0) {
                return Err(Error::input(format!(
                    "--focus-d {d} must be a non-negative vergence in dioptres"
                )));
            }
            Ok((normalised_focus_d(d), "--focus-d".into()))
        }
        Some(FocusAsked::AtPixel(x, y)) => {
            if x >= frame.width || y >= frame.height {
                return Err(Error::input(format!(
                    "--focus-at {x},{y} is outside the {}×{} frame",
                    frame.width, frame.height
                )));
            }
            Ok((vergence_at(x, y), format!("--focus-at {x},{y}")))
        }
        None => match scene.focus_m {
            Some(m) => Ok((scene_focus_d(m), "the scene's focus".into())),
            None => {
                let (x, y) = (frame.width / 2, frame.height / 2);
                Ok((
                    vergence_at(x, y),
                    format!(
                        "the default focus (depth at the frame centre {x},{y}; or use --focus-m)"
                    ),
                ))
            }
        },
    }
}

/// `--age`: a number of years within the range Watson & Yellott fitted (20 to 83).
pub fn parse_age_years(text: &str) -> std::result::Result<f64, String> {
    let age: f64 = text
        .trim()
        .parse()
        .map_err(|_| format!("{text:?} is not a number of years"))?;
    if !(age.is_finite() && (20.0..=83.0).contains(&age)) {
        return Err(format!(
            "{age} years is outside 20 to 83, the ages the Watson–Yellott pupil formula covers"
        ));
    }
    Ok(age)
}

/// The pupil formula for luminance-driven pupils.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum PupilModel {
    /// Watson & Yellott (2012) unified formula (field = the frame, one eye, --age).
    WatsonYellott,
    /// Moon & Spencer (1944), as Watson & Yellott quote it.
    MoonSpencer,
}

/// What the pupil falls back on when neither the user nor the scene gives one.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum PupilFallback {
    /// The pupil model at the scene's luminance, else the frame's mean luminance.
    Luminance,
    /// A fixed diameter (mm): the measuring commands keep the seed paper's 5 mm so that their
    /// tables stay comparable with its.
    FixedMm(f64),
}

/// The pupil the user asked for, and how to find one otherwise.
#[derive(Clone, Copy, Debug)]
pub struct PupilAsked<'a> {
    /// `--pupil-mm`.
    pub given_mm: Option<f64>,
    /// An adapting luminance (cd/m²) and the name it was given by, for messages.
    pub luminance_cdm2: Option<(f64, &'a str)>,
    pub model: PupilModel,
    pub age_years: f64,
    pub fallback: PupilFallback,
}

/// Whether [`pupil_mm`] needs the frame's pixels (it follows their mean luminance).
pub fn pupil_needs_frame(asked: &PupilAsked<'_>, scene: &SceneEye) -> bool {
    asked.given_mm.is_none()
        && asked.luminance_cdm2.is_none()
        && scene.pupil_mm.is_none()
        && scene.luminance_cdm2.is_none()
        && asked.fallback == PupilFallback::Luminance
}

/// The pupil diameter (mm) and the words naming where it came from: given, else the model at
/// the luminance given, else the scene's pupil, else the fallback (the model at the scene's or
/// the frame's mean luminance, or a fixed diameter). The frame's field of view sets the
/// Watson–Yellott field; its pixels are read only where [`pupil_needs_frame`] (a caller that
/// did not read them back passes no colour).
pub fn pupil_mm(
    asked: &PupilAsked<'_>,
    scene: &SceneEye,
    frame: &FrameView<'_>,
) -> Result<(f64, String)> {
    if let Some(p) = asked.given_mm {
        crate::limits::PUPIL_MM
            .check("--pupil-mm", p)
            .map_err(Error::input)?;
        return Ok((p, "given".into()));
    }
    let (luminance, source) = if let Some((l, name)) = asked.luminance_cdm2 {
        (l, name)
    } else if let Some(p) = scene.pupil_mm {
        return Ok((p, "scene".into()));
    } else if let PupilFallback::FixedMm(p) = asked.fallback {
        return Ok((p, "the seed paper's".into()));
    } else if let Some(l) = scene.luminance_cdm2 {
        (l, "scene luminance")
    } else {
        if frame.color.is_empty() {
            return Err(Error::input(
                "the pupil follows the frame's mean luminance, but the frame was not read",
            ));
        }
        (mean_luminance(frame.color), "frame mean luminance")
    };
    if !(luminance.is_finite() && luminance >= 0.0) {
        return Err(Error::input(format!(
            "luminance {luminance} cd/m² must be a non-negative number"
        )));
    }
    let (mm, model) = match asked.model {
        PupilModel::WatsonYellott => {
            let aspect = f64::from(frame.width) / f64::from(frame.height);
            let field_deg2 = frame.fov_y_deg * frame.fov_y_deg * aspect;
            let mm = watson_yellott_mm(luminance, field_deg2, asked.age_years, Viewing::OneEye);
            (mm, "Watson–Yellott")
        }
        PupilModel::MoonSpencer => (moon_spencer_mm(luminance), "Moon–Spencer"),
    };
    Ok((mm, format!("{model} at {luminance:.3} cd/m² ({source})")))
}

/// Mean luminance (cd/m²) of linear Rec.709 RGB.
pub fn mean_luminance(color: &[[f32; 4]]) -> f64 {
    let sum: f64 = color
        .iter()
        .map(|p| f64::from(crate::image_io::luminance([p[0], p[1], p[2]])))
        .sum();
    sum / color.len().max(1) as f64
}

/// Moves a scene's depths nearer than ocular renders to the nearest it renders; the warning
/// names `what` (the scene) and how many pixels moved.
pub fn clamp_near_depth(depth_m: &mut [f32], what: &str) -> Option<String> {
    let near = crate::render::focus::nearest_supported_m();
    let clamped = depth_m
        .iter_mut()
        .filter(|d| **d > 0.0 && **d < near)
        .fold(0, |n, d| {
            *d = near;
            n + 1
        });
    (clamped > 0).then(|| {
        format!(
            "{what}: {}",
            crate::inputs::depth::near_clamp_warning(clamped)
        )
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn frame<'a>(color: &'a [[f32; 4]], depth_m: &'a [f32]) -> FrameView<'a> {
        FrameView {
            width: 2,
            height: 1,
            fov_y_deg: 40.0,
            color,
            depth_m,
        }
    }

    fn asked(fallback: PupilFallback) -> PupilAsked<'static> {
        PupilAsked {
            given_mm: None,
            luminance_cdm2: None,
            model: PupilModel::WatsonYellott,
            age_years: 30.0,
            fallback,
        }
    }

    #[test]
    fn pupil_falls_back_in_order() {
        let color = [[100.0f32, 100.0, 100.0, 1.0]; 2];
        let view = frame(&color, &[1.0, 1.0]);
        let scene = SceneEye {
            pupil_mm: Some(3.5),
            ..SceneEye::default()
        };
        let a = asked(PupilFallback::Luminance);
        let unread = frame(&[], &[]);
        assert_eq!(pupil_mm(&a, &scene, &unread).unwrap().0, 3.5);
        let seed = asked(PupilFallback::FixedMm(5.0));
        assert_eq!(
            pupil_mm(&seed, &SceneEye::default(), &unread).unwrap().0,
            5.0
        );
        assert!(pupil_needs_frame(&a, &SceneEye::default()));
        assert!(pupil_mm(&a, &SceneEye::default(), &unread).is_err());
        let (mm, from) = pupil_mm(&a, &SceneEye::default(), &view).unwrap();
        let area = 40.0 * 40.0 * 2.0;
        assert_eq!(mm, watson_yellott_mm(100.0, area, 30.0, Viewing::OneEye));
        assert!(from.contains("frame mean luminance"), "{from}");
    }

    #[test]
    fn a_dark_young_pupil_is_not_clamped() {
        // Watson–Yellott gives about 8.2 mm at 20 years in the dark: within the accepted
        // pupils, so it is rendered as the formula gives it.
        let a = PupilAsked {
            luminance_cdm2: Some((0.0, "--luminance-cdm2")),
            age_years: 20.0,
            ..asked(PupilFallback::Luminance)
        };
        let view = frame(&[], &[]);
        let mm = pupil_mm(&a, &SceneEye::default(), &view).unwrap().0;
        assert!(mm > 8.0 && crate::limits::PUPIL_MM.contains(mm), "{mm}");
    }

    #[test]
    fn focus_is_asked_then_scene_then_centre_and_never_too_near() {
        let depth = [2.0f32, 4.0];
        let view = frame(&[], &depth);
        let none = SceneEye::default();
        let (d, from) = focus_d(None, &none, &view).unwrap();
        assert!(from.starts_with("the default focus"), "{from}");
        assert!(d > 0.2 && d < 0.5, "{d}");
        let scene = SceneEye {
            focus_m: Some(0.0),
            ..none
        };
        assert_eq!(focus_d(None, &scene, &view).unwrap().0, 0.0);
        let inf = Some(FocusAsked::DistanceM(f64::INFINITY));
        assert_eq!(focus_d(inf, &scene, &view).unwrap().0, 0.0);
        let near = Some(FocusAsked::DistanceM(0.01));
        let err = focus_d(near, &scene, &view).unwrap_err().to_string();
        assert!(err.starts_with("--focus-m: a focus at 0.0100 m"), "{err}");
        let outside = Some(FocusAsked::AtPixel(2, 0));
        assert!(focus_d(outside, &scene, &view).is_err());
    }
}
