//! Reading and writing images: OpenEXR for linear HDR colour and metric depth, PNG for
//! previews. Every write is atomic (a temporary file in the same folder, fsync, rename), so a
//! failed or interrupted write never leaves a partial file under the final name. Every failure
//! is an `Error::File` naming the file.

use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};

pub use crate::image_types::{ImageGray, ImageRgba};
use crate::{Error, Result};

/// Relative luminance of linear Rec.709/sRGB primaries; in ocular's calibrated frames it is
/// in cd/m².
pub fn luminance(rgb: [f32; 3]) -> f32 {
    0.2126 * rgb[0] + 0.7152 * rgb[1] + 0.0722 * rgb[2]
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum TonemapMode {
    /// Scale by the exposure, then clip at 1.
    #[default]
    Clamp,
    /// Scale by the exposure, then compress luminance with L / (1 + L) (hue kept).
    Reinhard,
}

/// How linear HDR values become an 8-bit preview.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Tonemap {
    /// Linear values are multiplied by 2^exposure_ev before the curve.
    pub exposure_ev: f32,
    pub mode: TonemapMode,
}

impl Default for Tonemap {
    fn default() -> Self {
        Tonemap {
            exposure_ev: 0.0,
            mode: TonemapMode::Clamp,
        }
    }
}

impl Tonemap {
    /// Exposure that maps the image's log-average luminance to middle grey (0.18): a sensible
    /// default for luminance-calibrated frames whose values are in cd/m².
    pub fn auto_exposure_ev(image: &ImageRgba) -> f32 {
        Tonemap::auto_exposure_ev_of(&image.pixels)
    }

    /// [`Tonemap::auto_exposure_ev`] of bare pixels (linear RGBA, alpha ignored).
    pub fn auto_exposure_ev_of(pixels: &[[f32; 4]]) -> f32 {
        let mut sum = 0.0f64;
        let mut count = 0usize;
        for p in pixels {
            let y = luminance([p[0], p[1], p[2]]);
            if y.is_finite() && y > 0.0 {
                sum += f64::from(y.max(1e-4)).ln();
                count += 1;
            }
        }
        if count == 0 {
            return 0.0;
        }
        let log_average = (sum / count as f64).exp();
        (0.18 / log_average).log2() as f32
    }

    fn apply(&self, rgb: [f32; 3]) -> [f32; 3] {
        let scale = self.exposure_ev.exp2();
        let rgb = rgb.map(|c| {
            if c.is_finite() {
                c.max(0.0) * scale
            } else {
                0.0
            }
        });
        match self.mode {
            TonemapMode::Clamp => rgb,
            TonemapMode::Reinhard => {
                let y = luminance(rgb);
                let k = 1.0 / (1.0 + y);
                rgb.map(|c| c * k)
            }
        }
    }
}

/// The sRGB transfer function of a linear value in [0, 1].
fn srgb_encode(linear: f32) -> f32 {
    let c = linear.clamp(0.0, 1.0);
    if c <= 0.003_130_8 {
        12.92 * c
    } else {
        1.055 * c.powf(1.0 / 2.4) - 0.055
    }
}

/// Decodes an 8-bit sRGB value to linear.
pub fn srgb_decode(encoded: u8) -> f32 {
    let c = f32::from(encoded) / 255.0;
    if c <= 0.040_45 {
        c / 12.92
    } else {
        ((c + 0.055) / 1.055).powf(2.4)
    }
}

fn file_error(path: &Path, message: impl std::fmt::Display) -> Error {
    Error::file(path, message)
}

