//! An animation frame by frame (`ocular video`): the scene's state and the eye's focus at frame
//! `i`, each from its own index only, so that any split of the frames renders the same
//! images; and the kernels the whole animation needs, planned from sampled frames.

use crate::gpu::Context;
use crate::psf::axes::Screen;
use crate::psf::plan::SceneNeeds;
use crate::render::frame::{dioptre_range, scene_needs, EyeState};
use crate::render::frame_plan::{self, FrameView, PupilAsked, SceneEye};
use crate::render::Rasterizer;
use crate::scene::{FrameState, Scene};
use crate::Result;

/// Everything that fixes frame `i`: the scene state and the eye state.
pub struct Timeline {
    pub scene: Scene,
    pub fps: f64,
    pub count: usize,
    /// A focus sweep from near to far (m) over a still scene, linear in dioptres.
    pub sweep: Option<(f64, f64)>,
}

impl Timeline {
    pub fn state(&self, index: usize) -> FrameState<'_> {
        let t = if self.sweep.is_some() {
            0.0
        } else {
            index as f64 / self.fps
        };
        self.scene.at_time(t)
    }

    pub fn focus_d(&self, index: usize, state: &FrameState<'_>) -> f64 {
        match self.sweep {
            Some((near, far)) => {
                let (dn, df) = (1.0 / near, if far.is_finite() { 1.0 / far } else { 0.0 });
                let t = if self.count > 1 {
                    index as f64 / (self.count - 1) as f64
                } else {
                    0.0
                };
                dn + (df - dn) * t
            }
            None => frame_plan::scene_focus_d(state.focus_m),
        }
    }
}

/// Frames sampled for planning the kernels: evenly spread, first and last included.
pub fn planning_frames(count: usize) -> Vec<usize> {
    const MAX: usize = 48;
    if count <= MAX {
        return (0..count).collect();
    }
    (0..MAX).map(|k| k * (count - 1) / (MAX - 1)).collect()
}

/// What the whole animation needs, from its planning frames (rasterised here), so that any
/// split renders identical frames; with the exposure of frame 0 where `auto_exposure`.
pub fn animation_needs(
    ctx: &Context,
    rasterizer: &mut Rasterizer,
    timeline: &Timeline,
    (width, height): (u32, u32),
    pupil: &PupilAsked<'_>,
    auto_exposure: bool,
) -> Result<(SceneNeeds, Option<f32>)> {
    let fov_y_deg = timeline.state(0).camera.fov_y_deg;
    let mut ranges = Vec::new();
    let mut states = Vec::new();
    let mut exposure_ev = None;
    for i in planning_frames(timeline.count) {
        let state = timeline.state(i);
        let frame = rasterizer.render(ctx, &state, width, height)?;
        if auto_exposure && exposure_ev.is_none() {
            exposure_ev = Some(crate::image_io::Tonemap::auto_exposure_ev_of(&frame.color));
        }
        ranges.push(dioptre_range(
            &frame.depth_m,
            width,
            height,
            state.camera.fov_y_deg,
        ));
        // The pupil's field is frame 0's, as every frame's is when it is rendered.
        let view = FrameView {
            width,
            height,
            fov_y_deg,
            color: &frame.color,
            depth_m: &frame.depth_m,
        };
        let (pupil_mm, _) = frame_plan::pupil_mm(pupil, &SceneEye::of(&state), &view)?;
        states.push(EyeState {
            focus_d: timeline.focus_d(i, &state),
            pupil_mm,
        });
    }
    let screen = Screen {
        fov_y_deg,
        height_px: height,
    };
    Ok((scene_needs(&ranges, &states, screen), exposure_ev))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn planning_samples_cover_both_ends() {
        let p = planning_frames(1000);
        assert_eq!((p[0], *p.last().unwrap()), (0, 999));
        assert_eq!(planning_frames(5), vec![0, 1, 2, 3, 4]);
    }
}
