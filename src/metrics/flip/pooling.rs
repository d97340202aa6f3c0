//! Pooling a FLIP map into numbers, and showing it. The papers recommend the mean as the one
//! number; the quartiles say how the error is spread (a mean of 0.1 from a few bad edges reads
//! differently from one spread everywhere).

/// Summary of an error map.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct FlipStats {
    pub mean: f64,
    pub min: f64,
    /// First quartile, median and third quartile: plain (unweighted) percentiles with linear
    /// interpolation between order statistics (numpy's default).
    pub q1: f64,
    pub median: f64,
    pub q3: f64,
    pub max: f64,
}

impl FlipStats {
    /// Statistics of a non-empty map (an empty one gives NaN throughout).
    pub fn of(map: &[f32]) -> FlipStats {
        if map.is_empty() {
            return FlipStats {
                mean: f64::NAN,
                min: f64::NAN,
                q1: f64::NAN,
                median: f64::NAN,
                q3: f64::NAN,
                max: f64::NAN,
            };
        }
        let mut sorted: Vec<f64> = map.iter().map(|&v| f64::from(v)).collect();
        sorted.sort_by(f64::total_cmp);
        let percentile = |p: f64| {
            let pos = p * (sorted.len() - 1) as f64;
            let lo = pos.floor() as usize;
            let hi = (lo + 1).min(sorted.len() - 1);
            sorted[lo] + (pos - lo as f64) * (sorted[hi] - sorted[lo])
        };
        FlipStats {
            mean: sorted.iter().sum::<f64>() / sorted.len() as f64,
            min: sorted[0],
            q1: percentile(0.25),
            median: percentile(0.5),
            q3: percentile(0.75),
            max: sorted[sorted.len() - 1],
        }
    }
}

/// Nine colours of the magma colour map (van der Walt & Smith, as FLIP shows its maps), sRGB
/// encoded, at t = 0, 1/8, …, 1.
const MAGMA: [[f64; 3]; 9] = [
    [0.001462, 0.000466, 0.013866],
    [0.113094, 0.065492, 0.276784],
    [0.316654, 0.071690, 0.485380],
    [0.512831, 0.148179, 0.507648],
    [0.716387, 0.214982, 0.475290],
    [0.904281, 0.319610, 0.388137],
    [0.986700, 0.535582, 0.382210],
    [0.996898, 0.769591, 0.534892],
    [0.987053, 0.991438, 0.749504],
];

/// 8-bit sRGB colour of an error in [0, 1] (0 black, 1 pale yellow); values outside clamp.
pub fn magma(error: f64) -> [u8; 3] {
    let t = if error.is_finite() {
        error.clamp(0.0, 1.0)
    } else {
        1.0
    };
    let x = t * (MAGMA.len() - 1) as f64;
    let i = (x.floor() as usize).min(MAGMA.len() - 2);
    let f = x - i as f64;
    [0, 1, 2].map(|c| {
        let v = MAGMA[i][c] * (1.0 - f) + MAGMA[i + 1][c] * f;
        (v * 255.0 + 0.5) as u8
    })
}
