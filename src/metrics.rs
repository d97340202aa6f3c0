//! Image quality metrics: MSE, PSNR and SSIM (Wang, Bovik, Sheikh & Simoncelli 2004).
//!
//! SSIM follows the paper's reference settings: an 11×11 Gaussian window with σ = 1.5
//! (normalised), K1 = 0.01, K2 = 0.03, L = the data range, population (not sample) moments;
//! computed per colour channel and averaged. The mean SSIM (MSSIM) averages the map over the
//! pixels whose window lies entirely inside the image — the 'valid' region of Wang's MATLAB
//! reference code, and what scikit-image's `structural_similarity(gaussian_weights=True,
//! sigma=1.5, use_sample_covariance=False)` reports after cropping its border. The per-pixel map
//! extends to the border by mirror reflection (scipy's 'reflect' mode) for display.
//!
//! An image with a side under 11 pixels has no valid region for that window: SSIM is then
//! computed with the largest odd window that fits (σ scaled with it), and `Ssim::window_px`
//! says which, so a caller can report it rather than print a number on another scale.
//!
//! The items defined here and the [`flip`] module are the public surface; `flip` stays public
//! as the FLIP metric's own namespace, with its own re-exported surface.

pub mod flip;

/// Radius of the 11×11 window.
pub const WINDOW_RADIUS: usize = 5;
const SIGMA: f64 = 1.5;
const K1: f64 = 0.01;
const K2: f64 = 0.03;

/// An RGB image view (alpha ignored): row-major, top row first.
#[derive(Clone, Copy, Debug)]
pub struct ImageView<'a> {
    pub width: usize,
    pub height: usize,
    pub pixels: &'a [[f32; 4]],
}

