//! Convolution pass: front-to-back blending of each tile's sorted fragments through the PSF
//! texture. See glsl/render/splat/convolve.comp.

use crate::gpu::{ComputePipeline, Context, GpuResult, Recorder};

use super::bands::{dispatch_offset, BandPush, BandSlot};
use super::passes::PassConfig;
use super::Resources;

pub(super) struct ConvolvePass {
    /// Indexed by whether the frame has hidden layers (`HIDDEN`: without them no fragment's
    /// light is partly blocked, and the walk skips `pupil_share`).
    pipeline: [ComputePipeline; 2],
    /// On axis, the same walks reading the layer texture (one read per pixel and fragment).
    layered: Option<[ComputePipeline; 2]>,
}

impl super::passes::Pass for ConvolvePass {
    /// Off axis the four-node kernels of a field lattice (src/render/splat/field.rs); the
    /// per-fragment blend is a pipeline constant of the visits walk (convolve.comp reads it
    /// from the frame block); `visit_slots` picks the walk for CPU implementations
    /// (glsl/render/splat/convolve_visits.comp says why). Every variant is created up front:
    /// on lavapipe the two hidden-layer variants add about 0.13 s to a run's start.
    fn new(ctx: &Context, config: &PassConfig) -> GpuResult<Self> {
        let build = |layered: bool, hidden: bool| {
            let builder = if config.visit_slots {
                ComputePipeline::builder(
                    "convolve",
                    crate::shaders::RENDER_SPLAT_CONVOLVE_VISITS_COMP,
                )
                .specialize(2, u32::from(config.per_fragment))
            } else {
                ComputePipeline::builder("convolve", crate::shaders::RENDER_SPLAT_CONVOLVE_COMP)
            };
            builder
                .push_constants::<BandPush>()
                .specialize(0, config.tile_size)
                .specialize(1, u32::from(config.off_axis))
                .specialize(3, u32::from(layered))
                .specialize(4, u32::from(hidden))
                .build(ctx)
        };
        Ok(ConvolvePass {
            pipeline: [build(false, false)?, build(false, true)?],
            layered: if config.off_axis {
                None
            } else {
                Some([build(true, false)?, build(true, true)?])
            },
        })
    }
}

impl ConvolvePass {
    /// Blends the band in `band.push.slot` of the band table into the output image, one
    /// workgroup per tile, dispatched as the table says.
    pub fn record(
        &self,
        rec: &mut Recorder<'_>,
        r: &Resources<'_>,
        band: &BandSlot<'_>,
    ) -> GpuResult<()> {
        let table = &r.frame.band_table;
        let hidden = usize::from(r.block.values.layers > 1);
        let pipeline = match (&self.layered, r.block.values.layered) {
            (Some(layered), 1) => &layered[hidden],
            _ => &self.pipeline[hidden],
        };
        rec.compute(pipeline)
            .read("psf_texture", (r.texture, r.sampler))
            .read("Atlas", r.atlas)
            .read("layer_texture", (r.layer_texture, r.sampler))
            .read("layer_sums", (r.layer_sums, r.sampler))
            .read("LayerAtlas", r.layer_atlas)
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
