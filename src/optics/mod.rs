//! Pure optics: Zernike algebra, Bessel functions and the ENZ point-spread-function engine.
//! No I/O, no GPU.

pub mod zernike;
