//! Merge pass: replaces blocks of similar, strongly blurred fragments by one fragment (2×2,
//! then optionally 4×4). See glsl/render/splat/merge.comp.

use crate::gpu::{Binding, BindingKind, Buffer, ComputePipeline, Context, GpuResult, Recorder};

use super::fragments::{kinds_with_fragments, FragmentStore};
use super::{FrameBlock, FrameUniform};

/// Push constants of one merge dispatch. Mirrors `MergePush` in glsl/render/splat/merge.comp.
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, Eq, bytemuck::Pod, bytemuck::Zeroable)]
pub(super) struct MergePush {
    /// Side of the blocks this dispatch makes: 2, then 4.
    pub block_size: u32,
}

pub(super) struct MergePass {
    pipeline: ComputePipeline,
}

impl MergePass {
    pub fn new(ctx: &Context) -> GpuResult<Self> {
        let pipeline = ComputePipeline::builder("merge", crate::shaders::RENDER_SPLAT_MERGE_COMP)
            .bindings(&kinds_with_fragments(&[BindingKind::StorageBuffer], &[]))
            .uniform::<FrameUniform>()
            .push_constants::<MergePush>()
            .build(ctx)?;
        Ok(MergePass { pipeline })
    }

    /// `levels`: 1 merges 2×2 blocks, 2 also merges 2×2 blocks of merged blocks.
    pub fn record(
        &self,
        rec: &mut Recorder<'_>,
        frame: FrameBlock<'_>,
        levels: u32,
        radii: &Buffer,
        fragments: &FragmentStore,
    ) -> GpuResult<()> {
        for level in 1..=levels {
            let size = 1u32 << level;
            let blocks = [frame.values.width / size, frame.values.height / size];
            let mut bindings = fragments.bind_with(&[Binding::Buffer(radii)], &[]);
            bindings.push(frame.binding());
            rec.dispatch(
                &self.pipeline,
                &bindings,
                &MergePush { block_size: size },
                [blocks[0].div_ceil(8), blocks[1].div_ceil(8), 1],
            )?;
        }
        Ok(())
    }
}
