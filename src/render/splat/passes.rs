//! The splat passes, held in one list. Each pass is one file in this folder and one shader of
//! the same stem in `glsl/render/splat/`; it owns its pipelines, binds what its shader names
//! (`gpu::reflect`), and is built once per splatter through [`Pass::new`]. Adding a pass is
//! its two files, one line in the `passes!` list of `mod.rs`, and one line where the frame is
//! recorded (`Splatter::record_front` or `record_back`).

use crate::gpu::{Context, GpuResult};

/// What a pass's pipelines may depend on, fixed when the splatter is built (its shaders'
/// specialisation constants).
#[derive(Clone, Copy, Debug)]
pub(super) struct PassConfig {
    /// Screen tile side (8, 16 or 32 pixels).
    pub tile_size: u32,
    /// The four-node kernels of a field lattice.
    pub off_axis: bool,
    /// The seed paper's per-fragment blend instead of depth groups.
    pub per_fragment: bool,
    /// The convolution's walk for CPU implementations.
    pub visit_slots: bool,
}

/// One pass of the splat: its pipelines, built once.
pub(super) trait Pass: Sized {
    fn new(ctx: &Context, config: &PassConfig) -> GpuResult<Self>;
}

/// Declares a pass that owns one compute pipeline, built from its shader with no pipeline
/// constants: `compute_pass!(Doc TileCountPass, "tile count", RENDER_SPLAT_TILE_COUNT_COMP)`,
/// with `push: Type` where its dispatches take push constants. A pass whose pipelines depend
/// on the [`PassConfig`] or the device implements [`Pass`] itself.
macro_rules! compute_pass {
    ($(#[$doc:meta])* $name:ident, $label:literal, $spirv:ident $(, push: $push:ty)?) => {
        $(#[$doc])*
        pub(super) struct $name {
            pipeline: crate::gpu::ComputePipeline,
        }

        impl super::passes::Pass for $name {
            fn new(
                ctx: &crate::gpu::Context,
                _: &super::passes::PassConfig,
            ) -> crate::gpu::GpuResult<Self> {
                let builder = crate::gpu::ComputePipeline::builder($label, crate::shaders::$spirv);
                $(let builder = builder.push_constants::<$push>();)?
                Ok($name {
                    pipeline: builder.build(ctx)?,
                })
            }
        }
    };
}
pub(super) use compute_pass;

/// Declares each pass's module and the struct that holds one of each, in frame order:
/// `passes! { field: module::Type, … }`.
macro_rules! passes {
    ($($(#[$doc:meta])* $field:ident: $module:ident::$ty:ident),* $(,)?) => {
        $(mod $module;)*

        /// Every pass of the splat, built together.
        pub(super) struct Passes {
            $($(#[$doc])* $field: $module::$ty,)*
        }

        impl Passes {
            fn new(
                ctx: &Context,
                config: &passes::PassConfig,
            ) -> crate::gpu::GpuResult<Passes> {
                use passes::Pass;
                Ok(Passes {
                    $($field: $module::$ty::new(ctx, config)?,)*
                })
            }
        }
    };
}
pub(super) use passes;
