//! Kernels over the visual field: one kernel grid per field direction (h, v), each computed
//! like an on-axis grid from the eye traced for that direction ([`crate::eye::field`]).
//!
//! # The elliptical pupil
//! Off axis the aberrations are fitted over the unit disc a stretch S maps onto the pupil
//! ellipse (physical pupil point q = R·S·u, R the on-axis pupil radius). Two things follow,
//! both exact for Fraunhofer diffraction:
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

use super::axes::{GridAxes, KernelSettings, Screen};
use super::cache::{grid_key, key_of};
use super::defocus::{ChannelOptics, ColumnOptics};
use super::grid::{kernels_from_columns, GridReport, Progress, Stage};
use super::kernels::KernelGrid;
use super::project::{crop, pitch_lambda_na, CroppedPsf, PsfMethod, MAX_PSF_SIDE};
use crate::eye::field::{check_field_deg, FieldPupil};
use crate::eye::Eye;
use crate::optics::fft_psf::psf_by_fft;
use crate::optics::zernike::{osa_index, wavefront_gradient};
use crate::{Error, Result};
use rayon::prelude::*;
use std::f64::consts::PI;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::time::Instant;

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

/// Accommodates `eye` for (pupil, focus) on axis and measures it at each wavelength for the
/// field direction `field_deg`, with the object at the focus distance.
pub fn field_column(
    eye: &Eye,
    pupil_mm: f64,
    focus_d: f64,
    wavelengths_nm: [f64; 3],
    settings: &KernelSettings,
    field_deg: [f64; 2],
) -> Result<ColumnOptics> {
    ColumnOptics::new_in_field(eye, pupil_mm, focus_d, wavelengths_nm, settings, field_deg)
}

/// Geometric half-extent (λ/NA of the disc) of the rays of wavefront `alpha_um` at defocus f.
fn ray_extent(alpha_um: &[f64], wavelength_nm: f64, f: f64) -> f64 {
    let lam_um = wavelength_nm * 1e-3;
    let k = f / PI;
    let mut worst = 0.0f64;
    let rings = 24;
    for ring in 1..=rings {
        let rho = ring as f64 / rings as f64;
        let spokes = 8 + 4 * ring;
        for j in 0..spokes {
            let th = 2.0 * PI * j as f64 / spokes as f64;
            let (x, y) = (rho * th.cos(), rho * th.sin());
            let (gx, gy) = wavefront_gradient(alpha_um, x, y);
            worst = worst.max((gx / lam_um + k * x).abs().max((gy / lam_um + k * y).abs()));
        }
    }
    worst
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

/// A field axis: `count` angles from `lo` to `hi` degrees.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct FieldAxes {
    pub h_deg: Vec<f64>,
    pub v_deg: Vec<f64>,
}

impl FieldAxes {
    /// Every (h, v), h-major.
    pub fn nodes(&self) -> Vec<[f64; 2]> {
        self.h_deg
            .iter()
            .flat_map(|&h| self.v_deg.iter().map(move |&v| [h, v]))
            .collect()
    }

    /// Parses `H0..H1:N,V0..V1:M` (degrees; N, M in 1–31; a count of 1 takes H0).
    pub fn parse(text: &str) -> std::result::Result<FieldAxes, String> {
        let allowed = "H0..H1:N,V0..V1:M in degrees, each axis within ±60°, N and M 1 to 31, \
                       every node at most 60° from the axis";
        let bad = || format!("--field-deg {text:?} is not allowed; need {allowed}");
        let parts: Vec<&str> = text.split(',').collect();
        if parts.len() != 2 {
            return Err(bad());
        }
        let axis = |p: &str| -> Option<Vec<f64>> {
            let (range, n) = p.trim().split_once(':')?;
            let (lo, hi) = range.split_once("..")?;
            let (lo, hi): (f64, f64) = (lo.trim().parse().ok()?, hi.trim().parse().ok()?);
            let n: usize = n.trim().parse().ok()?;
            let ok = lo.is_finite() && hi.is_finite() && (1..=31).contains(&n);
            if !ok || (n > 1 && hi <= lo) {
                return None;
            }
            Some(super::axes::linspace(lo, hi, n))
        };
        let axes = FieldAxes {
            h_deg: axis(parts[0]).ok_or_else(bad)?,
            v_deg: axis(parts[1]).ok_or_else(bad)?,
        };
        if axes.nodes().iter().any(|&n| check_field_deg(n).is_err()) {
            return Err(bad());
        }
        Ok(axes)
    }
}

/// Half-extents (h, v) in degrees of the field a pinhole frame shows: v = fov_y/2 and
/// tan h = tan(fov_y/2)·width/height.
pub fn frame_half_field_deg(fov_y_deg: f64, width_px: u32, height_px: u32) -> [f64; 2] {
    let t = (0.5 * fov_y_deg).to_radians().tan();
    let aspect = width_px as f64 / height_px as f64;
    [(t * aspect).atan().to_degrees(), 0.5 * fov_y_deg]
}

/// The cache key of the grid of one field direction.
pub fn field_grid_key(
    eye: &Eye,
    axes: &GridAxes,
    screen: &Screen,
    settings: &KernelSettings,
    field_deg: [f64; 2],
) -> String {
    let base = grid_key(eye, axes, screen, settings);
    if field_deg == [0.0, 0.0] {
        return base;
    }
    key_of(&[&base, &format!("field {:?}", field_deg)])
}

/// The kernel grid of one field direction: the on-axis grid at (0, 0).
pub fn compute_field_grid(
    eye: &Eye,
    axes: &GridAxes,
    screen: &Screen,
    settings: &KernelSettings,
    field_deg: [f64; 2],
    progress: Progress,
) -> Result<(KernelGrid, GridReport)> {
    check_field_deg(field_deg).map_err(|e| Error::input(e.to_string()))?;
    axes.validate().map_err(Error::input)?;
    settings.validate().map_err(Error::input)?;
    let t0 = Instant::now();
    let pairs: Vec<(f64, f64)> = axes
        .pupils_mm
        .iter()
        .flat_map(|&p| axes.focus_d.iter().map(move |&f| (p, f)))
        .collect();
    let done = AtomicUsize::new(0);
    let columns = pairs
        .par_iter()
        .map(|&(p, f)| {
            let c = field_column(eye, p, f, axes.wavelengths_nm, settings, field_deg);
            progress(
                Stage::Optics,
                done.fetch_add(1, Ordering::Relaxed) + 1,
                pairs.len(),
            );
            c
        })
        .collect::<Result<Vec<_>>>()?;
    let seconds_optics = t0.elapsed().as_secs_f64();
    let (grid, mut report) = kernels_from_columns(&columns, axes, screen, settings, progress)?;
    report.seconds_optics = seconds_optics;
    Ok((grid, report))
}
