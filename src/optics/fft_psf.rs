//! PSF by sampling the pupil function on a square grid and transforming it (FFT): the method
//! for wavefronts whose β expansion would need a very high degree (several µm of astigmatism,
//! keratoconus at large pupils), whose cost does not grow with the size of the aberration but
//! only with the grid.
//!
//! Same amplitude and orientation as [`super::psf`]: U(x, y) = (1/π)∫∫ P e^{ifρ²}
//! e^{i2π(xρcosθ + yρsinθ)} d²ρ, (x, y) in λ/NA, row 0 at +y, the optical axis at the centre
//! sample, 1 = the unaberrated in-focus peak.
//!
//! # Sampling
//! On a pupil grid of step du (pupil radius = 1) the sum Σ P e^{i2πx·u} du²/π is periodic in x
//! with period L = 1/du. With an output pitch p, an FFT of length N = L/p returns U at x = k·p.
//! L is chosen larger than the output grid by a guard band (the light beyond the grid that
//! wraps around is that far away), which also keeps the phase resolved: a ray that lands at
//! x in λ/NA has a phase slope 2πx per unit ρ, and the grid covers every ray of the caller's
//! extent, so the phase advances by less than π/2 per pupil sample. The pupil edge is
//! anti-aliased (each sample weighted by the fraction of its cell inside the disk, to first
//! order in du), and the sum is normalised by the sampled area, so that an unaberrated pupil
//! has U(0) = 1 exactly.

use super::error::{check_range, OpticsError};
use super::zernike::wavefront;
use num_complex::Complex32;
use rustfft::FftPlanner;
use std::f64::consts::PI;

/// Fewest pupil samples across the diameter: fewer would let the staircase of the pupil
/// edge scatter a visible part of the light.
pub const MIN_PUPIL_SAMPLES: f64 = 256.0;

/// Largest FFT length accepted (memory: the pruned transform keeps (2·A + 1)·size values).
pub const MAX_FFT_LEN: usize = 16384;

/// FFT length and pupil step for an output grid of `size` samples at `pitch` λ/NA.
pub fn fft_layout(pitch: f64, size: usize) -> (usize, f64) {
    let extent = size as f64 * pitch;
    let period = (1.25 * extent + 8.0).max(0.5 * MIN_PUPIL_SAMPLES);
    let n = fast_len((period / pitch).ceil() as usize);
    (n, 1.0 / (n as f64 * pitch))
}

/// The smallest 2^a·3^b·5^c ≥ `n` (rustfft is fastest on such lengths).
fn fast_len(n: usize) -> usize {
    let mut best = n.next_power_of_two();
    let mut p5 = 1;
    while p5 < best {
        let mut p3 = p5;
        while p3 < best {
            let mut p2 = p3;
            while p2 < n {
                p2 *= 2;
            }
            best = best.min(p2);
            p3 *= 3;
        }
        p5 *= 5;
    }
    best
}

/// Estimated cost of [`psf_by_fft`] in the units of the ENZ cost model (one unit ≈ one
/// complex multiply-add): the pupil samples plus the two pruned transform passes.
pub fn fft_cost(pitch: f64, size: usize) -> f64 {
    let (n, du) = fft_layout(pitch, size);
    let rows = 2.0 * (1.0 / du + 1.0).floor() + 1.0;
    let log = (n as f64).log2();
    rows * rows * 12.0 + (rows + size as f64) * n as f64 * log * 2.5 + (size * size) as f64
}

/// Intensity on a `size`² grid (odd size) at `pitch` λ/NA for the wavefront `alpha_um` (OSA,
/// µm, with piston, tilt and c(2,0) removed: defocus is `defocus_f`).
pub fn psf_by_fft(
    alpha_um: &[f64],
    wavelength_nm: f64,
    defocus_f: f64,
    pitch: f64,
    size: usize,
) -> Result<Vec<f64>, OpticsError> {
    check_range("pitch", pitch, 1e-4, 1e3, "1e-4 to 1000 lambda/NA")?;
    check_range("defocus_f", defocus_f, -1e5, 1e5, "|f| <= 1e5")?;
    check_range(
        "wavelength_nm",
        wavelength_nm,
        350.0,
        1100.0,
        "350 to 1100 nm",
    )?;
    let (n, du) = fft_layout(pitch, size);
    if n > MAX_FFT_LEN || size.is_multiple_of(2) || size > n {
        return Err(OpticsError::OutOfRange {
            field: "FFT grid".into(),
            value: n as f64,
            allowed: "an odd size and an FFT of at most 16384 samples per side",
        });
    }
    let half = (size / 2) as i64;
    let a_max = (1.0 / du + 1.0).floor() as i64;
    let k2pi = 2.0 * PI / (wavelength_nm * 1e-3);
    // single precision: the amplitude's rounding (~1e-7 of its peak) is far below
    // anything a kernel (stored as f32) can show
    let plan = FftPlanner::<f32>::new().plan_fft_inverse(n);
    let mut scratch = vec![Complex32::default(); plan.get_inplace_scratch_len()];
    let rows = (2 * a_max + 1) as usize;
    // tmp[k][row]: after the x pass, output column k (offset −half..=half) for each pupil row
    let mut tmp = vec![Complex32::default(); size * rows];
    let mut buf = vec![Complex32::default(); n];
    let mut area = 0.0;
    let order_nodes = row_nodes(alpha_um);
    let mut newton = vec![0.0; order_nodes.len()];
    for (ri, b) in (-a_max..=a_max).enumerate() {
        let v = b as f64 * du;
        if v.abs() > 1.0 + du {
            continue;
        }
        row_newton(alpha_um, v, &order_nodes, &mut newton);
        buf.iter_mut().for_each(|c| *c = Complex32::default());
        let mut any = false;
        for a in -a_max..=a_max {
            let u = a as f64 * du;
            let r = u.hypot(v);
            let w = coverage(u, v, r, du);
            if w <= 0.0 {
                continue;
            }
            any = true;
            area += w;
            let wf = newton_eval(&order_nodes, &newton, u);
            let phase = k2pi * wf + defocus_f * r * r;
            // a pupil wider than the period (pitch > ½) folds onto itself: the DFT sums it
            let (sin, cos) = phase.sin_cos();
            buf[a.rem_euclid(n as i64) as usize] +=
                Complex32::new((w * cos) as f32, (w * sin) as f32);
        }
        if !any {
            continue;
        }
        plan.process_with_scratch(&mut buf, &mut scratch);
        for k in -half..=half {
            tmp[(k + half) as usize * rows + ri] = buf[k.rem_euclid(n as i64) as usize];
        }
    }
    if area <= 0.0 {
        return Err(OpticsError::OutOfRange {
            field: "pupil sampling".into(),
            value: du,
            allowed: "a pupil step below 1",
        });
    }
    let norm = 1.0 / (area * area);
    let mut out = vec![0.0; size * size];
    for k in 0..size {
        buf.iter_mut().for_each(|c| *c = Complex32::default());
        for (ri, b) in (-a_max..=a_max).enumerate() {
            buf[b.rem_euclid(n as i64) as usize] += tmp[k * rows + ri];
        }
        plan.process_with_scratch(&mut buf, &mut scratch);
        for l in -half..=half {
            let row = (half - l) as usize;
            out[row * size + k] = f64::from(buf[l.rem_euclid(n as i64) as usize].norm_sqr()) * norm;
        }
    }
    Ok(out)
}

