//! Judging rendered frames against a truth on the displayed image (`ocular compare`): one row
//! of metrics per method, the SSIM maps as pictures, and the views truth's own convergence.
//! Every image is judged at one exposure, linear values scaled and clamped to [0, 1], because
//! that is what a person sees.

use crate::image_io;
use crate::metrics::flip::{ldr_flip, FlipStats};
use crate::metrics::{psnr, ssim, ssim_false_colour, ImageView};
use crate::render::edge_band::{band_quality, BandQuality};
use crate::render::frame::RenderedFrame;
use crate::render::views::ViewsImage;
use crate::{Error, Result};

/// How far the views truth is from converged: the change when its views double (the even
/// half against all of them), on the displayed image.
#[derive(Clone, Debug, serde::Serialize)]
pub struct ViewsConvergence {
    pub views: u32,
    pub half_views: u32,
    /// PSNR (dB) and MSSIM of the half-views image against the full one.
    pub psnr_db: f64,
    pub mssim: f64,
    /// Largest change of a displayed channel value (0–1).
    pub max_abs_change: f64,
    pub seconds_raster: f64,
    pub seconds_accumulate: f64,
}

#[derive(Clone, Debug, serde::Serialize)]
pub struct MethodResult {
    pub method: String,
    pub seconds: f64,
    pub psnr_db: f64,
    pub mssim: f64,
    pub speedup_vs_reference: f64,
    /// Mean LDR-FLIP of the displayed image against the truth's, at the report's `flip_ppd`.
    pub flip_mean: f64,
    /// GPU time of all passes (splat only).
    pub gpu_ms: Option<f64>,
    /// Pixel × fragment pairs inside a kernel's reach, per pixel of the frame (splat only): the
    /// frame's cost read without a clock.
    pub evaluations_per_pixel: Option<f64>,
    /// Filtered texture reads the GPU's convolution makes for them, per pixel, at most (splat
    /// only; `SplatStats::texture_reads`).
    pub texture_reads_per_pixel: Option<f64>,
    /// Depth layers the method saw.
    pub layers: u32,
    /// Quality over the occlusion-edge band (pixels within the local blur radius of a depth
    /// discontinuity).
    pub edge_band: BandQuality,
}

/// What the ground truth has in common with splat, printed with every comparison.
pub const TRUTH_SHARES: &str =
    "ground truth: the exact PSF of every pixel's vergence; it shares the \
blend (depth groups), the pinhole's local layout and the PSFs with splat, so it judges splat's \
kernel approximations (interpolation over distance and radius, merging, half-float texels), \
not the blend or the optics";

/// What the off-axis reference has in common with off-axis splat.
pub const FIELD_TRUTH_SHARES: &str = "ground truth: the exact PSF of every pixel's vergence and \
direction (the eye traced for every 1° field bin, no lattice); it shares the blend, the \
pinhole's local layout and the PSF computation of a direction with splat, so it judges the \
field lattice and its interpolation as well as the kernel approximations, not the optics";

/// A truth read with --truth-in: what it shares is what the run that saved it shared.
pub const LOADED_TRUTH_SHARES: &str = "ground truth: read with --truth-in; it shares with these \
methods what the run that saved it said (e.g. an off-axis reference judging on-axis splat \
measures what the field's aberrations change)";

/// What the views truth has in common with the methods it judges.
pub const VIEWS_SHARES: &str = "ground truth: multi-view accumulation over the pupil (geometric \
optics, rasterised from each pupil point, each channel shifted by the eye's ray aberration); it \
shares the scene, the focused eye and its Zernike coefficients per wavelength with splat, not \
the kernels, the blend or the single visible layer; it leaves out diffraction, so it judges \
where geometric blur dominates";

/// What the truth shares with the methods it judges, as the report words it: a truth read
/// from a file (`loaded`), the views truth, or the reference on or off axis.
pub fn truth_shares(loaded: bool, views: bool, off_axis: bool) -> &'static str {
    if loaded {
        LOADED_TRUTH_SHARES
    } else if views {
        VIEWS_SHARES
    } else if off_axis {
        FIELD_TRUTH_SHARES
    } else {
        TRUTH_SHARES
    }
}

/// The displayed image: linear values scaled by the exposure, clamped to [0, 1].
pub fn exposed(image: &[[f32; 4]], scale: f32) -> Vec<[f32; 4]> {
    image
        .iter()
        .map(|p| [0, 1, 2].map(|c| (p[c] * scale).clamp(0.0, 1.0)))
        .map(|v| [v[0], v[1], v[2], 1.0])
        .collect()
}

