//! The common cases a user meets every day, where the method is weakest: small blur near focus
//! over a wide frame, point lights against a distant background, in-focus backgrounds seen past
//! a blurred near edge, spots near the frame's edge. Each cell is judged against a truth
//! written here (closed forms, an independent geometric multi-view sum, the pinhole's geometry),
//! never against splat's own kernels or blend, and has a negative control that fails its bar.
//! Figures: `cargo test --release --test fidelity -- --nocapture`.

mod common;

use ocular::eye::file::resolve;
use ocular::metrics::{psnr, ImageView};
use ocular::psf::axes::Screen;
use ocular::render::frame::{
    dioptre_range, prepare_kernels, scene_needs, EyeState, FrameRenderer, KernelOptions, Method,
};
use ocular::render::splat::{FrameInput, HiddenLayer, SplatSettings};

/// The seed paper's blend: every fragment composited front to back, the output divided by
/// the coverage (the negative control for the light behind a point).
fn paper_blend() -> SplatSettings {
    SplatSettings {
        blend: ocular::render::blend::BlendSettings {
            mode: ocular::render::blend::BlendMode::PerFragment,
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
    let options = KernelOptions {
        cache_dir: cache(),
        progress: None,
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
    let mut color = vec![[0.0f32, 0.0, 0.0, 1.0]; w * h];
    let mut depth = vec![1000.0f32; w * h];
    for &x in &columns {
        color[cy * w + x] = [1.0; 4];
        depth[cy * w + x] = axial(0.25, x, cy, w, h, fov);
    }
    let input = one_layer((w, h, fov), &color, &depth);
    let state = EyeState {
        focus_d: 0.0,
        pupil_mm: 6.0,
    };
    let out = render(
        &ctx,
        "healthy",
        &input,
        state,
        SplatSettings::default(),
        true,
    );
    let paper = SplatSettings {
        blend: ocular::render::blend::BlendSettings::paper(),
        ..SplatSettings::default()
    };
    let control = render(&ctx, "healthy", &input, state, paper, false).splat;
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
    use ocular::psf::exact::ExactEye;
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
