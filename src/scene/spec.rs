//! The scene file format (TOML), as serde structs, and its translation into a `Scene`.
//! scenes/README.md documents every field; this file checks them and reports mistakes with
//! the file, line and column, and what is allowed.

use std::path::{Path, PathBuf};

use serde::Deserialize;
use toml::Spanned;

use super::animation::{unwrap_degrees, Track, Track3};
use super::camera::{Camera, MAX_PITCH_DEG};
use super::mesh::{self, Geometry, LocalMesh, Material};
use super::optotype::{self, ChartStyle, Direction, Glyph};
use super::{obj, Light, Orientation, Scene, Timeline};
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

#[derive(Deserialize, Clone, Copy, PartialEq, Eq, Debug)]
#[serde(rename_all = "lowercase")]
enum ObjectKind {
    Obj,
    Plane,
    Cube,
    Sphere,
    Cylinder,
    Optotype,
    Chart,
}

#[derive(Deserialize, Clone, Copy)]
#[serde(untagged)]
enum Size {
    Uniform(f64),
    Xy([f64; 2]),
    Xyz([f64; 3]),
}

#[derive(Deserialize, Clone, Copy, PartialEq, Eq, Debug, Default)]
#[serde(rename_all = "kebab-case")]
enum ObjColors {
    #[default]
    Mtl,
    PerGroup,
}

#[derive(Deserialize, Clone, Copy)]
#[serde(deny_unknown_fields)]
struct RepeatSpec {
    count: u32,
    step: [f64; 3],
    #[serde(default = "one")]
    growth: f64,
    #[serde(default = "one")]
    scale_growth: f64,
}

fn one() -> f64 {
    1.0
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct ObjectSpec {
    kind: ObjectKind,
    name: Option<String>,
    // Placement.
    translate: Option<[f64; 3]>,
    rotate_deg: Option<[f64; 3]>,
    scale: Option<Size>,
    repeat: Option<RepeatSpec>,
    // Material.
    color: Option<[f64; 3]>,
    texture: Option<String>,
    emission_cd_m2: Option<f64>,
    emission_color: Option<[f64; 3]>,
    // Shapes.
    file: Option<String>,
    colors: Option<ObjColors>,
    size_m: Option<Size>,
    radius_m: Option<f64>,
    height_m: Option<f64>,
    segments: Option<u32>,
    // Optotypes and charts.
    letter: Option<String>,
    direction: Option<String>,
    acuity_decimal: Option<f64>,
    logmar: Option<f64>,
    distance_m: Option<f64>,
    lines_logmar: Option<Vec<f64>>,
    letters_per_line: Option<u32>,
    optotype: Option<String>,
    seed: Option<u64>,
    card: Option<bool>,
    card_color: Option<[f64; 3]>,
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
fn line_col(text: &str, offset: usize) -> (usize, usize) {
    let before = &text[..offset.min(text.len())];
    let line = before.matches('\n').count() + 1;
    let column = before.len() - before.rfind('\n').map_or(0, |i| i + 1) + 1;
    (line, column)
}

struct Ctx<'a> {
    text: &'a str,
    origin: &'a Origin<'a>,
}

impl Ctx<'_> {
    fn error_at(&self, span: std::ops::Range<usize>, message: impl std::fmt::Display) -> Error {
        let (line, column) = line_col(self.text, span.start);
        Error::file(
            self.origin.label,
            format!("line {line}, column {column}: {message}"),
        )
    }

    fn resolve(&self, relative: &str) -> PathBuf {
        let p = Path::new(relative);
        if p.is_absolute() {
            p.to_path_buf()
        } else {
            self.origin.folder.join(p)
        }
    }
}

fn finite_positive(v: f64) -> bool {
    v.is_finite() && v > 0.0
}

