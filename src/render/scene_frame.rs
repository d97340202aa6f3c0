//! A scene frame recorded into splat's own submission: the rasteriser draws it there and
//! splat's input pass reads the targets, so no pixel crosses to the host and back. A peeled
//! frame draws every layer there too: layer 0 with the raster pipeline, each later one with
//! the peeling pipeline reading the previous layer's samples, drawn in the same submission.

use crate::gpu::{Context, GpuResult, Recorder};
use crate::render::splat::{RecordedInput, RecordedLayer};
use crate::render::Rasterizer;
use crate::scene::FrameState;
use crate::Result;

impl Rasterizer {
    /// `state`'s frame at `width`×`height` as an input splat records into its own submission
    /// ([`crate::render::splat::Splatter::render_recorded`]): the visible surface only, or
    /// more layers with [`SceneFrame::peeled`].
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
            layers: 1,
            gap_d: 0.0,
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
    layers: u32,
    gap_d: f32,
}

impl SceneFrame<'_, '_> {
    /// The first `layers` surfaces along each pixel's ray, as
    /// [`Rasterizer::render_layers`] makes them (the same draws, the same post-processing,
    /// done on the GPU): a later layer's surface lies behind the previous one's by more than
    /// `gap_d` dioptres.
    pub fn peeled(mut self, layers: u32, gap_d: f32) -> Self {
        self.layers = layers;
        self.gap_d = gap_d;
        self
    }
}

impl RecordedInput for SceneFrame<'_, '_> {
    fn size(&self) -> (u32, u32) {
        (self.width, self.height)
    }

    fn layers(&self) -> u32 {
        self.layers
    }

    fn fov_y_deg(&self) -> f64 {
        self.state.camera.fov_y_deg
    }

    fn prepare(&mut self) -> Result<u64> {
        let gap_d = (self.layers > 1).then_some(self.gap_d);
        self.raster
            .prepare_camera_frame(self.ctx, self.state, (self.width, self.height), gap_d)
    }

    fn record_layer<'a>(
        &'a self,
        rec: &mut Recorder<'_>,
        layer: u32,
    ) -> GpuResult<RecordedLayer<'a>> {
        self.raster.record_frame(rec, self.state, layer)
    }
}
