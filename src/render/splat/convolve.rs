//! Convolution pass: front-to-back blending of each tile's sorted fragments through the PSF
//! texture. See glsl/render/splat/convolve.comp.

use crate::gpu::{ComputePipeline, Context, GpuResult, Recorder};

use super::bands::{dispatch_offset, BandPush, BandSlot};
use super::Resources;

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
            .push_constants::<BandPush>()
            .specialize(0, tile_size)
            .specialize(1, u32::from(off_axis))
            .build(ctx)?;
        Ok(ConvolvePass { pipeline })
    }

    /// Blends the band in `band.push.slot` of the band table into the output image, one
    /// workgroup per tile, dispatched as the table says.
    pub fn record(
        &self,
        rec: &mut Recorder<'_>,
        r: &Resources<'_>,
        band: &BandSlot<'_>,
    ) -> GpuResult<()> {
        let table = &r.frame.band_table;
        rec.compute(&self.pipeline)
            .read("psf_texture", (r.texture, r.sampler))
            .read("Atlas", r.atlas)
            .read("Field", r.field_table)
            .read("Fragments", &r.frame.fragments)
            .read("Counts", &r.frame.counts)
            .read("Offsets", &r.frame.offsets)
            .read("Entries", band.entries)
            .read("BandTable", table)
            .write("color_out", &r.frame.color_out)
            .read("FrameUniform", r.block.buffer)
            .push(&band.push)
            .dispatch_indirect(table, dispatch_offset(band.push.slot))
    }
}
