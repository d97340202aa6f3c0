//! FLIP's contrast sensitivity filters (Andersson et al. 2020, section 3.1.1). Each opponent
//! channel's CSF is modelled in frequency as a sum of Gaussians, Ŝ(f) = Σ a_i exp(−b_i f²)
//! with f in cycles per degree; its spatial kernel, a_i √(π/b_i) exp(−π² r² / b_i) with r in
//! degrees, is sampled at the pixel pitch 1/ppd and normalised to unit sum, so a uniform area
//! keeps its colour and only contrast the eye cannot resolve is removed.

use super::plane::Plane;

/// One channel's CSF: a_1, b_1 (deg²), a_2, b_2.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CsfGaussians {
    pub a1: f64,
    pub b1: f64,
    pub a2: f64,
    pub b2: f64,
}

/// Achromatic (Y), red–green (Cx) and blue–yellow (Cz), as published; only blue–yellow has a
/// second Gaussian.
pub const CSF: [CsfGaussians; 3] = [
    CsfGaussians {
        a1: 1.0,
        b1: 0.0047,
        a2: 0.0,
        b2: 1e-5,
    },
    CsfGaussians {
        a1: 1.0,
        b1: 0.0053,
        a2: 0.0,
        b2: 1e-5,
    },
    CsfGaussians {
        a1: 34.1,
        b1: 0.04,
        a2: 13.5,
        b2: 0.025,
    },
];

/// Kernel radius in pixels: three standard deviations of the widest Gaussian of any channel
/// (the spatial Gaussian exp(−π² r² / b) has σ = √(b / 2π²) degrees), one radius for all.
pub fn radius_px(ppd: f64) -> usize {
    let b_max = CSF.iter().flat_map(|g| [g.b1, g.b2]).fold(0.0f64, f64::max);
    let sigma_deg = (b_max / (2.0 * std::f64::consts::PI.powi(2))).sqrt();
    (3.0 * sigma_deg * ppd).ceil() as usize
}

/// One Gaussian term sampled along one axis, unnormalised: exp(−π² x² / b) at x = k / ppd.
fn axis_samples(b: f64, radius: usize, ppd: f64) -> Vec<f64> {
    let pi2 = std::f64::consts::PI.powi(2);
    (0..=2 * radius)
        .map(|i| {
            let x_deg = (i as f64 - radius as f64) / ppd;
            (-pi2 * x_deg * x_deg / b).exp()
        })
        .collect()
}

/// A channel's 2-D kernel as a sum of separable terms (weight, 1-D taps): the sampled kernel
/// is Σ weight · taps(x) taps(y), with the weights chosen so that it sums to 1.
pub fn separable_terms(channel: usize, ppd: f64) -> Vec<(f64, Vec<f64>)> {
    let g = CSF[channel];
    let radius = radius_px(ppd);
    let mut terms: Vec<(f64, Vec<f64>)> = [(g.a1, g.b1), (g.a2, g.b2)]
        .into_iter()
        .filter(|&(a, _)| a != 0.0)
        .map(|(a, b)| {
            (
                a * (std::f64::consts::PI / b).sqrt(),
                axis_samples(b, radius, ppd),
            )
        })
        .collect();
    let total: f64 = terms
        .iter()
        .map(|(w, taps)| w * taps.iter().sum::<f64>().powi(2))
        .sum();
    for (w, _) in &mut terms {
        *w /= total;
    }
    terms
}

/// One YCxCz channel filtered by its CSF.
pub fn filter_channel(plane: &Plane, channel: usize, ppd: f64) -> Plane {
    let mut out: Option<Plane> = None;
    for (weight, taps) in separable_terms(channel, ppd) {
        let term = plane.separable(&taps, &taps);
        out = Some(match out {
            None => Plane::new(
                term.width,
                term.height,
                term.values.iter().map(|v| weight * v).collect(),
            ),
            Some(mut acc) => {
                for (a, v) in acc.values.iter_mut().zip(&term.values) {
                    *a += weight * v;
                }
                acc
            }
        });
    }
    out.expect("every channel has a first Gaussian")
}