/// Colour normalised to luminance 1, so that a separate photometric quantity sets its level.
fn chromaticity(color: [f64; 3]) -> Option<[f64; 3]> {
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
    if !(fov > 0.0 && fov < 179.0) {
        return Err(ctx.error_at(
            camera_span.clone(),
            format!("[camera] fov_y_deg = {fov}: must lie in (0, 179) degrees"),
        ));
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
            if !(v > 0.5 && v < 10.0) {
                return Err(ctx.error_at(
                    p.span(),
                    format!("pupil_mm = {v}: must lie in (0.5, 10) mm"),
                ));
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

fn size3(size: Size) -> [f64; 3] {
    match size {
        Size::Uniform(s) => [s, s, s],
        Size::Xy([x, y]) => [x, y, 1.0],
        Size::Xyz(v) => v,
    }
}

fn add_object(
    ctx: &Ctx<'_>,
    spanned: &Spanned<ObjectSpec>,
    camera: &Camera,
    geometry: &mut Geometry,
    texture_cache: &mut Vec<(PathBuf, usize)>,
) -> Result<()> {
    let span = spanned.span();
    let o = spanned.get_ref();
    let label = o
        .name
        .as_deref()
        .map(|n| format!("object \"{n}\": "))
        .unwrap_or_default();
    let err = |message: String| ctx.error_at(span.clone(), format!("{label}{message}"));
    let kind_name = format!("{:?}", o.kind).to_lowercase();

    // Fields each kind accepts beyond placement and material.
    let shape_fields: &[(&str, bool)] = &[
        ("file", o.file.is_some()),
        ("colors", o.colors.is_some()),
        ("size_m", o.size_m.is_some()),
        ("radius_m", o.radius_m.is_some()),
        ("height_m", o.height_m.is_some()),
        ("segments", o.segments.is_some()),
        ("letter", o.letter.is_some()),
        ("direction", o.direction.is_some()),
        ("acuity_decimal", o.acuity_decimal.is_some()),
        ("logmar", o.logmar.is_some()),
        ("distance_m", o.distance_m.is_some()),
        ("lines_logmar", o.lines_logmar.is_some()),
        ("letters_per_line", o.letters_per_line.is_some()),
        ("optotype", o.optotype.is_some()),
        ("seed", o.seed.is_some()),
        ("card", o.card.is_some()),
        ("card_color", o.card_color.is_some()),
    ];
    let accepted: &[&str] = match o.kind {
        ObjectKind::Obj => &["file", "colors"],
        ObjectKind::Plane => &["size_m"],
        ObjectKind::Cube => &["size_m"],
        ObjectKind::Sphere => &["radius_m", "segments"],
        ObjectKind::Cylinder => &["radius_m", "height_m", "segments"],
        ObjectKind::Optotype => &[
            "letter",
            "direction",
            "acuity_decimal",
            "logmar",
            "distance_m",
            "card",
            "card_color",
        ],
        ObjectKind::Chart => &[
            "lines_logmar",
            "letters_per_line",
            "optotype",
            "seed",
            "distance_m",
            "card",
            "card_color",
        ],
    };
    if let Some((field, _)) = shape_fields
        .iter()
        .find(|(name, present)| *present && !accepted.contains(name))
    {
        return Err(err(format!(
            "a {kind_name} object does not take {field}; it takes {} (plus translate, rotate_deg, \
             scale, repeat, color, texture, emission_cd_m2, emission_color)",
            accepted.join(", ")
        )));
    }

    let translate = o.translate.unwrap_or([0.0; 3]);
    let rotate = o.rotate_deg.unwrap_or([0.0; 3]);
    let scale = o.scale.map(size3).unwrap_or([1.0; 3]);
    if translate.iter().chain(&rotate).any(|v| !v.is_finite())
        || scale.iter().any(|v| !v.is_finite() || *v == 0.0)
    {
        return Err(err(
            "translate, rotate_deg and scale must be finite, scale non-zero".into(),
        ));
    }

    // Material.
    let color = o.color.unwrap_or([0.8, 0.8, 0.8]);
    if color.iter().any(|c| !c.is_finite() || *c < 0.0 || *c > 1.0) {
        return Err(err(format!(
            "color = {color:?}: a reflectance, 3 linear values in [0, 1]"
        )));
    }
    let emission = match o.emission_cd_m2 {
        None => [0.0; 3],
        Some(l) if l.is_finite() && l >= 0.0 => {
            let chroma = chromaticity(o.emission_color.unwrap_or([1.0; 3])).ok_or_else(|| {
                err("emission_color must be non-negative with some luminance".into())
            })?;
            chroma.map(|c| (c * l) as f32)
        }
        Some(l) => return Err(err(format!("emission_cd_m2 = {l}: must be ≥ 0"))),
    };
    let mut texture_index =
        |path: PathBuf, referenced: String, geometry: &mut Geometry| -> Result<usize> {
            if let Some((_, i)) = texture_cache.iter().find(|(p, _)| *p == path) {
                return Ok(*i);
            }
            let texture = obj::load_texture(&path, &referenced)?;
            geometry.textures.push(texture);
            let i = geometry.textures.len() - 1;
            texture_cache.push((path, i));
            Ok(i)
        };
    let object_texture = match &o.texture {
        Some(t) => {
            let (line, column) = line_col(ctx.text, span.start);
            Some(texture_index(
                ctx.resolve(t),
                format!("{} line {line}, column {column}", ctx.origin.label),
                geometry,
            )?)
        }
        None => None,
    };
    let add_material = |geometry: &mut Geometry, albedo: [f64; 3], texture: Option<usize>| {
        geometry.materials.push(Material {
            albedo: albedo.map(|c| c as f32),
            texture,
            emission,
        });
        geometry.materials.len() - 1
    };

    // Shape(s) in the local frame, each with its material.
    let mut parts: Vec<(LocalMesh, usize)> = Vec::new();
    let positive = |v: Option<f64>, name: &str, default: f64| -> Result<f64> {
        let v = v.unwrap_or(default);
        if finite_positive(v) {
            Ok(v)
        } else {
            Err(err(format!("{name} = {v}: must be > 0")))
        }
    };
    let segments = o.segments.unwrap_or(48);
    if !(6..=1024).contains(&segments) {
        return Err(err(format!("segments = {segments}: must lie in 6..=1024")));
    }
    // Optotypes are sized for their distance from the camera at time 0 unless told.
    let distance = || -> Result<f64> {
        let d = match o.distance_m {
            Some(d) => d,
            None => glam::DVec3::from(translate).distance(glam::DVec3::from(camera.position_m)),
        };
        if finite_positive(d) {
            Ok(d)
        } else {
            Err(err(format!(
                "distance_m = {d}: must be > 0 (defaults to the distance from the camera)"
            )))
        }
    };
    let card_color = o.card_color.unwrap_or([0.9, 0.9, 0.9]);
    match o.kind {
        ObjectKind::Obj => {
            let Some(file) = &o.file else {
                return Err(err(
                    "an obj object needs file = \"path/to/model.obj\"".into()
                ));
            };
            let path = ctx.resolve(file);
            let loaded = obj::load(&path)?;
            for part in loaded {
                let albedo = match (o.colors.unwrap_or_default(), o.color) {
                    (_, Some(c)) => c,
                    (ObjColors::PerGroup, None) => group_color(&part.name),
                    (ObjColors::Mtl, None) => part.diffuse.unwrap_or([0.8, 0.8, 0.8]),
                };
                let texture = match (&part.texture, object_texture) {
                    (_, Some(t)) => Some(t),
                    (Some(r), None) if o.colors != Some(ObjColors::PerGroup) => {
                        Some(texture_index(
                            r.path.clone(),
                            format!("{} line {}", r.referenced_from, r.line),
                            geometry,
                        )?)
                    }
                    _ => None,
                };
                let material = add_material(geometry, albedo, texture);
                parts.push((part.mesh, material));
            }
        }
        ObjectKind::Plane => {
            let s = o.size_m.map(size3).unwrap_or([1.0; 3]);
            if !(finite_positive(s[0]) && finite_positive(s[1])) {
                return Err(err(
                    "size_m must be > 0 (a number or [width, height])".into()
                ));
            }
            let m = add_material(geometry, color, object_texture);
            parts.push((mesh::plane(s[0], s[1]), m));
        }
        ObjectKind::Cube => {
            let s = o.size_m.map(size3).unwrap_or([1.0; 3]);
            if !s.iter().all(|&v| finite_positive(v)) || matches!(o.size_m, Some(Size::Xy(_))) {
                return Err(err("size_m must be > 0 (a number or [x, y, z])".into()));
            }
            let m = add_material(geometry, color, object_texture);
            parts.push((mesh::cuboid(s), m));
        }
        ObjectKind::Sphere => {
            let r = positive(o.radius_m, "radius_m", 0.5)?;
            let m = add_material(geometry, color, object_texture);
            parts.push((mesh::sphere(r, segments), m));
        }
        ObjectKind::Cylinder => {
            let r = positive(o.radius_m, "radius_m", 0.5)?;
            let h = positive(o.height_m, "height_m", 1.0)?;
            let m = add_material(geometry, color, object_texture);
            parts.push((mesh::cylinder(r, h, segments), m));
        }
        ObjectKind::Optotype => {
            let logmar = acuity_logmar(o, &err)?;
            let d = distance()?;
            let h = optotype::letter_height_m(logmar, d);
            let letter = o.letter.as_deref().unwrap_or("E");
            let direction = match &o.direction {
                None => Direction::Right,
                Some(s) => Direction::parse(s).ok_or_else(|| {
                    err(format!("direction = \"{s}\": use right, up, left or down"))
                })?,
            };
            let glyph = match letter {
                "E" => Glyph::TumblingE(direction),
                "C" | "landolt" => Glyph::LandoltC(direction),
                s if s.chars().count() == 1
                    && optotype::is_known_letter(s.chars().next().unwrap_or(' ')) =>
                {
                    Glyph::Letter(s.chars().next().unwrap_or('O'))
                }
                s => {
                    return Err(err(format!(
                        "letter = \"{s}\": use \"E\" (tumbling E), \"C\" (Landolt C) or a Sloan \
                         letter ({})",
                        optotype::SLOAN_LETTERS.iter().collect::<String>()
                    )))
                }
            };
            let lift = card_lift(d);
            let mut g = optotype::glyph_mesh(glyph, 0.0);
            for p in &mut g.positions {
                *p = [p[0] * h / 5.0, p[1] * h / 5.0, lift];
            }
            let letter_material = add_material(geometry, o.color.unwrap_or([0.03; 3]), None);
            parts.push((g, letter_material));
            if o.card.unwrap_or(true) {
                let card = add_material(geometry, card_color, None);
                parts.push((mesh::plane(2.0 * h, 2.0 * h), card));
            }
        }
        ObjectKind::Chart => {
            let d = distance()?;
            let lines = o
                .lines_logmar
                .clone()
                .unwrap_or_else(|| (0..=10).map(|i| 1.0 - 0.1 * f64::from(i)).collect());
            if lines.is_empty() || lines.iter().any(|l| !(-1.0..=2.0).contains(l)) {
                return Err(err(
                    "lines_logmar: a non-empty list of logMAR values in [-1, 2]".into(),
                ));
            }
            let per_line = o.letters_per_line.unwrap_or(5);
            if !(1..=20).contains(&per_line) {
                return Err(err(format!(
                    "letters_per_line = {per_line}: must lie in 1..=20"
                )));
            }
            let style = match o.optotype.as_deref().unwrap_or("sloan") {
                "sloan" => ChartStyle::Sloan,
                "E" | "tumbling-e" => ChartStyle::TumblingE,
                "C" | "landolt-c" => ChartStyle::LandoltC,
                s => {
                    return Err(err(format!(
                        "optotype = \"{s}\": use \"sloan\", \"E\" or \"C\""
                    )))
                }
            };
            let lift = card_lift(d);
            let (letters, width, height) =
                optotype::chart_mesh(&lines, per_line, d, style, o.seed.unwrap_or(1), lift);
            let letter_material = add_material(geometry, o.color.unwrap_or([0.03; 3]), None);
            parts.push((letters, letter_material));
            if o.card.unwrap_or(true) {
                let margin = optotype::letter_height_m(lines[0], d);
                let card = add_material(geometry, card_color, None);
                parts.push((
                    mesh::plane(width + 2.0 * margin, height + 2.0 * margin),
                    card,
                ));
            }
        }
    }

    // Placement, repeated if asked.
    let repeat = o.repeat.unwrap_or(RepeatSpec {
        count: 1,
        step: [0.0; 3],
        growth: 1.0,
        scale_growth: 1.0,
    });
    if !(1..=10_000).contains(&repeat.count)
        || !finite_positive(repeat.growth)
        || !finite_positive(repeat.scale_growth)
        || repeat.step.iter().any(|s| !s.is_finite())
    {
        return Err(err(
            "repeat: count in 1..=10000, finite step, growth and scale_growth > 0".into(),
        ));
    }
    let mut offset_factor = 0.0;
    for i in 0..repeat.count {
        let position = [0, 1, 2].map(|k| translate[k] + repeat.step[k] * offset_factor);
        let s = repeat.scale_growth.powi(i as i32);
        let model = mesh::model_matrix(position, rotate, scale.map(|v| v * s));
        for (m, material) in &parts {
            geometry.add(m, &model, *material);
        }
        offset_factor += repeat.growth.powi(i as i32);
    }
    Ok(())
}

/// How far letters sit in front of their card: far enough for the depth buffer to separate
/// them at any distance, too little to matter optically (0.01 % of the distance, ≥ 0.1 mm).
fn card_lift(distance_m: f64) -> f64 {
    (distance_m * 1e-4).max(1e-4)
}

fn acuity_logmar(o: &ObjectSpec, err: &dyn Fn(String) -> Error) -> Result<f64> {
    match (o.acuity_decimal, o.logmar) {
        (Some(v), None) if finite_positive(v) => Ok(-v.log10()),
        (Some(v), None) => Err(err(format!("acuity_decimal = {v}: must be > 0"))),
        (None, Some(l)) if (-1.0..=2.0).contains(&l) => Ok(l),
        (None, Some(l)) => Err(err(format!("logmar = {l}: must lie in [-1, 2]"))),
        (None, None) => Ok(0.0),
        (Some(_), Some(_)) => Err(err("give acuity_decimal or logmar, not both".into())),
    }
}

/// A stable, distinct, mid-grey-ish colour per OBJ group name.
fn group_color(name: &str) -> [f64; 3] {
    let mut h: u64 = 0xcbf2_9ce4_8422_2325;
    for b in name.bytes() {
        h ^= u64::from(b);
        h = h.wrapping_mul(0x100_0000_01b3);
    }
    let hue = (h % 360) as f64;
    // HSV with s = 0.45, v = 0.8 → linear-ish reflectances between about 0.44 and 0.8.
    let (s, v) = (0.45, 0.8);
    let c = v * s;
    let x = c * (1.0 - ((hue / 60.0) % 2.0 - 1.0).abs());
    let (r, g, b) = match (hue / 60.0) as u32 {
        0 => (c, x, 0.0),
        1 => (x, c, 0.0),
        2 => (0.0, c, x),
        3 => (0.0, x, c),
        4 => (x, 0.0, c),
        _ => (c, 0.0, x),
    };
    let m = v - c;
    [r + m, g + m, b + m]
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
                if !(f > 0.0 && f < 179.0) {
                    return Err(err(format!("fov_y_deg = {f}: must lie in (0, 179)")));
                }
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
            if !(p > 0.5 && p < 10.0) {
                return Err(err(format!("pupil_mm = {p}: must lie in (0.5, 10) mm")));
            }
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
