//! Tile-sort pass: sorts each tile's list by (depth, fragment index), one workgroup per tile.
//! See glsl/render/splat/tile_sort.comp.

use crate::gpu::{ComputePipeline, Context, GpuResult, Recorder};

use super::bands::{dispatch_offset, BandPush, BandSlot};
use super::Resources;

pub(super) struct TileSortPass {
    pipeline: ComputePipeline,
}

impl super::passes::Pass for TileSortPass {
    fn new(ctx: &Context, _: &super::passes::PassConfig) -> GpuResult<Self> {
        let cpu = ctx.device_info().kind == crate::gpu::DeviceKind::Cpu;
        let pipeline =
            ComputePipeline::builder("tile sort", crate::shaders::RENDER_SPLAT_TILE_SORT_COMP)
                .push_constants::<BandPush>()
                // keys each thread ranks (glsl/render/splat/tile_sort.comp)
                .specialize(0, if cpu { 8 } else { 2 })
                .build(ctx)?;
        Ok(TileSortPass { pipeline })
    }
}

impl TileSortPass {
    /// One workgroup per tile of the band in `band.push.slot` of the band table, dispatched
    /// as the table says.
    pub fn record(
        &self,
        rec: &mut Recorder<'_>,
        r: &Resources<'_>,
        band: &BandSlot<'_>,
    ) -> GpuResult<()> {
        let table = &r.frame.band_table;
        rec.compute(&self.pipeline)
            .read("Counts", &r.frame.counts)
            .read("Offsets", &r.frame.offsets)
            .write("Entries", band.entries)
            .read("BandTable", table)
            .push(&band.push)
            .dispatch_indirect(table, dispatch_offset(band.push.slot))
    }
}
