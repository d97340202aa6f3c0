//! Merge pass: replaces blocks of strongly blurred fragments by one fragment (2×2, then
//! optionally 4×4 up to 32×32): the seed paper's similar-colour rule, or level of detail by
//! blur. See glsl/render/splat/merge.comp.

use crate::gpu::{shader_block, GpuResult, Recorder};

use super::Resources;

shader_block! {
    /// Push constants of one merge dispatch. Mirrors `MergePush` in glsl/render/splat/merge.comp.
    #[derive(Clone, Copy, Debug, PartialEq, bytemuck::Pod, bytemuck::Zeroable)]
    pub(super) struct MergePush {
        /// Side of the blocks this dispatch makes: 2, then 4, … 32.
        pub block_size: u32,
        /// Level of detail by blur (see [`super::MergeSettings::blur_per_block`]); 0: the seed
        /// paper's tolerances.
        pub blur_per_block: f32,
        /// See [`super::MergeSettings::scale_error_px`].
        pub scale_error_px: f32,
    }
}

super::passes::compute_pass!(MergePass, "merge", RENDER_SPLAT_MERGE_COMP, push: MergePush);

impl MergePass {
    /// `merge.levels`: 1 merges 2×2 blocks, 2 also merges 2×2 blocks of merged blocks, and so
    /// on.
    pub fn record(
        &self,
        rec: &mut Recorder<'_>,
        r: &Resources<'_>,
        merge: &super::MergeSettings,
    ) -> GpuResult<()> {
        for level in 1..=merge.levels {
            let size = 1u32 << level;
            let blocks = [r.block.values.width / size, r.block.values.height / size];
            if blocks[0] == 0 || blocks[1] == 0 {
                break;
            }
            rec.compute(&self.pipeline)
                .read("Radii", r.radii)
                .write("Fragments", &r.frame.fragments)
                .read("FrameUniform", r.block.buffer)
                .push(&MergePush {
                    block_size: size,
                    blur_per_block: merge.blur_per_block,
                    scale_error_px: merge.scale_error_px,
                })
                .dispatch([blocks[0].div_ceil(8), blocks[1].div_ceil(8), 1])?;
        }
        Ok(())
    }
}
