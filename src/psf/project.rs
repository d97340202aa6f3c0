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

use super::axes::{KernelSettings, Screen};
use super::defocus::ChannelOptics;
use crate::optics::psf::{pitch_from_arcmin, psf_from_pupil, PsfRequest};
use crate::Result;

/// Largest PSF grid side; beyond it the pitch grows (the kernels are far coarser anyway).
pub const MAX_PSF_SIDE: usize = 2047;

/// A PSF cropped to its energy square, centred on the optical axis (the chief ray).
#[derive(Clone, Debug, PartialEq)]
pub struct CroppedPsf {
    /// Samples per side: 2·half + 1, in PSF-grid orientation (row 0 at +y).
    pub half: usize,
    pub values: Vec<f32>,
    /// Natural half-width of the energy square in samples (fractional: the crossing of the
    /// energy fraction interpolated between whole rings), ≤ half + 0.5.
    pub natural_half_samples: f64,
    /// Sample pitch in screen pixels.
    pub pixels_per_sample: f64,
    /// Fraction of the grid's energy inside the cropped square.
    pub kept_energy: f64,
    /// Total defocus f used and the grid side the PSF was computed on.
    pub defocus_f: f64,
    pub grid_side: usize,
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

    /// Resamples to a kernel of integer `radius` whose half-width r + 0.5 covers the PSF's
    /// natural half-width scaled to `support_px` (the natural radius plus 0.5 for the grid's
    /// own kernels; any size for the exact ones). Screen orientation, normalised to sum 1.
    pub fn resample(&self, radius: u32, support_px: f64) -> Vec<f64> {
        let side_out = 2 * radius as usize + 1;
        if radius == 0 || support_px <= 0.0 {
            let mut v = vec![0.0; side_out * side_out];
            v[side_out * side_out / 2] = 1.0;
            return v;
        }
        // samples per output pixel
        let scale = self.natural_half_samples / support_px;
        let n = self.side();
        let k = self.half as f64;
        // Output pixel i covers offsets [i − r − ½, i − r + ½]·scale (samples); sample c covers
        // [c − k − ½, c − k + ½]. Rows use the same offsets with the sign of y flipped.
        let weights = |flip: bool| -> Vec<(usize, Vec<f64>)> {
            (0..side_out)
                .map(|i| {
                    let u = i as f64 - radius as f64;
                    let (a, b) = ((u - 0.5) * scale, (u + 0.5) * scale);
                    // sample offsets s in [a, b]: index = k + s (columns), k − s (rows)
                    let lo = (a + k - 0.5).floor().max(0.0) as usize;
                    let hi = ((b + k + 0.5).ceil() as usize).min(n - 1);
                    let mut w = Vec::new();
                    if b + k + 0.5 <= 0.0 || a + k - 0.5 >= (n - 1) as f64 || lo > hi {
                        return (0, w);
                    }
                    for c in lo..=hi {
                        let s = c as f64 - k;
                        let ov = (b.min(s + 0.5) - a.max(s - 0.5)).max(0.0);
                        w.push(ov);
                    }
                    if flip {
                        // rows: sample row q has y = k − q, so offset s ↔ row k − s:
                        // reverse the run
                        w.reverse();
                        let first = n - 1 - hi;
                        (first, w)
                    } else {
                        (lo, w)
                    }
                })
                .collect()
        };
        let wx = weights(false);
        let wy = weights(true);
        // rows of the PSF reduced along x first
        let mut tmp = vec![0.0f64; n * side_out];
        for q in 0..n {
            let row = &self.values[q * n..(q + 1) * n];
            let out = &mut tmp[q * side_out..(q + 1) * side_out];
            for (i, (start, w)) in wx.iter().enumerate() {
                out[i] = w
                    .iter()
                    .zip(&row[*start..])
                    .map(|(a, b)| a * f64::from(*b))
                    .sum();
            }
        }
        let mut out = vec![0.0f64; side_out * side_out];
        for (j, (start, w)) in wy.iter().enumerate() {
            for (t, wq) in w.iter().enumerate() {
                if *wq == 0.0 {
                    continue;
                }
                let src = &tmp[(start + t) * side_out..(start + t + 1) * side_out];
                for (o, s) in out[j * side_out..(j + 1) * side_out].iter_mut().zip(src) {
                    *o += wq * s;
                }
            }
        }
        // Binning into whole pixels moves the first moment by up to half a pixel when the PSF
        // is narrow; a bilinear sub-pixel shift (mass-preserving) puts it back where the
        // samples inside the window have it.
        let (_, mx) = axis_moments(&wx, n, side_out, radius, scale, false);
        let (ty, my) = axis_moments(&wy, n, side_out, radius, scale, true);
        let (mut m, mut xm, mut ym) = (0.0, 0.0, 0.0);
        for q in 0..n {
            if ty[q] == 0.0 && my[q] == 0.0 {
                continue;
            }
            let row = &self.values[q * n..(q + 1) * n];
            // Σ_c v·tx[c] is the row's total after the x pass
            let a: f64 = tmp[q * side_out..(q + 1) * side_out].iter().sum();
            let b: f64 = row.iter().zip(&mx).map(|(v, w)| f64::from(*v) * w).sum();
            m += ty[q] * a;
            xm += ty[q] * b;
            ym += my[q] * a;
        }
        if m > 0.0 && m.is_finite() {
            let (gx, gy) = first_moment(&out, side_out);
            let total: f64 = out.iter().sum();
            if total > 0.0 {
                shift(&mut out, side_out, xm / m - gx / total, false);
                shift(&mut out, side_out, ym / m - gy / total, true);
            }
        }
        let total: f64 = out.iter().sum();
        if total > 0.0 && total.is_finite() {
            out.iter_mut().for_each(|v| *v /= total);
        } else {
            out.iter_mut().for_each(|v| *v = 0.0);
            out[side_out * side_out / 2] = 1.0;
        }
        out
    }
}

