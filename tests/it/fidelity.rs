//! The common cases a user meets every day, where the method is weakest: small blur near focus
//! over a wide frame, point lights against a distant background, in-focus backgrounds seen past
//! a blurred near edge, spots near the frame's edge. Each cell is judged against a truth
//! written here (closed forms, geometric pupil shares, the pinhole's geometry, a wave-optics PSF
//! computed from the eye's Zernike coefficients with rustfft), never against splat's own kernels
//! or blend, and has a negative control that fails its bar. docs/validation-common-cases.md
//! holds the figures and what each truth shares with splat.
//! Figures: `cargo test --release --test it fidelity:: -- --nocapture`.

use crate::common;

use ocular::eye::resolve;
use ocular::metrics::{psnr, ImageView};
use ocular::psf::Screen;
use ocular::render::splat::{FrameInput, HiddenLayer, SplatSettings};
use ocular::render::{
    dioptre_range, prepare_kernels, scene_needs, EyeState, FrameRenderer, KernelOptions, Method,
};

/// The seed paper's blend: every fragment composited front to back, the output divided by
/// the coverage (the negative control for the light behind a point).
fn paper_blend() -> SplatSettings {
    SplatSettings {
        blend: ocular::render::BlendSettings {
            mode: ocular::render::BlendMode::PerFragment,
            ..Default::default()
        },
        ..SplatSettings::default()
    }
}

struct Rendered {
    splat: Vec<[f32; 4]>,
    reference: Option<Vec<[f32; 4]>>,
    max_radius: u32,
}

fn cache() -> Option<std::path::PathBuf> {
    Some(std::path::PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("fidelity-kernels"))
}

/// Renders `input` through a preset eye with splat (and the reference when asked).
fn render(
    ctx: &ocular::gpu::Context,
    eye: &str,
    input: &FrameInput<'_>,
    state: EyeState,
    splat: SplatSettings,
    with_reference: bool,
) -> Rendered {
    render_on(
        ctx,
        eye,
        input,
        state,
        splat,
        with_reference,
        ocular::psf::GridAxes::default(),
    )
}

/// [`render`] with the kernels planned from `axes` (the seed paper's grid by default).
fn render_on(
    ctx: &ocular::gpu::Context,
    eye: &str,
    input: &FrameInput<'_>,
    state: EyeState,
    splat: SplatSettings,
    with_reference: bool,
    axes: ocular::psf::GridAxes,
) -> Rendered {
    let options = KernelOptions {
        cache_dir: cache(),
        progress: None,
        reference_axes: axes,
        // the axis given is the one measured, at every pixel scale
        objects_follow_screen: false,
        ..KernelOptions::default()
    };
    let screen = Screen {
        fov_y_deg: input.fov_y_deg,
        height_px: input.height,
    };
    let mut ranges = vec![dioptre_range(
        input.depth_m,
        input.width,
        input.height,
        input.fov_y_deg,
    )];
    for layer in input.hidden_layers {
        ranges.push(dioptre_range(
            layer.depth_m,
            input.width,
            input.height,
            input.fov_y_deg,
        ));
    }
    let eye = resolve(eye).unwrap().eye;
    let kernels = prepare_kernels(&eye, &scene_needs(&ranges, &[state], screen), &options).unwrap();
    let max_radius = kernels.grid.max_radius_px;
    let mut renderer = FrameRenderer::new(ctx, eye, kernels, options.settings.clone(), splat);
    let out = renderer.render(input, state, Method::Splat).unwrap().color;
    let reference = with_reference.then(|| {
        let single = FrameInput {
            hidden_layers: &[],
            mixed: None,
            ..*input
        };
        renderer
            .render(&single, state, Method::Reference)
            .unwrap()
            .color
    });
    Rendered {
        splat: out,
        reference,
        max_radius,
    }
}

/// A one-layer colour + depth frame of `w`×`h` at a vertical field of `fov` degrees.
fn one_layer<'a>(
    (w, h, fov): (usize, usize, f64),
    color: &'a [[f32; 4]],
    depth: &'a [f32],
) -> FrameInput<'a> {
    FrameInput {
        width: w as u32,
        height: h as u32,
        color,
        depth_m: depth,
        fov_y_deg: fov,
        hidden_layers: &[],
        mixed: None,
    }
}

fn db(a: &[[f32; 4]], b: &[[f32; 4]], w: usize, h: usize) -> f64 {
    psnr(ImageView::new(w, h, a), ImageView::new(w, h, b), 1.0)
}

/// View-axis depth of a point `distance_m` along the ray of pixel (x, y).
fn axial(distance_m: f64, x: usize, y: usize, w: usize, h: usize, fov_y_deg: f64) -> f32 {
    let f = 0.5 * h as f64 / (0.5 * fov_y_deg).to_radians().tan();
    let u = x as f64 + 0.5 - 0.5 * w as f64;
    let v = y as f64 + 0.5 - 0.5 * h as f64;
    (distance_m * f / (f * f + u * u + v * v).sqrt()) as f32
}

// ---------------------------------------------------------------------------------------
// Case 1: small blur over a wide frame is continuous in field angle.

const C1: (usize, usize, f64) = (320, 180, 60.0);

