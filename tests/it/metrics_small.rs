//! SSIM on images narrower or shorter than Wang's 11-pixel window (issue 20, defect 4): a value
//! on SSIM's own scale (never 2), computed with the largest window that fits and reported.

use ocular::metrics::{ssim, ImageView};

fn image(w: usize, h: usize, f: impl Fn(usize, usize, usize) -> f32) -> Vec<[f32; 4]> {
    (0..w * h)
        .map(|i| {
            let (x, y) = (i % w, i / w);
            [f(x, y, 0), f(x, y, 1), f(x, y, 2), 1.0]
        })
        .collect()
}

/// SSIM straight from Wang et al.'s definition: at each pixel whose (2r+1)² window lies inside
/// the image, Gaussian-weighted means, variances and covariance from a 2-D sum; averaged over
/// those pixels and the three channels.
fn brute_force_mssim(a: &[[f32; 4]], b: &[[f32; 4]], w: usize, h: usize, r: usize) -> f64 {
    let sigma = 1.5 * (2 * r + 1) as f64 / 11.0;
    let (c1, c2) = (0.01f64.powi(2), 0.03f64.powi(2));
    let mut total = 0.0;
    let mut count = 0usize;
    for c in 0..3 {
        for y in r..h - r {
            for x in r..w - r {
                let (mut sw, mut mx, mut my, mut mxx, mut myy, mut mxy) =
                    (0.0, 0.0, 0.0, 0.0, 0.0, 0.0);
                for dy in -(r as i64)..=r as i64 {
                    for dx in -(r as i64)..=r as i64 {
                        let g = (-((dx * dx + dy * dy) as f64) / (2.0 * sigma * sigma)).exp();
                        let i = (y as i64 + dy) as usize * w + (x as i64 + dx) as usize;
                        let (p, q) = (f64::from(a[i][c]), f64::from(b[i][c]));
                        sw += g;
                        mx += g * p;
                        my += g * q;
                        mxx += g * p * p;
                        myy += g * q * q;
                        mxy += g * p * q;
                    }
                }
                let (ux, uy) = (mx / sw, my / sw);
                let (vx, vy, cov) = (mxx / sw - ux * ux, myy / sw - uy * uy, mxy / sw - ux * uy);
                total += ((2.0 * ux * uy + c1) * (2.0 * cov + c2))
                    / ((ux * ux + uy * uy + c1) * (vx + vy + c2));
                count += 1;
            }
        }
    }
    total / count as f64
}

#[test]
fn identical_narrow_images_have_unit_ssim() {
    for (w, h) in [(8, 90), (90, 8), (1, 40), (3, 3), (10, 10)] {
        let a = image(w, h, |x, y, c| ((x * 7 + y * 3 + c) % 5) as f32 / 5.0);
        let s = ssim(ImageView::new(w, h, &a), ImageView::new(w, h, &a), 1.0);
        assert!(
            (s.mean - 1.0).abs() < 1e-12,
            "{w}×{h}: MSSIM {} of an image with itself",
            s.mean
        );
        assert!(
            s.window_px < 11 && s.window_px <= w.min(h),
            "{w}×{h}: window {}",
            s.window_px
        );
    }
    let a = image(64, 48, |x, y, _| ((x + y) % 3) as f32 / 3.0);
    assert_eq!(
        ssim(ImageView::new(64, 48, &a), ImageView::new(64, 48, &a), 1.0).window_px,
        11
    );
}

#[test]
fn narrow_images_match_the_definition_with_the_smaller_window() {
    let (w, h) = (8, 40);
    let a = image(w, h, |x, y, c| {
        (0.5 + 0.4 * (0.7 * x as f32 + 0.3 * y as f32 + c as f32).sin()).clamp(0.0, 1.0)
    });
    let b = image(w, h, |x, y, c| {
        (0.5 + 0.4 * (0.7 * x as f32 + 0.3 * y as f32 + c as f32).sin()
            + 0.1 * (2.1 * y as f32).cos())
        .clamp(0.0, 1.0)
    });
    let s = ssim(ImageView::new(w, h, &a), ImageView::new(w, h, &b), 1.0);
    assert_eq!(s.window_px, 7);
    let want = brute_force_mssim(&a, &b, w, h, 3);
    assert!(
        (s.mean - want).abs() < 1e-9,
        "MSSIM {} vs the definition {want}",
        s.mean
    );
    assert!(s.mean < 1.0 && s.mean > 0.0);
}
