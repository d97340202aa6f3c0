//! Fragment pass: one fragment per pixel with its dioptre index and per-channel blur radius.
//! See glsl/render/splat/fragments.comp.

use crate::gpu::{
    Binding, BindingKind, Buffer, ComputePipeline, Context, GpuResult, Image, Recorder,
};

use super::FrameParams;

pub(super) struct FragmentsPass {
    pipeline: ComputePipeline,
}

impl FragmentsPass {
    pub fn new(ctx: &Context) -> GpuResult<Self> {
        let pipeline =
            ComputePipeline::builder("fragments", crate::shaders::RENDER_SPLAT_FRAGMENTS_COMP)
                .bindings(&[
                    BindingKind::StorageImage,
                    BindingKind::StorageImage,
                    BindingKind::StorageBuffer,
                    BindingKind::StorageBuffer,
                ])
                .push_constants::<FrameParams>()
                .build(ctx)?;
        Ok(FragmentsPass { pipeline })
    }

    pub fn record(
        &self,
        rec: &mut Recorder<'_>,
        params: &FrameParams,
        color: &Image,
        depth: &Image,
        radii: &Buffer,
        fragments: &Buffer,
    ) -> GpuResult<()> {
        rec.dispatch(
            &self.pipeline,
            &[
                Binding::Storage(color),
                Binding::Storage(depth),
                Binding::Buffer(radii),
                Binding::Buffer(fragments),
            ],
            params,
            [
                params.width.div_ceil(8),
                (params.height * params.layers).div_ceil(8),
                1,
            ],
        )
    }
}