fn case1_scene() -> (Vec<[f32; 4]>, Vec<f32>) {
    let (w, h, _) = C1;
    let bars = [
        [0.9f32, 0.2, 0.2],
        [0.2, 0.8, 0.3],
        [0.2, 0.3, 0.9],
        [0.9, 0.9, 0.2],
    ];
    let mut color = vec![[0.0f32; 4]; w * h];
    let mut depth = vec![0.0f32; w * h];
    for y in 0..h {
        for x in 0..w {
            let i = y * w + x;
            let b = bars[(x / 4) % 4];
            color[i] = [b[0], b[1], b[2], 1.0];
            depth[i] = 6.0;
            if (32..144).contains(&x) && (36..144).contains(&y) {
                let v = if ((x - 32) / 6 + (y - 36) / 6) % 2 == 0 {
                    0.95
                } else {
                    0.05
                };
                color[i] = [v, v, v, 1.0];
                depth[i] = 0.5;
            }
            let (dx, dy) = (x as f64 + 0.5 - 240.0, y as f64 + 0.5 - 90.0);
            if dx.hypot(dy) < 30.0 {
                color[i] = [0.8, 0.6, 0.3, 1.0];
                depth[i] = 0.25;
            }
        }
    }
    (color, depth)
}

/// Mean squared error of splat against the reference over the card, in rings of 10 px around
/// the image centre (dB each).
fn ring_errors(a: &[[f32; 4]], b: &[[f32; 4]]) -> Vec<(usize, f64)> {
    let (w, h, _) = C1;
    let mut rings: Vec<(f64, usize)> = vec![(0.0, 0); 20];
    for y in 40..140 {
        for x in 36..140 {
            let i = y * w + x;
            let r = (x as f64 + 0.5 - 0.5 * w as f64).hypot(y as f64 + 0.5 - 0.5 * h as f64);
            let k = (r / 10.0) as usize;
            for c in 0..3 {
                rings[k].0 += f64::from(a[i][c] - b[i][c]).powi(2);
                rings[k].1 += 1;
            }
        }
    }
    rings
        .iter()
        .enumerate()
        .filter(|(_, r)| r.1 > 300)
        .map(|(k, r)| (k * 10, -10.0 * (r.0 / r.1 as f64).log10()))
        .collect()
}

#[test]
fn case1_small_blur_is_continuous_across_the_field() {
    let ctx = common::gpu();
    let (w, h, fov) = C1;
    let (color, depth) = case1_scene();
    let input = one_layer((w, h, fov), &color, &depth);
    let state = EyeState {
        focus_d: 1.0 / 6.0,
        pupil_mm: 5.0,
    };
    let out = render(
        &ctx,
        "keratoconus",
        &input,
        state,
        SplatSettings::default(),
        true,
    );
    let reference = out.reference.unwrap();
    let frame_db = db(&out.splat, &reference, w, h);
    let rings = ring_errors(&out.splat, &reference);
    eprintln!(
        "case 1: Rmax {} px, splat vs reference {frame_db:.2} dB",
        out.max_radius
    );
    for (r, e) in &rings {
        eprintln!("  ring {r:>3}–{:>3} px: {e:.2} dB", r + 10);
    }
    let (lo, hi) = rings.iter().fold((f64::INFINITY, 0.0f64), |(lo, hi), r| {
        (lo.min(r.1), hi.max(r.1))
    });
    eprintln!("  ring spread {:.2} dB", hi - lo);
    let jump = rings
        .windows(2)
        .map(|p| (p[0].1 - p[1].1).abs())
        .fold(0.0, f64::max);
    eprintln!("  largest step between neighbouring rings {jump:.2} dB");
    // Before: 33.9 dB, the rings 50–90 px at 21.9–27.8 dB against 62 dB inside.
    assert!(frame_db >= 60.0, "splat vs reference {frame_db:.2} dB");
    assert!(lo >= 58.0, "a ring at {lo:.2} dB: a seam");
    // The rings hold different parts of the card (its corners lie in the outer ones), so their
    // errors differ by content; the seam made a 34 dB step.
    assert!(jump <= 6.0, "neighbouring rings {jump:.2} dB apart: a seam");
    // Negative control: the unblurred input is far from the reference.
    let sharp = db(&color, &reference, w, h);
    eprintln!("  control, the unblurred input: {sharp:.2} dB");
    assert!(sharp < 45.0, "control {sharp:.2} dB");
    common::finish(ctx);
}

// ---------------------------------------------------------------------------------------
// Case 2: a point light in front of a distant background keeps its energy.

fn point_scene(distance_m: f64, background_m: f32) -> (Vec<[f32; 4]>, Vec<f32>, usize) {
    let (w, h, fov) = (321usize, 181usize, 30.0);
    let mut color = vec![[0.0f32, 0.0, 0.0, 1.0]; w * h];
    let mut depth = vec![background_m; w * h];
    let c = (h / 2) * w + w / 2;
    color[c] = [1.0; 4];
    depth[c] = axial(distance_m, w / 2, h / 2, w, h, fov);
    (color, depth, c)
}

