//! The multi-view ground truth (`--method views`) against closed forms and the eye's own PSF:
//! the geometric blur disc of pure defocus, the centroid of an aberrated point (a theorem: the
//! centroid of any PSF is the mean ray aberration, diffraction or not), and its convergence.

use crate::common;
use crate::common::scenes::square_scene;

use ocular::eye::resolve;
use ocular::metrics::{psnr, ImageView};
use ocular::psf::{ColumnOptics, ExactEye, KernelSettings, Screen, DEFAULT_WAVELENGTHS_NM};
use ocular::render::{views, Rasterizer};
use ocular::scene::Scene;

/// Energy, centroid (x, y) and variance (x, y) of one channel, pixel centres at integers.
fn moments(image: &[[f32; 4]], w: usize, c: usize) -> (f64, [f64; 2], [f64; 2]) {
    let (mut e, mut sx, mut sy, mut sxx, mut syy) = (0.0, 0.0, 0.0, 0.0, 0.0);
    for (i, p) in image.iter().enumerate() {
        let v = f64::from(p[c]);
        let (x, y) = ((i % w) as f64, (i / w) as f64);
        e += v;
        sx += v * x;
        sy += v * y;
        sxx += v * x * x;
        syy += v * y * y;
    }
    let (cx, cy) = (sx / e, sy / e);
    (e, [cx, cy], [sxx / e - cx * cx, syy / e - cy * cy])
}

/// The eye focused at `focus_d` with every aberration removed: pure geometric defocus.
fn perfect_column(pupil_mm: f64, focus_d: f64) -> ColumnOptics {
    let eye = resolve("healthy").unwrap().eye;
    let settings = KernelSettings::default();
    let mut column =
        ColumnOptics::new(&eye, pupil_mm, focus_d, DEFAULT_WAVELENGTHS_NM, &settings).unwrap();
    for ch in &mut column.channels {
        ch.alpha_um.iter_mut().for_each(|a| *a = 0.0);
        ch.residual_c20_um = 0.0;
    }
    column
}

#[test]
fn defocus_blur_disc_has_the_closed_form_radius() {
    let ctx = common::gpu();
    let mut raster = Rasterizer::new(&ctx).unwrap();
    let (w, h, fov) = (160u32, 90u32, 10.0f64);
    let (pupil_mm, focus_d, distance_m) = (6.0, 1.0, 0.25);
    let half_m = 0.001;
    let scene = square_scene(half_m, distance_m, fov);
    let state = scene.at_time(0.0);
    let column = perfect_column(pupil_mm, focus_d);
    let focal_px = 0.5 * f64::from(h) / (fov.to_radians() / 2.0).tan();
    // The square as the views see it on average (each view puts it at another sub-pixel
    // position, so MSAA's quantisation averages out): side s px, energy 100·s², variance
    // s²/12 per axis plus 1/12 for sampling pixel integrals at their centres (Sheppard).
    let side = focal_px * 2.0 * half_m / distance_m;
    let (e0, var0) = (100.0 * side * side, (side * side + 1.0) / 12.0);
    let c0 = [0.5 * f64::from(w) - 0.5, 0.5 * f64::from(h) - 0.5];
    // A point at vergence V seen through a pupil of radius a focused at V_f: a uniform disc of
    // angular radius a·|V − V_f|, whose variance per axis is r²/4.
    let expected = |focus: f64| 0.5e-3 * pupil_mm * (1.0 / distance_m - focus).abs() * focal_px;
    let radius_of = |image: &[[f32; 4]], c: usize| {
        let (_, _, var) = moments(image, w as usize, c);
        [0, 1].map(|k| 2.0 * (var[k] - var0).sqrt())
    };
    let out = views::render(&ctx, &mut raster, &state, (w, h), &column, focus_d, 256).unwrap();
    for c in 0..3 {
        let (e, centre, _) = moments(&out.color, w as usize, c);
        let r = radius_of(&out.color, c);
        eprintln!(
            "channel {c}: radius {:.3} / {:.3} px, expected {:.3}; energy ratio {:.5}; centroid moved {:.4}, {:.4} px",
            r[0],
            r[1],
            expected(focus_d),
            e / e0,
            centre[0] - c0[0],
            centre[1] - c0[1]
        );
        for rk in r {
            assert!(
                (rk / expected(focus_d) - 1.0).abs() < 0.01,
                "radius {rk} px, closed form {}",
                expected(focus_d)
            );
        }
        assert!((e / e0 - 1.0).abs() < 1e-3, "energy ratio {}", e / e0);
        assert!((centre[0] - c0[0]).abs() < 0.02 && (centre[1] - c0[1]).abs() < 0.02);
    }
    // Negative control: frusta that do not keep the focus plane (sheared for infinity) blur
    // as if focused at infinity, and fail the bar.
    let wrong = views::render(&ctx, &mut raster, &state, (w, h), &column, 0.0, 256).unwrap();
    let r = radius_of(&wrong.color, 1);
    eprintln!(
        "unsheared frusta: radius {:.3} px against {:.3}",
        r[0],
        expected(focus_d)
    );
    assert!((r[0] / expected(focus_d) - 1.0).abs() > 0.2);
    assert!((r[0] / expected(0.0) - 1.0).abs() < 0.02);
    drop(raster);
    common::finish(ctx);
}

