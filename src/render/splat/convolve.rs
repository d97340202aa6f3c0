//! Convolution pass: front-to-back blending of each tile's sorted fragments through the PSF
//! texture. See glsl/render/splat/convolve.comp.

use crate::gpu::{
    Binding, BindingKind, Buffer, ComputePipeline, Context, GpuResult, Image, Recorder, Sampler,
};

use super::bands::{dispatch_offset, BandPush};
use super::fragments::{kinds_with_fragments, FragmentStore};
use super::{FrameBlock, FrameUniform};

pub(super) struct ConvolvePass {
    pipeline: ComputePipeline,
}

impl ConvolvePass {
    /// `off_axis`: the four-node kernels of a field lattice (src/render/splat/field.rs);
    /// `per_fragment`: the seed paper's blend instead of depth groups (a pipeline constant of
    /// the visits walk; convolve.comp reads it from the frame block); `visit_slots`: the walk for
    /// CPU implementations (glsl/render/splat/convolve_visits.comp says why).
    pub fn new(
        ctx: &Context,
        tile_size: u32,
        off_axis: bool,
        per_fragment: bool,
        visit_slots: bool,
    ) -> GpuResult<Self> {
        let bindings = kinds_with_fragments(
            &[BindingKind::SampledImage],
            &[
                BindingKind::StorageBuffer,
                BindingKind::StorageBuffer,
                BindingKind::StorageBuffer,
                BindingKind::StorageImage,
                BindingKind::StorageBuffer,
                BindingKind::StorageBuffer,
                BindingKind::StorageBuffer,
            ],
        );
        let builder = if visit_slots {
            ComputePipeline::builder(
                "convolve",
                crate::shaders::RENDER_SPLAT_CONVOLVE_VISITS_COMP,
            )
            .specialize(2, u32::from(per_fragment))
        } else {
            ComputePipeline::builder("convolve", crate::shaders::RENDER_SPLAT_CONVOLVE_COMP)
        };
        let pipeline = builder
            .bindings(&bindings)
            .uniform::<FrameUniform>()
            .push_constants::<BandPush>()
            .specialize(0, tile_size)
            .specialize(1, u32::from(off_axis))
            .build(ctx)?;
        Ok(ConvolvePass { pipeline })
    }

    #[allow(clippy::too_many_arguments)]
    pub fn record(
        &self,
        rec: &mut Recorder<'_>,
        frame: FrameBlock<'_>,
        band: &BandPush,
        bands: &Buffer,
        // the PSF texture, its sampler and its layout (glsl/common/atlas.glsl)
        psf: (&Image, &Sampler, &Buffer),
        field_table: &Buffer,
        fragments: &FragmentStore,
        counts: &Buffer,
        offsets: &Buffer,
        entries: &Buffer,
        output: &Image,
    ) -> GpuResult<()> {
        let mut bindings = fragments.bind_with(
            &[Binding::Sampled(psf.0, psf.1)],
            &[
                Binding::Buffer(counts),
                Binding::Buffer(offsets),
                Binding::Buffer(entries),
                Binding::Storage(output),
                Binding::Buffer(field_table),
                Binding::Buffer(bands),
                Binding::Buffer(psf.2),
            ],
        );
        bindings.push(frame.binding());
        rec.dispatch_indirect(
            &self.pipeline,
            &bindings,
            band,
            bands,
            dispatch_offset(band.slot),
        )
    }
}