#[test]
fn case2_a_point_before_a_distant_background_keeps_its_energy() {
    let ctx = common::gpu();
    let (w, h, fov) = (321usize, 181usize, 30.0);
    let state = EyeState {
        focus_d: 0.0,
        pupil_mm: 6.0,
    };
    for distance_m in [0.25, 0.5] {
        for background in [1000.0f32, distance_m as f32] {
            let (color, depth, _) = point_scene(distance_m, background);
            let input = one_layer((w, h, fov), &color, &depth);
            // The background at the point's own depth is the cell where the method works: splat
            // only, as a check of the scene itself.
            let far = background > 10.0;
            let out = render(
                &ctx,
                "navarro",
                &input,
                state,
                SplatSettings::default(),
                far,
            );
            let control = if far {
                render(&ctx, "navarro", &input, state, paper_blend(), false).splat
            } else {
                out.splat.clone()
            };
            let total = |img: &[[f32; 4]]| {
                let mut t = [0.0f64; 3];
                for p in img {
                    for c in 0..3 {
                        t[c] += f64::from(p[c]);
                    }
                }
                t
            };
            let s = total(&out.splat);
            let r = total(out.reference.as_ref().unwrap_or(&out.splat));
            let k = total(&control);
            eprintln!(
                "case 2: point at {distance_m} m, background {background} m: splat {:.4} {:.4} {:.4}, \
                 reference {:.4} {:.4} {:.4}; control (divided by coverage) {:.4} {:.4} {:.4}",
                s[0], s[1], s[2], r[0], r[1], r[2], k[0], k[1], k[2]
            );
            // Before: 1.04–1.06 at 0.25 m, 1.18–1.22 at 0.5 m (R, G) against the far background.
            for c in 0..3 {
                assert!((s[c] - 1.0).abs() < 0.02, "splat total {:?}", s);
                assert!((r[c] - 1.0).abs() < 0.02, "reference total {:?}", r);
            }
            if far {
                assert!(
                    k.iter().take(2).any(|&t| (t - 1.0).abs() > 0.02),
                    "control kept its energy {k:?}"
                );
            }
        }
    }
    common::finish(ctx);
}

// ---------------------------------------------------------------------------------------
/// White point lights `distance_m` along the rays of `pixels`, on black at 1000 m.
fn point_lights(
    (w, h, fov): (usize, usize, f64),
    pixels: &[(usize, usize)],
    distance_m: f64,
) -> (Vec<[f32; 4]>, Vec<f32>) {
    let mut color = vec![[0.0f32, 0.0, 0.0, 1.0]; w * h];
    let mut depth = vec![1000.0f32; w * h];
    for &(x, y) in pixels {
        color[y * w + x] = [1.0; 4];
        depth[y * w + x] = axial(distance_m, x, y, w, h, fov);
    }
    (color, depth)
}

/// The spots through the healthy eye focused at infinity with a 6 mm pupil, and the seed
/// paper's blend as the control (its geometry is the narrow field's scale everywhere).
fn spots_and_paper_control(
    ctx: &ocular::gpu::Context,
    input: &FrameInput<'_>,
    with_reference: bool,
) -> (Rendered, Vec<[f32; 4]>) {
    let state = EyeState {
        focus_d: 0.0,
        pupil_mm: 6.0,
    };
    let out = render(
        ctx,
        "healthy",
        input,
        state,
        SplatSettings::default(),
        with_reference,
    );
    let paper = SplatSettings {
        blend: ocular::render::BlendSettings::paper(),
        ..SplatSettings::default()
    };
    let control = render(ctx, "healthy", input, state, paper, false).splat;
    (out, control)
}

// Case 4: spots near the frame's edge grow with the pinhole's scale, in splat and reference.

#[test]
fn case4_spots_grow_with_the_pinhole_scale_to_the_frame_edge() {
    let ctx = common::gpu();
    let (w, h, fov) = (641usize, 361usize, 60.0f64);
    let focal = 0.5 * h as f64 / (0.5 * fov).to_radians().tan();
    let cy = h / 2;
    let angles = [0.0f64, 25.0, -35.0, 42.0];
    let columns: Vec<usize> = angles
        .iter()
        .map(|a| (0.5 * w as f64 + focal * a.to_radians().tan() - 0.5).round() as usize)
        .collect();
    let pixels: Vec<(usize, usize)> = columns.iter().map(|&x| (x, cy)).collect();
    let (color, depth) = point_lights((w, h, fov), &pixels, 0.25);
    let input = one_layer((w, h, fov), &color, &depth);
    let (out, control) = spots_and_paper_control(&ctx, &input, true);
    let widths = |image: &[[f32; 4]], x: usize| common::spots::rms_widths(image, w, (x, cy), 36);
    for (name, image) in [
        ("splat", &out.splat),
        ("reference", out.reference.as_ref().unwrap()),
        ("control", &control),
    ] {
        let (w0x, w0y) = widths(image, columns[0]);
        let mut worst = 0.0f64;
        for (a, &x) in angles.iter().zip(&columns).skip(1) {
            let (wx, wy) = widths(image, x);
            let t = a.abs().to_radians();
            let (px, py) = (1.0 / t.cos().powi(2), 1.0 / t.cos());
            eprintln!(
                "case 4: {name:<9} {a:>5.0}°: growth {:.3} / {:.3} (pinhole {px:.3} / {py:.3})",
                wx / w0x,
                wy / w0y,
            );
            worst = worst.max((wx / w0x / px - 1.0).abs().max((wy / w0y / py - 1.0).abs()));
        }
        // Before: the reference grew 2.588 / 1.949 at 42° (pinhole 1.811 / 1.346). The control
        // is the seed paper's geometry (the centre's scale everywhere).
        if name == "control" {
            assert!(worst > 0.06, "control within {worst:.3} of the pinhole");
        } else {
            assert!(worst <= 0.06, "{name}: {worst:.3} off the pinhole's growth");
        }
    }
    common::finish(ctx);
}

// ---------------------------------------------------------------------------------------
// Case 3: an in-focus wall seen past the blurred edge of a near card, one and two layers.

const C3: (usize, usize, f64) = (480, 270, 30.0);
const CARD_M: f64 = 0.3;
const WALL_M: f64 = 3.0;
const PUPIL_MM: f64 = 6.0;

fn stripe(x: usize) -> f32 {
    if (x / 3).is_multiple_of(2) {
        0.9
    } else {
        0.1
    }
}

