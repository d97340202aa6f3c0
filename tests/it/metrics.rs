//! PSNR and SSIM against values computed by an independent, standard implementation:
//! scikit-image 0.26.0, `structural_similarity(p, q, gaussian_weights=True, sigma=1.5,
//! use_sample_covariance=False, data_range=1.0, channel_axis=-1)` and
//! `peak_signal_noise_ratio(p, q, data_range=1.0)`, on the images built below (the same
//! formulas evaluated in NumPy, rounded to float32 as here).

use ocular::metrics::{psnr, ssim, ImageView};

const W: usize = 37;
const H: usize = 23;

fn build(f: impl Fn(f64, f64, usize) -> f64) -> Vec<[f32; 4]> {
    let mut out = Vec::new();
    for y in 0..H {
        for x in 0..W {
            let v = [0, 1, 2].map(|c| f(x as f64, y as f64, c) as f32);
            out.push([v[0], v[1], v[2], 1.0]);
        }
    }
    out
}

fn image_a() -> Vec<[f32; 4]> {
    build(|x, y, c| 0.5 + 0.4 * (0.3 * x + 0.2 * y + c as f64).sin())
}

fn image_b() -> Vec<[f32; 4]> {
    build(|x, y, c| {
        let a = f64::from((0.5 + 0.4 * (0.3 * x + 0.2 * y + c as f64).sin()) as f32);
        (a + 0.08 * (1.7 * x).sin() * (2.3 * y + c as f64).cos()).clamp(0.0, 1.0)
    })
}

fn image_c() -> Vec<[f32; 4]> {
    build(|x, y, c| 0.3 + 0.5 * (((x / 4.0).floor() + (y / 4.0).floor() + c as f64) % 2.0))
}

fn image_d() -> Vec<[f32; 4]> {
    build(|x, y, c| {
        let v = f64::from(
            (0.3 + 0.5 * (((x / 4.0).floor() + (y / 4.0).floor() + c as f64) % 2.0)) as f32,
        );
        0.8 * v + 0.1
    })
}

fn view(p: &[[f32; 4]]) -> ImageView<'_> {
    ImageView::new(W, H, p)
}

#[test]
fn ssim_and_psnr_match_scikit_image() {
    let (a, b, c, d) = (image_a(), image_b(), image_c(), image_d());
    let cases = [
        (&a, &b, 0.9475041761139464, 27.963065294841503),
        (&c, &d, 0.9755223914556205, 25.8522301078558),
    ];
    for (p, q, want_ssim, want_psnr) in cases {
        let s = ssim(view(p), view(q), 1.0);
        let r = psnr(view(p), view(q), 1.0);
        assert!(
            (s.mean - want_ssim).abs() < 1e-6,
            "SSIM {} vs scikit-image {want_ssim}",
            s.mean
        );
        assert!(
            (r - want_psnr).abs() < 1e-6,
            "PSNR {r} vs scikit-image {want_psnr}"
        );
        assert_eq!(s.map.len(), W * H);
        assert!(s.map.iter().all(|v| v.is_finite() && *v <= 1.0 + 1e-6));
    }
}

#[test]
fn identical_images_give_infinite_psnr_and_unit_ssim() {
    let a = image_a();
    assert_eq!(psnr(view(&a), view(&a), 1.0), f64::INFINITY);
    let s = ssim(view(&a), view(&a), 1.0);
    assert!((s.mean - 1.0).abs() < 1e-12);
    assert!(s.map.iter().all(|v| (v - 1.0).abs() < 1e-6));
}

#[test]
fn ssim_is_symmetric_and_drops_with_distortion() {
    let (a, b) = (image_a(), image_b());
    let ab = ssim(view(&a), view(&b), 1.0).mean;
    let ba = ssim(view(&b), view(&a), 1.0).mean;
    assert!((ab - ba).abs() < 1e-12);
    let worse = build(|x, y, c| {
        let a = f64::from((0.5 + 0.4 * (0.3 * x + 0.2 * y + c as f64).sin()) as f32);
        (a + 0.25 * (1.7 * x).sin() * (2.3 * y + c as f64).cos()).clamp(0.0, 1.0)
    });
    assert!(ssim(view(&a), view(&worse), 1.0).mean < ab);
}
