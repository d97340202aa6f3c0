//! The runtime as an engine: a steady-state frame is one queue submission with no allocation
//! and reads back only its image and the band table's header (band count, status, list total,
//! live fragments), banded frames included (bands planned on the GPU); a frame whose lists
//! outgrow the buffer falls back to host-planned bands with the same image; the PSF texture is rebuilt only when the
//! eye's state changes; the convolution's early exit changes the image by less than its ε.

use crate::common;

use common::pixels::{max_rgb_difference, opaque_pixels};
use common::synthetic::SyntheticEye;
use ocular::psf::{DioptreAxis, KernelGrid};
use ocular::render::splat::{
    ConvolveWalk, FrameInput, MergeSettings, SplatOutput, SplatSettings, Splatter, ViewState,
};
use ocular::render::{BlendMode, BlendSettings, Rasterizer};
use ocular::scene::{FrameState, Scene};

struct Frame {
    color: Vec<[f32; 4]>,
    depth: Vec<f32>,
}

const W: u32 = 96;
const H: u32 = 64;

impl Frame {
    fn new(f: impl Fn(u32, u32) -> ([f32; 3], f32)) -> Frame {
        let (color, depth) = opaque_pixels(W, H, f);
        Frame { color, depth }
    }

    fn input(&self) -> FrameInput<'_> {
        FrameInput {
            width: W,
            height: H,
            color: &self.color,
            depth_m: &self.depth,
            fov_y_deg: 10.0,
            hidden_layers: &[],
            mixed: None,
        }
    }
}

fn textured(x: u32, y: u32) -> [f32; 3] {
    let (x, y) = (x as f32, y as f32);
    [
        0.5 + 0.4 * (0.3 * x).sin(),
        0.5 + 0.4 * (0.2 * y).cos(),
        0.5 + 0.4 * (0.1 * (x + y)).sin(),
    ]
}

/// Kernels of a synthetic eye focused at `focus_d`, whose blur grows with the pupil.
fn grid_focused(focus_d: f64) -> KernelGrid {
    let mut eye = SyntheticEye::new(focus_d, 3.0);
    eye.pupil_scale = true;
    eye.grid(DioptreAxis::spanning(0.0, 5.0, 11), 20, &[3.0, 5.0], H)
}

fn grid() -> KernelGrid {
    grid_focused(0.5)
}

const VIEW: ViewState = ViewState {
    pupil_mm: 3.0,
    focus_d: 0.5,
};

/// The settings of the tests that size lists: merging of 2×2 blocks only, as the seed paper
/// did, so that the blurred textured frame keeps long lists (the default merges its blocks up
/// to 32×32, as its colours agree within the tolerance of its large blur).
fn list_settings() -> SplatSettings {
    SplatSettings {
        merge: MergeSettings {
            levels: 1,
            blur_per_block: 0.0,
            ..MergeSettings::default()
        },
        ..SplatSettings::default()
    }
}

fn render(splatter: &mut Splatter, frame: &Frame, view: ViewState) -> SplatOutput {
    splatter.render(&frame.input(), view, false).unwrap()
}

#[test]
fn steady_frames_are_one_submission_without_allocations() {
    let ctx = common::gpu();
    let frame = Frame::new(|x, y| {
        let d = if (30..60).contains(&x) && (20..40).contains(&y) {
            0.4
        } else {
            2.0
        };
        (textured(x, y), d)
    });
    let mut splatter = Splatter::new(&ctx, grid(), SplatSettings::default()).unwrap();
    let first = render(&mut splatter, &frame, VIEW);
    let names = |o: &SplatOutput| -> Vec<String> {
        o.timings.passes.iter().map(|p| p.name.clone()).collect()
    };
    eprintln!("first frame: {:?}", first.stats);
    assert_eq!(first.stats.submissions, 2, "planning frame");
    assert!(names(&first).contains(&"psf texture".to_string()));
    for _ in 0..2 {
        let next = render(&mut splatter, &frame, VIEW);
        eprintln!("steady frame: {:?}", next.stats);
        assert_eq!(next.stats.submissions, 1);
        assert_eq!(next.stats.allocations, 0);
        assert_eq!(
            next.stats.submission_objects, 0,
            "a steady frame reuses its command buffer, fence and pools"
        );
        // Barriers only where a command depends on an earlier one: fewer than commands (a
        // barrier after every command, as before, would make them equal).
        assert!(
            next.stats.barriers > 0 && next.stats.barriers < next.stats.commands,
            "{} barriers for {} commands",
            next.stats.barriers,
            next.stats.commands
        );
        let image_bytes = u64::from(W * H) * 16;
        assert_eq!(
            next.stats.readback_bytes,
            image_bytes + 32,
            "image and band header"
        );
        // the pixels, the radii (per object distance two vec4: natural and core radii, and
        // the peak radius), the field table (its header and one node's radii) and the frame's
        // uniforms
        assert!(
            next.stats.upload_bytes
                <= u64::from(W * H) * 20
                    + 3 * 11 * 16
                    + 32
                    + ocular::render::splat::FRAME_UNIFORM_BYTES
        );
        assert!(
            !names(&next).contains(&"psf texture".to_string()),
            "the PSF texture was rebuilt for an unchanged eye state"
        );
        assert_eq!(
            next.color, first.color,
            "steady frames differ from the first"
        );
        assert_eq!(next.stats.list_entries, first.stats.list_entries);
    }
    // A new pupil rebuilds the texture (and changes the image).
    let other = render(
        &mut splatter,
        &frame,
        ViewState {
            pupil_mm: 4.0,
            ..VIEW
        },
    );
    assert!(names(&other).contains(&"psf texture".to_string()));
    assert_ne!(other.color, first.color);
    drop(splatter);
    common::finish(ctx);
}

