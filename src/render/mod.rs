//! Rendering: joins the eye's kernels (`psf`) with the GPU layer (`gpu`).

pub mod reference;
pub mod slices;
pub mod splat;
