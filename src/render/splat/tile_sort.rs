//! Tile-sort pass: sorts each tile's list by (depth, fragment index), one workgroup per tile.
//! See glsl/render/splat/tile_sort.comp.

use crate::gpu::{Binding, BindingKind, Buffer, ComputePipeline, Context, GpuResult, Recorder};

use super::bands::BandPush;
use super::tile_fill::per_tile_groups;

pub(super) struct TileSortPass {
    pipeline: ComputePipeline,
}

impl TileSortPass {
    pub fn new(ctx: &Context) -> GpuResult<Self> {
        let pipeline =
            ComputePipeline::builder("tile sort", crate::shaders::RENDER_SPLAT_TILE_SORT_COMP)
                .bindings(&[
                    BindingKind::StorageBuffer,
                    BindingKind::StorageBuffer,
                    BindingKind::StorageBuffer,
                ])
                .push_constants::<BandPush>()
                .build(ctx)?;
        Ok(TileSortPass { pipeline })
    }

    pub fn record(
        &self,
        rec: &mut Recorder<'_>,
        band: &BandPush,
        counts: &Buffer,
        offsets: &Buffer,
        entries: &Buffer,
    ) -> GpuResult<()> {
        rec.dispatch(
            &self.pipeline,
            &[
                Binding::Buffer(counts),
                Binding::Buffer(offsets),
                Binding::Buffer(entries),
            ],
            band,
            per_tile_groups(band.tiles()),
        )
    }
}