#[test]
fn a_frame_that_outgrows_the_lists_falls_back_to_bands() {
    let ctx = common::gpu();
    let sharp = Frame::new(|x, y| (textured(x, y), 2.0)); // 0.5 D: near focus, short lists
    let blurred = Frame::new(|x, y| (textured(x, y), 0.2)); // 5 D: long lists
    let mut splatter = Splatter::new(&ctx, grid(), list_settings()).unwrap();
    render(&mut splatter, &sharp, VIEW);
    let steady = render(&mut splatter, &sharp, VIEW);
    assert_eq!(steady.stats.submissions, 1);
    let grown = render(&mut splatter, &blurred, VIEW);
    eprintln!("outgrown frame: {:?}", grown.stats);
    // More than the list buffer's 25 % headroom over the steady frame.
    assert!(4 * grown.stats.list_entries > 5 * steady.stats.list_entries);
    assert_eq!(grown.stats.submissions, 3, "one try, then planned bands");
    let mut fresh = Splatter::new(&ctx, grid(), list_settings()).unwrap();
    let expected = render(&mut fresh, &blurred, VIEW);
    assert_eq!(grown.color, expected.color);
    drop((splatter, fresh));
    common::finish(ctx);
}

/// A frame whose lists need several bands is still one submission once steady: the bands are
/// planned on the GPU from the prefix sum, into as many slots as the last frame needed plus a
/// spare, and the image is the one the host-planned bands and a single band give, to the bit.
/// Lists that outgrow the slots (more bands than recorded) fall back to the host's plan.
#[test]
fn banded_steady_frames_are_one_submission() {
    let ctx = common::gpu();
    let blurred = Frame::new(|x, y| (textured(x, y), 0.2)); // 5 D from focus: long lists
    let sharp = Frame::new(|x, y| (textured(x, y), 2.0)); // 0.5 D: at focus, short lists
    let mut whole = Splatter::new(&ctx, grid(), list_settings()).unwrap();
    let expected = render(&mut whole, &blurred, VIEW);
    assert_eq!(expected.stats.bands, 1);
    let entries = expected.stats.list_entries;
    // A list budget of a quarter of the frame's lists: four or five bands.
    let banded_settings = SplatSettings {
        max_list_bytes: entries * 8 / 4,
        ..list_settings()
    };
    let mut banded = Splatter::new(&ctx, grid(), banded_settings).unwrap();
    let first = render(&mut banded, &blurred, VIEW);
    eprintln!("first banded frame: {:?}", first.stats);
    assert!(first.stats.bands >= 4, "{} bands", first.stats.bands);
    assert_eq!(first.stats.submissions, 2, "planning frame");
    assert_eq!(
        first.color, expected.color,
        "host-planned bands change the image"
    );
    for _ in 0..2 {
        let next = render(&mut banded, &blurred, VIEW);
        eprintln!("steady banded frame: {:?}", next.stats);
        assert_eq!(next.stats.submissions, 1);
        assert_eq!(next.stats.allocations, 0);
        assert_eq!(next.stats.bands, first.stats.bands);
        assert_eq!(next.stats.list_entries, entries);
        let image_bytes = u64::from(W * H) * 16;
        assert_eq!(next.stats.readback_bytes, image_bytes + 32);
        assert_eq!(
            next.color, expected.color,
            "GPU-planned bands change the image"
        );
    }
    // A sharp frame needs fewer bands than the slots: still one submission, and the image of
    // a fresh splatter.
    let short = render(&mut banded, &sharp, VIEW);
    eprintln!("sharp frame: {:?}", short.stats);
    assert_eq!(short.stats.submissions, 1);
    assert!(
        short.stats.bands + 1 < first.stats.bands,
        "{:?}",
        short.stats
    );
    let mut fresh = Splatter::new(&ctx, grid(), list_settings()).unwrap();
    assert_eq!(short.color, render(&mut fresh, &sharp, VIEW).color);
    // Back to the blurred frame: more bands than the sharp frame's slots (its bands and a
    // spare), so the GPU's plan is incomplete and the frame is planned on the host.
    let regrown = render(&mut banded, &blurred, VIEW);
    eprintln!("regrown banded frame: {:?}", regrown.stats);
    assert_eq!(
        regrown.stats.submissions, 3,
        "one try, then host-planned bands"
    );
    assert_eq!(regrown.color, expected.color);
    drop((whole, banded, fresh));
    common::finish(ctx);
}

