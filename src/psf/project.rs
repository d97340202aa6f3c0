//! From one channel's pupil at one defocus to screen kernels: sample the PSF, crop it to the
//! smallest centred square that keeps the configured energy, and resample it with area
//! weighting to any kernel radius.
//!
//! # Orientation
//! The PSF grid ([`crate::optics::psf`]) is the RETINAL image: x, y parallel to the pupil
//! axes, which are the OSA axes of the aberrations (+x to the subject's left, i.e. to the
//! right of an examiner facing the eye; +y up), row 0 at +y. The eye inverts: light that lands
//! at retinal offset (x, y) is seen as coming from the object-space direction (−x, −y). On the
//! screen the subject's right is −x (OSA) and down is −y, so a screen offset (dx right, dy down)
//! shows the retinal PSF at (x, y) = (dx, dy)·scale: the screen kernel is the PSF grid with its
//! rows reversed, columns kept. Example: coma c(3,1) > 0 has its retinal core at +x and its
//! flare towards −x, so on the screen the flare points left; c(3,−1) > 0 (retinal flare
//! towards −y) points up on the screen.

use super::axes::{KernelSettings, MethodChoice, Screen};
use super::defocus::ChannelOptics;
use super::integrate::BoxIntegrator;
use crate::optics::fft_psf::{fft_cost, psf_by_fft};
use crate::optics::psf::{pitch_from_arcmin, psf_from_pupil, PsfRequest};
use crate::Result;
use serde::Serialize;

/// Largest PSF grid side at the diffraction pitch; beyond it the pitch grows up to
/// [`KernelSettings::samples_per_pixel`] samples per screen pixel.
pub const MAX_PSF_SIDE: usize = 1025;
/// Largest PSF grid side at all (a PSF of several hundred pixels' radius).
pub const HARD_MAX_PSF_SIDE: usize = 4095;

/// Most bins per side a grid's PSF keeps for pixel integration (memory: a grid holds one set
/// of bins per PSF until the largest radius is known).
pub const MAX_BINS: usize = 512;

/// How a PSF was computed.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum PsfMethod {
    /// The ENZ series of the β expansion (its truncation is the missed pupil energy).
    Enz,
    /// The sampled pupil function, transformed ([`crate::optics::fft_psf`]).
    Fft,
}

/// A PSF cropped to its energy square, centred on the optical axis (the chief ray).
#[derive(Clone, Debug, PartialEq)]
pub struct CroppedPsf {
    /// Samples per side: 2·half + 1, in PSF-grid orientation (row 0 at +y).
    pub half: usize,
    pub values: Vec<f32>,
    /// Natural half-width of the energy square in samples (fractional: the crossing of the
    /// energy fraction interpolated between whole rings), ≤ half + 0.5.
    pub natural_half_samples: f64,
    /// Sample pitch in screen pixels and in λ/NA.
    pub pixels_per_sample: f64,
    pub pitch_lambda_na: f64,
    /// Fraction of the grid's energy inside the cropped square.
    pub kept_energy: f64,
    /// Total defocus f used and the grid side the PSF was computed on.
    pub defocus_f: f64,
    pub grid_side: usize,
    pub method: PsfMethod,
    /// Pupil energy the computation left out: the β truncation for ENZ, 0 for the sampled
    /// pupil (which keeps all of it).
    pub missed_energy: f64,
}

impl CroppedPsf {
    pub fn side(&self) -> usize {
        2 * self.half + 1
    }

    /// Natural projected radius in pixels: the energy square's half-width minus the half
    /// pixel of the centre texel (a kernel of radius r spans r + 0.5 px each way).
    pub fn natural_radius_px(&self) -> f64 {
        (self.natural_half_samples * self.pixels_per_sample - 0.5).max(0.0)
    }

    /// Prepares pixel integration for kernels up to `max_radius` at their grid scale (the
    /// natural half-width spanning r + 0.5 px), see [`BoxIntegrator`], keeping at most
    /// `max_bins` bins per side.
    pub fn integrator(&self, max_radius: u32, max_bins: usize) -> BoxIntegrator {
        self.integrator_for_scale(self.scale_for(max_radius as f64 + 0.5), max_bins)
    }

    /// As [`Self::integrator`] for pixels no smaller than `finest` samples.
    pub fn integrator_for_scale(&self, finest: f64, max_bins: usize) -> BoxIntegrator {
        // bins of a quarter λ/NA: the intensity's finest period is half a λ/NA
        let max_bin = if self.pitch_lambda_na > 0.0 {
            (0.25 / self.pitch_lambda_na).floor().max(1.0) as usize
        } else {
            1
        };
        BoxIntegrator::new(&self.values, self.side(), finest, max_bin, max_bins)
    }

