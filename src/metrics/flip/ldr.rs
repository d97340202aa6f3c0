//! LDR-FLIP: the colour error raised to one minus the feature difference. HDR-FLIP
//! ([`super::hdr`]) runs it once per exposure, so it is a module of its own below both the
//! HDR pass and the module's front (`flip`), not part of that front.

use super::plane::Plane;
use super::{colour, csf, features};
use crate::metrics::ImageView;

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
