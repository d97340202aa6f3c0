//! Prefix-sum pass: exclusive scan of the tile counts into list offsets, plus the total.
//! See glsl/render/splat/prefix_sum.comp.

use crate::gpu::{shader_block, GpuResult, Recorder};

use super::Resources;

shader_block! {
    /// Push constants of one prefix-sum dispatch. Mirrors `PrefixSumPush` in
    /// glsl/render/splat/prefix_sum.comp (the scan needs no frame values).
    #[derive(Clone, Copy, Debug, PartialEq, Eq, bytemuck::Pod, bytemuck::Zeroable)]
    pub(super) struct PrefixSumPush {
        /// 0: scan blocks of 1024; 1: scan the block totals; 2: add each block's base.
        pub phase: u32,
        /// Values scanned.
        pub count: u32,
    }
}

super::passes::compute_pass!(PrefixSumPass, "prefix sum", RENDER_SPLAT_PREFIX_SUM_COMP, push: PrefixSumPush);

impl PrefixSumPass {
    /// Scans the tile counts into the offsets (tiles + 1 elements: the total last).
    pub fn record(&self, rec: &mut Recorder<'_>, r: &Resources<'_>) -> GpuResult<()> {
        let count = r.frame.tiles_x * r.frame.tiles_y;
        let blocks = count.div_ceil(1024).max(1);
        for (phase, groups) in [(0u32, blocks), (1, 1), (2, blocks)] {
            rec.compute(&self.pipeline)
                .read("Counts", &r.frame.counts)
                .write("Offsets", &r.frame.offsets)
                .write("BlockSums", &r.frame.block_sums)
                .push(&PrefixSumPush { phase, count })
                .dispatch([groups, 1, 1])?;
        }
        Ok(())
    }
}
