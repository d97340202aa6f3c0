//! A depth-peeled scene stays on the GPU: every layer is drawn inside splat's own submission
//! (the peel reading the previous layer's depth, which splat's input pass wrote) and taken into
//! splat's stacked inputs with the host's post-processing done there. The image must equal the
//! old round trip (each layer drawn in its own submission, read back, post-processed on the
//! host, the previous depth uploaded for the next peel, the frames uploaded to splat), and a
//! steady frame must be one submission with no allocation and no pixel uploaded.

use crate::common;

use common::pixels::{hidden_layers, max_rgb_difference};
use common::synthetic::SyntheticEye;
use ocular::psf::{DioptreAxis, KernelGrid};
use ocular::render::splat::{FrameInput, SplatOutput, SplatSettings, Splatter, ViewState};
use ocular::render::{BlendSettings, Frame, Rasterizer};
use ocular::scene::{FrameState, Scene};

const W: u32 = 160;
const H: u32 = 90;
const LAYERS: u32 = 2;

/// Kernels for the primitives scene at 160×90: a synthetic eye focused at 1 D over 0–5 D.
fn grid() -> KernelGrid {
    SyntheticEye::new(1.0, 3.0).grid(DioptreAxis::spanning(0.0, 5.0, 11), 20, &[3.0], H)
}

fn view() -> ViewState {
    ViewState {
        pupil_mm: 3.0,
        focus_d: 1.0,
    }
}

fn gap_d() -> f32 {
    BlendSettings::default().group_tolerance_d
}

/// The peeled layers as the host path makes them (`render_layers`).
fn host_layers(
    ctx: &ocular::gpu::Context,
    raster: &mut Rasterizer,
    state: &FrameState<'_>,
) -> Vec<Frame> {
    raster
        .render_layers(ctx, state, (W, H), LAYERS, gap_d())
        .unwrap()
}

/// Splats `visible` with `hidden` behind it, uploaded from the host.
fn splat_host(
    splatter: &mut Splatter,
    state: &FrameState<'_>,
    visible: &Frame,
    hidden: &[&Frame],
) -> SplatOutput {
    let hidden = hidden_layers(hidden.iter().copied());
    let input = FrameInput {
        width: W,
        height: H,
        color: &visible.color,
        depth_m: &visible.depth_m,
        fov_y_deg: state.camera.fov_y_deg,
        hidden_layers: &hidden,
        mixed: None,
    };
    splatter.render(&input, view(), false).unwrap()
}

fn splat_on_gpu(
    ctx: &ocular::gpu::Context,
    raster: &mut Rasterizer,
    splatter: &mut Splatter,
    state: &FrameState<'_>,
) -> SplatOutput {
    let mut frame = raster
        .scene_frame(ctx, state, (W, H))
        .peeled(LAYERS, gap_d());
    splatter.render_recorded(&mut frame, view()).unwrap()
}

