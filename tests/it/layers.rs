//! Layered inputs: depth peeling in the rasteriser, and splat over several layers. A blurred
//! near card over a textured far wall shows the wall's texture through its blurred edge with
//! two layers and not with one; a hidden layer that is empty changes nothing; what a floor
//! buries stays hidden.

use crate::common;

use std::path::Path;

use common::pixels::{hidden_layers, max_rgb_difference};
use common::synthetic::SyntheticEye;
use ocular::psf::DioptreAxis;
use ocular::render::splat::{FrameInput, SplatSettings, Splatter, ViewState};
use ocular::render::{Frame, Rasterizer, DEFAULT_GROUP_TOLERANCE_D};
use ocular::scene::Scene;

const W: u32 = 160;
const H: u32 = 90;
const FOV: f64 = 20.0;
const WALL_M: f64 = 2.0;
const CARD_M: f64 = 0.25;
/// Blur of the synthetic eye: pixels of radius per dioptre of defocus.
const PX_PER_D: f64 = 3.0;

fn focal_px() -> f64 {
    0.5 * f64::from(H) / (FOV.to_radians() / 2.0).tan()
}

/// The pupil whose geometric blur is PX_PER_D at this focal length (radius × focal length):
/// the parallax that decides what a hidden point shows through must match the kernels.
fn pupil_mm() -> f64 {
    2000.0 * PX_PER_D / focal_px()
}

/// The grey self-lit card at 0.25 m whose right edge is the frame's centre column.
fn card_object() -> String {
    format!(
        "\n[[object]]\nkind = \"plane\"\nsize_m = 1.0\ntranslate = [-0.5, 0.0, {}]\n\
         color = [0.0, 0.0, 0.0]\nemission_cd_m2 = 40.0\n",
        -CARD_M
    )
}

/// A self-lit checkerboard wall (squares of 5 px) at 2 m, optionally a grey self-lit card at
/// 0.25 m whose right edge is the frame's centre column, and a sphere in front of the wall.
fn scene(card: bool, sphere: bool) -> Scene {
    let mut text = format!(
        "[camera]\nposition = [0.0, 0.0, 0.0]\nfov_y_deg = {FOV}\nfar_m = 100.0\n\n\
         [[object]]\nkind = \"plane\"\nsize_m = 3.0\ntranslate = [0.0, 0.0, {}]\n\
         color = [0.0, 0.0, 0.0]\nemission_cd_m2 = 10.0\n",
        -WALL_M
    );
    let square_m = 5.0 * WALL_M / focal_px();
    for i in -20i32..20 {
        for j in -12i32..12 {
            if (i + j).rem_euclid(2) == 0 {
                text += &format!(
                    "\n[[object]]\nkind = \"plane\"\nsize_m = {square_m}\n\
                     translate = [{}, {}, {}]\ncolor = [0.0, 0.0, 0.0]\nemission_cd_m2 = 100.0\n",
                    (f64::from(i) + 0.5) * square_m,
                    (f64::from(j) + 0.5) * square_m,
                    -WALL_M + 0.001
                );
            }
        }
    }
    if card {
        text += &card_object();
    }
    if sphere {
        text += "\n[[object]]\nkind = \"sphere\"\nradius_m = 0.1\ntranslate = [0.2, 0.0, -1.0]\n\
                 color = [0.0, 0.0, 0.0]\nemission_cd_m2 = 60.0\n";
    }
    Scene::from_toml(&text, "test scene", Path::new(".")).unwrap()
}

fn layers(scene: &Scene, k: u32) -> Vec<Frame> {
    let ctx = common::gpu();
    let mut raster = Rasterizer::new(&ctx).unwrap();
    let frames = raster
        .render_layers(
            &ctx,
            &scene.at_time(0.0),
            (W, H),
            k,
            DEFAULT_GROUP_TOLERANCE_D,
        )
        .unwrap();
    drop(raster);
    common::finish(ctx);
    frames
}

fn splat(frames: &[Frame]) -> Vec<[f32; 4]> {
    // focused on the wall (0.5 D), 3 px of blur per dioptre: the card blurs by 10.5 px
    splat_focused(frames, 1.0 / WALL_M, true)
}