    /// The kernel of integer `radius` whose half-width r + 0.5 covers the PSF's natural
    /// half-width scaled to `support_px` (the natural radius plus 0.5 for the grid's own
    /// kernels; any size for the exact ones): each texel is the PSF integrated over the
    /// pixel's area. Screen orientation, normalised to sum 1.
    pub fn resample(&self, radius: u32, support_px: f64) -> Vec<f64> {
        let scale = self.scale_for(support_px);
        self.integrator_for_scale(scale, 4 * MAX_BINS)
            .kernel(radius, scale)
    }

    /// Samples per output pixel for a kernel whose natural half-width spans `support_px`.
    pub fn scale_for(&self, support_px: f64) -> f64 {
        if support_px > 0.0 {
            self.natural_half_samples / support_px
        } else {
            0.0
        }
    }
}

/// The sample pitch (λ/NA) for a channel and screen: fine enough for diffraction (the
/// intensity is band-limited to 2 cycles per λ/NA; [`KernelSettings::samples_per_lambda_na`]
/// samples per λ/NA resolve it for the cubic interpolant the pixel integration uses) and for
/// the screen (`samples_per_pixel` per pixel), and never coarser than the retinal sample.
pub fn pitch_lambda_na(ch: &ChannelOptics, screen: &Screen, settings: &KernelSettings) -> f64 {
    let retinal = pitch_from_arcmin(
        60.0 * settings.sample_um / settings.um_per_deg,
        ch.pupil_mm,
        ch.wavelength_nm,
    );
    let per_2pi = 4.0 / settings.samples_per_2pi;
    let pixel = pixel_lambda_na(ch, screen);
    // the diffraction pitch, but never more than MAX_SAMPLES_PER_PIXEL per pixel: a pixel
    // that wide averages the intensity's finest ripples out, except at its edges
    let diffraction = (1.0 / settings.samples_per_lambda_na).max(pixel / MAX_SAMPLES_PER_PIXEL);
    retinal
        .min(per_2pi)
        .min(diffraction)
        .min(pixel / settings.samples_per_pixel)
}

/// Samples per screen pixel beyond which the diffraction pitch is relaxed.
pub const MAX_SAMPLES_PER_PIXEL: f64 = 64.0;

/// One screen pixel at the centre of the frame in λ/NA.
pub fn pixel_lambda_na(ch: &ChannelOptics, screen: &Screen) -> f64 {
    1.0 / (screen.px_per_radian() * ch.radians_per_lambda_na())
}

/// The grid a PSF at defocus f is computed on: (pitch in λ/NA, half side in samples). The grid
/// covers the geometric (ray) extent plus the diffraction margin; beyond [`MAX_PSF_SIDE`] the
/// pitch grows, but never past `samples_per_pixel / 2` samples per pixel.
pub fn psf_grid(
    ch: &ChannelOptics,
    f: f64,
    screen: &Screen,
    settings: &KernelSettings,
) -> (f64, usize) {
    let mut pitch = pitch_lambda_na(ch, screen, settings);
    let half_extent = ch.ray_extent(f) * 1.02 + settings.diffraction_margin + pitch;
    let mut half = (half_extent / pitch).ceil() as usize;
    if 2 * half + 1 > MAX_PSF_SIDE {
        let coarsest = 2.0 * pixel_lambda_na(ch, screen) / settings.samples_per_pixel;
        pitch = (half_extent / (MAX_PSF_SIDE / 2) as f64).min(coarsest.max(pitch));
        half = ((half_extent / pitch).ceil() as usize).min(HARD_MAX_PSF_SIDE / 2);
        pitch = pitch.max(half_extent / half as f64);
    }
    (pitch, half)
}

/// Estimated cost of the ENZ synthesis of a `size`² grid (the units of
/// [`crate::optics::fft_psf::fft_cost`]): every pixel sums one radial value per azimuthal
/// order, four mirror pixels at a time, and every distinct radius costs a Bessel sequence
/// and one short series per order.
pub fn enz_cost(degree: u32, size: usize) -> f64 {
    let combos = 2.0 * degree as f64 + 1.0;
    let terms = ((degree + 1) * (degree + 2) / 2) as f64;
    let pixels = (size * size) as f64;
    ENZ_PIXEL_UNITS * pixels * combos + ENZ_RADIUS_UNITS * (pixels / 8.0 + 64.0) * (terms + 40.0)
}

/// Calibration of [`enz_cost`] against [`fft_cost`] (measured with `cargo bench --bench
/// kernels -- --methods` on x86-64).
const ENZ_PIXEL_UNITS: f64 = 5.0;
const ENZ_RADIUS_UNITS: f64 = 2.0;

