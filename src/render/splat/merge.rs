//! Merge pass: replaces blocks of similar, strongly blurred fragments by one fragment (2×2,
//! then optionally 4×4). See glsl/render/splat/merge.comp.

use crate::gpu::{Binding, BindingKind, Buffer, ComputePipeline, Context, GpuResult, Recorder};

use super::fragments::{kinds_with_fragments, FragmentStore};
use super::FrameParams;

pub(super) struct MergePass {
    pipeline: ComputePipeline,
}

impl MergePass {
    pub fn new(ctx: &Context) -> GpuResult<Self> {
        let pipeline = ComputePipeline::builder("merge", crate::shaders::RENDER_SPLAT_MERGE_COMP)
            .bindings(&kinds_with_fragments(&[BindingKind::StorageBuffer], &[]))
            .push_constants::<FrameParams>()
            .build(ctx)?;
        Ok(MergePass { pipeline })
    }

    /// `levels`: 1 merges 2×2 blocks, 2 also merges 2×2 blocks of merged blocks.
    pub fn record(
        &self,
        rec: &mut Recorder<'_>,
        params: &FrameParams,
        levels: u32,
        radii: &Buffer,
        fragments: &FragmentStore,
    ) -> GpuResult<()> {
        for level in 1..=levels {
            let size = 1u32 << level;
            let mut p = *params;
            p.pass_u = [size, 0, 0, 0];
            let blocks = [params.width / size, params.height / size];
            rec.dispatch(
                &self.pipeline,
                &fragments.bind_with(&[Binding::Buffer(radii)], &[]),
                &p,
                [blocks[0].div_ceil(8), blocks[1].div_ceil(8), 1],
            )?;
        }
        Ok(())
    }
}
