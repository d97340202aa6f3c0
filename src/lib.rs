//! ocular: renders a 3D scene as a particular human eye sees it.
//!
//! The map of the crate is in docs/design.md: `optics`, `eye` and `psf` are pure numerics;
//! `gpu` is a thin Vulkan layer that knows nothing about eyes; `render` joins them; `cli` holds
//! one file per subcommand.

pub mod aberrations;
pub mod cli;
pub mod error;
pub mod eye;
pub mod gpu;
pub mod image_io;
mod image_types;
pub mod inputs;
pub mod limits;
pub mod metrics;
pub mod optics;
pub mod psf;
#[cfg(feature = "python")]
mod python;
pub mod render;
pub mod scene;
pub mod viewer;

/// SPIR-V of every shader under `glsl/`, compiled by build.rs.
pub mod shaders {
    include!(concat!(env!("OUT_DIR"), "/shaders.rs"));
}

pub use error::{Error, Result};