impl<'a> ImageView<'a> {
    pub fn new(width: usize, height: usize, pixels: &'a [[f32; 4]]) -> ImageView<'a> {
        assert_eq!(
            pixels.len(),
            width * height,
            "image of {width}×{height} needs {} pixels",
            width * height
        );
        ImageView {
            width,
            height,
            pixels,
        }
    }
}

/// Mean squared error over the three colour channels.
pub fn mse(a: ImageView<'_>, b: ImageView<'_>) -> f64 {
    assert_same_size(a, b);
    let sum: f64 = a
        .pixels
        .iter()
        .zip(b.pixels)
        .map(|(p, q)| {
            (0..3)
                .map(|c| (f64::from(p[c]) - f64::from(q[c])).powi(2))
                .sum::<f64>()
        })
        .sum();
    sum / (3 * a.pixels.len()) as f64
}

/// Peak signal-to-noise ratio in dB for values spanning `data_range` (1 for [0, 1] images);
/// +∞ for identical images.
pub fn psnr(a: ImageView<'_>, b: ImageView<'_>, data_range: f64) -> f64 {
    let e = mse(a, b);
    if e == 0.0 {
        f64::INFINITY
    } else {
        10.0 * (data_range * data_range / e).log10()
    }
}

/// SSIM result: the mean over the valid region (per channel and averaged) and a per-pixel map
/// (channel mean) covering the whole image.
#[derive(Clone, Debug)]
pub struct Ssim {
    pub mean: f64,
    pub per_channel: [f64; 3],
    pub map: Vec<f32>,
    /// Side of the Gaussian window used: 11, or smaller for an image with a side under 11.
    pub window_px: usize,
}

pub fn ssim(a: ImageView<'_>, b: ImageView<'_>, data_range: f64) -> Ssim {
    assert_same_size(a, b);
    let (w, h) = (a.width, a.height);
    // The largest window (of at most Wang's 11) whose valid region is not empty.
    let radius = WINDOW_RADIUS.min(w.min(h).saturating_sub(1) / 2);
    let sigma = SIGMA * (2 * radius + 1) as f64 / (2 * WINDOW_RADIUS + 1) as f64;
    let weights = gaussian_window(radius, sigma);
    let c1 = (K1 * data_range).powi(2);
    let c2 = (K2 * data_range).powi(2);
    let mut map = vec![0.0f64; w * h];
    let mut per_channel = [0.0; 3];
    for (c, channel_mean) in per_channel.iter_mut().enumerate() {
        let x: Vec<f64> = a.pixels.iter().map(|p| f64::from(p[c])).collect();
        let y: Vec<f64> = b.pixels.iter().map(|p| f64::from(p[c])).collect();
        let xx: Vec<f64> = x.iter().map(|v| v * v).collect();
        let yy: Vec<f64> = y.iter().map(|v| v * v).collect();
        let xy: Vec<f64> = x.iter().zip(&y).map(|(p, q)| p * q).collect();
        let [mx, my, mxx, myy, mxy] =
            [&x, &y, &xx, &yy, &xy].map(|v| blur(v, w, h, radius, &weights));
        let mut valid_sum = 0.0;
        let mut valid_count = 0usize;
        for row in 0..h {
            for col in 0..w {
                let i = row * w + col;
                let (ux, uy) = (mx[i], my[i]);
                let vx = mxx[i] - ux * ux;
                let vy = myy[i] - uy * uy;
                let cov = mxy[i] - ux * uy;
                let s = ((2.0 * ux * uy + c1) * (2.0 * cov + c2))
                    / ((ux * ux + uy * uy + c1) * (vx + vy + c2));
                map[i] += s / 3.0;
                let inside = row >= radius && col >= radius && row + radius < h && col + radius < w;
                if inside {
                    valid_sum += s;
                    valid_count += 1;
                }
            }
        }
        // The window fits, so the valid region holds at least one pixel (none for an empty
        // image, whose mean is NaN).
        *channel_mean = valid_sum / valid_count as f64;
    }
    Ssim {
        mean: per_channel.iter().sum::<f64>() / 3.0,
        per_channel,
        map: map.into_iter().map(|v| v as f32).collect(),
        window_px: 2 * radius + 1,
    }
}

fn assert_same_size(a: ImageView<'_>, b: ImageView<'_>) {
    assert!(
        a.width == b.width && a.height == b.height,
        "images differ in size: {}×{} and {}×{}",
        a.width,
        a.height,
        b.width,
        b.height
    );
}

fn gaussian_window(radius: usize, sigma: f64) -> Vec<f64> {
    let w: Vec<f64> = (0..=2 * radius)
        .map(|i| {
            let d = i as f64 - radius as f64;
            (-d * d / (2.0 * sigma * sigma)).exp()
        })
        .collect();
    let sum: f64 = w.iter().sum();
    w.into_iter().map(|v| v / sum).collect()
}

/// Mirror index for scipy's 'reflect' mode (d c b a | a b c d | d c b a).
fn reflect(i: isize, n: usize) -> usize {
    let n = n as isize;
    if n == 1 {
        return 0;
    }
    let period = 2 * n;
    let mut k = i.rem_euclid(period);
    if k >= n {
        k = period - 1 - k;
    }
    k as usize
}

/// Separable Gaussian blur with mirror-reflected borders.
fn blur(v: &[f64], w: usize, h: usize, radius: usize, weights: &[f64]) -> Vec<f64> {
    let r = radius as isize;
    let mut tmp = vec![0.0; w * h];
    for row in 0..h {
        for col in 0..w {
            tmp[row * w + col] = (-r..=r)
                .map(|d| weights[(d + r) as usize] * v[row * w + reflect(col as isize + d, w)])
                .sum();
        }
    }
    let mut out = vec![0.0; w * h];
    for row in 0..h {
        for col in 0..w {
            out[row * w + col] = (-r..=r)
                .map(|d| weights[(d + r) as usize] * tmp[reflect(row as isize + d, h) * w + col])
                .sum();
        }
    }
    out
}

/// False-colour rendering of an SSIM map (1 = identical → dark blue; lower → towards yellow
/// and red), scaled so that `floor` maps to the hottest colour. Returns 8-bit sRGB RGBA.
pub fn ssim_false_colour(map: &[f32], floor: f32) -> Vec<[u8; 4]> {
    map.iter()
        .map(|&s| {
            let t = ((1.0 - s) / (1.0 - floor).max(1e-6)).clamp(0.0, 1.0);
            // A perceptually ordered ramp: navy → teal → yellow → red.
            let stops = [
                [0.05, 0.05, 0.35],
                [0.0, 0.55, 0.6],
                [0.95, 0.85, 0.1],
                [0.8, 0.05, 0.05],
            ];
            let x = t * 3.0;
            let i = (x.floor() as usize).min(2);
            let f = x - i as f32;
            let c = [0, 1, 2].map(|k| stops[i][k] * (1.0 - f) + stops[i + 1][k] * f);
            [
                (c[0] * 255.0) as u8,
                (c[1] * 255.0) as u8,
                (c[2] * 255.0) as u8,
                255,
            ]
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn window_is_normalised_and_symmetric() {
        let w = gaussian_window(WINDOW_RADIUS, SIGMA);
        assert_eq!(w.len(), 11);
        assert!((w.iter().sum::<f64>() - 1.0).abs() < 1e-15);
        for i in 0..=WINDOW_RADIUS {
            assert_eq!(w[i], w[2 * WINDOW_RADIUS - i]);
        }
    }

    #[test]
    fn reflect_matches_scipy_reflect_mode() {
        // n = 4: indices -3..7 map to c b a | a b c d | d c b a
        let got: Vec<usize> = (-3..8).map(|i| reflect(i, 4)).collect();
        assert_eq!(got, [2, 1, 0, 0, 1, 2, 3, 3, 2, 1, 0]);
    }
}