/// Geometric truth, green channel, for column x: the share of the pupil whose rays to the wall
/// point of column x (in focus: all of them meet there) are stopped by the card (the half-plane
/// left of the image centre at CARD_M), times the card's grey, plus the rest times the wall
/// convolved with the eye's in-focus green kernel (`wall_row`).
fn case3_truth(x: usize, wall_row: &[f64]) -> f64 {
    let (w, h, fov) = C3;
    let f = 0.5 * h as f64 / (0.5 * fov).to_radians().tan();
    let a = 0.5 * PUPIL_MM * 1e-3;
    let mut card = 0.0;
    const SUB: usize = 16;
    for k in 0..SUB {
        let xc = x as f64 + (k as f64 + 0.5) / SUB as f64 - 0.5 * w as f64;
        let wall_x = WALL_M * xc / f;
        // ray from pupil point u to (wall_x, WALL_M) crosses CARD_M at u + (wall_x − u)·t
        let t = CARD_M / WALL_M;
        // blocked where that lateral position is < 0: u < −wall_x·t/(1 − t)
        let s = (-wall_x * t / (1.0 - t) / a).clamp(-1.0, 1.0);
        card += (std::f64::consts::PI - s.acos() + s * (1.0 - s * s).sqrt()) / std::f64::consts::PI;
    }
    card /= SUB as f64;
    card * 0.2 + (1.0 - card) * wall_row[x]
}

#[test]
fn case3_an_in_focus_wall_past_a_near_edge() {
    use ocular::psf::ExactEye;
    use ocular::render::reference::ExactKernels;
    let ctx = common::gpu();
    let (w, h, fov) = C3;
    let mut color0 = vec![[0.0f32; 4]; w * h];
    let mut depth0 = vec![0.0f32; w * h];
    let mut color1 = vec![[0.0f32; 4]; w * h];
    let mut depth1 = vec![f32::INFINITY; w * h];
    for y in 0..h {
        for x in 0..w {
            let i = y * w + x;
            let s = stripe(x);
            if x < w / 2 {
                color0[i] = [0.2, 0.2, 0.2, 1.0];
                depth0[i] = CARD_M as f32;
                color1[i] = [s, s, s, 1.0];
                depth1[i] = WALL_M as f32;
            } else {
                color0[i] = [s, s, s, 1.0];
                depth0[i] = WALL_M as f32;
            }
        }
    }
    let hidden = [HiddenLayer {
        color: &color1,
        depth_m: &depth1,
    }];
    let state = EyeState {
        focus_d: 1.0 / WALL_M,
        pupil_mm: PUPIL_MM,
    };
    // The wall through the in-focus green kernel, one row (the stripes are vertical).
    let screen = Screen {
        fov_y_deg: fov,
        height_px: h as u32,
    };
    let options = KernelOptions::default();
    let eye = resolve("healthy").unwrap().eye;
    let exact = ExactEye::new(
        &eye,
        PUPIL_MM,
        state.focus_d,
        [612.0, 549.0, 464.0],
        screen,
        options.settings.clone(),
        64,
    )
    .unwrap();
    let k = exact.kernel(1, 1.0 / WALL_M);
    let r = k.radius as i64;
    let wall_row: Vec<f64> = (0..w as i64)
        .map(|x| {
            let mut v = 0.0;
            for dx in -r..=r {
                let column: f64 = (-r..=r).map(|dy| f64::from(k.at(dx, dy))).sum();
                let sx = (x - dx).clamp(0, w as i64 - 1) as usize;
                v += column * f64::from(stripe(sx));
            }
            v
        })
        .collect();
    let band_db = |image: &[[f32; 4]]| {
        let (mut se, mut n) = (0.0, 0);
        for y in 100..170 {
            for x in w / 2 - 12..w / 2 + 12 {
                se += (f64::from(image[y * w + x][1]) - case3_truth(x, &wall_row)).powi(2);
                n += 1;
            }
        }
        -10.0 * (se / n as f64).log10()
    };
    let one = one_layer((w, h, fov), &color0, &depth0);
    let two = FrameInput {
        hidden_layers: &hidden,
        mixed: None,
        ..one
    };
    let single = render(
        &ctx,
        "healthy",
        &one,
        state,
        SplatSettings::default(),
        false,
    )
    .splat;
    let layered = render(
        &ctx,
        "healthy",
        &two,
        state,
        SplatSettings::default(),
        false,
    )
    .splat;
    let (db1, db2) = (band_db(&single), band_db(&layered));
    eprintln!("case 3: edge band ±12 px, green: one layer {db1:.2} dB, two layers {db2:.2} dB");
    let y = 135;
    for x in w / 2 - 6..w / 2 + 2 {
        eprintln!(
            "  x {x}: truth {:.3} one {:.3} two {:.3}",
            case3_truth(x, &wall_row),
            single[y * w + x][1],
            layered[y * w + x][1]
        );
    }
    // Before: two layers 27.2 dB, worse than one. The one-layer image is the control: it
    // cannot know the stripes hidden behind the card.
    assert!(db2 >= 45.0, "two layers {db2:.2} dB");
    assert!(db2 >= db1 + 1.0, "two layers {db2:.2} dB, one {db1:.2} dB");
    assert!(db1 < 30.0, "control (one layer) {db1:.2} dB");
    common::finish(ctx);
}

// ---------------------------------------------------------------------------------------
// An independent wave-optics PSF for the truths below: the pupil function of one channel of
// the focused eye (its measured Zernike coefficients, the only thing shared with the kernels)
// sampled on a grid, transformed with rustfft, squared, and integrated over screen pixels.
// Nothing of the kernels' own path (ENZ, β, the cropped PSF, its resampling) is used: the
// Zernike polynomials are written here, and the orientation follows the documented one (a
// screen offset (right, down) shows the object-space direction −θ of the OSA axes).

