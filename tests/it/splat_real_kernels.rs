//! The GPU runtime fed with a real eye's kernels (lavapipe, tiny frame): a layered depth scene
//! rendered by tiled splatting against the ground truth with the exact kernels of the same
//! eye. Depths sit between the grid's object samples, so interpolation over distance and
//! radius is exercised.

use crate::common;
use common::pixels::{opaque_pixels, psnr};

use ocular::eye::Eye;
use ocular::psf::{
    kernels_from_columns, no_progress, plan_for_scene, ColumnOptics, ExactEye, GridAxes,
    KernelSettings, SceneNeeds, Screen,
};
use ocular::render::reference;
use ocular::render::splat::{FrameInput, SplatSettings, Splatter, ViewState};

fn texture(x: u32, y: u32, seed: f32) -> [f32; 3] {
    let (x, y) = (x as f32, y as f32);
    [
        0.5 + 0.45 * (0.21 * x + seed).sin(),
        0.5 + 0.45 * (0.17 * y + 0.5 * seed).cos(),
        0.5 + 0.45 * ((x + y) * 0.09 + 2.0 * seed).sin(),
    ]
}

#[test]
fn real_kernels_splat_like_the_ground_truth() {
    let (w, h) = (120u32, 72u32);
    let (color, depth) = opaque_pixels(w, h, |x, y| {
        if (60..100).contains(&x) && (14..44).contains(&y) {
            (texture(x, y, 2.0), 1.0 / 3.1)
        } else if (15..70).contains(&x) && (30..64).contains(&y) {
            (texture(x, y, 1.0), 1.0 / 1.4)
        } else {
            (texture(x, y, 0.0), 1.0 / 0.45)
        }
    });
    let screen = Screen {
        fov_y_deg: 3.0,
        height_px: h,
    };
    let (pupil_mm, focus_d) = (4.0, 1.4);
    let plan = plan_for_scene(
        &SceneNeeds {
            dioptre_min: 0.45,
            dioptre_max: 3.1,
            focus_d: vec![focus_d],
            pupils_mm: vec![pupil_mm],
            screen,
        },
        &GridAxes::default(),
    )
    .unwrap();
    let settings = KernelSettings::default();
    let column = ColumnOptics::new(
        &Eye::navarro(),
        pupil_mm,
        focus_d,
        plan.axes.wavelengths_nm,
        &settings,
    )
    .unwrap();
    let (grid, report) = kernels_from_columns(
        std::slice::from_ref(&column),
        &plan.axes,
        &screen,
        &settings,
        &no_progress,
    )
    .unwrap();
    assert!(
        (3..=24).contains(&grid.max_radius_px),
        "Rmax {}",
        grid.max_radius_px
    );
    let exact = ExactEye {
        column,
        screen,
        settings,
        max_radius_px: grid.max_radius_px,
    };
    let input = FrameInput {
        width: w,
        height: h,
        color: &color,
        depth_m: &depth,
        fov_y_deg: 3.0,
        hidden_layers: &[],
        mixed: None,
    };
    let truth = reference::render(&input, &exact);
    let ctx = common::gpu();
    let mut splatter = Splatter::new(&ctx, grid, SplatSettings::default()).unwrap();
    let out = splatter
        .render(&input, ViewState { pupil_mm, focus_d }, false)
        .unwrap();
    let db = psnr(&out.color, &truth);
    eprintln!(
        "real kernels (Navarro, {pupil_mm} mm, focus {focus_d} D, Rmax {} px, {} PSFs): \
         splat vs ground truth {db:.2} dB",
        report.max_radius_px, report.psfs_computed
    );
    assert!(db >= 45.0, "{db:.2} dB");
    drop(splatter);
    common::finish(ctx);
}
