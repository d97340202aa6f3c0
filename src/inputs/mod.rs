//! Colour and depth from files other tools wrote (Blender and other renderers, cameras,
//! image editors): which data to take, how to read it as linear cd/m² and metres, and what to
//! refuse. Everything a file input goes through before it reaches a renderer is here, once.
//!
//! The submodules are private: [`load`], its types and the `pub use` items below are the
//! module's public surface.

pub(crate) mod depth;
pub(crate) mod exr;
pub(crate) mod layered;
pub(crate) mod picture;

use std::path::{Path, PathBuf};

use crate::image_types::ImageRgba;
use crate::{Error, Result};

// Depth: raw samples to metres, and what that did.
pub use depth::{apply, DepthReport};

/// What to read and how.
#[derive(Clone, Debug)]
pub struct FileInputOptions {
    pub color: PathBuf,
    /// None: the depth comes from the colour file (an EXR holding both).
    pub depth: Option<PathBuf>,
    pub color_layer: Option<String>,
    pub depth_channel: Option<String>,
    /// Scene units → metres.
    pub depth_scale: f64,
    /// Luminance (cd/m²) of white: of sRGB white in pictures (None:
    /// [`picture::DEFAULT_WHITE_CDM2`]), of 1.0 in EXR colour (None: EXR values are cd/m²).
    pub white_cdm2: Option<f64>,
    /// Replace non-finite colour samples by 0 instead of refusing the file.
    pub repair_nonfinite: bool,
    /// Of a multi-view EXR (OpenEXR's convention; Blender's stereoscopy output), read this
    /// view alone (`left`, `right`); None: a single view.
    pub view: Option<String>,
}

/// A colour + depth frame read from files, with where each came from.
#[derive(Clone, Debug)]
pub struct FileInput {
    pub color: ImageRgba,
    pub depth_m: Vec<f32>,
    /// `c.exr (ViewLayer.Combined)`, `photo.png (sRGB, white 80 cd/m²)`.
    pub color_source: String,
    /// `d.exr (ViewLayer.Depth.Z)`.
    pub depth_source: String,
    pub depth_report: DepthReport,
    /// Lines for stderr and the JSON summary, each starting with the file it concerns.
    pub warnings: Vec<String>,
    /// Hidden layers (colour, depth in metres; +∞ where empty) of a layered EXR, nearest
    /// first; empty for any other input.
    pub hidden_layers: Vec<(Vec<[f32; 4]>, Vec<f32>)>,
}

#[derive(Clone, Copy, PartialEq, Eq)]
enum Kind {
    Exr,
    Picture,
}

fn kind_of(path: &Path, option: &str) -> Result<Kind> {
    let ext = path
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase);
    match ext.as_deref() {
        Some("exr") => Ok(Kind::Exr),
        Some("png" | "jpg" | "jpeg" | "tif" | "tiff") => Ok(Kind::Picture),
        _ => Err(Error::input(format!(
            "{option} {}: expected .exr (linear), or .png, .jpg/.jpeg, .tif/.tiff (sRGB)",
            path.display()
        ))),
    }
}

