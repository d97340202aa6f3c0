//! Objects of a scene file: the `[[object]]` table, its checks, and the geometry each kind
//! makes (OBJ parts, primitives, optotypes and charts), placed and repeated in world space.

use std::path::PathBuf;

use serde::Deserialize;
use toml::Spanned;

use super::camera::Camera;
use super::mesh::{self, Geometry, LocalMesh, Material};
use super::obj;
use super::optotype::{self, ChartStyle, Direction, Glyph};
use super::spec::{chromaticity, finite_positive, line_col, Ctx};
use crate::{Error, Result};

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
pub(super) struct ObjectSpec {
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

fn size3(size: Size) -> [f64; 3] {
    match size {
        Size::Uniform(s) => [s, s, s],
        Size::Xy([x, y]) => [x, y, 1.0],
        Size::Xyz(v) => v,
    }
}

pub(super) fn add_object(
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
            let loaded = obj::load(&path).map_err(|e| match e {
                // Say where a missing model was asked for; other errors point into the OBJ.
                Error::File { path, message } if message.ends_with("not found") => {
                    let (line, _) = line_col(ctx.text, span.start);
                    Error::File {
                        path,
                        message: format!(
                            "{message} (file = \"{file}\" in {} line {line})",
                            ctx.origin.label
                        ),
                    }
                }
                e => e,
            })?;
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
