//! One frame of `ocular video`: the eye's pupil for it, and its panels, each through its own
//! eye and spectacle. A panel's frame stays on the GPU (drawn in splat's own submission)
//! unless the pupil follows the frame's luminance, which needs its pixels on the host.

use super::video::VideoArgs;
use crate::gpu::Context;
use crate::image_io::ImageRgba;
use crate::render::frame::{EyeState, FrameRenderer, Method};
use crate::render::frame_plan::{self, FrameView, PupilAsked, PupilFallback, PupilModel, SceneEye};
use crate::render::{Frame, Rasterizer};
use crate::scene::FrameState;
use crate::Result;

const IDENTITY: [[f64; 2]; 2] = [[1.0, 0.0], [0.0, 1.0]];

/// The pupil options of a video frame: Watson–Yellott at the scene's luminance, else at the
/// frame's mean luminance, where neither `--pupil-mm` nor the scene gives a pupil.
pub(super) fn pupil_asked(args: &VideoArgs) -> PupilAsked<'static> {
    PupilAsked {
        given_mm: args.pupil_mm,
        luminance_cdm2: None,
        model: PupilModel::WatsonYellott,
        age_years: args.age,
        fallback: PupilFallback::Luminance,
    }
}

/// Whether the pupil follows the frame's own mean luminance.
pub(super) fn pupil_needs_frame(args: &VideoArgs, state: &FrameState<'_>) -> bool {
    frame_plan::pupil_needs_frame(&pupil_asked(args), &SceneEye::of(state))
}

/// The pupil for `state` over a `width`×`height` field of `fov_y_deg`; `frame` is read only
/// where [`pupil_needs_frame`].
pub(super) fn pupil_for(
    args: &VideoArgs,
    state: &FrameState<'_>,
    frame: Option<&Frame>,
    (width, height): (u32, u32),
    fov_y_deg: f64,
) -> Result<f64> {
    let view = FrameView {
        width,
        height,
        fov_y_deg,
        color: frame.map_or(&[][..], |f| &f.color),
        depth_m: &[],
    };
    Ok(frame_plan::pupil_mm(&pupil_asked(args), &SceneEye::of(state), &view)?.0)
}

/// One splatted panel of `state`'s frame per renderer, each seen through its spectacle's
/// magnification (`None`: none).
pub(super) fn render_panels(
    ctx: &Context,
    rasterizer: &mut Rasterizer,
    state: &FrameState<'_>,
    size: (u32, u32),
    (args, focus_d, fov_y_deg): (&VideoArgs, f64, f64),
    renderers: &mut [FrameRenderer],
    magnifications: &[Option<[[f64; 2]; 2]>],
) -> Result<Vec<Vec<[f32; 4]>>> {
    // Read back only where the pupil needs the pixels; then that frame also serves the
    // panels seen without a spectacle, unless they take hidden layers (peeled on the GPU).
    let layers = args.layers.unwrap_or(crate::render::raster::DEFAULT_LAYERS);
    let gap_d = crate::render::splat::SplatSettings::default()
        .blend
        .group_tolerance_d;
    let measured = if pupil_needs_frame(args, state) {
        rasterizer.set_view_magnification(IDENTITY);
        Some(rasterizer.render(ctx, state, size.0, size.1)?)
    } else {
        None
    };
    let eye_state = EyeState {
        focus_d,
        pupil_mm: pupil_for(args, state, measured.as_ref(), size, fov_y_deg)?,
    };
    let mut panels = Vec::new();
    for (renderer, magnification) in renderers.iter_mut().zip(magnifications) {
        let out = match (&measured, magnification) {
            (Some(frame), None) if layers == 1 => {
                let input = frame.input(state.camera.fov_y_deg);
                renderer.render(&input, eye_state, Method::Splat)?
            }
            _ => {
                rasterizer.set_view_magnification(magnification.unwrap_or(IDENTITY));
                let mut frame = rasterizer
                    .scene_frame(ctx, state, size)
                    .peeled(layers, gap_d);
                renderer.render_recorded(&mut frame, eye_state)?
            }
        };
        panels.push(out.color);
    }
    Ok(panels)
}

/// Panels side by side; labels drawn in the top-left corner of each panel.
pub(super) fn compose(
    width: u32,
    height: u32,
    panels: &[Vec<[f32; 4]>],
    labels: Option<&[&str]>,
) -> ImageRgba {
    let n = panels.len() as u32;
    let mut pixels = vec![[0.0f32, 0.0, 0.0, 1.0]; (width * n * height) as usize];
    for (k, panel) in panels.iter().enumerate() {
        for y in 0..height {
            for x in 0..width {
                pixels[(y * width * n + k as u32 * width + x) as usize] =
                    panel[(y * width + x) as usize];
            }
        }
    }
    let mut image = ImageRgba::new(width * n, height, pixels);
    if let Some(labels) = labels {
        for (k, label) in labels.iter().enumerate() {
            crate::psf::preview::draw_label(&mut image, k as u32 * width + 6, 6, label);
        }
    }
    image
}