/// Reads colour and depth as the options say, applying the depth policy ([`depth`]) and the
/// refusal of non-finite colour.
pub fn load(options: &FileInputOptions) -> Result<FileInput> {
    let scale = options.depth_scale;
    if !(scale.is_finite() && scale > 0.0 && scale <= 1e6) {
        return Err(Error::input(format!(
            "--depth-scale {scale} must be a positive factor from scene units to metres (at \
             most 1e6)"
        )));
    }
    let color_kind = kind_of(&options.color, "--color")?;
    if let Some(white) = options.white_cdm2 {
        if !(white.is_finite() && white > 0.0 && white <= 1e6) {
            return Err(Error::input(format!(
                "--white-cdm2 {white} must be a luminance in (0, 1e6] cd/m²"
            )));
        }
    }
    if options.color_layer.is_some() && color_kind != Kind::Exr {
        return Err(Error::input(
            "--color-layer applies to EXR colour; pictures have one layer",
        ));
    }
    let mut warnings = Vec::new();
    let in_view = |file: exr::ExrChannels, path: &Path| match &options.view {
        Some(view) => file.only_view(path, view),
        None => Ok(file),
    };
    let color_exr = match color_kind {
        Kind::Exr => Some(in_view(
            exr::ExrChannels::read(&options.color)?,
            &options.color,
        )?),
        Kind::Picture => {
            if let Some(view) = &options.view {
                return Err(Error::input(format!(
                    "--color {}: a picture has one view, not a {view} view; a stereo pair from                      pictures is one file per eye",
                    options.color.display()
                )));
            }
            None
        }
    };
    if let Some(file) = &color_exr {
        if let Some(layers) = layered::read_layers(&options.color, file)? {
            if options.view.is_some() {
                return Err(Error::file(
                    &options.color,
                    "a layered EXR with views is not read yet: give one layered file per eye",
                ));
            }
            return load_layered(options, layers);
        }
    }
    let (mut color, color_source, color_layer) = match &color_exr {
        Some(file) => {
            let (mut image, group) = file.color(&options.color, options.color_layer.as_deref())?;
            if let Some(white) = options.white_cdm2 {
                let k = white as f32;
                for p in &mut image.pixels {
                    for v in &mut p[..3] {
                        *v *= k;
                    }
                }
            }
            let layer = file
                .channels
                .iter()
                .find(|c| c.group == group)
                .map(|c| (c.layer.clone(), c.view.clone()));
            let mut notes: Vec<String> = Vec::new();
            if !group.is_empty() {
                notes.push(group.clone());
            }
            if let Some(white) = options.white_cdm2 {
                notes.push(format!("1.0 = {white} cd/m²"));
            }
            let label = if notes.is_empty() {
                options.color.display().to_string()
            } else {
                format!("{} ({})", options.color.display(), notes.join(", "))
            };
            (image, label, layer)
        }
        None => {
            let white = options.white_cdm2.unwrap_or(picture::DEFAULT_WHITE_CDM2);
            let (image, encoding) = picture::read_picture(&options.color, white)?;
            let label = match encoding {
                picture::Encoding::Srgb => {
                    format!("{} (sRGB, white {white} cd/m²)", options.color.display())
                }
                picture::Encoding::LinearFloat => {
                    format!("{} (linear float)", options.color.display())
                }
            };
            (image, label, None)
        }
    };
    if let Some(w) = check_finite_color(&options.color, &mut color, options.repair_nonfinite)? {
        warnings.push(w);
    }

    let depth_path = options.depth.as_ref().unwrap_or(&options.color);
    let depth_option = if options.depth.is_some() {
        "--depth"
    } else {
        "--color (used for depth too, as --depth is not given)"
    };
    if kind_of(depth_path, depth_option)? != Kind::Exr {
        return Err(Error::input(format!(
            "{depth_option} {}: depth must be an EXR holding depth in scene units",
            depth_path.display()
        )));
    }
    let separate;
    let depth_file = match (&options.depth, &color_exr) {
        (None, Some(file)) => file,
        _ => {
            let file = exr::ExrChannels::read(depth_path)?;
            // a depth file with views gives the same view; a single-view one is this view's
            separate = if file.views.is_empty() {
                file
            } else {
                in_view(file, depth_path)?
            };
            &separate
        }
    };
    let (channel, candidates) = depth_file.depth(
        depth_path,
        options.depth_channel.as_deref(),
        color_layer.as_ref().map(|(l, v)| (l.as_str(), v.as_str())),
    )?;
    let raw = exr::RawDepth::from_channel(channel, candidates);
    if (color.width, color.height) != (raw.image.width, raw.image.height) {
        return Err(Error::input(format!(
            "colour {} is {}×{} but depth {} is {}×{}; they must match",
            color_source, color.width, color.height, raw.channel, raw.image.width, raw.image.height
        )));
    }
    let (depth_m, report) = depth::apply(&raw.image.pixels, raw.image.width, raw.half, scale);
    for w in report.warnings() {
        warnings.push(format!("{}: {w}", depth_path.display()));
    }
    Ok(FileInput {
        color,
        depth_m,
        color_source,
        depth_source: format!("{} ({})", depth_path.display(), raw.channel),
        depth_report: report,
        warnings,
        hidden_layers: Vec::new(),
    })
}

