//! Tile-count pass: how many fragments each screen tile's list will hold (exact overlap of the
//! kernel's square support with the tile). See glsl/render/splat/tile_count.comp.

use crate::gpu::{GpuResult, Recorder};

use super::Resources;

super::passes::compute_pass!(TileCountPass, "tile count", RENDER_SPLAT_TILE_COUNT_COMP);

impl TileCountPass {
    /// `r.frame.counts` must be zeroed (tiles + 5 elements: the live fragments, the kernel
    /// evaluations and the texture reads follow the tiles).
    pub fn record(&self, rec: &mut Recorder<'_>, r: &Resources<'_>) -> GpuResult<()> {
        let p = r.block.values;
        rec.compute(&self.pipeline)
            .read("Fragments", &r.frame.fragments)
            .read("Field", r.field_table)
            .write("Counts", &r.frame.counts)
            .read("FrameUniform", r.block.buffer)
            .dispatch([p.width.div_ceil(8), (p.height * p.layers).div_ceil(8), 1])
    }
}