/// How many pixels have a non-finite R, G or B, and the first one's (x, y).
pub fn non_finite(pixels: &[[f32; 4]], width: usize) -> Option<(usize, (usize, usize))> {
    let bad = |p: &[f32; 4]| !(p[0].is_finite() && p[1].is_finite() && p[2].is_finite());
    let first = pixels.iter().position(bad)?;
    let count = pixels.iter().filter(|p| bad(p)).count();
    Some((count, (first % width.max(1), first / width.max(1))))
}

/// The truth every row is judged against, and what every row shares.
pub struct Judge<'a> {
    pub width: usize,
    pub height: usize,
    /// The exposure's linear scale (2^EV).
    pub scale: f32,
    /// The truth, displayed.
    pub truth: Vec<[f32; 4]>,
    /// The occlusion-edge band's mask.
    pub band: &'a [bool],
    pub flip_ppd: f64,
    /// What a speed-up is measured against (s; NaN where the truth was read, not rendered).
    pub reference_seconds: f64,
}

/// One judged row and its SSIM map.
pub struct Row {
    pub result: MethodResult,
    pub ssim_map: Vec<f32>,
    /// The SSIM window the frame allowed (11 unless the frame is smaller).
    pub window_px: usize,
}

impl Judge<'_> {
    fn view<'p>(&self, pixels: &'p [[f32; 4]]) -> ImageView<'p> {
        ImageView::new(self.width, self.height, pixels)
    }

    /// The row of `frame` (named `name`, rendered from `layers` depth layers); refused if any
    /// of its pixels is not finite, since no metric of NaN is a number.
    pub fn row(&self, frame: &RenderedFrame, name: &str, layers: u32) -> Result<Row> {
        if let Some((count, first)) = non_finite(&frame.color, self.width) {
            return Err(Error::input(format!(
                "the {} image has {count} pixels that are not finite (first at x = {}, y = {}); \
                 no metric is computed from them",
                frame.method.name(),
                first.0,
                first.1
            )));
        }
        let image = exposed(&frame.color, self.scale);
        let (image_view, truth_view) = (self.view(&image), self.view(&self.truth));
        let quality = ssim(image_view, truth_view, 1.0);
        let edge_band = band_quality(&image, &self.truth, &quality.map, self.band, self.width);
        let flip_mean = FlipStats::of(&ldr_flip(truth_view, image_view, self.flip_ppd)).mean;
        let result = MethodResult {
            method: name.to_string(),
            layers,
            edge_band,
            seconds: frame.seconds,
            psnr_db: psnr(image_view, truth_view, 1.0),
            mssim: quality.mean,
            flip_mean,
            // a truth read with --truth-in has no time (NaN), nor a speed-up
            speedup_vs_reference: if frame.seconds.is_nan() {
                f64::NAN
            } else {
                self.reference_seconds / frame.seconds.max(1e-12)
            },
            gpu_ms: frame.timings.as_ref().map(|t| t.total_ms()),
            evaluations_per_pixel: frame
                .stats
                .as_ref()
                .map(|s| s.kernel_evaluations as f64 / (self.width * self.height).max(1) as f64),
            texture_reads_per_pixel: frame
                .stats
                .as_ref()
                .map(|s| s.texture_reads as f64 / (self.width * self.height).max(1) as f64),
        };
        Ok(Row {
            result,
            ssim_map: quality.map,
            window_px: quality.window_px,
        })
    }

    /// The views truth's change when its views double, displayed as the rows are.
    pub fn views_convergence(&self, image: &ViewsImage) -> ViewsConvergence {
        let full = exposed(&image.color, self.scale);
        let half = exposed(&image.half_color, self.scale);
        let quality = ssim(self.view(&half), self.view(&full), 1.0);
        let max_abs_change = half
            .iter()
            .zip(&full)
            .flat_map(|(a, b)| (0..3).map(move |c| f64::from((a[c] - b[c]).abs())))
            .fold(0.0, f64::max);
        ViewsConvergence {
            views: image.views,
            half_views: image.views.div_ceil(2),
            psnr_db: psnr(self.view(&half), self.view(&full), 1.0),
            mssim: quality.mean,
            max_abs_change,
            seconds_raster: image.seconds_raster,
            seconds_accumulate: image.seconds_accumulate,
        }
    }
}

/// An SSIM map as linear RGB for a PNG written at exposure 0: the false colour (1.0 → navy,
/// ≤ `floor` → red) decoded from sRGB, so the file shows exactly the false colour.
pub fn ssim_map_rgb(map: &[f32], floor: f32) -> Vec<[f32; 4]> {
    ssim_false_colour(map, floor)
        .iter()
        .map(|p| [0, 1, 2].map(|c| image_io::srgb_decode(p[c])))
        .map(|v| [v[0], v[1], v[2], 1.0])
        .collect()
}
