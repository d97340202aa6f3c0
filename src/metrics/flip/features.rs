//! FLIP's feature detection (Andersson et al. 2020, section 3.2): edges and points of the
//! achromatic channel, found with the first and second derivatives of a Gaussian whose σ is
//! half the width w = 0.082° of the smallest feature the eye resolves at the given ppd. A
//! feature present in one image and not the other raises the colour error towards 1.

use super::plane::Plane;

/// Width in degrees of the features detected (the paper's w).
pub const FEATURE_WIDTH_DEG: f64 = 0.082;
/// Exponent of the feature difference (q_f).
pub const QF: f64 = 0.5;

/// σ of the detector in pixels.
pub fn sigma_px(ppd: f64) -> f64 {
    0.5 * FEATURE_WIDTH_DEG * ppd
}

/// The detector's 1-D taps: the Gaussian (sum 1), its first derivative and its second
/// derivative, each derivative scaled so its positive taps sum to 1 and its negative taps to
/// −1 (so a unit step gives an edge response of 1 whatever the ppd).
pub struct FeatureTaps {
    pub gaussian: Vec<f64>,
    pub first: Vec<f64>,
    pub second: Vec<f64>,
}

impl FeatureTaps {
    pub fn new(ppd: f64) -> FeatureTaps {
        let sigma = sigma_px(ppd);
        let radius = (3.0 * sigma).ceil() as isize;
        let xs: Vec<f64> = (-radius..=radius).map(|k| k as f64).collect();
        let g: Vec<f64> = xs
            .iter()
            .map(|x| (-x * x / (2.0 * sigma * sigma)).exp())
            .collect();
        let g_sum: f64 = g.iter().sum();
        let first: Vec<f64> = xs.iter().zip(&g).map(|(x, g)| -x * g).collect();
        let second: Vec<f64> = xs
            .iter()
            .zip(&g)
            .map(|(x, g)| (x * x / (sigma * sigma) - 1.0) * g)
            .collect();
        FeatureTaps {
            gaussian: g.iter().map(|v| v / g_sum).collect(),
            first: balance(&first),
            second: balance(&second),
        }
    }
}

/// Scales positive taps to sum 1 and negative taps to sum −1.
fn balance(taps: &[f64]) -> Vec<f64> {
    let positive: f64 = taps.iter().filter(|v| **v > 0.0).sum();
    let negative: f64 = -taps.iter().filter(|v| **v < 0.0).sum::<f64>();
    taps.iter()
        .map(|&v| {
            if v > 0.0 {
                v / positive
            } else if v < 0.0 {
                v / negative
            } else {
                0.0
            }
        })
        .collect()
}

/// Edge and point strength of a luminance plane (Y / Y_white, so 0 to 1 on an LDR image):
/// the magnitudes of the gradient and of the pair of second derivatives.
pub struct Features {
    pub edges: Plane,
    pub points: Plane,
}

pub fn detect(luminance: &Plane, taps: &FeatureTaps) -> Features {
    // x derivatives are taken along rows and smoothed along columns, and vice versa
    let dx = luminance.separable(&taps.first, &taps.gaussian);
    let ddx = luminance.separable(&taps.second, &taps.gaussian);
    let smooth_x = luminance.along_rows(&taps.gaussian);
    let dy = smooth_x.along_columns(&taps.first);
    let ddy = smooth_x.along_columns(&taps.second);
    let magnitude = |a: &Plane, b: &Plane| {
        Plane::new(
            a.width,
            a.height,
            a.values
                .iter()
                .zip(&b.values)
                .map(|(p, q)| p.hypot(*q))
                .collect(),
        )
    };
    Features {
        edges: magnitude(&dx, &dy),
        points: magnitude(&ddx, &ddy),
    }
}

/// The feature difference in [0, 1]: the larger of the edge and point differences, divided by
/// √2 (their largest possible value), raised to q_f.
pub fn feature_difference(reference: &Features, test: &Features) -> Vec<f64> {
    let n = reference.edges.values.len();
    (0..n)
        .map(|i| {
            let edge = (reference.edges.values[i] - test.edges.values[i]).abs();
            let point = (reference.points.values[i] - test.points.values[i]).abs();
            (edge.max(point) / std::f64::consts::SQRT_2).powf(QF)
        })
        .collect()
}