/// A sharp card in front of a bright, blurred textured wall: tiles inside the card stop once
/// every pixel is covered to 1 − ε. The output C/A moves by at most 2ε/(1 − ε) times the
/// brightest colour behind. With depth groups a closed group covers a card pixel fully, so the
/// exit is exact there; the seed paper's blend approaches full coverage only gradually, so a
/// large ε shows that the exit happens.
#[test]
fn early_exit_changes_the_image_by_less_than_epsilon() {
    let ctx = common::gpu();
    // The eye focuses on the card at 0.25 m (4 D); the wall at infinity blurs by ~12 px.
    // The card is small enough that the wall's light reaches every tile inside it.
    let frame = Frame::new(|x, y| {
        if (36..60).contains(&x) && (24..40).contains(&y) {
            ([0.2, 0.3, 0.4], 0.25)
        } else {
            (textured(x, y).map(|v| 8.0 * v), f32::INFINITY)
        }
    });
    let view = ViewState {
        pupil_mm: 3.0,
        focus_d: 4.0,
    };
    let run = |epsilon: f32, blend: BlendSettings| {
        let settings = SplatSettings {
            saturation_epsilon: epsilon,
            blend,
            merge: MergeSettings {
                levels: 0,
                ..MergeSettings::default()
            },
            ..SplatSettings::default()
        };
        let mut splatter = Splatter::new(&ctx, grid_focused(4.0), settings).unwrap();
        render(&mut splatter, &frame, view).color
    };
    let brightest = 8.0 * 0.9;
    for (blend, name) in [
        (BlendSettings::default(), "depth groups"),
        (BlendSettings::paper(), "the paper's blend"),
    ] {
        let exact = run(0.0, blend);
        for epsilon in [1e-3f32, 0.3] {
            let change = max_rgb_difference(&exact, &run(epsilon, blend));
            let bound = 2.0 * epsilon / (1.0 - epsilon) * brightest;
            eprintln!("{name}, ε = {epsilon}: worst change {change:.2e} (bound {bound:.2e})");
            assert!(change <= bound, "{name}, ε = {epsilon}: {change}");
            if blend.mode == BlendMode::PerFragment && epsilon > 0.1 {
                assert!(change > 0.0, "the early exit never triggered");
            }
        }
    }
    common::finish(ctx);
}

/// The same synthetic eye on an object axis fine enough for the layer kernels: 1/32 D, where
/// neighbouring distances' radii differ by at most a quarter pixel.
fn grid_fine(focus_d: f64) -> KernelGrid {
    let mut eye = SyntheticEye::new(focus_d, 3.0);
    eye.pupil_scale = true;
    eye.grid(DioptreAxis::spanning(0.0, 5.0, 161), 20, &[3.0, 5.0], H)
}

/// A near card over a blurred textured wall, both in the grid's range.
fn card_frame() -> Frame {
    Frame::new(|x, y| {
        if (30..60).contains(&x) && (20..40).contains(&y) {
            ([0.9, 0.3, 0.1], 0.3)
        } else {
            (textured(x, y).map(|v| 4.0 * v), 1.5)
        }
    })
}

