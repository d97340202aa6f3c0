//! Layer-kernels pass: each object distance's own kernel for this frame, from the PSF texture's
//! radius levels, so that the convolution reads one texel for all channels. See
//! glsl/render/splat/layer_kernels.comp.

use crate::gpu::{shader_block, Dispatch, GpuResult, Recorder};

use super::atlas::{layer_slot_width, LayerLayout, SAT_KIND};
use super::Resources;

shader_block! {
    /// Push constants of one dispatch: a field node and a kind of slot. Mirrors
    /// `LayerKernelsPush` in glsl/render/splat/layer_kernels.comp.
    #[derive(Clone, Copy, Debug, PartialEq, bytemuck::Pod, bytemuck::Zeroable)]
    pub(super) struct LayerKernelsPush {
        pub node: u32,
        /// 0: plain; 1 … 4: blocks of side 4 … 32; 5: the plain kernels' summed-area tables
        /// (one workgroup per object distance).
        pub kind: u32,
    }
}

super::passes::compute_pass!(LayerKernelsPass, "layer kernels", RENDER_SPLAT_LAYER_KERNELS_COMP, push: LayerKernelsPush);

impl LayerKernelsPass {
    /// Writes every node's slots of `layout` from the PSF texture, which must hold this
    /// frame's blend, and on axis the plain kernels' summed-area tables.
    pub fn record(
        &self,
        rec: &mut Recorder<'_>,
        r: &Resources<'_>,
        layout: &LayerLayout,
    ) -> GpuResult<()> {
        for node in 0..layout.nodes {
            for (kind, slot) in layout.kinds[..SAT_KIND].iter().enumerate() {
                let Some((_, side)) = slot else { continue };
                let width = layer_slot_width(layout.max_radius, *side);
                let push = LayerKernelsPush {
                    node,
                    kind: kind as u32,
                };
                self.bind(rec, r, &push)
                    .dispatch([width.div_ceil(8), width.div_ceil(8), layout.objects])?;
            }
        }
        // The summed-area tables: one workgroup per object distance, on axis (one node).
        if layout.nodes == 1 && layout.kinds[SAT_KIND].is_some() {
            let push = LayerKernelsPush {
                node: 0,
                kind: SAT_KIND as u32,
            };
            self.bind(rec, r, &push).dispatch([1, 1, layout.objects])?;
        }
        Ok(())
    }

    fn bind<'r, 'rec, 'a>(
        &'a self,
        rec: &'r mut Recorder<'rec>,
        r: &Resources<'a>,
        push: &'a LayerKernelsPush,
    ) -> Dispatch<'r, 'rec, 'a> {
        rec.compute(&self.pipeline)
            .read("psf_texture", (r.texture, r.sampler))
            .write("layer_texture", r.layer_texture)
            .write("layer_sums", r.layer_sums)
            .read("Field", r.field_table)
            .read("Atlas", r.atlas)
            .read("LayerAtlas", r.layer_atlas)
            .read("FrameUniform", r.block.buffer)
            .push(push)
    }
}
