//! FLIP, the perceptual difference of a test image from a reference as seen by alternating
//! between them at a given viewing distance (Andersson, Nilsson, Akenine-Möller, Oskarsson,
//! Åström & Fairchild 2020, "FLIP: A Difference Evaluator for Alternating Images"), and its
//! HDR extension (Andersson, Nilsson, Shirley & Akenine-Möller 2021, "Visualizing Errors in
//! Rendered High Dynamic Range Images").
//!
//! Per pixel: the colour error ΔE_c (both images in YCxCz, filtered by the contrast
//! sensitivity of each opponent channel, compared in Hunt-adjusted CIELAB with HyAB and mapped
//! to [0, 1]) is raised to 1 − ΔE_f, where ΔE_f is the difference in edge and point strength,
//! so that an error on a feature counts more. HDR-FLIP is the per-pixel maximum of LDR-FLIP
//! over a range of exposures, each tone mapped.
//!
//! Everything is computed in f64 on float images: an HDR image needs no 8-bit detour, and an
//! LDR one is used at the precision it has.

pub mod colour;
pub mod csf;
pub mod features;
pub mod hdr;
mod plane;
pub mod pooling;

pub use hdr::{hdr_flip, ExposureRange, HdrFlip, HdrSettings, ToneMapper};
pub use plane::Plane;
pub use pooling::{magma, FlipStats};

use crate::metrics::ImageView;

/// Pixels per degree of a viewer `distance_m` from a monitor `width_m` wide showing
/// `resolution_x` pixels across (small-angle: one degree covers distance · π/180 metres).
pub fn pixels_per_degree(width_m: f64, resolution_x: f64, distance_m: f64) -> f64 {
    distance_m * (resolution_x / width_m) * std::f64::consts::PI / 180.0
}

/// FLIP's default viewing condition: 0.7 m from a 0.7 m wide monitor of 3840 pixels across
/// (≈ 67.02 pixels per degree).
pub const DEFAULT_PPD: f64 = 0.7 * (3840.0 / 0.7) * std::f64::consts::PI / 180.0;

/// The viewing conditions every front door accepts, in pixels per degree.
pub const PPD_RANGE: (f64, f64) = (1.0, 10_000.0);

/// Whether `ppd` is a viewing condition FLIP is computed for (finite, within PPD_RANGE).
pub fn ppd_in_range(ppd: f64) -> bool {
    ppd.is_finite() && (PPD_RANGE.0..=PPD_RANGE.1).contains(&ppd)
}

/// Linear sRGB planes of an image, clamped to [0, 1] (what an LDR display can show).
fn clamped_planes(image: ImageView<'_>) -> [Plane; 3] {
    [0, 1, 2].map(|c| {
        Plane::new(
            image.width,
            image.height,
            image
                .pixels
                .iter()
                .map(|p| f64::from(p[c]).clamp(0.0, 1.0))
                .collect(),
        )
    })
}

/// LDR-FLIP of two images in linear sRGB (values outside [0, 1] are clamped): the per-pixel
/// error in [0, 1], row-major. `ppd` is the viewing condition in pixels per degree.
pub fn ldr_flip(reference: ImageView<'_>, test: ImageView<'_>, ppd: f64) -> Vec<f32> {
    assert!(
        reference.width == test.width && reference.height == test.height,
        "FLIP of images of different sizes"
    );
    assert!(ppd.is_finite() && ppd > 0.0, "ppd {ppd} is not positive");
    flip_planes(&clamped_planes(reference), &clamped_planes(test), ppd)
}

/// LDR-FLIP of two images given as linear sRGB planes in [0, 1].
pub(crate) fn flip_planes(reference: &[Plane; 3], test: &[Plane; 3], ppd: f64) -> Vec<f32> {
    let to_ycxcz = |rgb: &[Plane; 3]| -> [Plane; 3] {
        let (w, h) = (rgb[0].width, rgb[0].height);
        let converted: Vec<[f64; 3]> = (0..w * h)
            .map(|i| {
                colour::linear_rgb_to_ycxcz([rgb[0].values[i], rgb[1].values[i], rgb[2].values[i]])
            })
            .collect();
        [0, 1, 2].map(|c| Plane::new(w, h, converted.iter().map(|v| v[c]).collect()))
    };
    let (ref_ycc, test_ycc) = (to_ycxcz(reference), to_ycxcz(test));
    let colour = colour_error_map(&ref_ycc, &test_ycc, ppd);
    let feature = feature_difference_map(&ref_ycc[0], &test_ycc[0], ppd);
    colour
        .iter()
        .zip(&feature)
        .map(|(c, f)| c.powf(1.0 - f) as f32)
        .collect()
}

/// The colour error ΔE_c in [0, 1] of two images in YCxCz.
pub fn colour_error_map(reference: &[Plane; 3], test: &[Plane; 3], ppd: f64) -> Vec<f64> {
    let filtered = |img: &[Plane; 3]| -> [Plane; 3] {
        [0, 1, 2].map(|c| csf::filter_channel(&img[c], c, ppd))
    };
    let (r, t) = (filtered(reference), filtered(test));
    let cmax = colour::max_error();
    let lab = |img: &[Plane; 3], i: usize| {
        let ycc = [img[0].values[i], img[1].values[i], img[2].values[i]];
        let rgb = colour::xyz_to_linear_rgb(colour::ycxcz_to_xyz(ycc));
        colour::linear_rgb_to_hunt_lab(rgb)
    };
    (0..r[0].values.len())
        .map(|i| colour::colour_error(colour::hyab(lab(&r, i), lab(&t, i)), cmax))
        .collect()
}

/// The feature difference ΔE_f in [0, 1] from the Y channels of two images in YCxCz.
pub fn feature_difference_map(reference_y: &Plane, test_y: &Plane, ppd: f64) -> Vec<f64> {
    // YCxCz's Y is 116 Y/Y_white − 16: back to relative luminance, 0 to 1
    let relative = |p: &Plane| {
        Plane::new(
            p.width,
            p.height,
            p.values.iter().map(|y| (y + 16.0) / 116.0).collect(),
        )
    };
    let taps = features::FeatureTaps::new(ppd);
    features::feature_difference(
        &features::detect(&relative(reference_y), &taps),
        &features::detect(&relative(test_y), &taps),
    )
}
