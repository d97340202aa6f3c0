//! Synthetic RGBA frames, and comparisons of RGBA images over their colour channels (alpha is
//! not compared), written for the tests.

use ocular::render::splat::HiddenLayer;
use ocular::render::Frame;

/// Rasterised layers as the splatter's hidden layers, in the order given.
pub fn hidden_layers<'a>(frames: impl IntoIterator<Item = &'a Frame>) -> Vec<HiddenLayer<'a>> {
    frames
        .into_iter()
        .map(|f| HiddenLayer {
            color: &f.color,
            depth_m: &f.depth_m,
        })
        .collect()
}

/// An opaque frame's colour and depth, row by row, each pixel's from `f(x, y)`.
pub fn opaque_pixels(
    width: u32,
    height: u32,
    f: impl Fn(u32, u32) -> ([f32; 3], f32),
) -> (Vec<[f32; 4]>, Vec<f32>) {
    (0..height)
        .flat_map(|y| (0..width).map(move |x| (x, y)))
        .map(|(x, y)| {
            let ([r, g, b], d) = f(x, y);
            ([r, g, b, 1.0], d)
        })
        .unzip()
}

/// The largest absolute difference of any colour channel at any pixel.
pub fn max_rgb_difference(a: &[[f32; 4]], b: &[[f32; 4]]) -> f32 {
    assert_eq!(a.len(), b.len());
    a.iter()
        .zip(b)
        .flat_map(|(a, b)| (0..3).map(move |c| (a[c] - b[c]).abs()))
        .fold(0.0f32, f32::max)
}

/// PSNR (dB) over the colour channels with a peak of 1; infinite for identical images.
pub fn psnr(a: &[[f32; 4]], b: &[[f32; 4]]) -> f64 {
    assert_eq!(a.len(), b.len());
    let mse: f64 = a
        .iter()
        .zip(b)
        .map(|(p, q)| {
            (0..3)
                .map(|c| (f64::from(p[c]) - f64::from(q[c])).powi(2))
                .sum::<f64>()
        })
        .sum::<f64>()
        / (3 * a.len()) as f64;
    if mse == 0.0 {
        f64::INFINITY
    } else {
        10.0 * (1.0 / mse).log10()
    }
}