/// The 2-layer frame peeled on the GPU gives the same image as the layers read back,
/// post-processed on the host and uploaded (the same draws and the same f32 arithmetic — one
/// division by the coverage per channel, the same comparisons — so the bar is exact
/// equality), for two views through one splatter (a stale layer would fail the second). The
/// negative controls show the bar would see a wrong stack: without the hidden layer, or with
/// the two layers swapped, the image changes.
#[test]
fn a_peeled_scene_on_the_gpu_matches_the_host_round_trip() {
    let ctx = common::gpu();
    let scene = Scene::load("primitives").unwrap();
    let first = scene.at_time(0.0);
    let mut moved = scene.at_time(0.0);
    moved.camera.position_m[0] += 0.3;
    let mut raster = Rasterizer::new(&ctx).unwrap();
    let mut on_gpu = Splatter::new(&ctx, grid(), SplatSettings::default()).unwrap();
    let mut via_host = Splatter::new(&ctx, grid(), SplatSettings::default()).unwrap();
    let mut previous: Option<Vec<[f32; 4]>> = None;
    for state in [&first, &moved] {
        let layers = host_layers(&ctx, &mut raster, state);
        let covered = layers[1].depth_m.iter().filter(|d| d.is_finite()).count();
        eprintln!("layer 1 covers {covered} of {} pixels", W * H);
        assert!(covered > 100, "the hidden layer is (nearly) empty: no test");
        let expected = splat_host(&mut via_host, state, &layers[0], &[&layers[1]]);
        let got = splat_on_gpu(&ctx, &mut raster, &mut on_gpu, state);
        let difference = max_rgb_difference(&got.color, &expected.color);
        eprintln!("largest difference GPU-peeled vs host round trip: {difference:e}");
        assert!(difference == 0.0, "largest difference {difference}");

        // Negative controls, through the host path: a stack the GPU path must not equal.
        let brightest = expected
            .color
            .iter()
            .flat_map(|c| c[..3].iter().copied())
            .fold(0.0f32, f32::max);
        let visible_only = splat_host(&mut via_host, state, &layers[0], &[]);
        let swapped = splat_host(&mut via_host, state, &layers[1], &[&layers[0]]);
        for (control, name) in [
            (&visible_only, "layer 1 missing"),
            (&swapped, "layers swapped"),
        ] {
            let change = max_rgb_difference(&got.color, &control.color);
            eprintln!("{name}: largest difference {change:e} (brightest {brightest:e})");
            assert!(
                change > 1e-3 * brightest,
                "{name} gives the same image: the comparison sees nothing"
            );
        }
        if let Some(previous) = &previous {
            assert_ne!(&got.color, previous, "the moved camera changed nothing");
        }
        previous = Some(got.color);
    }
    drop((on_gpu, via_host, raster));
    common::finish(ctx);
}

/// A steady 2-layer scene frame is one submission from the first draw to the read-back,
/// allocates nothing (the device's own count, rasteriser included), uploads no pixels (the
/// previous layer's depth is written on the GPU) and reads back only the image and two list
/// sizes. The host round trip, as a control, moves every layer both ways.
#[test]
fn a_steady_peeled_frame_is_one_submission_and_moves_no_layer() {
    const UPLOAD_BOUND: u64 = 4096;
    let ctx = common::gpu();
    let scene = Scene::load("primitives").unwrap();
    let state = scene.at_time(0.0);
    let mut raster = Rasterizer::new(&ctx).unwrap();
    let mut splatter = Splatter::new(&ctx, grid(), SplatSettings::default()).unwrap();
    let first = splat_on_gpu(&ctx, &mut raster, &mut splatter, &state);
    eprintln!("first peeled frame: {:?}", first.stats);
    let image_bytes = u64::from(W * H) * 16;
    for _ in 0..2 {
        let allocations_before = ctx.allocations();
        let next = splat_on_gpu(&ctx, &mut raster, &mut splatter, &state);
        eprintln!("steady peeled frame: {:?}", next.stats);
        assert_eq!(next.stats.submissions, 1);
        assert_eq!(next.stats.allocations, 0);
        assert_eq!(ctx.allocations(), allocations_before);
        assert_eq!(next.stats.submission_objects, 0);
        // more live fragments than pixels: the hidden layer's are in the stack
        assert!(next.stats.live_fragments > u64::from(W * H));
        assert!(next.stats.upload_bytes <= UPLOAD_BOUND);
        assert_eq!(
            next.stats.readback_bytes,
            image_bytes + 32,
            "image and band header"
        );
        assert_eq!(next.color, first.color);
    }
    // The host round trip: per layer a draw and a read-back, per later layer an upload of the
    // previous depth, then every layer uploaded to splat.
    let mut via_host = Splatter::new(&ctx, grid(), SplatSettings::default()).unwrap();
    for _ in 0..2 {
        let allocations_before = ctx.allocations();
        let layers = host_layers(&ctx, &mut raster, &state);
        let old = splat_host(&mut via_host, &state, &layers[0], &[&layers[1]]);
        let pixels = u64::from(W * H);
        eprintln!(
            "host round trip: splat uploaded {} B; raster read back {} B and uploaded {} B of \
             previous depth; {} allocations in all",
            old.stats.upload_bytes,
            u64::from(LAYERS) * pixels * 20,
            u64::from(LAYERS - 1) * pixels * 4,
            ctx.allocations() - allocations_before
        );
        assert!(old.stats.upload_bytes >= u64::from(LAYERS) * pixels * 20);
    }
    drop((splatter, via_host, raster));
    common::finish(ctx);
}