/// Fraction of the pupil cell of side `du` at (u, v) (radius r) inside the unit disk, to first
/// order: the edge is a straight line across the cell, whose width along the normal is
/// du·(|cos| + |sin|).
fn coverage(u: f64, v: f64, r: f64, du: f64) -> f64 {
    if r == 0.0 {
        return 1.0;
    }
    let width = du * (u.abs() + v.abs()) / r;
    (0.5 + (1.0 - r) / width).clamp(0.0, 1.0)
}

/// Chebyshev nodes in x on which each pupil row's wavefront (a polynomial of the wavefront's
/// order in x) is interpolated exactly.
fn row_nodes(alpha_um: &[f64]) -> Vec<f64> {
    let order = super::zernike::order_for_len(alpha_um.len()) as usize;
    let k = order + 1;
    (0..k)
        .map(|i| 1.1 * ((2 * i + 1) as f64 * PI / (2 * k) as f64).cos())
        .collect()
}

/// Newton divided differences of W(·, v) on `nodes`.
fn row_newton(alpha_um: &[f64], v: f64, nodes: &[f64], out: &mut [f64]) {
    for (o, &x) in out.iter_mut().zip(nodes) {
        *o = wavefront(alpha_um, x, v);
    }
    for j in 1..nodes.len() {
        for i in (j..nodes.len()).rev() {
            out[i] = (out[i] - out[i - 1]) / (nodes[i] - nodes[i - j]);
        }
    }
}

fn newton_eval(nodes: &[f64], coef: &[f64], x: f64) -> f64 {
    let mut acc = 0.0;
    for i in (0..coef.len()).rev() {
        acc = acc * (x - nodes[i]) + coef[i];
    }
    acc
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rows_interpolate_the_wavefront_exactly() {
        let alpha: Vec<f64> = (0..28).map(|j| ((j * 7 % 11) as f64 - 5.0) * 0.1).collect();
        let nodes = row_nodes(&alpha);
        let mut c = vec![0.0; nodes.len()];
        for v in [-1.0, -0.3, 0.0, 0.77] {
            row_newton(&alpha, v, &nodes, &mut c);
            for u in [-1.0, -0.5, 0.1, 0.9, 1.02] {
                let d = newton_eval(&nodes, &c, u) - wavefront(&alpha, u, v);
                assert!(d.abs() < 1e-11, "{u} {v} {d}");
            }
        }
    }

    #[test]
    fn unaberrated_peak_and_energy() {
        let (p, size) = (0.125, 161);
        let i = psf_by_fft(&[0.0; 15], 550.0, 0.0, p, size).unwrap();
        let c = size / 2;
        assert!((i[c * size + c] - 1.0).abs() < 1e-5);
        // Σ I p² π = encircled energy within ±10 λ/NA: about 1 − 1/(π²·10)·(4/π) for the
        // square (Airy tail)
        let e: f64 = i.iter().sum::<f64>() * p * p * PI;
        assert!(e > 0.98 && e < 1.0, "{e}");
        // first dark ring of the Airy pattern at 0.61 λ/NA
        let at = |x: f64| {
            let k = (x / p).round() as usize;
            i[c * size + c + k]
        };
        assert!(at(0.625) < 2e-3, "{}", at(0.625));
    }

    #[test]
    fn fast_lengths() {
        assert_eq!(fast_len(1000), 1000);
        assert_eq!(fast_len(1001), 1024);
        assert_eq!(fast_len(7), 8);
        assert_eq!(fast_len(1025), 1080);
    }
}
