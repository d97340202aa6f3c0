//! Point-spread functions turned into screen-space kernels (pure numerics, no GPU).
//!
//! - [`axes`]: the grid's axes, the screen and the numerical settings.
//! - [`defocus`]: one (pupil, focus) state of an eye and the defocus of every object distance.
//! - [`project`]: PSF sampling (ENZ or FFT per PSF), energy crop, screen orientation.
//! - [`integrate`]: the PSF integrated over screen pixels of any size.
//! - [`grid`]: the whole precomputation; [`plan`]: only what a scene needs.
//! - [`exact`]: exact kernels at any vergence for the ground truth.
//! - [`field_shape`]: a field direction's elliptical pupil; [`field_psf`]: a channel's PSF
//!   anywhere in the field (the on-axis one, or the disc's resampled onto the ellipse);
//!   [`field`]: kernels for a direction of the visual field;
//!   [`field_plan`]: which directions a frame needs; [`field_kernels`]: the runtime's kernels
//!   over those directions.
//! - [`cache`]: grid files and the on-disk cache; [`preview`]: contact sheet and size plot.
//! - [`kernels`]: the contract with the GPU runtime.

pub mod axes;
pub mod cache;
pub mod defocus;
pub mod exact;
pub mod field;
pub mod field_kernels;
pub mod field_plan;
pub mod field_psf;
pub mod field_shape;
pub mod grid;
pub mod integrate;
pub mod kernels;
pub mod plan;
pub mod preview;
pub mod project;
pub mod request;
