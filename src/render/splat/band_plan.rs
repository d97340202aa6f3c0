//! Band-plan pass: packs whole tile rows into bands that fit the list buffer, on the GPU from
//! the prefix sum, and writes the band table the list passes read (their ranges and the
//! indirect dispatches of tile sort and convolve). See glsl/render/splat/band_plan.comp.

use crate::gpu::{shader_block, GpuResult, Recorder};

use super::Resources;

shader_block! {
    /// Push constants of the band-plan dispatch. Mirrors `BandPlanPush` in
    /// glsl/render/splat/band_plan.comp.
    #[derive(Clone, Copy, Debug, PartialEq, Eq, bytemuck::Pod, bytemuck::Zeroable)]
    pub(super) struct BandPlanPush {
        pub tiles_x: u32,
        pub tiles: u32,
        /// Entries the list buffer holds.
        pub capacity: u32,
        /// Slots recorded after this dispatch.
        pub slots: u32,
    }
}

super::passes::compute_pass!(BandPlanPass, "band plan", RENDER_SPLAT_BAND_PLAN_COMP, push: BandPlanPush);

impl BandPlanPass {
    /// Plans `slots` slots of the band table for a list buffer of `capacity` entries, from
    /// the tile counts and offsets (tiles + 1 each).
    pub fn record(
        &self,
        rec: &mut Recorder<'_>,
        r: &Resources<'_>,
        (slots, capacity): (u32, u32),
    ) -> GpuResult<()> {
        rec.compute(&self.pipeline)
            .read("Counts", &r.frame.counts)
            .read("Offsets", &r.frame.offsets)
            .write("BandTable", &r.frame.band_table)
            .push(&BandPlanPush {
                tiles_x: r.frame.tiles_x,
                tiles: r.frame.tiles_x * r.frame.tiles_y,
                capacity,
                slots,
            })
            .dispatch([1, 1, 1])
    }
}
