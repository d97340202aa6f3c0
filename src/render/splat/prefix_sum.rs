//! Prefix-sum pass: exclusive scan of the tile counts into list offsets, plus the total.
//! See glsl/render/splat/prefix_sum.comp.

use crate::gpu::{Binding, BindingKind, Buffer, ComputePipeline, Context, GpuResult, Recorder};

/// Push constants of one prefix-sum dispatch. Mirrors `PrefixSumPush` in
/// glsl/render/splat/prefix_sum.comp (the scan needs no frame values).
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, Eq, bytemuck::Pod, bytemuck::Zeroable)]
pub(super) struct PrefixSumPush {
    /// 0: scan blocks of 1024; 1: scan the block totals; 2: add each block's base.
    pub phase: u32,
    /// Values scanned.
    pub count: u32,
}

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
                .push_constants::<PrefixSumPush>()
                .build(ctx)?;
        Ok(PrefixSumPass { pipeline })
    }

    /// Scans `count` values of `counts` into `offsets` (count + 1 elements).
    pub fn record(
        &self,
        rec: &mut Recorder<'_>,
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
            let push = PrefixSumPush { phase, count };
            rec.dispatch(&self.pipeline, &bindings, &push, [groups, 1, 1])?;
        }
        Ok(())
    }
}
