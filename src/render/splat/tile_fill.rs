//! Tile-fill pass: writes each fragment's (depth, index) key into the list of every tile of
//! the current band it reaches. See glsl/render/splat/tile_fill.comp.

use crate::gpu::{Binding, BindingKind, Buffer, ComputePipeline, Context, GpuResult, Recorder};

use super::bands::BandPush;
use super::fragments::{kinds_with_fragments, FragmentStore};
use super::{FrameBlock, FrameUniform};

pub(super) struct TileFillPass {
    pipeline: ComputePipeline,
}

impl TileFillPass {
    pub fn new(ctx: &Context) -> GpuResult<Self> {
        let pipeline =
            ComputePipeline::builder("tile fill", crate::shaders::RENDER_SPLAT_TILE_FILL_COMP)
                .bindings(&kinds_with_fragments(
                    &[],
                    &[
                        BindingKind::StorageBuffer,
                        BindingKind::StorageBuffer,
                        BindingKind::StorageBuffer,
                    ],
                ))
                .uniform::<FrameUniform>()
                .push_constants::<BandPush>()
                .build(ctx)?;
        Ok(TileFillPass { pipeline })
    }

    /// `cursors` must be zeroed; `entries` holds the band's lists.
    #[allow(clippy::too_many_arguments)]
    pub fn record(
        &self,
        rec: &mut Recorder<'_>,
        frame: FrameBlock<'_>,
        band: &BandPush,
        fragments: &FragmentStore,
        offsets: &Buffer,
        cursors: &Buffer,
        entries: &Buffer,
    ) -> GpuResult<()> {
        let mut bindings = fragments.bind_with(
            &[],
            &[
                Binding::Buffer(offsets),
                Binding::Buffer(cursors),
                Binding::Buffer(entries),
            ],
        );
        bindings.push(frame.binding());
        let p = frame.values;
        rec.dispatch(
            &self.pipeline,
            &bindings,
            band,
            [p.width.div_ceil(8), (p.height * p.layers).div_ceil(8), 1],
        )
    }
}

/// Workgroup grid with one workgroup per tile, folded into two dimensions past the per-axis
/// dispatch limit (the shaders unfold it and skip the excess).
pub(super) fn per_tile_groups(tiles: u32) -> [u32; 3] {
    const AXIS: u32 = 65_535;
    [tiles.clamp(1, AXIS), tiles.div_ceil(AXIS).max(1), 1]
}
