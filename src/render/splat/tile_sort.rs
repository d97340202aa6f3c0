//! Tile-sort pass: sorts each tile's list by (depth, fragment index), one workgroup per tile.
//! See glsl/render/splat/tile_sort.comp.

use crate::gpu::{Binding, BindingKind, Buffer, ComputePipeline, Context, GpuResult, Recorder};

use super::bands::{dispatch_offset, BandPush};

pub(super) struct TileSortPass {
    pipeline: ComputePipeline,
}

impl TileSortPass {
    pub fn new(ctx: &Context) -> GpuResult<Self> {
        let cpu = ctx.device_info().kind == crate::gpu::DeviceKind::Cpu;
        let pipeline =
            ComputePipeline::builder("tile sort", crate::shaders::RENDER_SPLAT_TILE_SORT_COMP)
                .bindings(&[
                    BindingKind::StorageBuffer,
                    BindingKind::StorageBuffer,
                    BindingKind::StorageBuffer,
                    BindingKind::StorageBuffer,
                ])
                .push_constants::<BandPush>()
                // keys each thread ranks (glsl/render/splat/tile_sort.comp)
                .specialize(0, if cpu { 8 } else { 2 })
                .build(ctx)?;
        Ok(TileSortPass { pipeline })
    }

    /// One workgroup per tile of the band in `band.slot` of `bands`, dispatched as the band
    /// table says.
    pub fn record(
        &self,
        rec: &mut Recorder<'_>,
        band: &BandPush,
        bands: &Buffer,
        counts: &Buffer,
        offsets: &Buffer,
        entries: &Buffer,
    ) -> GpuResult<()> {
        rec.dispatch_indirect(
            &self.pipeline,
            &[
                Binding::Buffer(counts),
                Binding::Buffer(offsets),
                Binding::Buffer(entries),
                Binding::Buffer(bands),
            ],
            band,
            bands,
            dispatch_offset(band.slot),
        )
    }
}