/// A layered EXR (parts `layer0`, `layer1`, …): layer 0 is the frame, the rest hidden layers.
fn load_layered(
    options: &FileInputOptions,
    (width, height, layers): (u32, u32, Vec<layered::RawLayer>),
) -> Result<FileInput> {
    let path = &options.color;
    if let Some(depth) = &options.depth {
        if depth != path {
            return Err(Error::input(format!(
                "--depth {}: {} is a layered EXR (parts layer0, layer1, …) holding its own depth; \
                 give it as --depth too, or leave --depth out",
                depth.display(),
                path.display()
            )));
        }
    }
    for (given, name) in [
        (options.color_layer.is_some(), "--color-layer"),
        (options.depth_channel.is_some(), "--depth-channel"),
    ] {
        if given {
            return Err(Error::input(format!(
                "{name} does not apply to the layered EXR {} (parts layer0, layer1, … with R, G, \
                 B, Z each)",
                path.display()
            )));
        }
    }
    let white = options.white_cdm2.unwrap_or(1.0) as f32;
    let mut warnings = Vec::new();
    let mut layers = layers.into_iter();
    let first = layers.next().expect("layer0 is there");
    let mut color = ImageRgba::new(
        width,
        height,
        first
            .color
            .iter()
            .map(|c| [c[0] * white, c[1] * white, c[2] * white, 1.0])
            .collect(),
    );
    if let Some(w) = check_finite_color(path, &mut color, options.repair_nonfinite)? {
        warnings.push(w);
    }
    let (depth_m, report) = depth::apply(&first.z, width, first.half, options.depth_scale);
    for w in report.warnings() {
        warnings.push(format!("{}: {w}", path.display()));
    }
    let mut hidden_layers = Vec::new();
    for (k, mut layer) in layers.enumerate() {
        for c in &mut layer.color {
            for v in &mut c[..3] {
                *v *= white;
            }
        }
        hidden_layers.push(layered::hidden_layer(
            path,
            k + 1,
            layer,
            width,
            options.depth_scale,
        )?);
    }
    Ok(FileInput {
        color,
        depth_m,
        color_source: format!("{} (layer0 of {})", path.display(), 1 + hidden_layers.len()),
        depth_source: format!("{} (layer0.Z)", path.display()),
        depth_report: report,
        warnings,
        hidden_layers,
    })
}

/// Refuses colour with NaN or infinite samples (they would spread through every kernel that
/// touches them), naming their count and the first; with `repair` replaces them by 0 instead
/// and returns the warning to print.
pub fn check_finite_color(
    path: &Path,
    image: &mut ImageRgba,
    repair: bool,
) -> Result<Option<String>> {
    let bad: Vec<usize> = image
        .pixels
        .iter()
        .enumerate()
        .filter(|(_, p)| p.iter().any(|v| !v.is_finite()))
        .map(|(i, _)| i)
        .collect();
    let Some(&first) = bad.first() else {
        return Ok(None);
    };
    let w = image.width.max(1) as usize;
    let (x, y) = (first % w, first / w);
    if !repair {
        return Err(Error::file(
            path,
            format!(
                "{} pixel(s) have non-finite colour (NaN or infinity), first at ({x}, {y}); fix \
                 the file or pass --repair-nonfinite to render them as black",
                bad.len()
            ),
        ));
    }
    for &i in &bad {
        for v in image.pixels[i].iter_mut() {
            if !v.is_finite() {
                *v = 0.0;
            }
        }
    }
    Ok(Some(format!(
        "{}: {} pixel(s) with non-finite colour, first at ({x}, {y}), set to 0 \
         (--repair-nonfinite)",
        path.display(),
        bad.len()
    )))
}