/// Writes a file through `write` into `NAME.tmp-PID` next to `path`, syncs it and renames it
/// into place; on any failure the temporary file is removed and `path` is untouched.
pub fn write_atomic<F>(path: &Path, write: F) -> Result<()>
where
    F: FnOnce(&mut BufWriter<std::fs::File>) -> std::result::Result<(), String>,
{
    let file_name = path
        .file_name()
        .ok_or_else(|| file_error(path, "not a file name"))?;
    let mut tmp_name = file_name.to_os_string();
    tmp_name.push(format!(".tmp-{}", std::process::id()));
    let tmp: PathBuf = path.with_file_name(tmp_name);
    let result = (|| -> std::result::Result<(), String> {
        let file = std::fs::File::create(&tmp).map_err(|e| format!("cannot create: {e}"))?;
        let mut writer = BufWriter::new(file);
        write(&mut writer)?;
        writer.flush().map_err(|e| format!("cannot write: {e}"))?;
        let file = writer
            .into_inner()
            .map_err(|e| format!("cannot write: {}", e.error()))?;
        file.sync_all().map_err(|e| format!("cannot sync: {e}"))?;
        drop(file);
        std::fs::rename(&tmp, path).map_err(|e| format!("cannot rename into place: {e}"))
    })();
    if let Err(message) = result {
        let _ = std::fs::remove_file(&tmp);
        return Err(file_error(path, message));
    }
    // Make the rename itself durable where the platform allows syncing a folder.
    if let Some(dir) = path.parent().filter(|d| !d.as_os_str().is_empty()) {
        if let Ok(d) = std::fs::File::open(dir) {
            let _ = d.sync_all();
        }
    }
    Ok(())
}

/// Writes `text` to `path` atomically (see [`write_atomic`]).
pub fn write_text_atomic(path: impl AsRef<Path>, text: &str) -> Result<()> {
    write_atomic(path.as_ref(), |w| {
        w.write_all(text.as_bytes())
            .map_err(|e| format!("cannot write: {e}"))
    })
}

fn check_size(path: &Path, width: u32, height: u32, len: usize) -> Result<()> {
    if width == 0 || height == 0 {
        return Err(file_error(
            path,
            format!("cannot write an empty {width}×{height} image"),
        ));
    }
    if len != width as usize * height as usize {
        return Err(file_error(
            path,
            format!("{len} pixels do not make a {width}×{height} image"),
        ));
    }
    Ok(())
}

/// Reads the colour of an EXR as f32 (missing alpha reads as 1): the one `<layer>.Combined`
/// group, else the one RGB group, else the one luminance (Y) group (see
/// [`crate::inputs::exr`]); several candidates or none is an error that lists them.
pub fn read_exr_rgba(path: impl AsRef<Path>) -> Result<ImageRgba> {
    let path = path.as_ref();
    let file = crate::inputs::exr::ExrChannels::read(path)?;
    Ok(file.color(path, None)?.0)
}

/// Reads the depth channel of an EXR, raw (no background or unit policy): a `Depth` pass
/// (`ViewLayer.Depth.Z`, `Depth.V`), a channel named Z or depth, or the only channel of a
/// one-channel file (see [`crate::inputs::exr`]).
pub fn read_exr_depth(path: impl AsRef<Path>) -> Result<ImageGray> {
    Ok(read_exr_depth_channel(path)?.0)
}

/// As `read_exr_depth`, also returning the channel used and every candidate channel present.
pub fn read_exr_depth_channel(path: impl AsRef<Path>) -> Result<(ImageGray, String, Vec<String>)> {
    let path = path.as_ref();
    let file = crate::inputs::exr::ExrChannels::read(path)?;
    let (channel, candidates) = file.depth(path, None, None)?;
    let raw = crate::inputs::exr::RawDepth::from_channel(channel, candidates);
    Ok((raw.image, raw.channel, raw.candidates))
}

/// Writes linear RGBA as 32-bit float EXR (channels R, G, B, A). Identical pixels give
/// identical bytes (see [`exr_rgba_bytes`]).
pub fn write_exr_rgba(path: impl AsRef<Path>, image: &ImageRgba) -> Result<()> {
    let path = path.as_ref();
    check_size(path, image.width, image.height, image.pixels.len())?;
    let bytes = exr_rgba_bytes(image).map_err(|m| file_error(path, m))?;
    write_bytes_atomic(path, &bytes)
}

/// The tile layout and compression of ocular's EXRs, with the blocks stored in increasing-y
/// order: the encoder compresses tiles on several threads, and with the format's "unspecified"
/// order it stores them as they finish, so identical pixels gave different files.
fn deterministic_encoding() -> exr::image::Encoding {
    exr::image::Encoding {
        line_order: exr::meta::attribute::LineOrder::Increasing,
        ..exr::image::Encoding::FAST_LOSSLESS
    }
}

