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
//!
//! The `pub use` items below are the module's public surface, with [`colour`], [`csf`] and
//! [`features`], which stay public as the namespaces of FLIP's building blocks (colour spaces,
//! contrast sensitivity, edge and point detection) that tests check one function at a time.

pub mod colour;
pub mod csf;
pub mod features;
pub(crate) mod hdr;
mod ldr;
mod plane;
pub(crate) mod pooling;

// LDR-FLIP and its two error maps.
pub use ldr::{colour_error_map, feature_difference_map, ldr_flip};
pub use plane::Plane;
// HDR-FLIP: exposures and tone mapping.
pub use hdr::{exposure_range, hdr_flip, ExposureRange, HdrFlip, HdrSettings, ToneMapper};
// Pooled statistics and the colour map.
pub use pooling::{magma, FlipStats};

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