/// Per sample index along one axis: the part of its unit box inside the kernel window, and
/// that part's first moment in output pixels. `runs` are the resampling weights (see
/// [`CroppedPsf::resample`]); rows (`flip`) run opposite to the offsets.
fn axis_moments(
    runs: &[(usize, Vec<f64>)],
    n: usize,
    side_out: usize,
    radius: u32,
    scale: f64,
    flip: bool,
) -> (Vec<f64>, Vec<f64>) {
    let mut tot = vec![0.0; n];
    let mut mom = vec![0.0; n];
    let k = (n / 2) as f64;
    for (i, (start, w)) in runs.iter().enumerate().take(side_out) {
        let u = i as f64 - radius as f64;
        let (a, b) = ((u - 0.5) * scale, (u + 0.5) * scale);
        for (t, wt) in w.iter().enumerate() {
            if *wt <= 0.0 {
                continue;
            }
            let idx = start + t;
            let s = if flip { k - idx as f64 } else { idx as f64 - k };
            let (lo, hi) = (a.max(s - 0.5), b.min(s + 0.5));
            tot[idx] += wt;
            mom[idx] += wt * 0.5 * (lo + hi) / scale;
        }
    }
    (tot, mom)
}

/// Σ v·dx and Σ v·dy (screen axes, pixels from the centre) of a square kernel.
fn first_moment(values: &[f64], side: usize) -> (f64, f64) {
    let c = (side / 2) as f64;
    let (mut x, mut y) = (0.0, 0.0);
    for (t, v) in values.iter().enumerate() {
        x += v * ((t % side) as f64 - c);
        y += v * ((t / side) as f64 - c);
    }
    (x, y)
}

/// Moves a square kernel's mass by `delta` pixels (|delta| < 1) along x or y (`vertical`),
/// linearly between neighbours: the first moment moves by exactly `delta`.
fn shift(values: &mut [f64], side: usize, delta: f64, vertical: bool) {
    let t = delta.abs().min(1.0);
    if t == 0.0 || !t.is_finite() {
        return;
    }
    let step: isize = if delta > 0.0 { 1 } else { -1 };
    let old = values.to_vec();
    for j in 0..side {
        for i in 0..side {
            let (pi, pj) = if vertical {
                (i as isize, j as isize - step)
            } else {
                (i as isize - step, j as isize)
            };
            let from = if (0..side as isize).contains(&pi) && (0..side as isize).contains(&pj) {
                old[pj as usize * side + pi as usize]
            } else {
                0.0
            };
            values[j * side + i] = (1.0 - t) * old[j * side + i] + t * from;
        }
    }
}

/// The sample pitch (λ/NA) for a channel and screen: the finest of the retinal sample size,
/// N samples per 2π of defocus, and `samples_per_pixel` per output pixel.
pub fn pitch_lambda_na(ch: &ChannelOptics, screen: &Screen, settings: &KernelSettings) -> f64 {
    let retinal = pitch_from_arcmin(
        60.0 * settings.sample_um / settings.um_per_deg,
        ch.pupil_mm,
        ch.wavelength_nm,
    );
    let per_2pi = 4.0 / settings.samples_per_2pi;
    let pixel = 1.0 / (screen.px_per_radian() * ch.radians_per_lambda_na());
    retinal.min(per_2pi).min(pixel / settings.samples_per_pixel)
}

/// Computes the PSF of `ch` for an object at `object_d` dioptres and crops it.
pub fn cropped_psf(
    ch: &ChannelOptics,
    object_d: f64,
    screen: &Screen,
    settings: &KernelSettings,
) -> Result<CroppedPsf> {
    let f = ch.defocus_f(object_d);
    cropped_psf_at_f(ch, f, screen, settings)
}

/// As [`cropped_psf`] for a given total defocus f.
pub fn cropped_psf_at_f(
    ch: &ChannelOptics,
    f: f64,
    screen: &Screen,
    settings: &KernelSettings,
) -> Result<CroppedPsf> {
    let mut pitch = pitch_lambda_na(ch, screen, settings);
    let half_extent = ch.ray_extent(f) * 1.02 + settings.diffraction_margin + pitch;
    let mut half = (half_extent / pitch).ceil() as usize;
    if 2 * half + 1 > MAX_PSF_SIDE {
        half = MAX_PSF_SIDE / 2;
        pitch = half_extent / half as f64;
    }
    let mut req = PsfRequest::new(
        Vec::new(),
        ch.pupil_mm,
        ch.wavelength_nm,
        pitch,
        2 * half + 1,
    );
    req.include_tilt = false;
    req.radial_tolerance = settings.radial_tolerance;
    req.beta_tolerance = settings.beta_tolerance;
    req.defocus_f = f;
    let psf = psf_from_pupil(&ch.pupil, &req)?;
    let pixels_per_sample = pitch * ch.radians_per_lambda_na() * screen.px_per_radian();
    Ok(crop(
        &psf.intensity,
        2 * half + 1,
        settings.energy,
        pixels_per_sample,
        f,
    ))
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
        let dy = q.abs_diff(c);
        for (i, v) in row.iter().enumerate() {
            rings[dy.max(i.abs_diff(c))] += v.max(0.0);
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
        kept_energy: if total > 0.0 { kept / total } else { 1.0 },
        defocus_f,
        grid_side: side,
    }
}
