//! Tile-count pass: how many fragments each screen tile's list will hold (exact overlap of the
//! kernel's square support with the tile). See glsl/render/splat/tile_count.comp.

use crate::gpu::{Binding, BindingKind, Buffer, ComputePipeline, Context, GpuResult, Recorder};

use super::fragments::{kinds_with_fragments, FragmentStore};
use super::{FrameBlock, FrameUniform};

pub(super) struct TileCountPass {
    pipeline: ComputePipeline,
}

impl TileCountPass {
    pub fn new(ctx: &Context) -> GpuResult<Self> {
        let pipeline =
            ComputePipeline::builder("tile count", crate::shaders::RENDER_SPLAT_TILE_COUNT_COMP)
                .bindings(&kinds_with_fragments(&[], &[BindingKind::StorageBuffer]))
                .uniform::<FrameUniform>()
                .build(ctx)?;
        Ok(TileCountPass { pipeline })
    }

    /// `counts` must be zeroed (tiles + 1 elements; the last counts live fragments).
    pub fn record(
        &self,
        rec: &mut Recorder<'_>,
        frame: FrameBlock<'_>,
        fragments: &FragmentStore,
        counts: &Buffer,
    ) -> GpuResult<()> {
        let mut bindings = fragments.bind_with(&[], &[Binding::Buffer(counts)]);
        bindings.push(frame.binding());
        let p = frame.values;
        rec.dispatch(
            &self.pipeline,
            &bindings,
            &(),
            [p.width.div_ceil(8), (p.height * p.layers).div_ceil(8), 1],
        )
    }
}
