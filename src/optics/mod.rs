//! Pure optics numerics: no I/O, no GPU.
//!
//! - [`zernike`]: OSA/ANSI Zernike algebra (std only; compiled on its own by the eye model).
//! - [`prescription`]: sphere / cylinder / axis and its second-order Zernike terms.
//! - [`bessel`]: J_n and spherical j_k by Miller recurrence.
//! - [`quadrature`]: Gauss–Legendre, Fejér (cosine-sampled pupil) rules.
//! - [`enz`]: V_n^m(r, f) (Bessel–Bessel series, power series, quadrature) and radial tables.
//! - [`beta`]: ENZ pupil coefficients β from wavefront coefficients α.
//! - [`amplitude`]: the ENZ amplitude U (the optical field) of one pupil at one defocus, on
//!   grids: per-order radial coefficients and interpolation tables.
//! - [`fft_psf`]: the PSF by FFT of the sampled pupil function (large aberrations).
//! - [`psf`]: the high-level PSF entry point ([`PsfRequest`] → [`Psf`]).
//!
//! The submodules are private and the `pub use` items below are the module's public surface,
//! except [`zernike`], which stays public: its Zernike algebra (indexing, radial polynomials,
//! bases, fits, rescaling, [`zernike::Prescription`]) is one namespace that tests and the
//! other modules use as a whole.

pub(crate) mod amplitude;
pub(crate) mod bessel;
pub(crate) mod beta;
pub(crate) mod enz;
mod error;
pub(crate) mod fft_psf;
pub(crate) mod prescription;
pub(crate) mod psf;
pub(crate) mod pupil;
pub(crate) mod quadrature;
pub mod zernike;

// Bessel functions.
pub use bessel::{bessel_j, bessel_j_sequence, spherical_j, spherical_j_sequence};
// Quadrature rules.
pub use quadrature::gauss_legendre_01;
// V_n^m(r, f) and its tables.
pub use enz::{
    interpolation_step, quadrature_nodes, try_vnm, vnm, vnm_power_series, vnm_quadrature,
    vnm_quadrature_all, VTable,
};
// ENZ pupil coefficients and the amplitude they give.
pub use amplitude::RadialAmplitude;
pub use beta::{beta_from_alpha, StilesCrawford};
// PSFs: the high-level entry point and the FFT path.
pub use fft_psf::{fft_cost, psf_by_fft};
pub use psf::{
    compute_psf, defocus_f_from_c20, defocus_f_from_dioptres, expand_pupil, psf_from_pupil,
    split_wavefront, Psf, PsfRequest,
};

pub use error::OpticsError;
