//! `--off-axis` at run time: a textured surface at one distance across a wide field (a sphere
//! around the eye, so that every pixel has the same vergence along its ray), through the
//! wide-angle eye. The splat mixes each fragment's kernel from the four lattice nodes around
//! its direction; the ground truth traces the eye for every field bin (no lattice, no
//! interpolation over the field; it shares the PSF computation of a direction and the blend
//! with splat, not the lattice). Figures:
//! `cargo test --release --test it off_axis_runtime:: -- --nocapture`.

use crate::common;
use common::frames::{frame_renderer, splat_and_truth};
use common::pixels::max_rgb_difference;

use ocular::eye::resolve;
use ocular::psf::Screen;
use ocular::render::splat::{ConvolveWalk, FrameInput, SplatSettings};
use ocular::render::{
    dioptre_range, prepare_kernels, scene_needs, EyeState, FrameRenderer, KernelOptions, Method,
};

const W: usize = 240;
const H: usize = 135;
const FOV_Y_DEG: f64 = 40.0;
/// The surface's distance along every ray: 5 D of defocus for an eye focused far away.
const DISTANCE_M: f64 = 0.2;
/// Field bin of the reference (degrees): coarse enough for a test, finer than the lattice.
const REFERENCE_STEP_DEG: f64 = 2.5;

fn texture(x: usize, y: usize) -> [f32; 3] {
    let (x, y) = (x as f32, y as f32);
    [
        0.5 + 0.45 * (0.71 * x).sin() * (0.53 * y).cos(),
        0.5 + 0.45 * (0.61 * y + 0.4).cos() * (0.47 * x).sin(),
        0.5 + 0.45 * ((x + 2.0 * y) * 0.37).sin(),
    ]
}

/// PSNR (peak 1) over the pixels at least `margin` from every edge.
fn psnr(a: &[[f32; 4]], b: &[[f32; 4]], margin: usize) -> f64 {
    let (mut se, mut n) = (0.0f64, 0usize);
    for y in margin..H - margin {
        for x in margin..W - margin {
            for c in 0..3 {
                se += f64::from(a[y * W + x][c] - b[y * W + x][c]).powi(2);
                n += 1;
            }
        }
    }
    10.0 * (n as f64 / se).log10()
}

/// Per column, the mean over the interior rows of |a − b| (all channels).
fn column_error(a: &[[f32; 4]], b: &[[f32; 4]], margin: usize) -> Vec<f64> {
    (0..W)
        .map(|x| {
            let mut s = 0.0f64;
            for y in margin..H - margin {
                for c in 0..3 {
                    s += f64::from((a[y * W + x][c] - b[y * W + x][c]).abs());
                }
            }
            s / (3 * (H - 2 * margin)) as f64
        })
        .collect()
}