/// The convolution's two walks (pixels, for GPUs; visits, for CPU implementations) render the
/// same image: depth groups and the paper's blend, merged blocks, a chromatic eye whose
/// channels fall on different radius levels (so some fragments take several slots), and a
/// near card over a blurred textured wall; both with the radius levels (a coarse object axis)
/// and with the layer kernels (a fine one). Equal up to the order of float additions.
#[test]
fn convolve_walks_agree() {
    let ctx = common::gpu();
    let frame = card_frame();
    let run = |walk: ConvolveWalk, blend: BlendSettings, grid: &KernelGrid, layered: bool| {
        let settings = SplatSettings {
            blend,
            convolve_walk: walk,
            ..SplatSettings::default()
        };
        let mut splatter = Splatter::new(&ctx, grid.clone(), settings).unwrap();
        let out = render(&mut splatter, &frame, VIEW);
        assert_eq!(out.stats.layer_kernels, layered, "{walk:?}");
        out.color
    };
    let coarse = grid_focused(2.0);
    let fine = grid_fine(2.0);
    for (blend, grid, layered, name) in [
        (BlendSettings::default(), &coarse, false, "depth groups"),
        (BlendSettings::paper(), &coarse, false, "the paper's blend"),
        (
            BlendSettings::default(),
            &fine,
            true,
            "depth groups, layer kernels",
        ),
        (
            BlendSettings::paper(),
            &fine,
            true,
            "the paper's blend, layer kernels",
        ),
    ] {
        let pixels = run(ConvolveWalk::Pixels, blend, grid, layered);
        let visits = run(ConvolveWalk::Visits, blend, grid, layered);
        let worst = max_rgb_difference(&pixels, &visits);
        eprintln!("{name}: worst difference between the walks {worst:.2e}");
        assert!(worst <= 1e-5 * 4.0, "{name}: the walks differ by {worst}");
        let mean: f32 = pixels.iter().map(|p| p[1]).sum::<f32>() / pixels.len() as f32;
        assert!(mean > 0.1, "{name}: an empty image ({mean}) proves nothing");
    }
    common::finish(ctx);
}

/// The layer kernels (each object distance's own kernel, one read) against the radius levels
/// they are built from (up to three reads, mixed at each fragment's radius): on a fine object
/// axis the two differ only where a fragment lies between two distances, by the blend of two
/// kernels a fraction of a pixel apart in radius.
#[test]
fn layer_kernels_match_the_radius_levels() {
    let ctx = common::gpu();
    let frame = card_frame();
    let run = |layer_kernels: bool| {
        let settings = SplatSettings {
            layer_kernels,
            ..SplatSettings::default()
        };
        let mut splatter = Splatter::new(&ctx, grid_fine(2.0), settings).unwrap();
        let out = render(&mut splatter, &frame, VIEW);
        assert_eq!(out.stats.layer_kernels, layer_kernels);
        out.color
    };
    let (layers, levels) = (run(true), run(false));
    let peak = 4.0f64;
    let db_of = |image: &[[f32; 4]]| {
        let mse = image
            .iter()
            .zip(&levels)
            .flat_map(|(a, b)| (0..3).map(move |c| (f64::from(a[c]) - f64::from(b[c])).powi(2)))
            .sum::<f64>()
            / (3 * image.len()) as f64;
        10.0 * (peak * peak / mse).log10()
    };
    let db = db_of(&layers);
    // Negative control: the unblurred input, in the layer kernels' place.
    let sharp = db_of(&frame.color);
    eprintln!(
        "layer kernels against the radius levels: {db:.2} dB (peak {peak}); the unblurred input \
         {sharp:.2} dB"
    );
    assert!(db > LAYERS_AGAINST_LEVELS_DB, "{db} dB");
    assert!(
        sharp < LAYERS_AGAINST_LEVELS_DB,
        "the control passed: {sharp} dB"
    );
    common::finish(ctx);
}

/// Measured on lavapipe: 88.58 dB.
const LAYERS_AGAINST_LEVELS_DB: f64 = 85.0;

const SCENE_W: u32 = 160;
const SCENE_H: u32 = 90;

/// Kernels for the primitives scene at 160×90: a synthetic eye focused at 1 D over 0–5 D.
fn scene_grid() -> KernelGrid {
    SyntheticEye::new(1.0, 3.0).grid(DioptreAxis::spanning(0.0, 5.0, 11), 20, &[3.0], SCENE_H)
}

fn scene_view() -> ViewState {
    ViewState {
        pupil_mm: 3.0,
        focus_d: 1.0,
    }
}

/// Splats a rasterised frame the old way: read back to the host, then uploaded.
fn splat_through_host(
    ctx: &ocular::gpu::Context,
    raster: &mut Rasterizer,
    splatter: &mut Splatter,
    state: &FrameState<'_>,
) -> SplatOutput {
    let frame = raster.render(ctx, state, SCENE_W, SCENE_H).unwrap();
    let input = FrameInput {
        width: SCENE_W,
        height: SCENE_H,
        color: &frame.color,
        depth_m: &frame.depth_m,
        fov_y_deg: state.camera.fov_y_deg,
        hidden_layers: &[],
        mixed: None,
    };
    splatter.render(&input, scene_view(), false).unwrap()
}

