//! The frame renderer as the tests of real eyes drive it: the splat of one frame and its
//! ground truth, from the same kernels.

use ocular::eye::Eye;
use ocular::gpu::Context;
use ocular::render::splat::{FrameInput, SplatSettings};
use ocular::render::{EyeState, FrameRenderer, KernelOptions, Method, PreparedKernels};

/// A renderer of `kernels` for `eye`, splatting with the default settings.
pub fn frame_renderer(
    ctx: &Context,
    eye: Eye,
    kernels: PreparedKernels,
    options: &KernelOptions,
) -> FrameRenderer {
    FrameRenderer::new(
        ctx,
        eye,
        kernels,
        options.settings.clone(),
        SplatSettings::default(),
    )
}

/// The splat's image of `input` and the ground truth's.
pub fn splat_and_truth(
    renderer: &mut FrameRenderer,
    input: &FrameInput<'_>,
    state: EyeState,
) -> (Vec<[f32; 4]>, Vec<[f32; 4]>) {
    let mut image = |method| renderer.render(input, state, method).unwrap().color;
    (image(Method::Splat), image(Method::Reference))
}
