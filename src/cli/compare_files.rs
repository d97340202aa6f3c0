//! The files of `ocular compare`: the images and SSIM maps `--maps` writes, its folder, and
//! the images `--truth-in` and `--judge` read.

use std::path::PathBuf;

use super::outputs::Outputs;
use crate::image_io::{self, ImageRgba, Tonemap, TonemapMode};
use crate::render::frame::RenderedFrame;
use crate::render::judge::{non_finite, ssim_map_rgb};
use crate::{Error, Result};

/// The images at the display exposure and the SSIM maps (every row but the truth's).
pub(super) fn write_maps(
    outputs: &mut Outputs,
    (dir, side): (&std::path::Path, Option<&str>),
    (width, height): (u32, u32),
    frames: &[(&RenderedFrame, String, u32)],
    maps: &[Vec<f32>],
    exposure_ev: f32,
) -> Result<()> {
    let shown = Tonemap {
        exposure_ev,
        mode: TonemapMode::Clamp,
    };
    for (i, frame) in frames.iter().enumerate() {
        let name = if i == 0 { "truth" } else { frame.1.as_str() };
        let image = ImageRgba::new(width, height, frame.0.color.clone());
        image_io::write_png(outputs.temporary(&map_file(dir, side, name)), &image, shown)?;
    }
    let flat = Tonemap {
        exposure_ev: 0.0,
        mode: TonemapMode::Clamp,
    };
    for (frame, map) in frames[1..].iter().zip(&maps[1..]) {
        let name = format!("ssim_{}", frame.1);
        image_io::write_png(
            outputs.temporary(&map_file(dir, side, &name)),
            &ImageRgba::new(width, height, ssim_map_rgb(map, 0.9)),
            flat,
        )?;
    }
    Ok(())
}

/// The file of map `name` in `dir`: `NAME.png`, or a pair's `SIDE_NAME.png`.
pub(super) fn map_file(
    dir: &std::path::Path,
    side: Option<&str>,
    name: &str,
) -> std::path::PathBuf {
    match side {
        Some(side) => dir.join(format!("{side}_{name}.png")),
        None => dir.join(format!("{name}.png")),
    }
}

/// The files `--maps` writes, without extension.
pub(super) fn map_names(no_slices: bool, views: bool, layers: bool) -> Vec<&'static str> {
    let mut names = vec!["truth"];
    let mut judged = vec![];
    if views {
        judged.push(("reference", "ssim_reference"));
    }
    judged.push(("splat", "ssim_splat"));
    if layers {
        judged.push(("splat-layers", "ssim_splat-layers"));
    }
    if !no_slices {
        judged.push(("slices", "ssim_slices"));
    }
    names.extend(judged.iter().map(|j| j.0));
    names.extend(judged.iter().map(|j| j.1));
    names
}

/// A `--maps` folder this run created, removed again (if still empty) unless kept.
pub(super) struct CreatedFolder(Option<PathBuf>);

impl CreatedFolder {
    pub(super) fn keep(&mut self) {
        self.0 = None;
    }
}

impl Drop for CreatedFolder {
    fn drop(&mut self) {
        if let Some(dir) = &self.0 {
            let _ = std::fs::remove_dir(dir);
        }
    }
}

/// The `--maps` folder: an existing folder, or a new one in an existing folder.
pub(super) fn maps_folder(dir: &std::path::Path) -> Result<CreatedFolder> {
    if dir.is_dir() {
        return Ok(CreatedFolder(None));
    }
    if dir.exists() {
        return Err(Error::input(format!(
            "--maps {}: is a file; give a folder",
            dir.display()
        )));
    }
    std::fs::create_dir(dir)
        .map_err(|e| Error::input(format!("--maps {}: cannot create it ({e})", dir.display())))?;
    Ok(CreatedFolder(Some(dir.to_path_buf())))
}

/// An image for `--truth-in` or `--judge`, refused if any colour value is not finite (metrics
/// of NaN are not numbers).
pub(super) fn read_truth(option: &str, path: &PathBuf) -> Result<ImageRgba> {
    let image = image_io::read_exr_rgba(path)?;
    if let Some((count, (x, y))) = non_finite(&image.pixels, image.width as usize) {
        return Err(Error::input(format!(
            "{option} {}: {count} pixels are not finite (first at x = {x}, y = {y}); an image \
             to judge or judge by must hold finite colour",
            path.display()
        )));
    }
    Ok(image)
}

/// The row of a `--judge` image: its file name without the extension.
pub(super) fn judged_name(path: &std::path::Path) -> String {
    let stem = path.file_stem().map(|s| s.to_string_lossy().into_owned());
    stem.filter(|s| !s.is_empty())
        .unwrap_or_else(|| "judged".to_string())
}