/// The rasterised frame stays on the GPU: drawn in splat's own submission and taken into its
/// inputs there, it gives the same image as the frame read back and uploaded (the colour and
/// depth are the same 32-bit floats either way, so the bar is exact equality), for two
/// different views through one splatter (a stale input would fail the second).
#[test]
fn a_scene_frame_on_the_gpu_matches_the_host_round_trip() {
    let ctx = common::gpu();
    let scene = Scene::load("primitives").unwrap();
    let first = scene.at_time(0.0);
    let mut moved = scene.at_time(0.0);
    moved.camera.position_m[0] += 0.3;
    let mut raster = Rasterizer::new(&ctx).unwrap();
    let mut on_gpu = Splatter::new(&ctx, scene_grid(), SplatSettings::default()).unwrap();
    let mut via_host = Splatter::new(&ctx, scene_grid(), SplatSettings::default()).unwrap();
    let mut previous: Option<Vec<[f32; 4]>> = None;
    for state in [&first, &moved] {
        let expected = splat_through_host(&ctx, &mut raster, &mut via_host, state);
        let got = on_gpu
            .render_recorded(
                &mut raster.scene_frame(&ctx, state, (SCENE_W, SCENE_H)),
                scene_view(),
            )
            .unwrap();
        let worst = max_rgb_difference(&got.color, &expected.color);
        eprintln!("largest difference GPU-resident vs host round trip: {worst:e}");
        assert_eq!(got.color.len(), expected.color.len());
        assert!(worst == 0.0, "largest difference {worst}");
        if let Some(previous) = &previous {
            assert_ne!(&got.color, previous, "the moved camera changed nothing");
        }
        previous = Some(got.color);
    }
    drop((on_gpu, via_host, raster));
    common::finish(ctx);
}

/// A steady-state scene frame is one submission from the draw to the read-back, allocates
/// nothing (rasteriser included: the device's own count), sends the device only its uniforms
/// and radii, and reads back only the image and two list sizes. The host round trip, as a
/// negative control, uploads the whole frame.
#[test]
fn a_steady_scene_frame_is_one_submission_and_uploads_no_pixels() {
    const UPLOAD_BOUND: u64 = 4096;
    let ctx = common::gpu();
    let scene = Scene::load("primitives").unwrap();
    let state = scene.at_time(0.0);
    let mut raster = Rasterizer::new(&ctx).unwrap();
    let mut splatter = Splatter::new(&ctx, scene_grid(), SplatSettings::default()).unwrap();
    let mut frame = || {
        splatter
            .render_recorded(
                &mut raster.scene_frame(&ctx, &state, (SCENE_W, SCENE_H)),
                scene_view(),
            )
            .unwrap()
    };
    let first = frame();
    eprintln!("first scene frame: {:?}", first.stats);
    assert!(
        first.stats.allocations > 0,
        "the first frame made its targets"
    );
    for _ in 0..2 {
        let allocations_before = ctx.allocations();
        let next = frame();
        eprintln!("steady scene frame: {:?}", next.stats);
        assert_eq!(next.stats.submissions, 1);
        assert_eq!(next.stats.allocations, 0);
        assert_eq!(ctx.allocations(), allocations_before);
        assert_eq!(next.stats.submission_objects, 0);
        assert!(next.stats.upload_bytes <= UPLOAD_BOUND);
        let image_bytes = u64::from(SCENE_W * SCENE_H) * 16;
        assert_eq!(
            next.stats.readback_bytes,
            image_bytes + 32,
            "image and band header"
        );
        let passes: Vec<&str> = next
            .timings
            .passes
            .iter()
            .map(|p| p.name.as_str())
            .collect();
        assert!(
            passes.contains(&"raster") && passes.contains(&"convolve"),
            "{passes:?}"
        );
        assert_eq!(next.color, first.color);
    }
    let mut via_host = Splatter::new(&ctx, scene_grid(), SplatSettings::default()).unwrap();
    splat_through_host(&ctx, &mut raster, &mut via_host, &state);
    let old = splat_through_host(&ctx, &mut raster, &mut via_host, &state);
    eprintln!("steady host round-trip frame: {:?}", old.stats);
    assert_eq!(old.stats.submissions, 1, "plus the raster's own submission");
    assert!(old.stats.upload_bytes > UPLOAD_BOUND);
    drop((splatter, via_host, raster));
    common::finish(ctx);
}
