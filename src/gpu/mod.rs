//! A thin, safe RAII layer over ash and gpu-allocator. It knows nothing about eyes: passes in
//! `render` build on it. Every resource holds the device alive; every submission waits for
//! completion, so resources can be dropped in any order.

mod access;
mod bind;
mod block;
mod buffer;
mod commands;
mod context;
mod error;
mod graphics;
mod image;
mod pipeline;
mod reflect;
mod render_pass;
mod submit_slot;
pub mod texture_probe;

pub use bind::{Bindable, Dispatch, NamedBindings};
pub(crate) use block::shader_block;
pub use block::ShaderBlock;
pub use buffer::{Buffer, Residency};
pub use commands::{PassTime, Recorder, Timings};
pub use context::{
    list_devices, resolve_device, Context, ContextOptions, DeviceInfo, DeviceKind, Validation,
    ValidationLog,
};
pub use error::{GpuError, GpuResult};
pub use graphics::{
    CullMode, DepthCompare, Framebuffer, GraphicsPipeline, GraphicsPipelineBuilder,
    VertexAttribute, VertexFormat,
};
pub use image::{Edge, Image, ImageUsage, Sampler, TexelFormat};
pub use pipeline::{Binding, ComputePipeline, ComputePipelineBuilder};
pub use reflect::{reflect, Access, BindingKind, BlockLayout, ReflectedBinding, Reflection};

pub use ash::vk;

/// A validating context for the unit tests that need a device, and the check that its layer
/// stayed silent (as `tests/common` does for the integration tests).
#[cfg(test)]
pub(crate) mod testing {
    use super::{Context, ContextOptions};

    pub(crate) fn gpu() -> Context {
        Context::new(&ContextOptions::for_tests())
            .unwrap_or_else(|e| panic!("GPU unit tests need a Vulkan device (ci/setup.sh): {e}"))
    }

    /// Drops the context and asserts that validation produced no message in its life.
    pub(crate) fn finish(ctx: Context) {
        let log = ctx.validation_log();
        drop(ctx);
        let messages = log.take();
        assert!(messages.is_empty(), "validation:\n{}", messages.join("\n"));
    }
}
