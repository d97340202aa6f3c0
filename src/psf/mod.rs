//! Point-spread functions turned into screen-space kernels (pure numerics, no GPU).
//!
//! - [`axes`]: the grid's axes, the screen and the numerical settings.
//! - [`defocus`]: one (pupil, focus) state of an eye and the defocus of every object distance.
//! - [`project`]: PSF sampling (ENZ or FFT per PSF), energy crop, screen orientation.
//! - [`integrate`]: the PSF integrated over screen pixels of any size.
//! - [`grid`]: the whole precomputation; [`plan`]: only what a scene needs;
//!   [`object_knots`]: which object samples get a PSF of their own; [`level_band`]: which
//!   radius levels each object distance holds.
//! - [`exact`]: exact kernels at any vergence for the ground truth.
//! - [`field_shape`]: a field direction's elliptical pupil; [`field_psf`]: a channel's PSF
//!   anywhere in the field (the on-axis one, or the disc's resampled onto the ellipse);
//!   [`field`]: kernels for a direction of the visual field;
//!   [`field_plan`]: which directions a frame needs; [`field_kernels`]: the runtime's kernels
//!   over those directions.
//! - [`cache`]: grid files and the on-disk cache; [`preview`]: contact sheet and size plot.
//! - [`kernels`]: the contract with the GPU runtime.
//!
//! The submodules are private: the `pub use` items below are the module's public surface.

pub(crate) mod axes;
pub(crate) mod cache;
pub(crate) mod defocus;
pub(crate) mod exact;
pub(crate) mod field;
pub(crate) mod field_kernels;
pub(crate) mod field_plan;
pub(crate) mod field_psf;
pub(crate) mod field_shape;
pub(crate) mod grid;
pub(crate) mod integrate;
pub(crate) mod kernels;
pub(crate) mod level_band;
pub(crate) mod object_knots;
pub(crate) mod plan;
pub(crate) mod preview;
pub(crate) mod project;
pub(crate) mod request;

// The grid's axes, the screen and the numerical settings.
pub use axes::{linspace, GridAxes, KernelSettings, MethodChoice, Screen, DEFAULT_WAVELENGTHS_NM};
// An eye's optics per channel and object distance, and the exact eye of the ground truth.
pub use defocus::{ChannelOptics, ColumnOptics};
pub use exact::ExactEye;
// PSF sampling, cropping and its cost.
pub use field_psf::cropped_psf;
pub use project::{cropped_psf_at_f, enz_cost, psf_grid, CroppedPsf};
// Kernel grids: their computation, what a scene needs, and the contract with the GPU runtime.
pub use grid::{compute_grid, kernels_from_columns, no_progress, GridReport};
pub use kernels::{
    kernel_side, level_block_radius, level_count, level_of_radius, level_radius_px, DioptreAxis,
    KernelGrid, KernelSet,
};
pub use object_knots::DEFAULT_OBJECT_TOLERANCE;
pub use plan::{objects_for_screen, plan_for_scene, SceneNeeds, OBJECT_STEP_BLUR_PX};
// Kernels across the visual field.
pub use field::{field_column, frame_half_field_deg, FieldAxes};
pub use field_plan::{plan_field_axes, Probe, FIELD_TOLERANCE_UM};
// Grid files and the on-disk cache.
pub use cache::{cache_path, cached, grid_key, read_grid, write_grid, CacheOutcome};
