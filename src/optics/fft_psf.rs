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
    // one planner per thread: a grid's PSFs share a few lengths, whose plans it keeps
    let plan = PLANNER.with(|p| p.borrow_mut().plan_fft_inverse(n));
    let mut scratch = vec![Complex32::default(); plan.get_inplace_scratch_len()];
    let rows = (2 * a_max + 1) as usize;
    // the FFT bin of pupil offset −a_max..=a_max (rows and columns alike), and of output
    // offset −half..=half: a division each, made once here rather than per sample
    let bin = |i: i64| i.rem_euclid(n as i64) as usize;
    let pupil_bins: Vec<usize> = (-a_max..=a_max).map(bin).collect();
    let out_bins: Vec<usize> = (-half..=half).map(bin).collect();
    // tmp[k][row]: after the x pass, output column k (offset −half..=half) for each pupil row.
    // Rows are transformed BLOCK at a time and written to tmp a block's run of rows at once:
    // one row at a time wrote tmp with a stride of `rows`, a cache miss per value.
    let mut tmp = vec![Complex32::default(); size * rows];
    let mut block = vec![Complex32::default(); BLOCK * size];
    let mut buf = vec![Complex32::default(); n];
    let mut area = 0.0;
    let order_nodes = row_nodes(alpha_um);
    let mut newton = vec![0.0; order_nodes.len()];
    // a cell wholly inside the disk has coverage 1 and one wholly outside 0: only the cells
    // within half a diagonal of the rim need the rim's distance
    let rim = 0.5 * std::f64::consts::SQRT_2 * du;
    let (inside2, outside2) = ((1.0 - rim).max(0.0).powi(2), (1.0 + rim).powi(2));
    for first in (0..rows).step_by(BLOCK) {
        let count = BLOCK.min(rows - first);
        for j in 0..count {
            let v = ((first + j) as i64 - a_max) as f64 * du;
            let out = &mut block[j * size..(j + 1) * size];
            let mut row_area = 0.0;
            if v * v < outside2 {
                row_newton(alpha_um, v, &order_nodes, &mut newton);
                row_area = pupil_row(
                    &mut buf,
                    (&order_nodes, &newton),
                    v,
                    du,
                    a_max,
                    &pupil_bins,
                    (inside2, outside2),
                    (k2pi, defocus_f),
                );
            }
            if row_area > 0.0 {
                area += row_area;
                plan.process_with_scratch(&mut buf, &mut scratch);
                out.iter_mut()
                    .zip(&out_bins)
                    .for_each(|(o, &b)| *o = buf[b]);
            } else {
                out.iter_mut().for_each(|o| *o = Complex32::default());
            }
        }
        for k in 0..size {
            let run = &mut tmp[k * rows + first..k * rows + first + count];
            for (j, t) in run.iter_mut().enumerate() {
                *t = block[j * size + k];
            }
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
    // columns BLOCK at a time, for the same reason: out is written a run of columns per row
    for first in (0..size).step_by(BLOCK) {
        let count = BLOCK.min(size - first);
        for j in 0..count {
            let k = first + j;
            let column = &tmp[k * rows..(k + 1) * rows];
            if rows < n {
                // the rows' bins are distinct, 0..=a_max and n − a_max..n: write them, and
                // clear only the bins between
                buf[a_max as usize + 1..n - a_max as usize].fill(Complex32::default());
                for (&p, t) in pupil_bins.iter().zip(column) {
                    buf[p] = *t;
                }
            } else {
                // a pupil wider than the period folds onto itself: the DFT sums it
                buf.fill(Complex32::default());
                for (&p, t) in pupil_bins.iter().zip(column) {
                    buf[p] += *t;
                }
            }
            plan.process_with_scratch(&mut buf, &mut scratch);
            let col = &mut block[j * size..(j + 1) * size];
            col.iter_mut()
                .zip(&out_bins)
                .for_each(|(o, &b)| *o = buf[b]);
        }
        // output row 0 is +y: offset l = half − row
        for row in 0..size {
            let l = size - 1 - row;
            let run = &mut out[row * size + first..row * size + first + count];
            for (j, o) in run.iter_mut().enumerate() {
                *o = f64::from(block[j * size + l].norm_sqr()) * norm;
            }
        }
    }
    Ok(out)
}

thread_local! {
    static PLANNER: std::cell::RefCell<FftPlanner<f32>> = std::cell::RefCell::new(FftPlanner::new());
}

/// Rows (first pass) or columns (second pass) transformed before their results are written
/// out together: 8 single-precision complex values fill a 64-byte cache line.
const BLOCK: usize = 8;

/// One pupil row at height `v` (`newton`: the wavefront along it) sampled into `buf` at the
/// FFT bins of its columns; returns the area its samples cover (0: none, `buf` untouched).
#[allow(clippy::too_many_arguments)]
fn pupil_row(
    buf: &mut [Complex32],
    (nodes, newton): (&[f64], &[f64]),
    v: f64,
    du: f64,
    a_max: i64,
    bins: &[usize],
    (inside2, outside2): (f64, f64),
    (k2pi, defocus_f): (f64, f64),
) -> f64 {
    // the columns that can touch the disk on this row
    let reach = (outside2 - v * v).max(0.0).sqrt();
    let a_reach = ((reach / du).ceil() as i64).min(a_max);
    let mut area = 0.0;
    buf.iter_mut().for_each(|c| *c = Complex32::default());
    for a in -a_reach..=a_reach {
        let u = a as f64 * du;
        let r2 = u * u + v * v;
        let w = if r2 <= inside2 {
            1.0
        } else if r2 >= outside2 {
            continue;
        } else {
            coverage(u, v, r2.sqrt(), du)
        };
        if w <= 0.0 {
            continue;
        }
        area += w;
        let (sin, cos) = sin_cos(k2pi * newton_eval(nodes, newton, u) + defocus_f * r2);
        // a pupil wider than the period (pitch > ½) folds onto itself: the DFT sums it
        buf[bins[(a + a_max) as usize]] += Complex32::new((w * cos) as f32, (w * sin) as f32);
    }
    area
}

/// sin and cos of `x` (radians, any size a pupil phase takes) to about 1e-11 absolute: the
/// argument is reduced to a quarter turn in f64 and the series summed to degree 13. The
/// library's sincos cost a sixth of a keratoconus grid's time, for a precision the f32
/// transform that follows cannot keep.
fn sin_cos(x: f64) -> (f64, f64) {
    let turns = x * (0.5 / PI);
    // round to nearest by the 1.5·2⁵² trick (the library's round is a call): exact for the
    // |4·turns| < 2⁵¹ of any phase a pupil takes
    const SHIFT: f64 = 6_755_399_441_055_744.0;
    let quarter = (turns * 4.0 + SHIFT) - SHIFT;
    let t = (turns - 0.25 * quarter) * (2.0 * PI);
    let t2 = t * t;
    let s = t
        * (1.0
            + t2 * (-1.0 / 6.0
                + t2 * (1.0 / 120.0
                    + t2 * (-1.0 / 5040.0
                        + t2 * (1.0 / 362_880.0
                            + t2 * (-1.0 / 39_916_800.0 + t2 * (1.0 / 6_227_020_800.0)))))));
    let c = 1.0
        + t2 * (-0.5
            + t2 * (1.0 / 24.0
                + t2 * (-1.0 / 720.0
                    + t2 * (1.0 / 40_320.0
                        + t2 * (-1.0 / 3_628_800.0 + t2 * (1.0 / 479_001_600.0))))));
    match (quarter as i64).rem_euclid(4) {
        0 => (s, c),
        1 => (c, -s),
        2 => (-s, -c),
        _ => (-c, s),
    }
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
    fn sin_cos_agrees_with_the_library_over_a_pupils_phases() {
        // quarter-turn boundaries, tiny, negative, and the thousands of radians a defocused
        // keratoconus pupil reaches
        let mut worst = 0.0f64;
        for i in -200_000..=200_000 {
            let x = f64::from(i) * 0.0371 + 1e-3 * f64::from(i % 7);
            let (s, c) = sin_cos(x);
            worst = worst.max((s - x.sin()).abs()).max((c - x.cos()).abs());
        }
        for x in [
            0.0,
            PI / 4.0,
            -PI / 4.0,
            PI / 2.0,
            3.0 * PI,
            1e5 + 0.3,
            -2.5e6,
        ] {
            let (s, c) = sin_cos(x);
            worst = worst.max((s - x.sin()).abs()).max((c - x.cos()).abs());
        }
        assert!(worst < 1e-10, "{worst:e}");
    }

    #[test]
    fn fast_lengths() {
        assert_eq!(fast_len(1000), 1000);
        assert_eq!(fast_len(1001), 1024);
        assert_eq!(fast_len(7), 8);
        assert_eq!(fast_len(1025), 1080);
    }
}
