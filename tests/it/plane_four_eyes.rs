//! The physical image of a textured plane at one distance is the plane convolved with the eye's
//! PSF. For the four estimated eyes (the seed paper's conditions: 4 mm pupil, focus at
//! infinity, planes at 0.5 m and 1 m), the splat runtime and the ground truth are compared with
//! that convolution, computed here independently of their blend (it shares the exact kernel,
//! not the method). The figures are the plane table of docs/validation.md:
//! `cargo test --release --test it plane_four_eyes:: -- --nocapture`.

use crate::common;
use common::frames::{frame_renderer, splat_and_truth};

use ocular::eye::resolve;
use ocular::psf::{ExactEye, Screen};
use ocular::render::reference::{ExactKernels, DIOPTRE_BIN_D};
use ocular::render::splat::FrameInput;
use ocular::render::{dioptre_range, prepare_kernels, scene_needs, EyeState, KernelOptions};

const W: usize = 160;
const H: usize = 90;
/// Narrow enough that one view-axis depth is one distance along every ray (0.4 % apart).
const FOV_Y_DEG: f64 = 5.0;

fn texture(x: usize, y: usize) -> [f32; 3] {
    let (x, y) = (x as f32, y as f32);
    [
        0.5 + 0.45 * (0.41 * x).sin() * (0.29 * y).cos(),
        0.5 + 0.45 * (0.23 * y + 0.4).cos() * (0.13 * x).sin(),
        0.5 + 0.45 * ((x + 2.0 * y) * 0.17).sin(),
    ]
}

/// PSNR (peak 1) over the pixels at least `margin` from every edge, against the plain
/// convolution with one kernel per channel.
fn psnr_against_convolution(
    image: &[[f32; 4]],
    color: &[[f32; 4]],
    kernels: &[ocular::render::reference::Kernel; 3],
    margin: usize,
) -> f64 {
    let (mut se, mut n) = (0.0f64, 0usize);
    for y in margin..H - margin {
        for x in margin..W - margin {
            for (c, k) in kernels.iter().enumerate() {
                let r = k.radius as i64;
                let mut v = 0.0f64;
                for dy in -r..=r {
                    for dx in -r..=r {
                        // light from source (x − dx, y − dy) reaches (x, y) with weight k(dx, dy)
                        let (sx, sy) = ((x as i64 - dx) as usize, (y as i64 - dy) as usize);
                        v += f64::from(k.at(dx, dy)) * f64::from(color[sy * W + sx][c]);
                    }
                }
                se += (f64::from(image[y * W + x][c]) - v).powi(2);
                n += 1;
            }
        }
    }
    10.0 * (n as f64 / se).log10()
}

#[test]
fn a_plane_through_the_four_eyes_is_its_convolution() {
    let ctx = common::gpu();
    let color: Vec<[f32; 4]> = (0..W * H)
        .map(|i| {
            let c = texture(i % W, i / W);
            [c[0], c[1], c[2], 1.0]
        })
        .collect();
    let options = KernelOptions {
        cache_dir: None,
        progress: None,
        ..KernelOptions::default()
    };
    let state = EyeState {
        focus_d: 0.0,
        pupil_mm: 4.0,
    };
    let screen = Screen {
        fov_y_deg: FOV_Y_DEG,
        height_px: H as u32,
    };
    eprintln!("eye          plane   Rmax  splat dB   reference dB");
    for name in ["healthy", "myopia", "astigmatism", "keratoconus"] {
        for distance_m in [0.5f32, 1.0] {
            let depth = vec![distance_m; W * H];
            let input = FrameInput {
                width: W as u32,
                height: H as u32,
                color: &color,
                depth_m: &depth,
                fov_y_deg: FOV_Y_DEG,
                hidden_layers: &[],
                mixed: None,
            };
            let eye = resolve(name).unwrap().eye;
            let range = dioptre_range(&depth, W as u32, H as u32, FOV_Y_DEG);
            let kernels =
                prepare_kernels(&eye, &scene_needs(&[range], &[state], screen), &options).unwrap();
            let max_radius = kernels.grid.max_radius_px;
            let exact = ExactEye::new(
                &eye,
                state.pupil_mm,
                state.focus_d,
                kernels.grid.wavelengths_nm,
                screen,
                options.settings.clone(),
                max_radius,
            )
            .unwrap();
            let mut renderer = frame_renderer(&ctx, eye, kernels, &options);
            // The plane's vergence at the frame's centre, in the ground truth's bins.
            let d = (1.0 / f64::from(distance_m) / DIOPTRE_BIN_D).round() * DIOPTRE_BIN_D;
            let k = [0, 1, 2].map(|c| exact.kernel(c, d));
            let margin = k.iter().map(|k| k.radius as usize).max().unwrap() + 1;
            let (splat, truth) = splat_and_truth(&mut renderer, &input, state);
            let db_splat = psnr_against_convolution(&splat, &color, &k, margin);
            let db_truth = psnr_against_convolution(&truth, &color, &k, margin);
            eprintln!(
                "{name:<12} {distance_m:>4.1} m {max_radius:>4} px  {db_splat:>8.1}  {db_truth:>12.1}"
            );
            assert!(
                db_truth >= 60.0,
                "{name} at {distance_m} m: reference {db_truth:.1} dB"
            );
            // Measured 67.4–73.4 dB. Merging with the colour bound at 1/1020 of white (the
            // previous default in display units) scores 55.7–73.6 and fails it: a texture whose
            // period is near the block side adds the blocks' errors along the kernel's rim.
            assert!(
                db_splat >= 62.0,
                "{name} at {distance_m} m: splat {db_splat:.1} dB"
            );
        }
    }
    common::finish(ctx);
}
