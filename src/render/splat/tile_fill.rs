//! Tile-fill pass: writes each fragment's (depth, index) key into the list of every tile of
//! the current band it reaches. See glsl/render/splat/tile_fill.comp.

use crate::gpu::{Binding, BindingKind, Buffer, ComputePipeline, Context, GpuResult, Recorder};

use super::bands::BandPush;
use super::fragments::{kinds_with_fragments, FragmentStore};
use super::{FrameBlock, FrameUniform};

pub(super) struct TileFillPass {
    pipeline: ComputePipeline,
}

impl TileFillPass {
    pub fn new(ctx: &Context) -> GpuResult<Self> {
        let pipeline =
            ComputePipeline::builder("tile fill", crate::shaders::RENDER_SPLAT_TILE_FILL_COMP)
                .bindings(&kinds_with_fragments(
                    &[],
                    &[
                        BindingKind::StorageBuffer,
                        BindingKind::StorageBuffer,
                        BindingKind::StorageBuffer,
                        BindingKind::StorageBuffer,
                    ],
                ))
                .uniform::<FrameUniform>()
                .push_constants::<BandPush>()
                .build(ctx)?;
        Ok(TileFillPass { pipeline })
    }

    /// `cursors` must be zeroed; `entries` holds the lists of the band in `band.slot` of
    /// `bands` (the band table).
    #[allow(clippy::too_many_arguments)]
    pub fn record(
        &self,
        rec: &mut Recorder<'_>,
        frame: FrameBlock<'_>,
        band: &BandPush,
        bands: &Buffer,
        fragments: &FragmentStore,
        offsets: &Buffer,
        cursors: &Buffer,
        entries: &Buffer,
    ) -> GpuResult<()> {
        let mut bindings = fragments.bind_with(
            &[],
            &[
                Binding::Buffer(offsets),
                Binding::Buffer(cursors),
                Binding::Buffer(entries),
                Binding::Buffer(bands),
            ],
        );
        bindings.push(frame.binding());
        let p = frame.values;
        rec.dispatch(
            &self.pipeline,
            &bindings,
            band,
            [p.width.div_ceil(8), (p.height * p.layers).div_ceil(8), 1],
        )
    }
}