/// (n, m) of an OSA/ANSI single index.
fn osa(j: usize) -> (i64, i64) {
    let mut n = 0i64;
    while (n + 1) * (n + 2) / 2 <= j as i64 {
        n += 1;
    }
    (n, 2 * j as i64 - n * (n + 2))
}

/// The OSA Zernike polynomial j at polar (ρ, φ), orthonormal over the unit disc.
fn zernike(j: usize, rho: f64, phi: f64) -> f64 {
    let (n, m) = osa(j);
    let am = m.abs();
    let fact = |k: i64| (1..=k).map(|v| v as f64).product::<f64>();
    let mut radial = 0.0;
    for k in 0..=(n - am) / 2 {
        let sign = if k % 2 == 0 { 1.0 } else { -1.0 };
        radial += sign * fact(n - k) / (fact(k) * fact((n + am) / 2 - k) * fact((n - am) / 2 - k))
            * rho.powi((n - 2 * k) as i32);
    }
    let norm = if m == 0 {
        ((n + 1) as f64).sqrt()
    } else {
        (2.0 * (n + 1) as f64).sqrt()
    };
    let angular = if m >= 0 {
        (am as f64 * phi).cos()
    } else {
        (am as f64 * phi).sin()
    };
    norm * radial * angular
}

/// The screen kernel (side 2·half + 1, row-major, rows down) of one channel of the focused
/// eye for an object whose vergence at the entrance pupil is `dv` dioptres below the focus
/// (`dv` = V_focus − V_object), at `focal_px` pixels per radian: an `n`-point transform with
/// `s` (odd) samples per pixel. Normalised to sum 1 over the kernel.
fn wave_kernel(
    ch: &ocular::psf::ChannelOptics,
    dv: f64,
    focal_px: f64,
    (n, s, half): (usize, usize, usize),
) -> Vec<f64> {
    use rustfft::num_complex::Complex;
    let lambda = ch.wavelength_nm * 1e-9;
    let radius = 0.5e-3 * ch.pupil_mm;
    // angular pitch λ/(nΔ) = 1/(s·focal_px)
    let delta = lambda * s as f64 * focal_px / n as f64;
    assert!(
        2.0 * radius < 0.75 * n as f64 * delta,
        "pupil too large for the grid"
    );
    let mut coeffs: Vec<(usize, f64)> = ch
        .alpha_um
        .iter()
        .enumerate()
        .filter(|&(j, a)| j != 4 && *a != 0.0)
        .map(|(j, &a)| (j, a * 1e-6))
        .collect();
    coeffs.push((4, ch.residual_c20_um * 1e-6));
    let mut field = vec![Complex::new(0.0f64, 0.0); n * n];
    for iy in 0..n {
        for ix in 0..n {
            let x = (ix as f64 - 0.5 * n as f64) * delta / radius;
            let y = (iy as f64 - 0.5 * n as f64) * delta / radius;
            let rho = x.hypot(y);
            if rho > 1.0 {
                continue;
            }
            let phi = y.atan2(x);
            let w: f64 = coeffs
                .iter()
                .map(|&(j, a)| a * zernike(j, rho, phi))
                .sum::<f64>()
                + 0.5 * radius * radius * dv * rho * rho;
            field[iy * n + ix] = Complex::from_polar(1.0, 2.0 * std::f64::consts::PI * w / lambda);
        }
    }
    let fft = rustfft::FftPlanner::new().plan_fft_forward(n);
    for row in field.chunks_mut(n) {
        fft.process(row);
    }
    let mut column = vec![Complex::new(0.0, 0.0); n];
    for ix in 0..n {
        for iy in 0..n {
            column[iy] = field[iy * n + ix];
        }
        fft.process(&mut column);
        for iy in 0..n {
            field[iy * n + ix] = column[iy];
        }
    }
    // intensity at OSA frequency (u, v) lies at screen offset (−u, −v)/s pixels
    let at = |u: i64, v: i64| {
        let (iu, iv) = (
            u.rem_euclid(n as i64) as usize,
            v.rem_euclid(n as i64) as usize,
        );
        field[iv * n + iu].norm_sqr()
    };
    let side = 2 * half + 1;
    let hs = (s as i64 - 1) / 2;
    let mut kernel = vec![0.0; side * side];
    for (k, value) in kernel.iter_mut().enumerate() {
        let dx = (k % side) as i64 - half as i64;
        let dy = (k / side) as i64 - half as i64;
        for v in s as i64 * dy - hs..=s as i64 * dy + hs {
            for u in s as i64 * dx - hs..=s as i64 * dx + hs {
                *value += at(-u, -v);
            }
        }
    }
    let total: f64 = kernel.iter().sum();
    kernel.iter_mut().for_each(|v| *v /= total);
    kernel
}

/// The focused healthy eye's channels (its Zernike coefficients per wavelength).
fn healthy_column(pupil_mm: f64, focus_d: f64) -> ocular::psf::ColumnOptics {
    ocular::psf::ColumnOptics::new(
        &resolve("healthy").unwrap().eye,
        pupil_mm,
        focus_d,
        ocular::psf::DEFAULT_WAVELENGTHS_NM,
        &ocular::psf::KernelSettings::default(),
    )
    .unwrap()
}

// ---------------------------------------------------------------------------------------
// Case 7: a small-blur sweep, 0.1–1 D, against the wave-optics truth.

const C7: (usize, usize, f64) = (320, 180, 5.0);

