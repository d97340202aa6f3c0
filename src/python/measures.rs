//! Image metrics (the library's PSNR and SSIM, as `ocular compare` computes them) and EXR
//! files in and out, so that arrays can meet the CLI.

use std::path::PathBuf;

use numpy::PyArray3;
use pyo3::prelude::*;

use super::arrays::{f32_array, rgb_out};
use super::{guarded, missing_file, value_error};
use crate::image_io::{ImageGray, ImageRgba};
use crate::metrics::ImageView;

/// An (H, W, 3) float32 array as RGBA pixels, with its width and height.
fn rgb_image(obj: &Bound<'_, PyAny>, name: &str) -> PyResult<(usize, usize, Vec<[f32; 4]>)> {
    let a = f32_array(obj, name)?;
    let [h, w, 3] = a.shape.as_slice() else {
        return Err(value_error(format!(
            "{name}: shape {:?} where (H, W, 3) is required",
            a.shape
        )));
    };
    let pixels = a
        .values
        .chunks_exact(3)
        .map(|c| [c[0], c[1], c[2], 1.0])
        .collect();
    Ok((*w, *h, pixels))
}

/// Two images of one size: (width, height, image pixels, reference pixels).
type ImagePair = (usize, usize, Vec<[f32; 4]>, Vec<[f32; 4]>);

fn image_pair(
    image: &Bound<'_, PyAny>,
    reference: &Bound<'_, PyAny>,
    data_range: f64,
) -> PyResult<ImagePair> {
    let (w, h, a) = rgb_image(image, "image")?;
    let (rw, rh, b) = rgb_image(reference, "reference")?;
    if (w, h) != (rw, rh) {
        return Err(value_error(format!(
            "image is {w}×{h} but reference is {rw}×{rh}; they must match"
        )));
    }
    if !(data_range.is_finite() && data_range > 0.0) {
        return Err(value_error(format!(
            "data_range {data_range} must be a positive number (1 for images in [0, 1])"
        )));
    }
    Ok((w, h, a, b))
}

/// Peak signal-to-noise ratio (dB) of `image` against `reference` over the three channels;
/// inf for identical images.
#[pyfunction]
#[pyo3(signature = (image, reference, data_range = 1.0))]
pub fn psnr(
    image: &Bound<'_, PyAny>,
    reference: &Bound<'_, PyAny>,
    data_range: f64,
) -> PyResult<f64> {
    let (w, h, a, b) = image_pair(image, reference, data_range)?;
    Ok(crate::metrics::psnr(
        ImageView::new(w, h, &a),
        ImageView::new(w, h, &b),
        data_range,
    ))
}

/// Mean SSIM (Wang et al. 2004: 11×11 Gaussian window, σ 1.5, per channel and averaged, over
/// the valid region). With `full=True`: (mean, per-pixel map as an (H, W) float32 array).
#[pyfunction]
#[pyo3(signature = (image, reference, data_range = 1.0, full = false))]
pub fn ssim<'py>(
    py: Python<'py>,
    image: &Bound<'py, PyAny>,
    reference: &Bound<'py, PyAny>,
    data_range: f64,
    full: bool,
) -> PyResult<Bound<'py, PyAny>> {
    let (w, h, a, b) = image_pair(image, reference, data_range)?;
    let s = py.allow_threads(|| {
        crate::metrics::ssim(
            ImageView::new(w, h, &a),
            ImageView::new(w, h, &b),
            data_range,
        )
    });
    if full {
        let map = super::arrays::gray_out(py, w, h, s.map);
        Ok((s.mean, map).into_pyobject(py)?.into_any())
    } else {
        Ok(s.mean.into_pyobject(py)?.into_any())
    }
}

