//! Rendering: joins scenes, the eye's kernels (`psf`) and the GPU layer (`gpu`). Each GPU pass
//! is one Rust file plus GLSL files of the same stem under glsl/render/.

pub mod blend;
pub mod edge_band;
pub mod focus;
pub mod frame;
pub mod frame_plan;
pub mod judge;
pub mod projection;
pub mod raster;
pub mod reference;
pub mod scene_frame;
pub mod slices;
pub mod splat;
pub mod timeline;
pub mod views;

pub use raster::{Frame, Rasterizer, MSAA_SAMPLES};