/// PSNR (dB) of `a` against `b` over the frame's interior (40 px from every side), RGB or
/// one channel.
fn interior_db(a: &[[f32; 4]], b: &[[f32; 4]], channels: std::ops::Range<usize>) -> f64 {
    let (w, h, _) = C7;
    let (mut se, mut n) = (0.0, 0);
    for y in 40..h - 40 {
        for x in 40..w - 40 {
            for c in channels.clone() {
                se += (f64::from(a[y * w + x][c]) - f64::from(b[y * w + x][c])).powi(2);
                n += 1;
            }
        }
    }
    -10.0 * (se / n as f64).log10()
}

#[test]
fn case7_small_blur_sweep_against_the_wave_optics_truth() {
    let ctx = common::gpu();
    let (w, h, fov) = C7;
    let focal = 0.5 * h as f64 / (0.5 * fov).to_radians().tan();
    // grey value noise, one value per pixel (every spatial frequency up to Nyquist)
    let mut seed = 0x2545_f491_4f6c_dd1du64;
    let color: Vec<[f32; 4]> = (0..w * h)
        .map(|_| {
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            let v = 0.05 + 0.9 * (seed >> 11) as f32 / (1u64 << 53) as f32;
            [v, v, v, 1.0]
        })
        .collect();
    let state = EyeState {
        focus_d: 0.0,
        pupil_mm: 6.0,
    };
    let column = healthy_column(state.pupil_mm, state.focus_d);
    let truth_of = |dv_of: &dyn Fn(usize) -> f64| {
        let kernels: Vec<Vec<f64>> = (0..3)
            .map(|c| wave_kernel(&column.channels[c], dv_of(c), focal, (576, 9, 31)))
            .collect();
        let mut out = color.clone();
        for y in 40..h - 40 {
            for x in 40..w - 40 {
                for (c, k) in kernels.iter().enumerate() {
                    let mut v = 0.0;
                    for dy in -31i64..=31 {
                        for dx in -31i64..=31 {
                            let sx = (x as i64 - dx).clamp(0, w as i64 - 1) as usize;
                            let sy = (y as i64 - dy).clamp(0, h as i64 - 1) as usize;
                            v += k[((dy + 31) * 63 + dx + 31) as usize]
                                * f64::from(color[sy * w + sx][c]);
                        }
                    }
                    out[y * w + x][c] = v as f32;
                }
            }
        }
        out
    };
    let e = column.channels[1].entrance_pupil_m;
    let in_focus = truth_of(&|c| column.channels[c].focus_vergence);
    eprintln!(
        "case 7: healthy, 6 mm, focus at infinity, {w}×{h} at {fov}° ({:.2} arcmin/px); \
         residual c(2,0) at 612/549/464 nm {:.3} / {:.3} / {:.3} µm",
        60.0 * (1.0 / focal).to_degrees(),
        column.channels[0].residual_c20_um,
        column.channels[1].residual_c20_um,
        column.channels[2].residual_c20_um,
    );
    // The default object axis (1/16 D steps from 0 D), one of 0.025 D steps from 0, and the
    // seed paper's (0.25 D steps from 0.125 D, the default before), kept as a control.
    let fine = ocular::psf::GridAxes {
        objects: ocular::psf::DioptreAxis::spanning(0.0, 10.0, 401),
        ..Default::default()
    };
    let paper = ocular::psf::GridAxes {
        objects: ocular::psf::DioptreAxis::spanning(0.125, 10.125, 41),
        ..Default::default()
    };
    // (defocus, bar on the default axis, bar on the fine axis): near the measured values. The
    // last three planes lie halfway between two default samples, where the blend between
    // neighbouring object distances errs most.
    let levels = [
        (0.1, 41.5, 45.0),
        (0.25, 50.5, 50.5),
        (0.5, 53.5, 53.5),
        (1.0, 50.5, 50.5),
        (0.15625, 50.5, 52.0),
        (0.40625, 41.5, 45.0),
        (0.96875, 53.0, 50.5),
    ];
    for (dioptres, bar, bar_fine) in levels {
        let distance = 1.0 / dioptres;
        let depth = vec![distance as f32; w * h];
        let input = one_layer((w, h, fov), &color, &depth);
        let splat = SplatSettings::default;
        let out = render(&ctx, "healthy", &input, state, splat(), false);
        let fine_out = render_on(&ctx, "healthy", &input, state, splat(), false, fine.clone());
        let paper_out = render_on(
            &ctx,
            "healthy",
            &input,
            state,
            splat(),
            false,
            paper.clone(),
        );
        let truth = truth_of(&|c| column.channels[c].focus_vergence - 1.0 / (distance + e));
        let rgb = |image: &[[f32; 4]]| {
            let all = interior_db(image, &truth, 0..3);
            let per = [0, 1, 2].map(|c| interior_db(image, &truth, c..c + 1));
            (all, per)
        };
        let (db, dp) = rgb(&out.splat);
        let (fine_db, fp) = rgb(&fine_out.splat);
        let (paper_db, pp) = rgb(&paper_out.splat);
        let sharp = interior_db(&color, &truth, 0..3);
        let focused = interior_db(&in_focus, &truth, 0..3);
        eprintln!(
            "  {dioptres:>7} D (plane at {distance:.3} m, Rmax {} px): splat vs truth, default \
             1/16 D axis {db:.2} dB (R {:.2} G {:.2} B {:.2}); 0.025 D axis {fine_db:.2} dB \
             (R {:.2} G {:.2} B {:.2}); controls: the seed paper's 0.25 D axis {paper_db:.2} dB \
             (R {:.2} G {:.2} B {:.2}), the unblurred input {sharp:.2} dB, the in-focus eye's \
             truth {focused:.2} dB",
            out.max_radius, dp[0], dp[1], dp[2], fp[0], fp[1], fp[2], pp[0], pp[1], pp[2]
        );
        assert!(db >= bar, "{dioptres} D: splat {db:.2} dB");
        assert!(
            fine_db >= bar_fine,
            "{dioptres} D: 0.025 D axis {fine_db:.2} dB"
        );
        assert!(
            sharp < bar && focused < bar && paper_db < bar,
            "{dioptres} D: a control passed"
        );
    }
    common::finish(ctx);
}