/// Splat through the synthetic eye focused at `focus_d`, hidden light judged by the pupil's
/// view past the nearer surfaces or (control) wherever nearer groups leave coverage.
fn splat_focused(frames: &[Frame], focus_d: f64, pupil_visibility: bool) -> Vec<[f32; 4]> {
    let ctx = common::gpu();
    let eye = SyntheticEye::new(focus_d, PX_PER_D);
    let grid = eye.grid(
        DioptreAxis::spanning(0.125, 5.125, 41),
        16,
        &[pupil_mm()],
        H,
    );
    let settings = SplatSettings {
        pupil_visibility,
        ..SplatSettings::default()
    };
    let mut splatter = Splatter::new(&ctx, grid, settings).unwrap();
    let hidden = hidden_layers(&frames[1..]);
    let input = FrameInput {
        width: W,
        height: H,
        color: &frames[0].color,
        depth_m: &frames[0].depth_m,
        fov_y_deg: FOV,
        hidden_layers: &hidden,
        mixed: None,
    };
    let view = ViewState {
        pupil_mm: pupil_mm(),
        focus_d,
    };
    let out = splatter.render(&input, view, false).unwrap().color;
    drop(splatter);
    common::finish(ctx);
    out
}

/// Mean over `columns` of the standard deviation of green down rows 20..70.
fn contrast(image: &[[f32; 4]], columns: std::ops::Range<usize>) -> f64 {
    let n = columns.len() as f64;
    columns
        .map(|x| {
            let v: Vec<f64> = (20..70)
                .map(|y| f64::from(image[y * W as usize + x][1]))
                .collect();
            let mean = v.iter().sum::<f64>() / v.len() as f64;
            (v.iter().map(|a| (a - mean).powi(2)).sum::<f64>() / v.len() as f64).sqrt()
        })
        .sum::<f64>()
        / n
}

#[test]
fn peeling_finds_the_wall_behind_the_card_and_the_sphere() {
    let frames = layers(&scene(true, true), 2);
    let (l0, l1) = (&frames[0], &frames[1]);
    let at = |x: usize, y: usize| y * W as usize + x;
    // behind the card (left half): the wall; the card itself is layer 0
    for x in [10usize, 40, 70] {
        assert!((l0.depth_m[at(x, 45)] - CARD_M as f32).abs() < 1e-3);
        let d = l1.depth_m[at(x, 45)];
        assert!((d - WALL_M as f32).abs() < 2e-3, "x {x}: layer 1 depth {d}");
    }
    // the sphere's centre pixel: its own back is skipped, the wall is next
    let sx = (0.5 * f64::from(W) + focal_px() * 0.2) as usize;
    assert!((l0.depth_m[at(sx, 45)] - 0.9).abs() < 0.01);
    let d = l1.depth_m[at(sx, 45)];
    assert!((d - WALL_M as f32).abs() < 2e-3, "behind the sphere: {d}");
    // where the wall is visible there is nothing behind it (its squares are one surface)
    let held = (0..H as usize)
        .flat_map(|y| (100..W as usize).map(move |x| (x, y)))
        .filter(|&(x, _)| (x as i64 - sx as i64).abs() > 30)
        .find(|&(x, y)| !(l1.depth_m[at(x, y)].is_infinite() && l1.color[at(x, y)][1] == 0.0));
    if let Some((x, y)) = held {
        panic!(
            "layer 1 holds depth {} behind the bare wall at ({x}, {y}), layer 0 {}",
            l1.depth_m[at(x, y)],
            l0.depth_m[at(x, y)]
        );
    }
}