/// As [`super::field_psf::cropped_psf`] on axis, for a given total defocus f. The method is chosen per PSF: the ENZ
/// series where the channel's β expansion met its tolerance and is the cheaper of the two,
/// else the transform of the sampled pupil.
pub fn cropped_psf_at_f(
    ch: &ChannelOptics,
    f: f64,
    screen: &Screen,
    settings: &KernelSettings,
) -> Result<CroppedPsf> {
    let (pitch, half) = psf_grid(ch, f, screen, settings);
    let size = 2 * half + 1;
    let beta = &ch.pupil.beta;
    let converged = beta.truncation_error <= settings.beta_tolerance;
    let method = match settings.method {
        MethodChoice::Enz => PsfMethod::Enz,
        MethodChoice::Fft => PsfMethod::Fft,
        MethodChoice::Auto => {
            if converged && enz_cost(beta.degree, size) <= fft_cost(pitch, size) {
                PsfMethod::Enz
            } else {
                PsfMethod::Fft
            }
        }
    };
    let (intensity, missed) = match method {
        PsfMethod::Enz => {
            let mut req = PsfRequest::new(Vec::new(), ch.pupil_mm, ch.wavelength_nm, pitch, size);
            req.include_tilt = false;
            req.radial_tolerance = settings.radial_tolerance;
            req.beta_tolerance = settings.beta_tolerance;
            req.defocus_f = f;
            let psf = psf_from_pupil(&ch.pupil, &req)?;
            (psf.intensity, beta.truncation_error)
        }
        PsfMethod::Fft => (
            psf_by_fft(&ch.alpha_um, ch.wavelength_nm, f, pitch, size)?,
            0.0,
        ),
    };
    let pixels_per_sample = pitch * ch.radians_per_lambda_na() * screen.px_per_radian();
    let mut p = crop(&intensity, size, settings.energy, pixels_per_sample, f);
    p.pitch_lambda_na = pitch;
    p.method = method;
    p.missed_energy = missed;
    Ok(p)
}

/// Smallest centred square keeping `fraction` of the energy of a `side`² grid (odd side,
/// centre at side/2).
pub fn crop(
    intensity: &[f64],
    side: usize,
    fraction: f64,
    pixels_per_sample: f64,
    defocus_f: f64,
) -> CroppedPsf {
    let c = side / 2;
    let mut rings = vec![0.0f64; c + 1];
    for (q, row) in intensity.chunks(side).enumerate() {
        // Samples within dy of the centre column fall in ring dy; those beyond, in ring |i − c|
        // (the same ring from either side): contiguous runs, so the loops vectorise.
        let dy = q.abs_diff(c);
        rings[dy] += row[c - dy..=c + dy].iter().map(|v| v.max(0.0)).sum::<f64>();
        let outer = &mut rings[dy + 1..];
        let (left, right) = (&row[..c - dy], &row[c + dy + 1..]);
        for ((ring, l), r) in outer.iter_mut().zip(left.iter().rev()).zip(right) {
            *ring += l.max(0.0) + r.max(0.0);
        }
    }
    let total: f64 = rings.iter().sum();
    let target = fraction * total;
    let mut acc = 0.0;
    let mut k = c;
    let mut natural = c as f64 + 0.5;
    for (ring, e) in rings.iter().enumerate() {
        let before = acc;
        acc += e;
        if acc >= target {
            k = ring;
            // interpolate inside the ring: ring k > 0 adds the band from k − ½ to k + ½,
            // ring 0 the centre sample's half-width ½
            let t = if *e > 0.0 { (target - before) / e } else { 1.0 };
            natural = if ring == 0 {
                0.5 * t.clamp(0.0, 1.0)
            } else {
                ring as f64 - 0.5 + t.clamp(0.0, 1.0)
            };
            break;
        }
    }
    let n = 2 * k + 1;
    let mut values = Vec::with_capacity(n * n);
    let mut kept = 0.0;
    for q in c - k..=c + k {
        for i in c - k..=c + k {
            let v = intensity[q * side + i].max(0.0);
            kept += v;
            values.push(v as f32);
        }
    }
    CroppedPsf {
        half: k,
        values,
        natural_half_samples: natural.clamp(0.0, k as f64 + 0.5),
        pixels_per_sample,
        pitch_lambda_na: 0.0,
        kept_energy: if total > 0.0 { kept / total } else { 1.0 },
        defocus_f,
        grid_side: side,
        method: PsfMethod::Enz,
        missed_energy: 0.0,
    }
}
