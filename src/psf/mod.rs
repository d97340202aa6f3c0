//! Point-spread functions turned into screen-space kernels (pure numerics, no GPU).

pub mod kernels;
