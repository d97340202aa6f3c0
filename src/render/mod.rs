//! Rendering: joins scenes, the eye's kernels (`psf`) and the GPU layer (`gpu`). Each GPU pass
//! is one Rust file plus GLSL files of the same stem under glsl/render/.
//!
//! The `pub use` items below are the module's public surface. Four submodules stay public:
//! [`splat`], the tiled splatting renderer, and [`reference`](mod@reference), [`slices`] and
//! [`views`], three other renderers whose entry point is each called `render` (re-exporting
//! them would collide).

pub mod binocular;
pub(crate) mod blend;
pub(crate) mod edge_band;
pub(crate) mod focus;
pub(crate) mod frame;
pub mod frame_plan;
pub mod headset;
pub(crate) mod judge;
pub mod live;
pub(crate) mod projection;
pub(crate) mod raster;
pub mod reference;
pub(crate) mod scene_frame;
pub mod slices;
pub mod splat;
pub(crate) mod timeline;
pub mod views;

// Rasterising a scene into colour and depth.
pub use raster::{Frame, Rasterizer, SurfaceInputs, MSAA_SAMPLES, RASTER_SAMPLE_COUNTS};
// How layers of fragments are blended.
pub use blend::{BlendMode, BlendSettings, EdgePixels, DEFAULT_GROUP_TOLERANCE_D};
// One frame from a scene and an eye: its kernels and its renderer.
pub use frame::{
    dioptre_range, prepare_kernels, scene_needs, EyeState, FrameRenderer, KernelOptions, Method,
    PreparedKernels,
};
// An eye's far point, signed (beyond infinity for a hyperopic eye).
pub use focus::signed_far_point_d;
