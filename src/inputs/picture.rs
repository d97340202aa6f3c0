//! Colour from ordinary pictures (PNG, JPEG, TIFF): integer samples are sRGB-encoded and are
//! decoded to linear light, then scaled so that white is a luminance in cd/m²; float TIFF
//! samples are taken as linear already (and in cd/m²).

use std::path::Path;

use crate::image_types::ImageRgba;
use crate::{Error, Result};

/// Luminance of white (cd/m²) when none is given: the reference display of the sRGB standard
/// (IEC 61966-2-1) is 80 cd/m².
pub const DEFAULT_WHITE_CDM2: f64 = 80.0;

/// The sRGB transfer function inverted, for a sample in [0, 1].
pub fn srgb_to_linear(encoded: f32) -> f32 {
    let c = encoded.clamp(0.0, 1.0);
    if c <= 0.040_45 {
        c / 12.92
    } else {
        ((c + 0.055) / 1.055).powf(2.4)
    }
}

/// How a picture's samples were interpreted.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Encoding {
    /// 8- or 16-bit sRGB, decoded and scaled by the white luminance.
    Srgb,
    /// 32-bit float, taken as linear.
    LinearFloat,
}

/// Reads a PNG, JPEG or TIFF as linear RGBA: sRGB integers are decoded and multiplied by
/// `white_cdm2`; float samples are kept as they are. Alpha is never scaled.
pub fn read_picture(path: &Path, white_cdm2: f64) -> Result<(ImageRgba, Encoding)> {
    let reader = image::ImageReader::open(path).map_err(|e| {
        if e.kind() == std::io::ErrorKind::NotFound {
            Error::file(path, "no such file")
        } else {
            Error::file(path, format!("cannot read: {e}"))
        }
    })?;
    let reader = reader
        .with_guessed_format()
        .map_err(|e| Error::file(path, format!("cannot read: {e}")))?;
    let picture = reader.decode().map_err(|e| {
        Error::file(
            path,
            format!("not a readable PNG, JPEG or TIFF picture ({e})"),
        )
    })?;
    let float = matches!(
        picture,
        image::DynamicImage::ImageRgb32F(_) | image::DynamicImage::ImageRgba32F(_)
    );
    let (width, height) = (picture.width(), picture.height());
    let rgba = picture.into_rgba32f();
    let white = white_cdm2 as f32;
    let pixels: Vec<[f32; 4]> = rgba
        .pixels()
        .map(|p| {
            let [r, g, b, a] = p.0;
            if float {
                [r, g, b, a]
            } else {
                [
                    srgb_to_linear(r) * white,
                    srgb_to_linear(g) * white,
                    srgb_to_linear(b) * white,
                    a,
                ]
            }
        })
        .collect();
    let encoding = if float {
        Encoding::LinearFloat
    } else {
        Encoding::Srgb
    };
    Ok((ImageRgba::new(width, height, pixels), encoding))
}
