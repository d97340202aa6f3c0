//! Prefix-sum pass: exclusive scan of the tile counts into list offsets, plus the total.
//! See glsl/render/splat/prefix_sum.comp.

use crate::gpu::{Binding, BindingKind, Buffer, ComputePipeline, Context, GpuResult, Recorder};

use super::FrameParams;

pub(super) struct PrefixSumPass {
    pipeline: ComputePipeline,
}

impl PrefixSumPass {
    pub fn new(ctx: &Context) -> GpuResult<Self> {
        let pipeline =
            ComputePipeline::builder("prefix sum", crate::shaders::RENDER_SPLAT_PREFIX_SUM_COMP)
                .bindings(&[
                    BindingKind::StorageBuffer,
                    BindingKind::StorageBuffer,
                    BindingKind::StorageBuffer,
                ])
                .push_constants::<FrameParams>()
                .build(ctx)?;
        Ok(PrefixSumPass { pipeline })
    }

    /// Scans `count` values of `counts` into `offsets` (count + 1 elements).
    pub fn record(
        &self,
        rec: &mut Recorder<'_>,
        params: &FrameParams,
        count: u32,
        counts: &Buffer,
        offsets: &Buffer,
        block_sums: &Buffer,
    ) -> GpuResult<()> {
        let blocks = count.div_ceil(1024).max(1);
        let bindings = [
            Binding::Buffer(counts),
            Binding::Buffer(offsets),
            Binding::Buffer(block_sums),
        ];
        for (phase, groups) in [(0u32, blocks), (1, 1), (2, blocks)] {
            let mut p = *params;
            p.pass_u = [phase, count, 0, 0];
            rec.dispatch(&self.pipeline, &bindings, &p, [groups, 1, 1])?;
        }
        Ok(())
    }
}