/// FLIP (Andersson et al. 2020) of `image` against `reference`, as `ocular metrics` computes
/// it: LDR-FLIP of linear sRGB clamped to [0, 1], or with `hdr=True` HDR-FLIP over the
/// automatic exposure range with the ACES tone mapper. `ppd`: pixels per degree of the viewing
/// condition (default FLIP's, 67.02). Returns the mean error in [0, 1]; with `full=True`
/// (mean, per-pixel map as an (H, W) float32 array).
#[pyfunction]
#[pyo3(signature = (image, reference, ppd = crate::metrics::flip::DEFAULT_PPD, hdr = false, full = false))]
pub fn flip<'py>(
    py: Python<'py>,
    image: &Bound<'py, PyAny>,
    reference: &Bound<'py, PyAny>,
    ppd: f64,
    hdr: bool,
    full: bool,
) -> PyResult<Bound<'py, PyAny>> {
    let (w, h, a, b) = image_pair(image, reference, 1.0)?;
    if !crate::metrics::flip::ppd_in_range(ppd) {
        let (lo, hi) = crate::metrics::flip::PPD_RANGE;
        return Err(value_error(format!(
            "ppd {ppd} is outside {lo} to {hi} pixels per degree"
        )));
    }
    if let Some(bad) = a
        .iter()
        .chain(&b)
        .flat_map(|p| &p[..3])
        .find(|v| !v.is_finite())
    {
        return Err(value_error(format!(
            "image and reference must be finite (found {bad})"
        )));
    }
    if hdr && a.iter().chain(&b).flat_map(|p| &p[..3]).any(|v| *v < 0.0) {
        return Err(value_error(
            "HDR-FLIP takes non-negative linear values; image or reference has a negative one",
        ));
    }
    let map = py.allow_threads(|| {
        let test = ImageView::new(w, h, &a);
        let reference = ImageView::new(w, h, &b);
        if hdr {
            crate::metrics::flip::hdr_flip(
                reference,
                test,
                ppd,
                &crate::metrics::flip::HdrSettings::default(),
            )
            .map(|f| f.map)
            .map_err(|e| e.to_string())
        } else {
            Ok(crate::metrics::flip::ldr_flip(reference, test, ppd))
        }
    });
    let map = map.map_err(value_error)?;
    let mean = crate::metrics::flip::FlipStats::of(&map).mean;
    if full {
        let map = super::arrays::gray_out(py, w, h, map);
        Ok((mean, map).into_pyobject(py)?.into_any())
    } else {
        Ok(mean.into_pyobject(py)?.into_any())
    }
}

/// Reads the colour of an EXR (R, G, B; linear) as an (H, W, 3) float32 array.
#[pyfunction]
pub fn read_exr<'py>(py: Python<'py>, path: PathBuf) -> PyResult<Bound<'py, PyArray3<f32>>> {
    if let Some(e) = missing_file(&path) {
        return Err(e);
    }
    let image = guarded(py, move || crate::image_io::read_exr_rgba(&path))?;
    Ok(rgb_out(py, image.width, image.height, &image.pixels))
}

/// Writes an EXR atomically: an (H, W, 3) float32 array as linear R, G, B, or an (H, W)
/// float32 array as depth (channel Z, metres), as `ocular render --color/--depth` read them.
#[pyfunction]
pub fn write_exr(py: Python<'_>, path: PathBuf, array: &Bound<'_, PyAny>) -> PyResult<()> {
    let a = f32_array(array, "array")?;
    match a.shape.as_slice() {
        [h, w, 3] => {
            let pixels = a
                .values
                .chunks_exact(3)
                .map(|c| [c[0], c[1], c[2], 1.0])
                .collect();
            let image = ImageRgba::new(*w as u32, *h as u32, pixels);
            guarded(py, move || crate::image_io::write_exr_rgba(&path, &image))
        }
        [h, w] => {
            let image = ImageGray::new(*w as u32, *h as u32, a.values);
            guarded(py, move || crate::image_io::write_exr_depth(&path, &image))
        }
        other => Err(value_error(format!(
            "array: shape {other:?} where (H, W, 3) colour or (H, W) depth is required"
        ))),
    }
}
