//! The scene file format (TOML), as serde structs, and its translation into a `Scene`.
//! scenes/README.md documents every field; this file checks them and reports mistakes with
//! the file, line and column, and what is allowed.

use std::path::{Path, PathBuf};

use serde::Deserialize;
use toml::Spanned;

use super::animation::{unwrap_degrees, Track, Track3};
use super::camera::{Camera, MAX_PITCH_DEG};
use super::mesh::Geometry;
use super::objects::{add_object, ObjectSpec};
use super::{Light, Orientation, Scene, Timeline};
use crate::image_io::luminance;
use crate::{Error, Result};

/// At most this many point and directional lights (the raster shader's fixed array).
pub const MAX_LIGHTS: usize = 16;

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct SceneFile {
    name: Option<String>,
    #[allow(dead_code)]
    description: Option<String>,
    focus_m: Option<Spanned<f64>>,
    focus_dpt: Option<Spanned<f64>>,
    pupil_mm: Option<Spanned<f64>>,
    luminance_cd_m2: Option<Spanned<f64>>,
    camera: Spanned<CameraSpec>,
    background: Option<Spanned<BackgroundSpec>>,
    #[serde(default)]
    light: Vec<Spanned<LightSpec>>,
    #[serde(default)]
    object: Vec<Spanned<ObjectSpec>>,
    #[serde(default)]
    keyframe: Vec<Spanned<KeyframeSpec>>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct CameraSpec {
    position: [f64; 3],
    look_at: Option<[f64; 3]>,
    yaw_deg: Option<f64>,
    pitch_deg: Option<f64>,
    fov_y_deg: Option<f64>,
    near_m: Option<f64>,
    far_m: Option<f64>,
    resolution: Option<[u32; 2]>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct BackgroundSpec {
    color: Option<[f64; 3]>,
    luminance_cd_m2: Option<f64>,
}

#[derive(Deserialize, Clone, Copy, PartialEq, Eq, Debug)]
#[serde(rename_all = "lowercase")]
enum LightKind {
    Ambient,
    Directional,
    Point,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct LightSpec {
    kind: LightKind,
    color: Option<[f64; 3]>,
    illuminance_lux: Option<f64>,
    direction: Option<[f64; 3]>,
    position: Option<[f64; 3]>,
    intensity_cd: Option<f64>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct KeyframeSpec {
    time_s: f64,
    camera: Option<KeyCamera>,
    focus_m: Option<f64>,
    focus_dpt: Option<f64>,
    pupil_mm: Option<f64>,
    luminance_cd_m2: Option<f64>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct KeyCamera {
    position: Option<[f64; 3]>,
    look_at: Option<[f64; 3]>,
    yaw_deg: Option<f64>,
    pitch_deg: Option<f64>,
    fov_y_deg: Option<f64>,
}

/// Where a scene's text came from, for messages and relative paths.
pub struct Origin<'a> {
    /// Shown in errors (a path, or "built-in scene NAME").
    pub label: &'a str,
    /// Folder that relative OBJ and texture paths start from.
    pub folder: &'a Path,
}

/// 1-based line and column of byte `offset` in `text`.
pub(super) fn line_col(text: &str, offset: usize) -> (usize, usize) {
    let before = &text[..offset.min(text.len())];
    let line = before.matches('\n').count() + 1;
    let column = before.len() - before.rfind('\n').map_or(0, |i| i + 1) + 1;
    (line, column)
}

pub(super) struct Ctx<'a> {
    pub(super) text: &'a str,
    pub(super) origin: &'a Origin<'a>,
}

impl Ctx<'_> {
    pub(super) fn error_at(
        &self,
        span: std::ops::Range<usize>,
        message: impl std::fmt::Display,
    ) -> Error {
        let (line, column) = line_col(self.text, span.start);
        Error::file(
            self.origin.label,
            format!("line {line}, column {column}: {message}"),
        )
    }

    pub(super) fn resolve(&self, relative: &str) -> PathBuf {
        let p = Path::new(relative);
        if p.is_absolute() {
            p.to_path_buf()
        } else {
            self.origin.folder.join(p)
        }
    }
}

pub(super) fn finite_positive(v: f64) -> bool {
    v.is_finite() && v > 0.0
}

/// Colour normalised to luminance 1, so that a separate photometric quantity sets its level.
pub(super) fn chromaticity(color: [f64; 3]) -> Option<[f64; 3]> {
    let y = f64::from(luminance(color.map(|c| c as f32)));
    (color.iter().all(|c| c.is_finite() && *c >= 0.0) && y > 0.0).then(|| color.map(|c| c / y))
}

pub fn parse(text: &str, origin: &Origin<'_>) -> Result<Scene> {
    let ctx = Ctx { text, origin };
    let file: SceneFile = toml::from_str(text).map_err(|e| {
        let message = e.message().trim().to_string();
        match e.span() {
            Some(span) => ctx.error_at(span, message),
            None => Error::file(origin.label, message),
        }
    })?;

    // Camera.
    let camera_span = file.camera.span();
    let c = file.camera.get_ref();
    let orientation = match (c.look_at, c.yaw_deg, c.pitch_deg) {
        (Some(target), None, None) => Orientation::Target(target),
        (None, yaw, pitch) => Orientation::Angles(yaw.unwrap_or(0.0), pitch.unwrap_or(0.0)),
        _ => {
            return Err(ctx.error_at(
                camera_span,
                "[camera]: give either look_at or yaw_deg/pitch_deg, not both",
            ))
        }
    };
    let fov = c.fov_y_deg.unwrap_or(60.0);
    let near = c.near_m.unwrap_or(0.05);
    let far = c.far_m.unwrap_or(1000.0);
    if let Err(e) = crate::limits::FOV_Y_DEG.check("[camera] fov_y_deg =", fov) {
        return Err(ctx.error_at(camera_span.clone(), e));
    }
    if !(finite_positive(near) && finite_positive(far) && far > near) {
        return Err(ctx.error_at(
            camera_span.clone(),
            format!("[camera] near_m = {near}, far_m = {far}: need 0 < near_m < far_m"),
        ));
    }
    let resolution = c.resolution.unwrap_or([1280, 720]);
    if resolution.contains(&0) || resolution.iter().any(|&r| r > 16384) {
        return Err(ctx.error_at(
            camera_span.clone(),
            "[camera] resolution must be [width, height] with 1..16384 pixels each",
        ));
    }
    let base_camera = Camera {
        position_m: c.position,
        yaw_deg: 0.0,
        pitch_deg: 0.0,
        fov_y_deg: fov,
        near_m: near,
        far_m: far,
    };
    let mut base_camera = base_camera;
    match orientation {
        Orientation::Target(t) => {
            let d = [0, 1, 2].map(|k| t[k] - c.position[k]);
            let (yaw, pitch) = Camera::angles_towards(d).ok_or_else(|| {
                ctx.error_at(camera_span.clone(), "[camera] look_at equals position")
            })?;
            base_camera.yaw_deg = yaw;
            base_camera.pitch_deg = pitch;
        }
        Orientation::Angles(yaw, pitch) => {
            base_camera.yaw_deg = yaw;
            base_camera.pitch_deg = pitch.clamp(-MAX_PITCH_DEG, MAX_PITCH_DEG);
        }
    }

    // Focus, pupil, luminance.
    let focus_dpt = match (&file.focus_m, &file.focus_dpt) {
        (Some(m), None) => {
            let v = *m.get_ref();
            if !finite_positive(v) {
                return Err(ctx.error_at(
                    m.span(),
                    format!("focus_m = {v}: must be > 0 (use focus_dpt = 0 for infinity)"),
                ));
            }
            1.0 / v
        }
        (None, Some(d)) => {
            let v = *d.get_ref();
            if !(v.is_finite() && v >= 0.0) {
                return Err(ctx.error_at(d.span(), format!("focus_dpt = {v}: must be ≥ 0")));
            }
            v
        }
        (None, None) => 0.0,
        (Some(m), Some(_)) => {
            return Err(ctx.error_at(m.span(), "give focus_m or focus_dpt, not both"))
        }
    };
    let pupil_mm = match &file.pupil_mm {
        Some(p) => {
            let v = *p.get_ref();
            if let Err(e) = crate::limits::PUPIL_MM.check("pupil_mm =", v) {
                return Err(ctx.error_at(p.span(), e));
            }
            Some(v)
        }
        None => None,
    };
    let luminance_cd_m2 = match &file.luminance_cd_m2 {
        Some(l) => {
            let v = *l.get_ref();
            if !finite_positive(v) {
                return Err(ctx.error_at(l.span(), format!("luminance_cd_m2 = {v}: must be > 0")));
            }
            Some(v)
        }
        None => None,
    };

    // Background.
    let background_rgb = match &file.background {
        None => [0.0; 3],
        Some(b) => {
            let span = b.span();
            let b = b.get_ref();
            let color = b.color.unwrap_or([1.0, 1.0, 1.0]);
            if color.iter().any(|c| !c.is_finite() || *c < 0.0) {
                return Err(ctx.error_at(span, "[background] color must be 3 non-negative numbers"));
            }
            match b.luminance_cd_m2 {
                Some(l) if l.is_finite() && l >= 0.0 => {
                    let chroma = chromaticity(color).ok_or_else(|| {
                        ctx.error_at(span.clone(), "[background] color has no luminance")
                    })?;
                    chroma.map(|c| c * l)
                }
                Some(l) => {
                    return Err(ctx.error_at(
                        span,
                        format!("[background] luminance_cd_m2 = {l}: must be ≥ 0"),
                    ))
                }
                None => color,
            }
        }
    };

    // Lights.
    let mut lights = Vec::new();
    for spanned in &file.light {
        let span = spanned.span();
        let l = spanned.get_ref();
        let color = l.color.unwrap_or([1.0, 1.0, 1.0]);
        let chroma = chromaticity(color).ok_or_else(|| {
            ctx.error_at(
                span.clone(),
                "light color must be non-negative with some luminance",
            )
        })?;
        let allowed = match l.kind {
            LightKind::Ambient => "kind, color, illuminance_lux",
            LightKind::Directional => "kind, color, illuminance_lux, direction",
            LightKind::Point => "kind, color, intensity_cd, position",
        };
        let misplaced = match l.kind {
            LightKind::Ambient => {
                l.direction.is_some() || l.position.is_some() || l.intensity_cd.is_some()
            }
            LightKind::Directional => l.position.is_some() || l.intensity_cd.is_some(),
            LightKind::Point => l.direction.is_some() || l.illuminance_lux.is_some(),
        };
        if misplaced {
            return Err(ctx.error_at(
                span,
                format!("a {:?} light takes only: {allowed}", l.kind).to_lowercase(),
            ));
        }
        let need = |v: Option<f64>, name: &str| -> Result<f64> {
            match v {
                Some(x) if x.is_finite() && x >= 0.0 => Ok(x),
                Some(x) => Err(ctx.error_at(span.clone(), format!("{name} = {x}: must be ≥ 0"))),
                None => Err(ctx.error_at(span.clone(), format!("this light needs {name}"))),
            }
        };
        let rgb = |amount: f64| chroma.map(|c| (c * amount) as f32);
        lights.push(match l.kind {
            LightKind::Ambient => Light::Ambient {
                rgb_lux: rgb(need(l.illuminance_lux, "illuminance_lux")?),
            },
            LightKind::Directional => {
                let d = l.direction.ok_or_else(|| {
                    ctx.error_at(span.clone(), "a directional light needs direction = [x, y, z] (the way the light travels)")
                })?;
                let d = glam::DVec3::from(d);
                if !finite_positive(d.length()) {
                    return Err(ctx.error_at(span, "direction must not be zero"));
                }
                Light::Directional {
                    direction: d.normalize().as_vec3().to_array(),
                    rgb_lux: rgb(need(l.illuminance_lux, "illuminance_lux")?),
                }
            }
            LightKind::Point => Light::Point {
                position_m: l
                    .position
                    .ok_or_else(|| ctx.error_at(span.clone(), "a point light needs position = [x, y, z]"))?
                    .map(|c| c as f32),
                rgb_cd: rgb(need(l.intensity_cd, "intensity_cd")?),
            },
        });
    }
    let directional_or_point = lights
        .iter()
        .filter(|l| !matches!(l, Light::Ambient { .. }))
        .count();
    if directional_or_point > MAX_LIGHTS {
        return Err(Error::file(
            origin.label,
            format!("{directional_or_point} directional/point lights; at most {MAX_LIGHTS} are supported"),
        ));
    }

    // Objects.
    let mut geometry = Geometry::default();
    let mut texture_cache: Vec<(PathBuf, usize)> = Vec::new();
    for spanned in &file.object {
        add_object(
            &ctx,
            spanned,
            &base_camera,
            &mut geometry,
            &mut texture_cache,
        )?;
    }

    // Keyframes.
    let timeline = timeline(&ctx, &file.keyframe)?;

    Ok(Scene {
        id: super::next_scene_id(),
        name: file.name.clone().unwrap_or_else(|| {
            Path::new(origin.label)
                .file_stem()
                .map(|s| s.to_string_lossy().into_owned())
                .unwrap_or_else(|| "scene".into())
        }),
        source: origin.label.to_string(),
        geometry,
        lights,
        background_rgb: background_rgb.map(|c| c as f32),
        resolution,
        base_camera,
        base_orientation: orientation,
        focus_dpt,
        pupil_mm,
        luminance_cd_m2,
        timeline,
    })
}

fn timeline(ctx: &Ctx<'_>, keys: &[Spanned<KeyframeSpec>]) -> Result<Timeline> {
    let mut previous: Option<f64> = None;
    let mut position = Vec::new();
    let mut targets = Vec::new();
    let mut angles = Vec::new();
    let mut fov = Vec::new();
    let mut focus = Vec::new();
    let mut pupil = Vec::new();
    let mut lum = Vec::new();
    for spanned in keys {
        let span = spanned.span();
        let k = spanned.get_ref();
        let err = |m: String| ctx.error_at(span.clone(), m);
        let t = k.time_s;
        if !t.is_finite() || previous.is_some_and(|p| t <= p) {
            return Err(err(format!(
                "keyframe time_s = {t}: keyframes must be listed in strictly increasing time"
            )));
        }
        previous = Some(t);
        if let Some(c) = &k.camera {
            if let Some(p) = c.position {
                position.push((t, p));
            }
            match (c.look_at, c.yaw_deg, c.pitch_deg) {
                (Some(target), None, None) => targets.push((t, target)),
                (None, None, None) => {}
                (None, yaw, pitch) => angles.push((t, yaw, pitch)),
                _ => {
                    return Err(err(
                        "keyframe camera: give look_at or yaw_deg/pitch_deg, not both".into(),
                    ))
                }
            }
            if let Some(f) = c.fov_y_deg {
                crate::limits::FOV_Y_DEG
                    .check("fov_y_deg =", f)
                    .map_err(&err)?;
                fov.push((t, f));
            }
        }
        match (k.focus_m, k.focus_dpt) {
            (Some(m), None) if m > 0.0 => focus.push((t, 1.0 / m)),
            (None, Some(d)) if d.is_finite() && d >= 0.0 => focus.push((t, d)),
            (None, None) => {}
            _ => {
                return Err(err(
                    "keyframe focus: one of focus_m > 0 or focus_dpt ≥ 0".into()
                ))
            }
        }
        if let Some(p) = k.pupil_mm {
            crate::limits::PUPIL_MM
                .check("pupil_mm =", p)
                .map_err(&err)?;
            pupil.push((t, p));
        }
        if let Some(l) = k.luminance_cd_m2 {
            if !finite_positive(l) {
                return Err(err(format!("luminance_cd_m2 = {l}: must be > 0")));
            }
            // Luminance spans decades: interpolate its logarithm.
            lum.push((t, l.ln()));
        }
    }
    if !targets.is_empty() && !angles.is_empty() {
        return Err(Error::file(
            ctx.origin.label,
            "keyframes mix camera.look_at and camera.yaw_deg/pitch_deg; use one kind throughout",
        ));
    }
    let orientation = if !targets.is_empty() {
        Some(super::OrientationTrack::Target(Track3::new(&targets)))
    } else if !angles.is_empty() {
        let yaws: Vec<f64> = unwrap_degrees(
            &angles
                .iter()
                .map(|a| a.1.unwrap_or(0.0))
                .collect::<Vec<_>>(),
        );
        let yaw_keys: Vec<(f64, f64)> = angles.iter().zip(&yaws).map(|(a, &y)| (a.0, y)).collect();
        let pitch_keys: Vec<(f64, f64)> = angles
            .iter()
            .map(|a| (a.0, a.2.unwrap_or(0.0).clamp(-MAX_PITCH_DEG, MAX_PITCH_DEG)))
            .collect();
        Some(super::OrientationTrack::Angles(
            Track::new(&yaw_keys),
            Track::new(&pitch_keys),
        ))
    } else {
        None
    };
    Ok(Timeline {
        position: Track3::new(&position),
        orientation,
        fov_y_deg: Track::new(&fov),
        focus_dpt: Track::new(&focus),
        pupil_mm: Track::new(&pupil),
        ln_luminance: Track::new(&lum),
    })
}