// ---------------------------------------------------------------------------------------
// Case 8: spots to the frame's corners at a 90° vertical field grow with the pinhole's scale.

/// Green-channel second moments of a spot around pixel (x, y) over a square window of
/// half-side `window` (inside the frame): the covariance (xx, xy, yy) in px², with Sheppard's
/// 1/12 px² for pixel integration taken off the diagonal.
fn spot_covariance(
    image: &[[f32; 4]],
    w: usize,
    (x, y): (usize, usize),
    window: usize,
) -> [f64; 3] {
    let (mut e, mut mx, mut my) = (0.0f64, 0.0, 0.0);
    let mut samples = Vec::new();
    for py in y - window..=y + window {
        for px in x - window..=x + window {
            let v = f64::from(image[py * w + px][1]);
            let (dx, dy) = (px as f64 - x as f64, py as f64 - y as f64);
            samples.push((dx, dy, v));
            e += v;
            mx += v * dx;
            my += v * dy;
        }
    }
    let (mx, my) = (mx / e, my / e);
    let mut c = [0.0; 3];
    for (dx, dy, v) in samples {
        c[0] += v * (dx - mx).powi(2);
        c[1] += v * (dx - mx) * (dy - my);
        c[2] += v * (dy - my).powi(2);
    }
    [c[0] / e - 1.0 / 12.0, c[1] / e, c[2] / e - 1.0 / 12.0]
}

#[test]
fn case8_spots_to_the_corners_of_a_90_degree_field() {
    let ctx = common::gpu();
    // 90° vertical: the corners lie 63.9° off axis, the left and right edges 60.6°.
    let (w, h, fov) = (480usize, 270usize, 90.0f64);
    let focal = 0.5 * h as f64 / (0.5 * fov).to_radians().tan();
    let (cx, cy) = (0.5 * w as f64, 0.5 * h as f64);
    let corner = [cx, cy];
    let norm = cx.hypot(cy);
    // (name, screen direction, field angle): the centre, the diagonal to the bottom-right
    // corner, the top edge and the left edge
    let spots: Vec<(&str, [f64; 2], f64)> = vec![
        ("centre", [1.0, 0.0], 0.0),
        ("diagonal", [corner[0] / norm, corner[1] / norm], 30.0),
        ("diagonal", [corner[0] / norm, corner[1] / norm], 45.0),
        ("diagonal", [corner[0] / norm, corner[1] / norm], 58.0),
        ("top edge", [0.0, -1.0], 40.0),
        ("left edge", [-1.0, 0.0], 57.0),
    ];
    let pixels: Vec<(usize, usize)> = spots
        .iter()
        .map(|(_, d, a)| {
            let r = focal * a.to_radians().tan();
            (
                (cx + r * d[0]).floor() as usize,
                (cy + r * d[1]).floor() as usize,
            )
        })
        .collect();
    let (color, depth) = point_lights((w, h, fov), &pixels, 0.1);
    let input = one_layer((w, h, fov), &color, &depth);
    let (out, control) = spots_and_paper_control(&ctx, &input, false);
    eprintln!(
        "case 8: {w}×{h} at {fov}° vertical (corners {:.1}° off axis), Rmax {} px",
        (norm / focal).atan().to_degrees(),
        out.max_radius
    );
    let mut worst = [0.0f64; 2];
    for (k, image) in [&out.splat, &control].into_iter().enumerate() {
        let name = ["splat", "control"][k];
        let c0 = spot_covariance(image, w, pixels[0], 20);
        let v0 = 0.5 * (c0[0] + c0[2]);
        // a pure geometric disc of radius a·ΔV·f has an RMS width of half its radius per axis
        let disc = 3e-3 * (1.0 / 0.1) * focal;
        eprintln!(
            "  {name:<7} centre RMS width {:.3} / {:.3} px (geometric disc, entrance pupil at \
             the vertex: {:.3} px)",
            c0[0].sqrt(),
            c0[2].sqrt(),
            0.5 * disc
        );
        for ((label, _, _), &(x, y)) in spots.iter().zip(&pixels).skip(1) {
            // the pixel centre's own direction
            let (u, v) = (x as f64 + 0.5 - cx, y as f64 + 0.5 - cy);
            let rho = u.hypot(v);
            let (er, et) = ([u / rho, v / rho], [-v / rho, u / rho]);
            let t = (rho / focal).atan();
            let window = 24.min(x).min(y).min(w - 1 - x).min(h - 1 - y);
            let c = spot_covariance(image, w, (x, y), window);
            let along =
                |e: [f64; 2]| c[0] * e[0] * e[0] + 2.0 * c[1] * e[0] * e[1] + c[2] * e[1] * e[1];
            let (gr, gt) = ((along(er) / v0).sqrt(), (along(et) / v0).sqrt());
            let (pr, pt) = (1.0 / t.cos().powi(2), 1.0 / t.cos());
            eprintln!(
                "  {name:<7} {label:<9} {:>5.1}° (window ±{window}): growth radial {gr:.3} / \
                 tangential {gt:.3} (pinhole {pr:.3} / {pt:.3})",
                t.to_degrees()
            );
            worst[k] = worst[k]
                .max((gr / pr - 1.0).abs())
                .max((gt / pt - 1.0).abs());
        }
        eprintln!("  {name}: worst {:.2} % off the pinhole", 100.0 * worst[k]);
    }
    assert!(
        worst[0] <= 0.04,
        "splat {:.3} off the pinhole's growth",
        worst[0]
    );
    assert!(
        worst[1] > 0.04,
        "control within {:.3} of the pinhole",
        worst[1]
    );
    common::finish(ctx);
}

