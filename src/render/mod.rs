//! Rendering: joins scenes, the GPU layer and (later) the eye's PSFs. Each GPU pass is one
//! Rust file plus GLSL files of the same stem under glsl/render/.

pub mod raster;

pub use raster::{Frame, Rasterizer, MSAA_SAMPLES};