#[test]
fn aberrated_point_centroid_matches_the_eyes_psf() {
    let ctx = common::gpu();
    let mut raster = Rasterizer::new(&ctx).unwrap();
    let (w, h, fov) = (96u32, 96u32, 4.0f64);
    let (pupil_mm, focus_d) = (6.0, 1.0);
    // a point at the focus distance: all its blur is the eye's aberration
    let scene = square_scene(0.000_5, 1.0 / focus_d, fov);
    let state = scene.at_time(0.0);
    let c0 = [0.5 * f64::from(w) - 0.5, 0.5 * f64::from(h) - 0.5];
    let eye = resolve("keratoconus").unwrap().eye;
    let settings = KernelSettings::default();
    let screen = Screen {
        fov_y_deg: fov,
        height_px: h,
    };
    let exact = ExactEye::new(
        &eye,
        pupil_mm,
        focus_d,
        DEFAULT_WAVELENGTHS_NM,
        screen,
        settings.clone(),
        40,
    )
    .unwrap();
    let out = views::render(
        &ctx,
        &mut raster,
        &state,
        (w, h),
        &exact.column,
        focus_d,
        512,
    )
    .unwrap();
    let mut mirrored_misses = 0;
    for c in 0..3 {
        let (_, cv, var) = moments(&out.color, w as usize, c);
        let (natural, kernel) = exact.kernel_checked(c, focus_d).unwrap();
        let side = kernel.side();
        let pixels: Vec<[f32; 4]> = kernel.values.iter().map(|&v| [v, v, v, 1.0]).collect();
        let (_, ck, _) = moments(&pixels, side, 0);
        let kernel_shift = [ck[0] - kernel.radius as f64, ck[1] - kernel.radius as f64];
        let views_shift = [cv[0] - c0[0], cv[1] - c0[1]];
        let spread = (var[0] + var[1]).sqrt();
        let miss = ((views_shift[0] - kernel_shift[0]).powi(2)
            + (views_shift[1] - kernel_shift[1]).powi(2))
        .sqrt();
        let mirrored = ((views_shift[0] - kernel_shift[0]).powi(2)
            + (-views_shift[1] - kernel_shift[1]).powi(2))
        .sqrt();
        eprintln!(
            "channel {c}: views centroid ({:.3}, {:.3}) px, PSF kernel ({:.3}, {:.3}) px (radius {natural:.1}); spot rms {spread:.2} px; miss {miss:.3}, mirrored {mirrored:.3}",
            views_shift[0], views_shift[1], kernel_shift[0], kernel_shift[1]
        );
        assert!(miss < 0.08, "channel {c}: centroids differ by {miss} px");
        if mirrored > 0.3 {
            mirrored_misses += 1;
        }
    }
    // Negative control: the views image mirrored top to bottom (the retinal orientation
    // taken for the screen's) fails the bar in every channel.
    assert_eq!(mirrored_misses, 3);
    drop(raster);
    common::finish(ctx);
}

#[test]
fn doubling_the_views_changes_the_image_little() {
    let ctx = common::gpu();
    let mut raster = Rasterizer::new(&ctx).unwrap();
    let scene = Scene::load("primitives").unwrap();
    let state = scene.at_time(0.0);
    let (w, h) = (160u32, 90u32);
    let eye = resolve("myopia").unwrap().eye;
    let focus_d = 1.0 / state.focus_m;
    let column = ColumnOptics::new(
        &eye,
        5.0,
        focus_d,
        DEFAULT_WAVELENGTHS_NM,
        &KernelSettings::default(),
    )
    .unwrap();
    let peak = raster
        .render(&ctx, &state, w, h)
        .unwrap()
        .color
        .iter()
        .map(|p| p[1])
        .fold(0.0f32, f32::max);
    let change_db = |n: u32, raster: &mut Rasterizer| {
        let out = views::render(&ctx, raster, &state, (w, h), &column, focus_d, n).unwrap();
        let db = psnr(
            ImageView::new(w as usize, h as usize, &out.half_color),
            ImageView::new(w as usize, h as usize, &out.color),
            f64::from(peak),
        );
        eprintln!("{} → {n} views: {db:.2} dB", n / 2);
        db
    };
    let converged = change_db(256, &mut raster);
    assert!(
        converged > 60.0,
        "doubling to 256 views changes {converged} dB"
    );
    // Negative control: a handful of views is visibly unconverged and fails the bar.
    let coarse = change_db(8, &mut raster);
    assert!(coarse < 60.0, "8 views: {coarse} dB");
    drop(raster);
    common::finish(ctx);
}