#[test]
fn the_wall_shows_through_the_cards_blurred_edge_with_two_layers_only() {
    let frames = layers(&scene(true, false), 2);
    let one = splat(&frames[..1]);
    let two = splat(&frames);
    let centre = W as usize / 2;
    // the card side of its edge, within its 10.5 px blur radius
    let band = centre - 7..centre - 1;
    let visible = contrast(&one, centre + 12..centre + 30);
    let (c1, c2) = (contrast(&one, band.clone()), contrast(&two, band));
    eprintln!(
        "wall contrast: visible {visible:.3}; through the card's edge: 1 layer {c1:.4}, 2 layers {c2:.4}"
    );
    assert!(c2 > 0.15 * visible, "two layers: {c2} against {visible}");
    // One layer cannot know the wall behind the card: it fills the card's edge with the mean
    // of the wall beside it (render::blend::background_behind), whose texture is the
    // neighbours', not the hidden wall's (measured: 4.9 % of the visible contrast against the
    // two layers' 19.5 %).
    assert!(c1 < 0.5 * c2, "one layer: {c1} against two layers' {c2}");
    // away from the edge both agree: the hidden layer only shows where the card leaves coverage
    // (the frame's own left border, with nothing beyond it, is left out)
    let far = contrast(&two, 25..60) - contrast(&one, 25..60);
    assert!(far.abs() < 0.01 * visible, "inside the card: {far}");
}

#[test]
fn an_empty_hidden_layer_changes_nothing() {
    // the card over the wall, the wall's part behind the card unknown (one layer)
    let visible = layers(&scene(true, false), 1).remove(0);
    let mut empty = visible.clone();
    empty.color.iter_mut().for_each(|c| *c = [0.0; 4]);
    empty.depth_m.iter_mut().for_each(|d| *d = f32::INFINITY);
    let one = splat(std::slice::from_ref(&visible));
    let two = splat(&[visible.clone(), empty.clone()]);
    let peak = one.iter().map(|p| p[1]).fold(0.0f32, f32::max);
    let worst = max_rgb_difference(&one, &two);
    eprintln!("empty hidden layer: largest change {worst:e} of a peak {peak}");
    assert!(worst <= 1e-6 * peak);
    // Negative control: the empty pixels taken as black surfaces far away (not skipped)
    // darken the card's blurred edge.
    let mut black = empty;
    black.depth_m.iter_mut().for_each(|d| *d = 1e6);
    let darkened = max_rgb_difference(&one, &splat(&[visible, black]));
    eprintln!("black far layer: largest change {darkened:e}");
    assert!(
        darkened > 0.05 * peak,
        "a black far layer changed {darkened}"
    );
}

/// A self-lit floor seen from 1 m up, looking at its point 8 m ahead, and a bright post
/// standing at 8 m whose lower half is buried under the floor (as the colonnade's columns
/// are): the buried half is the second layer below the post's foot.
fn buried_post_scene() -> Scene {
    let text = format!(
        "[camera]\nposition = [0.0, 1.0, 0.0]\nlook_at = [0.0, 0.0, -8.0]\nfov_y_deg = {FOV}\n\
         far_m = 100.0\n\n\
         [[object]]\nkind = \"plane\"\nsize_m = [20.0, 80.0]\ntranslate = [0.0, 0.0, -40.0]\n\
         rotate_deg = [-90.0, 0.0, 0.0]\ncolor = [0.0, 0.0, 0.0]\nemission_cd_m2 = 10.0\n\n\
         [[object]]\nkind = \"cube\"\nsize_m = [0.3, 3.0, 0.3]\ntranslate = [0.0, 0.0, -8.0]\n\
         color = [0.0, 0.0, 0.0]\nemission_cd_m2 = 100.0\n"
    );
    Scene::from_toml(&text, "buried post", Path::new(".")).unwrap()
}

