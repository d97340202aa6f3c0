//! Tile-fill pass: writes each fragment's (depth, index) key into the list of every tile of
//! the current band it reaches. See glsl/render/splat/tile_fill.comp.

use crate::gpu::{GpuResult, Recorder};

use super::bands::{BandPush, BandSlot};
use super::Resources;

super::passes::compute_pass!(TileFillPass, "tile fill", RENDER_SPLAT_TILE_FILL_COMP, push: BandPush);

impl TileFillPass {
    /// `r.frame.cursors` must be zeroed; `band.entries` receives the lists of the band in
    /// `band.push.slot` of the band table.
    pub fn record(
        &self,
        rec: &mut Recorder<'_>,
        r: &Resources<'_>,
        band: &BandSlot<'_>,
    ) -> GpuResult<()> {
        let p = r.block.values;
        rec.compute(&self.pipeline)
            .read("Fragments", &r.frame.fragments)
            .read("Offsets", &r.frame.offsets)
            .write("Cursors", &r.frame.cursors)
            .write("Entries", band.entries)
            .read("BandTable", &r.frame.band_table)
            .read("FrameUniform", r.block.buffer)
            .push(&band.push)
            .dispatch([p.width.div_ceil(8), (p.height * p.layers).div_ceil(8), 1])
    }
}