#[test]
fn a_wall_across_the_field_matches_the_traced_eye_without_seams() {
    let ctx = common::gpu();
    let color: Vec<[f32; 4]> = (0..W * H)
        .map(|i| {
            let c = texture(i % W, i / W);
            [c[0], c[1], c[2], 1.0]
        })
        .collect();
    // view-axis depth of a point at DISTANCE_M along the ray of each pixel
    let f = (0.5 * H as f64) / (0.5 * FOV_Y_DEG).to_radians().tan();
    let depth: Vec<f32> = (0..W * H)
        .map(|i| {
            let x = ((i % W) as f64 + 0.5 - 0.5 * W as f64) / f;
            let y = ((i / W) as f64 + 0.5 - 0.5 * H as f64) / f;
            (DISTANCE_M / (1.0 + x * x + y * y).sqrt()) as f32
        })
        .collect();
    let input = FrameInput {
        width: W as u32,
        height: H as u32,
        color: &color,
        depth_m: &depth,
        fov_y_deg: FOV_Y_DEG,
        hidden_layers: &[],
        mixed: None,
    };
    let state = EyeState {
        focus_d: 0.0,
        pupil_mm: 5.0,
    };
    let screen = Screen {
        fov_y_deg: FOV_Y_DEG,
        height_px: H as u32,
    };
    let eye = resolve("navarro-wide").unwrap().eye;
    let range = dioptre_range(&depth, W as u32, H as u32, FOV_Y_DEG);
    let needs = scene_needs(&[range], &[state], screen);
    let on_axis_options = KernelOptions {
        cache_dir: None,
        progress: None,
        ..KernelOptions::default()
    };
    let options = KernelOptions {
        field_width_px: Some(W as u32),
        ..on_axis_options.clone()
    };
    let kernels = prepare_kernels(&eye, &needs, &options).unwrap();
    let field = kernels.field.as_ref().expect("off-axis kernels").clone();
    let rmax = kernels.grid.max_radius_px;
    let mut renderer = frame_renderer(&ctx, eye.clone(), kernels, &options);
    renderer.reference_field_step_deg = REFERENCE_STEP_DEG;
    let (splat, truth) = splat_and_truth(&mut renderer, &input, state);
    // A fresh renderer of the same kernels splatting with other settings.
    let splat_with = |settings: SplatSettings| {
        FrameRenderer::new(
            &ctx,
            eye.clone(),
            prepare_kernels(&eye, &needs, &options).unwrap(),
            options.settings.clone(),
            settings,
        )
        .render(&input, state, Method::Splat)
    };
    // The off-axis convolution is a pipeline of its own: tile sizes give the same image (32 is
    // refused: on lavapipe the four-node convolution at 16 pixels per thread went wrong).
    {
        let tile_size = 16;
        let other = splat_with(SplatSettings {
            tile_size,
            ..SplatSettings::default()
        })
        .unwrap()
        .color;
        let worst = max_rgb_difference(&other, &splat);
        assert!(
            worst <= 1e-6,
            "tile size {tile_size} changes the image by {worst:e}"
        );
    }
    // The GPU's walk (convolve.comp, its reads planned per batch) gives the visits walk's image
    // off axis too, up to the order of float additions.
    {
        let pixels = splat_with(SplatSettings {
            convolve_walk: ConvolveWalk::Pixels,
            ..SplatSettings::default()
        })
        .unwrap()
        .color;
        let worst = max_rgb_difference(&pixels, &splat);
        eprintln!("off axis: worst difference between the walks {worst:.2e}");
        assert!(
            worst <= 1e-5,
            "the pixel walk differs off axis by {worst:e}"
        );
    }
    let refused = splat_with(SplatSettings {
        tile_size: 32,
        ..SplatSettings::default()
    })
    .err()
    .expect("--off-axis with 32-pixel tiles is refused")
    .to_string();
    assert!(refused.contains("--tile-size 8 or 16"), "{refused}");
    let on_axis = {
        let k = prepare_kernels(&eye, &needs, &on_axis_options).unwrap();
        let mut r = frame_renderer(&ctx, eye, k, &on_axis_options);
        r.render(&input, state, Method::Splat).unwrap().color
    };
    let margin = rmax as usize + 2;
    let db = psnr(&splat, &truth, margin);
    let db_on_axis = psnr(&on_axis, &truth, margin);
    let h = &field.plan.axes.h_deg;
    eprintln!(
        "lattice {} × {} (h {:.1}..{:.1}°), Rmax {rmax} px: off-axis splat {db:.2} dB, \
         on-axis splat {db_on_axis:.2} dB against the traced eye",
        h.len(),
        field.plan.axes.v_deg.len(),
        h[0],
        h[h.len() - 1],
    );

    // Seams: the error against the truth, column by column, jumps no more where a column
    // crosses a lattice node, or the midpoint between two (where a nearest-node lookup would
    // switch kernels), than it does elsewhere.
    let column_deg = |x: usize| ((x as f64 + 0.5 - 0.5 * W as f64) / f).atan().to_degrees();
    let errors = column_error(&splat, &truth, margin);
    let jumps: Vec<(usize, f64)> = (margin..W - margin - 1)
        .map(|x| (x, (errors[x + 1] - errors[x]).abs()))
        .collect();
    let mut boundaries = h.clone();
    boundaries.extend(h.windows(2).map(|w| 0.5 * (w[0] + w[1])));
    let crosses = |x: usize| {
        boundaries
            .iter()
            .any(|&n| (column_deg(x) - n) * (column_deg(x + 1) - n) <= 0.0)
    };
    let at_nodes: Vec<f64> = jumps.iter().filter(|j| crosses(j.0)).map(|j| j.1).collect();
    let mut elsewhere: Vec<f64> = jumps
        .iter()
        .filter(|j| !crosses(j.0))
        .map(|j| j.1)
        .collect();
    elsewhere.sort_by(f64::total_cmp);
    let typical = elsewhere[elsewhere.len() * 9 / 10];
    let worst_node = at_nodes.iter().copied().fold(0.0, f64::max);
    eprintln!(
        "column error jumps: worst at a lattice node or midpoint {worst_node:.2e}, 90th \
         percentile elsewhere {typical:.2e} ({} crossings)",
        at_nodes.len()
    );
    assert!(!at_nodes.is_empty());
    // measured: 51.21 dB off axis (42.85 before the local scale became continuous), 32.24 dB
    // with the on-axis PSF
    assert!(
        db >= 49.5,
        "off-axis splat {db:.2} dB against the traced eye"
    );
    assert!(
        db_on_axis < db - 8.0,
        "the on-axis PSF ({db_on_axis:.2} dB) must be visibly further from the traced eye"
    );
    // Measured: 1.10e-3 at a node (then 1.5× the typical jump); since the local scale became
    // continuous the frame is 51.2 dB from the traced eye (was 42.9) and the typical jump
    // elsewhere fell to 6.6e-4 while the node's stayed at 1.14e-3: bounded absolutely, and
    // within 2× of the rest.
    assert!(
        worst_node <= 1.3e-3 && worst_node <= 2.0 * typical,
        "a seam at a lattice node: {worst_node:.2e} against {typical:.2e} elsewhere"
    );
    drop(renderer);
    common::finish(ctx);
}
