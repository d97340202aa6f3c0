//! The elliptical pupil of a field direction: off axis the aberrations are fitted over the unit
//! disc a stretch S maps onto the pupil ellipse (physical pupil point q = R·S·u, R the on-axis
//! pupil radius). What follows from it for the PSF and the defocus is in [`super::field_psf`].
//!
//! A channel's state ([`super::defocus::ChannelOptics`]) carries this shape, so it sits below
//! the on-axis modules and needs nothing of theirs.

use crate::eye::field::FieldPupil;

/// How a field direction's pupil maps onto the unit disc.
#[derive(Clone, Debug, PartialEq)]
pub struct FieldShape {
    pub field_deg: [f64; 2],
    /// S: symmetric, in the pupil-plane basis (e₁, e₂); the ellipse is R·S·(unit disc).
    pub stretch: [[f64; 2]; 2],
}

impl FieldShape {
    /// From a measured field pupil: S = (a_t/R)·t tᵀ + (a_s/R)·s sᵀ.
    pub fn from_pupil(p: &FieldPupil, pupil_mm: f64) -> FieldShape {
        let r = pupil_mm / 2.0;
        let (st, ss) = (p.semi_axes_mm[0] / r, p.semi_axes_mm[1] / r);
        let a = p.tangential_axis_deg.to_radians();
        let (t, s) = ([a.cos(), a.sin()], [-a.sin(), a.cos()]);
        let m = |i: usize, j: usize| st * t[i] * t[j] + ss * s[i] * s[j];
        FieldShape {
            field_deg: p.field_deg,
            stretch: [[m(0, 0), m(0, 1)], [m(1, 0), m(1, 1)]],
        }
    }

    fn squared(&self) -> [[f64; 2]; 2] {
        let s = &self.stretch;
        let m = |i: usize, j: usize| s[i][0] * s[0][j] + s[i][1] * s[1][j];
        [[m(0, 0), m(0, 1)], [m(1, 0), m(1, 1)]]
    }

    /// Mean of S² over directions: scales the isotropic defocus of an object.
    pub fn mean_square(&self) -> f64 {
        let q = self.squared();
        0.5 * (q[0][0] + q[1][1])
    }

    /// The astigmatic part of an object's defocus, c(2,2) and c(2,−2) in µm, for a vergence
    /// difference `delta` (1/m, focus minus object) over a pupil of `pupil_mm`.
    pub fn object_astigmatism_um(&self, delta: f64, pupil_mm: f64) -> (f64, f64) {
        let q = self.squared();
        let r2 = (0.5e-3 * pupil_mm).powi(2);
        let k = 1e6 * 0.5 * delta * r2 / 6f64.sqrt();
        (k * 0.5 * (q[0][0] - q[1][1]), k * q[0][1])
    }
}