// ---------------------------------------------------------------------------------------
// Case 9: a defocused wall behind the in-focus edge of a near card (the hidden layer out of
// focus), one and two layers.

const C9: (usize, usize, f64) = (320, 180, 20.0);
const C9_CARD_M: f64 = 0.25;
const C9_WALL_M: f64 = 4.0;

#[test]
fn case9_a_defocused_wall_behind_an_in_focus_edge() {
    let ctx = common::gpu();
    let (w, h, fov) = C9;
    let focal = 0.5 * h as f64 / (0.5 * fov).to_radians().tan();
    let edge = w / 2;
    // The wall is bright (0.9) where the card hides it and dark (0.1) where it is seen: all
    // the light near the edge comes from behind the card.
    let wall = |x: usize| if x < edge { 0.9f32 } else { 0.1 };
    let mut color0 = vec![[0.0f32; 4]; w * h];
    let mut depth0 = vec![0.0f32; w * h];
    let mut color1 = vec![[0.0f32; 4]; w * h];
    let mut depth1 = vec![f32::INFINITY; w * h];
    for y in 0..h {
        for x in 0..w {
            let i = y * w + x;
            let v = wall(x);
            if x < edge {
                color0[i] = [0.2, 0.2, 0.2, 1.0];
                depth0[i] = C9_CARD_M as f32;
                color1[i] = [v, v, v, 1.0];
                depth1[i] = C9_WALL_M as f32;
            } else {
                color0[i] = [v, v, v, 1.0];
                depth0[i] = C9_WALL_M as f32;
            }
        }
    }
    let hidden = [HiddenLayer {
        color: &color1,
        depth_m: &depth1,
    }];
    let state = EyeState {
        focus_d: 1.0 / C9_CARD_M,
        pupil_mm: 6.0,
    };
    // Truth (green): focused on the card, every ray of a pixel crosses the card's plane at that
    // pixel's own point, so a card pixel is the card's grey, and a pixel past the edge sees
    // the whole wall (the hidden part included) through the full pupil: the wall convolved
    // with the eye's green PSF at the wall's defocus, from the wave-optics kernel above.
    let column = healthy_column(state.pupil_mm, state.focus_d);
    let ch = &column.channels[1];
    let dv = ch.focus_vergence - 1.0 / (C9_WALL_M + ch.entrance_pupil_m);
    let half = 11usize;
    let kernel = wave_kernel(ch, dv, focal, (1024, 43, half));
    let side = 2 * half + 1;
    let row: Vec<f64> = (0..side)
        .map(|dx| (0..side).map(|dy| kernel[dy * side + dx]).sum())
        .collect();
    let truth = |x: usize| {
        if x < edge {
            return 0.2;
        }
        (0..side)
            .map(|k| {
                let sx = (x as i64 - (k as i64 - half as i64)).clamp(0, w as i64 - 1);
                row[k] * f64::from(wall(sx as usize))
            })
            .sum::<f64>()
    };
    // The band: 2..12 px either side of the edge (the in-focus PSF of the card's edge, left
    // out of the truth, reaches about a pixel).
    let columns: Vec<usize> = (edge - 12..edge - 2).chain(edge + 2..edge + 12).collect();
    let band_db = |image: &[[f32; 4]]| {
        let (mut se, mut n) = (0.0, 0);
        for y in 60..120 {
            for &x in &columns {
                se += (f64::from(image[y * w + x][1]) - truth(x)).powi(2);
                n += 1;
            }
        }
        -10.0 * (se / n as f64).log10()
    };
    let one = one_layer((w, h, fov), &color0, &depth0);
    let two = FrameInput {
        hidden_layers: &hidden,
        mixed: None,
        ..one
    };
    let single = render(
        &ctx,
        "healthy",
        &one,
        state,
        SplatSettings::default(),
        false,
    );
    let layered = render(
        &ctx,
        "healthy",
        &two,
        state,
        SplatSettings::default(),
        false,
    )
    .splat;
    let (db1, db2) = (band_db(&single.splat), band_db(&layered));
    eprintln!(
        "case 9: wall defocus {dv:.3} D (geometric disc radius {:.2} px), Rmax {} px; band \
         2–12 px either side of the edge, green: two layers {db2:.2} dB, one layer {db1:.2} dB",
        0.5e-3 * state.pupil_mm * dv * focal,
        single.max_radius
    );
    let y = 90;
    for x in edge - 3..edge + 8 {
        eprintln!(
            "  x {:>+3}: truth {:.3} two {:.3} one {:.3}",
            x as i64 - edge as i64,
            truth(x),
            layered[y * w + x][1],
            single.splat[y * w + x][1]
        );
    }
    // the two columns at the edge, left out of the band
    let edge_err =
        |image: &[[f32; 4]]| [edge - 1, edge].map(|x| f64::from(image[y * w + x][1]) - truth(x));
    eprintln!(
        "  at the edge (x −1, 0): two layers off the truth by {:+.3} / {:+.3}",
        edge_err(&layered)[0],
        edge_err(&layered)[1]
    );
    assert!(db2 >= 62.0, "two layers {db2:.2} dB");
    // Negative control: one layer cannot know the bright wall behind the card.
    assert!(db1 < 30.0, "control (one layer) {db1:.2} dB");
    common::finish(ctx);
}