#[test]
fn what_the_floor_buries_stays_hidden() {
    let frames = layers(&buried_post_scene(), 2);
    let at = |x: usize, y: usize| y * W as usize + x;
    let (cx, foot) = (W as usize / 2, H as usize / 2);
    // the peel found the buried half under the floor in front of the post's foot
    let buried = (foot + 4..H as usize - 2)
        .filter(|&y| frames[1].color[at(cx, y)][1] > 50.0)
        .count();
    assert!(buried > 20, "buried rows in layer 1: {buried}");
    // focused at 0.5 m: floor and post blur by about 5.6 px
    let one = splat_focused(&frames[..1], 2.0, true);
    let two = splat_focused(&frames, 2.0, true);
    let control = splat_focused(&frames, 2.0, false);
    // the floor in front of the foot, past the post's blur, away from the frame's border
    let rows = foot + 10..H as usize - 10;
    let cols = cx - 12..cx + 12;
    let floor = one[at(cx, H as usize - 12)][1];
    let change = |img: &[[f32; 4]]| {
        rows.clone()
            .flat_map(|y| cols.clone().map(move |x| (x, y)))
            .map(|(x, y)| (img[at(x, y)][1] - one[at(x, y)][1]).abs())
            .fold(0.0f32, f32::max)
    };
    let (hidden, leaked) = (change(&two), change(&control));
    eprintln!(
        "floor {floor:.2}: two layers change it by at most {hidden:.3}; without the pupil test by {leaked:.3}"
    );
    assert!(
        hidden < 0.01 * floor,
        "two layers: {hidden} on a floor of {floor}"
    );
    // Negative control: the buried half shows through the floor when hidden light fills
    // whatever coverage nearer groups leave.
    assert!(
        leaked > 0.05 * floor,
        "control: {leaked} on a floor of {floor}"
    );
}

/// A black wall at 2 m with a bright vertical stripe on it just behind the right edge of a
/// card at 0.25 m (`card`: whether the card is there).
fn stripe_scene(card: bool) -> Scene {
    let px_m = WALL_M / focal_px();
    let mut text = format!(
        "[camera]\nposition = [0.0, 0.0, 0.0]\nfov_y_deg = {FOV}\nfar_m = 100.0\n\n\
         [[object]]\nkind = \"plane\"\nsize_m = 3.0\ntranslate = [0.0, 0.0, {}]\n\
         color = [0.0, 0.0, 0.0]\n\n\
         [[object]]\nkind = \"plane\"\nsize_m = [{}, 2.0]\ntranslate = [{}, 0.0, {}]\n\
         color = [0.0, 0.0, 0.0]\nemission_cd_m2 = 100.0\n",
        -WALL_M,
        2.0 * px_m,
        -3.0 * px_m,
        -WALL_M + 0.001
    );
    if card {
        text += &card_object();
    }
    Scene::from_toml(&text, "stripe behind a card", Path::new(".")).unwrap()
}

#[test]
fn a_blurred_hidden_stripe_lands_outside_a_sharp_cards_edge() {
    // Focused on the card: the wall blurs by 10.5 px. A ray from the stripe (2–4 px behind
    // the card's edge) to the pupil misses the card exactly when it lands outside the card's
    // sharp edge (the parallax and the blur share the scale a·f), so beyond the edge the eye
    // sees what it would see with no card at all. (A point farther than the focus lands on
    // the side of its pupil point, so the rays that pass the edge are those that land past
    // it; with the orientation mirrored this light would fall under the card instead.)
    let focus_d = 1.0 / CARD_M;
    let bare = splat_focused(&layers(&stripe_scene(false), 1), focus_d, true);
    let frames = layers(&stripe_scene(true), 2);
    let one = splat_focused(&frames[..1], focus_d, true);
    let two = splat_focused(&frames, focus_d, true);
    let edge = W as usize / 2;
    let light = |img: &[[f32; 4]]| -> f64 {
        (20..70)
            .flat_map(|y| (edge + 1..edge + 11).map(move |x| (x, y)))
            .map(|(x, y)| f64::from(img[y * W as usize + x][1]))
            .sum()
    };
    let (l_bare, l_one, l_two) = (light(&bare), light(&one), light(&two));
    eprintln!(
        "stripe light past the card's edge: no card {l_bare:.1}, one layer {l_one:.1}, two layers {l_two:.1}"
    );
    assert!(
        l_bare > 100.0,
        "the stripe's blur reaches past the edge: {l_bare}"
    );
    assert!(
        (l_two - l_bare).abs() < 0.2 * l_bare,
        "two layers: {l_two} against {l_bare} with no card"
    );
    // Negative control: one layer knows nothing of the stripe.
    assert!(l_one < 0.02 * l_bare, "one layer: {l_one}");
}
