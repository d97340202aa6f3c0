//! A scene frame recorded into splat's own submission: the rasteriser draws it there and
//! splat's input pass reads the targets, so no pixel crosses to the host and back.

use crate::gpu::{Buffer, Context, GpuResult, Image, Recorder};
use crate::render::splat::RecordedInput;
use crate::render::Rasterizer;
use crate::scene::FrameState;
use crate::Result;

impl Rasterizer {
    /// `state`'s frame at `width`×`height` as an input splat records into its own submission
    /// ([`crate::render::splat::Splatter::render_recorded`]).
    pub fn scene_frame<'r, 's>(
        &'r mut self,
        ctx: &'r Context,
        state: &'r FrameState<'s>,
        (width, height): (u32, u32),
    ) -> SceneFrame<'r, 's> {
        SceneFrame {
            raster: self,
            ctx,
            state,
            width,
            height,
        }
    }
}

/// A scene frame drawn inside splat's submission ([`Rasterizer::scene_frame`]).
pub struct SceneFrame<'r, 's> {
    raster: &'r mut Rasterizer,
    ctx: &'r Context,
    state: &'r FrameState<'s>,
    width: u32,
    height: u32,
}

impl RecordedInput for SceneFrame<'_, '_> {
    fn size(&self) -> (u32, u32) {
        (self.width, self.height)
    }

    fn fov_y_deg(&self) -> f64 {
        self.state.camera.fov_y_deg
    }

    fn prepare(&mut self) -> Result<u64> {
        self.raster
            .prepare_camera_frame(self.ctx, self.state, (self.width, self.height))
    }

    fn record<'a>(&'a self, rec: &mut Recorder<'_>) -> GpuResult<(&'a Image, &'a Buffer)> {
        self.raster.record_frame(rec, self.state)
    }
}
