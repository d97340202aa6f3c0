//! A channel's PSF anywhere in the field: on axis [`super::project`]'s, off axis the disc's PSF
//! resampled onto the elliptical pupil ([`super::field_shape`]). Kept apart from the on-axis
//! sampling so that it depends on it, not the reverse.
//!
//! # The elliptical pupil
//! Two things follow from the stretch S, both exact for Fraunhofer diffraction:
//! - The PSF: U_phys(x) ∝ U_disc(S·x) with x in λ/NA of the on-axis pupil, so the disc's PSF
//!   (computed as on axis) is resampled through S: a pupil narrowed tangentially widens the
//!   PSF tangentially.
//! - The defocus of an object off the focus distance adds (ΔD/2)|q|² = (ΔD·R²/2)·uᵀS²u in
//!   normalised coordinates: an isotropic part (the ENZ defocus f, scaled by the mean of S²)
//!   and an astigmatic part that changes with the object, added to the wavefront of each PSF.
//!   Treating it as isotropic in the disc would invert the blur ellipse of a defocused point.
//!
//! These PSFs are computed by FFT of the sampled pupil (the per-object astigmatism rules out
//! the shared β expansion of the ENZ path).

use super::axes::{KernelSettings, Screen};
use super::defocus::{ring_gradients, ChannelOptics};
use super::field_shape::FieldShape;
use super::project::{
    crop, cropped_psf_at_f, pitch_lambda_na, CroppedPsf, PsfMethod, MAX_PSF_SIDE,
};
use crate::optics::fft_psf::psf_by_fft;
use crate::optics::zernike::osa_index;
use crate::Result;
use std::f64::consts::PI;

/// Computes the PSF of `ch` for an object at `object_d` dioptres and crops it.
pub fn cropped_psf(
    ch: &ChannelOptics,
    object_d: f64,
    screen: &Screen,
    settings: &KernelSettings,
) -> Result<CroppedPsf> {
    if let Some(shape) = &ch.field {
        return cropped_field_psf(ch, shape, object_d, screen, settings);
    }
    let f = ch.defocus_f(object_d);
    cropped_psf_at_f(ch, f, screen, settings)
}

/// Geometric half-extent (λ/NA of the disc) of the rays of wavefront `alpha_um` at defocus f.
fn ray_extent(alpha_um: &[f64], wavelength_nm: f64, f: f64) -> f64 {
    let lam_um = wavelength_nm * 1e-3;
    let k = f / PI;
    ring_gradients(alpha_um, 24).fold(0.0f64, |worst, ([x, y], (gx, gy))| {
        worst.max((gx / lam_um + k * x).abs().max((gy / lam_um + k * y).abs()))
    })
}

/// The PSF of an off-axis channel for an object at `object_d` dioptres, on the physical
/// (elliptical-pupil) angular grid, cropped like an on-axis one.
pub fn cropped_field_psf(
    ch: &ChannelOptics,
    shape: &FieldShape,
    object_d: f64,
    screen: &Screen,
    settings: &KernelSettings,
) -> Result<CroppedPsf> {
    let f = ch.defocus_f(object_d);
    let delta = ch.focus_vergence - ch.vergence_at_pupil(object_d);
    let mut alpha = ch.alpha_um.clone();
    let (c22, c2m2) = shape.object_astigmatism_um(delta, ch.pupil_mm);
    alpha[osa_index(2, 2)] += c22;
    alpha[osa_index(2, -2)] += c2m2;
    let s = &shape.stretch;
    // Smallest stretch: the physical grid must reach the disc's extent divided by it.
    let tr = s[0][0] + s[1][1];
    let det = s[0][0] * s[1][1] - s[0][1] * s[1][0];
    let s_min = 0.5 * (tr - (tr * tr - 4.0 * det).max(0.0).sqrt());
    let pitch_phys = pitch_lambda_na(ch, screen, settings);
    let mut pitch = pitch_phys * s_min;
    let half_extent =
        ray_extent(&alpha, ch.wavelength_nm, f) * 1.02 + settings.diffraction_margin + pitch_phys;
    let mut half = (half_extent / pitch).ceil() as usize;
    if 2 * half + 1 > MAX_PSF_SIDE {
        half = MAX_PSF_SIDE / 2;
        pitch = half_extent / half as f64;
    }
    let size = 2 * half + 1;
    let disc = psf_by_fft(&alpha, ch.wavelength_nm, f, pitch, size)?;
    // Physical grid at the same density: pitch · (1/s_min) spans the same samples.
    let pitch_p = pitch / s_min;
    let half_p = ((half_extent / s_min) / pitch_p).ceil() as usize;
    let side_p = 2 * half_p + 1;
    let c = half as f64;
    let sample = |xn: f64, yn: f64| {
        let (col, row) = (xn / pitch + c, c - yn / pitch);
        if col < 0.0 || row < 0.0 || col >= (size - 1) as f64 || row >= (size - 1) as f64 {
            return 0.0;
        }
        let (i, j) = (col.floor(), row.floor());
        let (fx, fy) = (col - i, row - j);
        let at = |jj: usize, ii: usize| disc[jj * size + ii];
        let (i, j) = (i as usize, j as usize);
        (1.0 - fy) * ((1.0 - fx) * at(j, i) + fx * at(j, i + 1))
            + fy * ((1.0 - fx) * at(j + 1, i) + fx * at(j + 1, i + 1))
    };
    let mut phys = vec![0.0; side_p * side_p];
    for (row, line) in phys.chunks_mut(side_p).enumerate() {
        let y = (half_p as f64 - row as f64) * pitch_p;
        for (col, v) in line.iter_mut().enumerate() {
            let x = (col as f64 - half_p as f64) * pitch_p;
            *v = sample(s[0][0] * x + s[0][1] * y, s[1][0] * x + s[1][1] * y) * det;
        }
    }
    let pixels_per_sample = pitch_p * ch.radians_per_lambda_na() * screen.px_per_radian();
    let mut p = crop(&phys, side_p, settings.energy, pixels_per_sample, f);
    p.pitch_lambda_na = pitch_p;
    p.method = PsfMethod::Fft;
    p.missed_energy = 0.0;
    Ok(p)
}