/// The bytes of a 32-bit float RGBA EXR of `image`: a pure function of the pixels.
pub fn exr_rgba_bytes(image: &ImageRgba) -> std::result::Result<Vec<u8>, String> {
    use exr::prelude::*;
    if image.width == 0 || image.height == 0 {
        return Err(format!(
            "cannot write an empty {}×{} image",
            image.width, image.height
        ));
    }
    let width = image.width as usize;
    let channels = SpecificChannels::rgba(|position: Vec2<usize>| {
        let p = image.pixels[position.y() * width + position.x()];
        (p[0], p[1], p[2], p[3])
    });
    exr_bytes(&Image::from_encoded_channels(
        (width, image.height as usize),
        deterministic_encoding(),
        channels,
    ))
}

/// The bytes of a one-layer EXR image.
fn exr_bytes<'c, C>(
    image: &'c exr::image::Image<exr::image::Layer<C>>,
) -> std::result::Result<Vec<u8>, String>
where
    C: exr::image::write::channels::WritableChannels<'c>,
{
    use exr::prelude::*;
    let mut cursor = std::io::Cursor::new(Vec::new());
    image
        .write()
        .to_buffered(&mut cursor)
        .map_err(|e| format!("cannot encode EXR: {e}"))?;
    Ok(cursor.into_inner())
}

fn write_bytes_atomic(path: &Path, bytes: &[u8]) -> Result<()> {
    write_atomic(path, |writer| {
        writer
            .write_all(bytes)
            .map_err(|e| format!("cannot write: {e}"))
    })
}

/// Writes one 32-bit float channel named `channel` (use "Z" for depth, the EXR convention);
/// byte-deterministic like [`write_exr_rgba`].
pub fn write_exr_gray(path: impl AsRef<Path>, image: &ImageGray, channel: &str) -> Result<()> {
    use exr::prelude::*;
    let path = path.as_ref();
    check_size(path, image.width, image.height, image.pixels.len())?;
    let width = image.width as usize;
    let channels = SpecificChannels::build()
        .with_channel(channel)
        .with_pixel_fn(
            |position: Vec2<usize>| (image.pixels[position.y() * width + position.x()],),
        );
    let bytes = exr_bytes(&Image::from_encoded_channels(
        (width, image.height as usize),
        deterministic_encoding(),
        channels,
    ))
    .map_err(|m| file_error(path, m))?;
    write_bytes_atomic(path, &bytes)
}

/// Writes depth in metres as a single-channel EXR with the conventional channel name Z.
pub fn write_exr_depth(path: impl AsRef<Path>, image: &ImageGray) -> Result<()> {
    write_exr_gray(path, image, "Z")
}

/// Writes an 8-bit sRGB PNG preview of linear RGB (alpha is dropped).
pub fn write_png(path: impl AsRef<Path>, image: &ImageRgba, tonemap: Tonemap) -> Result<()> {
    let path = path.as_ref();
    check_size(path, image.width, image.height, image.pixels.len())?;
    let bytes = png_bytes(image, tonemap).map_err(|m| file_error(path, m))?;
    write_bytes_atomic(path, &bytes)
}

/// The bytes of the 8-bit sRGB PNG that [`write_png`] writes.
pub fn png_bytes(image: &ImageRgba, tonemap: Tonemap) -> std::result::Result<Vec<u8>, String> {
    use image::ImageEncoder;
    let mut rgb8 = Vec::with_capacity(image.pixels.len() * 3);
    for p in &image.pixels {
        let rgb = tonemap.apply([p[0], p[1], p[2]]);
        rgb8.extend(rgb.map(|c| (srgb_encode(c) * 255.0 + 0.5) as u8));
    }
    let mut out = Vec::new();
    image::codecs::png::PngEncoder::new(&mut out)
        .write_image(
            &rgb8,
            image.width,
            image.height,
            image::ExtendedColorType::Rgb8,
        )
        .map_err(|e| format!("cannot encode PNG: {e}"))?;
    Ok(out)
}
