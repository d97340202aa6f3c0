//! High-level PSF computation: Zernike wavefront → ENZ amplitude → intensity on a Cartesian grid.
//!
//! # Geometry and orientation
//! The amplitude (the optical field) is
//! U(x, y) = (1/π)∫∫ P(ρ, θ) e^{ifρ²} e^{i2π(xρcosθ + yρsinθ)} ρ dρ dθ with (x, y) in units of
//! λ/NA and P the pupil function in the Zernike pupil axes (θ counter-clockwise from +x). Its
//! ENZ form is U = 2 Σ β_nm √(n+1) i^m V_nm(r, f) e^{imφ}. The unaberrated in-focus peak is
//! U(0, 0) = 1, so intensities are in units of the diffraction-limited peak.
//!
//! The output grid is row-major, `size × size`, with the optical axis at pixel
//! (col, row) = (size/2, size/2) (0-based), x = (col − size/2)·pitch to the right and
//! y = (size/2 − row)·pitch upwards (row 0 is the top row, as in an image). x and y are parallel
//! to the pupil's x and y. With this kernel a positive tilt c(1,1) moves the spot to −x by
//! 2c/λ (λ/NA units), and a positive coma c(3,1) puts the sharp core at +x with its flare
//! (the comet tail) extending towards −x; c(3,−1) does the same along y (core at +y, i.e.
//! towards row 0). Tested in tests/it/optics_psf.rs.
//!
//! # Accuracy
//! The β expansion misses a fraction `beta_tolerance` of the pupil energy; the amplitude error
//! that causes is spread over the PSF, so relative to the peak of a strongly blurred PSF (peak
//! ≪ 1) it is larger, roughly sqrt(tolerance/peak). The default 1e-8 keeps 1 D–10 D defocused
//! PSFs within ~1e-4 of their peak. Radial interpolation adds `radial_tolerance` (relative to
//! the amplitude maximum).
//!
//! # Defocus, tilt and piston
//! c(2,0) is carried by f (f = 4√3·π·c(2,0)/λ added to the requested f), never by β; tilt is an
//! exact translation of the amplitude, so it is applied by shifting the evaluation grid (or dropped
//! with `include_tilt = false`); piston is a global phase.

use super::amplitude::{AmplitudeTable, Block8, LagrangeRule, RadialAmplitude};
use super::beta::{beta_from_alpha, BetaExpansion, StilesCrawford};
use super::enz::MAX_ABS_F;
use super::error::{check_range, OpticsError};
use super::quadrature::fejer1_01;
use super::zernike::{is_valid_nm, num_terms, osa_index};
use num_complex::Complex64;
use rayon::prelude::*;
use std::f64::consts::PI;
use std::time::Instant;

/// Highest Zernike order accepted in a wavefront description.
pub const MAX_INPUT_ORDER: u32 = 30;

/// Everything needed for one PSF.
#[derive(Debug, Clone)]
pub struct PsfRequest {
    /// Wavefront (n, m, µm), OSA/ANSI, over `pupil_diameter_mm`.
    pub coefficients_um: Vec<(u32, i32, f64)>,
    pub pupil_diameter_mm: f64,
    /// 350–1100 nm.
    pub wavelength_nm: f64,
    /// Extra ENZ defocus parameter f (sign kept), added to the one from c(2,0).
    /// See [`defocus_f_from_dioptres`].
    pub defocus_f: f64,
    /// Grid spacing in λ/NA (see [`pitch_from_arcmin`]).
    pub pitch_lambda_over_na: f64,
    /// Grid side in pixels.
    pub size: usize,
    /// Allowed relative pupil energy missed by the β expansion (1 − Σ|β|²).
    pub beta_tolerance: f64,
    /// Cap on the β expansion degree.
    pub max_degree: u32,
    /// Optional amplitude apodisation; `None` = uniform pupil.
    pub stiles_crawford: Option<StilesCrawford>,
    /// Apply tilt as a translation (true) or drop it, centring the PSF (false).
    pub include_tilt: bool,
    /// Relative accuracy of the radial interpolation of the amplitude tables.
    pub radial_tolerance: f64,
    /// Lagrange taps for the radial tables (even, 4–20); `None` picks the cheapest order that
    /// meets `radial_tolerance`.
    pub radial_taps: Option<usize>,
    /// Use rayon across radial nodes and rows (false: one core, for timing and batch use).
    pub parallel: bool,
}

impl PsfRequest {
    /// A request with default numerical settings (tolerance 1e-8, degree cap 160,
    /// interpolation 1e-6, tilt included, no apodisation, single-threaded).
    pub fn new(
        coefficients_um: Vec<(u32, i32, f64)>,
        pupil_diameter_mm: f64,
        wavelength_nm: f64,
        pitch_lambda_over_na: f64,
        size: usize,
    ) -> Self {
        PsfRequest {
            coefficients_um,
            pupil_diameter_mm,
            wavelength_nm,
            defocus_f: 0.0,
            pitch_lambda_over_na,
            size,
            beta_tolerance: 1e-8,
            max_degree: 160,
            stiles_crawford: None,
            include_tilt: true,
            radial_tolerance: 1e-6,
            radial_taps: None,
            parallel: false,
        }
    }
}

/// One computed PSF with the figures that describe its accuracy.
#[derive(Debug, Clone)]
pub struct Psf {
    pub size: usize,
    pub pitch_lambda_over_na: f64,
    /// |U|², row-major (see module docs for orientation); 1 = diffraction-limited peak.
    pub intensity: Vec<f64>,
    /// Total ENZ f used (requested f plus the c(2,0) part).
    pub defocus_f: f64,
    /// Translation applied for tilt, (x, y) in λ/NA (the spot moves by minus this).
    pub tilt_shift: (f64, f64),
    pub beta_degree: u32,
    pub beta_truncation_error: f64,
    /// Σ|β|² (≈ pupil energy; 1 without apodisation).
    pub beta_energy: f64,
    /// Peak intensity on the grid / peak of the same pupil without aberration.
    pub strehl: f64,
    pub peak_intensity: f64,
    /// Σ I·pitch²·π / pupil energy: fraction of the light that falls on the grid.
    pub energy_in_grid: f64,
    /// Radial table step (λ/NA; 0 = evaluated exactly at every distinct pixel radius) and the
    /// number of radial evaluations.
    pub radial_step: f64,
    /// Lagrange taps used (0 = exact evaluation).
    pub radial_taps: usize,
    pub radial_nodes: usize,
    pub seconds_beta: f64,
    /// Bessel–Bessel coefficients D (once per pupil and f).
    pub seconds_coefficients: f64,
    /// Radial evaluations (table nodes or distinct radii).
    pub seconds_table: f64,
    pub seconds_synthesis: f64,
}

/// ENZ defocus parameter for a vergence error ΔD (dioptres) over a pupil: f = π·ΔD·R²/λ
/// (R radius in m, λ in m). Positive ΔD has the sign of a positive c(2,0) (a myopic eye).
pub fn defocus_f_from_dioptres(delta_d: f64, pupil_diameter_mm: f64, wavelength_nm: f64) -> f64 {
    let r = 0.5 * pupil_diameter_mm * 1e-3;
    PI * delta_d * r * r / (wavelength_nm * 1e-9)
}

/// ENZ defocus parameter of a c(2,0) coefficient: the ρ² part of c·√3(2ρ² − 1) gives
/// f = 2π/λ · 2√3·c.
pub fn defocus_f_from_c20(c20_um: f64, wavelength_nm: f64) -> f64 {
    4.0 * 3f64.sqrt() * PI * c20_um / (wavelength_nm * 1e-3)
}

/// Grid pitch in λ/NA for an object-space angle per pixel in arcmin: r = 1 ↔ 2λ/D radians.
pub fn pitch_from_arcmin(arcmin: f64, pupil_diameter_mm: f64, wavelength_nm: f64) -> f64 {
    let theta = arcmin.to_radians() / 60.0;
    theta * (pupil_diameter_mm * 1e-3) / (2.0 * wavelength_nm * 1e-9)
}

/// Inverse of [`pitch_from_arcmin`].
pub fn arcmin_from_pitch(pitch: f64, pupil_diameter_mm: f64, wavelength_nm: f64) -> f64 {
    (pitch * 2.0 * wavelength_nm * 1e-9 / (pupil_diameter_mm * 1e-3)).to_degrees() * 60.0
}

fn validate(req: &PsfRequest) -> Result<(), OpticsError> {
    check_range(
        "pupil_diameter_mm",
        req.pupil_diameter_mm,
        1e-3,
        20.0,
        "0 < pupil diameter <= 20 mm",
    )?;
    check_range(
        "wavelength_nm",
        req.wavelength_nm,
        350.0,
        1100.0,
        "350 to 1100 nm",
    )?;
    check_range(
        "defocus_f",
        req.defocus_f,
        -MAX_ABS_F,
        MAX_ABS_F,
        "|f| <= 5000",
    )?;
    check_range(
        "pitch_lambda_over_na",
        req.pitch_lambda_over_na,
        1e-4,
        1e3,
        "1e-4 to 1000 (units of lambda/NA)",
    )?;
    check_range("size", req.size as f64, 1.0, 8192.0, "1 to 8192 pixels")?;
    check_range(
        "beta_tolerance",
        req.beta_tolerance,
        1e-14,
        0.5,
        "1e-14 to 0.5",
    )?;
    check_range("max_degree", req.max_degree as f64, 1.0, 300.0, "1 to 300")?;
    check_range(
        "radial_tolerance",
        req.radial_tolerance,
        1e-14,
        1e-2,
        "1e-14 to 1e-2",
    )?;
    if let Some(t) = req.radial_taps {
        if !(4..=20).contains(&t) || t % 2 == 1 {
            return Err(OpticsError::OutOfRange {
                field: "radial_taps".into(),
                value: t as f64,
                allowed: "an even number from 4 to 20",
            });
        }
    }
    if let Some(sc) = req.stiles_crawford {
        check_range(
            "stiles_crawford.rho_per_mm2",
            sc.rho_per_mm2,
            0.0,
            1.0,
            "0 to 1 per mm^2",
        )?;
    }
    for &(n, m, v) in &req.coefficients_um {
        if !is_valid_nm(n, m) || n > MAX_INPUT_ORDER {
            return Err(OpticsError::UnknownTerm {
                n,
                m,
                max_n: MAX_INPUT_ORDER,
            });
        }
        check_range(
            &format!("coefficient ({n}, {m})"),
            v,
            -1e3,
            1e3,
            "|c| <= 1000 um",
        )?;
    }
    Ok(())
}

/// Split a wavefront into the part expanded in β, the total f and the tilt translation.
pub struct PupilSplit {
    /// OSA vector with piston, tilt and c(2,0) removed (µm).
    pub alpha_um: Vec<f64>,
    pub f: f64,
    pub tilt_shift: (f64, f64),
}

/// See [`PupilSplit`]. Inputs must already be validated.
pub fn split_wavefront(
    coefficients_um: &[(u32, i32, f64)],
    wavelength_nm: f64,
    extra_f: f64,
    include_tilt: bool,
) -> PupilSplit {
    let order = coefficients_um
        .iter()
        .map(|c| c.0)
        .max()
        .unwrap_or(0)
        .max(2);
    let mut a = vec![0.0; num_terms(order)];
    for &(n, m, v) in coefficients_um {
        a[osa_index(n, m)] += v;
    }
    let lam_um = wavelength_nm * 1e-3;
    let f = extra_f + defocus_f_from_c20(a[4], wavelength_nm);
    // exp(i2π·2c·x/λ) turns U(x) into U(x + 2c/λ): Z(1,1) = 2ρcosθ, Z(1,−1) = 2ρsinθ.
    let tilt_shift = if include_tilt {
        (2.0 * a[2] / lam_um, 2.0 * a[1] / lam_um)
    } else {
        (0.0, 0.0)
    };
    a[0] = 0.0;
    a[1] = 0.0;
    a[2] = 0.0;
    a[4] = 0.0;
    PupilSplit {
        alpha_um: a,
        f,
        tilt_shift,
    }
}

/// Peak intensity of the unaberrated, in-focus pupil with the given apodisation:
/// |U(0)|² = (2∫A ρ dρ)².
pub fn ideal_peak(stiles_crawford: Option<StilesCrawford>, pupil_diameter_mm: f64) -> f64 {
    match stiles_crawford {
        None => 1.0,
        Some(sc) => {
            let (t, w) = fejer1_01(64);
            let s: f64 = t
                .iter()
                .zip(&w)
                .map(|(t, w)| w * sc.amplitude(t.sqrt(), 0.5 * pupil_diameter_mm))
                .sum();
            s * s
        }
    }
}

/// Intensity on the request's grid. Without a tilt shift the grid is symmetric about the
/// axis and has far fewer distinct radii than pixels: the amplitude is then evaluated exactly at
/// each distinct radius. Otherwise (or when a table is cheaper) the radial values are tabulated
/// and interpolated, with the interpolation order chosen by a cost model. Returns (intensity,
/// step (0 = exact), taps (0 = exact), radial evaluations, time after the radial stage).
fn synthesize(
    rf: &RadialAmplitude,
    req: &PsfRequest,
    shift: (f64, f64),
) -> (Vec<f64>, f64, usize, usize, Instant) {
    let n = req.size;
    let p = req.pitch_lambda_over_na;
    let half = (n / 2) as i64;
    let (sx, sy) = shift;
    let centred = sx == 0.0 && sy == 0.0;
    // Per pixel and azimuthal combination, in tap-equivalents: a centred grid shares the
    // interpolation and half the angular work among four mirror images.
    let pixel_taps = |t: usize| {
        if centred {
            t as f64 / 4.0 + 2.2
        } else {
            t as f64 + 9.0
        }
    };
    let c_count = rf.combos();
    let mut intensity = vec![0.0; n * n];
    // Interpolation order by a cost model: table nodes cost one radial evaluation each,
    // pixels cost (taps + angular sum ≈ 9 taps) per azimuthal combination; one pixel-tap costs
    // about PIXEL_WEIGHT units of radial work (measured on x86-64, SSE2 only).
    let pixels = (n * n) as f64;
    let work = rf.work_per_radius() as f64 + 64.0;
    let ext0 = |i: i64| (i - half).unsigned_abs() as f64 * p;
    let rmax0 = {
        let xm = ext0(0).max(ext0(n as i64 - 1));
        (xm + sx.abs()).hypot(xm + sy.abs())
    };
    let candidates: Vec<usize> = match req.radial_taps {
        Some(t) => vec![t],
        None => vec![4, 6, 8, 10, 12, 16, 20],
    };
    let (rule, step) = candidates
        .iter()
        .map(|&t| {
            let rule = LagrangeRule::new(t);
            let step = rule.step_for(req.radial_tolerance);
            let cost = rmax0 / step * work + PIXEL_WEIGHT * pixels * c_count as f64 * pixel_taps(t);
            (cost, rule, step)
        })
        .min_by(|a, b| a.0.total_cmp(&b.0))
        .map(|(_, r, s)| (r, s))
        .expect("non-empty");
    let ext = |i: i64| (i - half).unsigned_abs() as f64 * p;
    let xmax = ext(0).max(ext(n as i64 - 1));
    let r_max = (xmax + sx.abs()).hypot(xmax + sy.abs()) + step;
    let table_nodes = (r_max / step).ceil() as usize + 2 * rule.taps;
    // distinct a² + b² over the centred grid (a, b = pixel offsets from the axis)
    let kmax = (half * half) as usize * 2 + 1;
    let exact = sx == 0.0 && sy == 0.0 && kmax <= 1 << 24;
    let mut keys = Vec::new();
    if exact {
        let mut seen = vec![false; kmax];
        for a in 0..n as i64 {
            for b in 0..n as i64 {
                let k = ((a - half).pow(2) + (b - half).pow(2)) as usize;
                seen[k] = true;
            }
        }
        keys = (0..kmax).filter(|&k| seen[k]).collect();
    }
    let row_x = |col: usize| (col as f64 - half as f64) * p + sx;
    let row_y = |row: usize| (half as f64 - row as f64) * p + sy;
    let exact_cost = keys.len() as f64 * work + PIXEL_WEIGHT * pixels * c_count as f64 * 2.2;
    let table_cost =
        table_nodes as f64 * work + PIXEL_WEIGHT * pixels * c_count as f64 * pixel_taps(rule.taps);
    let symmetric = SymmetricGrid {
        n,
        pitch: p,
        c_count,
        degree: rf.degree,
        parallel: req.parallel,
    };
    if exact && exact_cost <= table_cost {
        let mut index = vec![u32::MAX; kmax];
        for (i, &k) in keys.iter().enumerate() {
            index[k] = i as u32;
        }
        let radii: Vec<f64> = keys.iter().map(|&k| (k as f64).sqrt() * p).collect();
        let mut g = vec![Complex64::default(); keys.len() * c_count];
        let block = 64;
        if req.parallel {
            g.par_chunks_mut(block * c_count)
                .zip(radii.par_chunks(block))
                .for_each_init(Block8::default, |s, (o, r)| rf.eval_radii(r, s, o));
        } else {
            let mut s = Block8::default();
            rf.eval_radii(&radii, &mut s, &mut g);
        }
        let t2 = Instant::now();
        let radial = |a: i64, b: i64, out: &mut [Complex64]| {
            let k = index[(a * a + b * b) as usize] as usize;
            out.copy_from_slice(&g[k * c_count..(k + 1) * c_count]);
            true
        };
        symmetric.fill(&mut intensity, radial);
        (intensity, 0.0, 0, keys.len(), t2)
    } else {
        let table = AmplitudeTable::new(rf, r_max, rule, step, req.parallel);
        let t2 = Instant::now();
        if centred {
            let radial = |a: i64, b: i64, out: &mut [Complex64]| {
                table.radial(p * (a as f64).hypot(b as f64), out)
            };
            symmetric.fill(&mut intensity, radial);
        } else {
            // Visit pixels in order of radius: neighbours then read the same table rows,
            // which stay in cache (the table itself is usually far larger than the cache).
            let mut order: Vec<(f64, u32)> = (0..n * n)
                .map(|i| (row_x(i % n).hypot(row_y(i / n)), i as u32))
                .collect();
            order.sort_unstable_by(|a, b| a.0.total_cmp(&b.0));
            let eval = |chunk: &[(f64, u32)]| -> Vec<f64> {
                let mut g = vec![Complex64::default(); c_count];
                chunk
                    .iter()
                    .map(|&(_, i)| {
                        let i = i as usize;
                        table.at(row_x(i % n), row_y(i / n), &mut g).norm_sqr()
                    })
                    .collect()
            };
            let values: Vec<f64> = if req.parallel {
                order.par_chunks(4096).flat_map_iter(eval).collect()
            } else {
                eval(&order)
            };
            for (&(_, i), v) in order.iter().zip(values) {
                intensity[i as usize] = v;
            }
        }
        (intensity, step, table.rule.taps, table.nodes(), t2)
    }
}

/// An n × n grid of `pitch` centred on the axis, whose radial values have `c_count`
/// combinations up to `degree`, filled four mirror images at a time.
#[derive(Clone, Copy)]
struct SymmetricGrid {
    n: usize,
    pitch: f64,
    c_count: usize,
    degree: u32,
    parallel: bool,
}

impl SymmetricGrid {
    /// Fills `out` four mirror images at a time: (a, b), (−a, −b), (a, −b), (−a, b) in pixel
    /// offsets share their radial values. `radial(a, b, g)` writes the radial values at the
    /// radius of offset (a, b) (false: outside, leave 0).
    fn fill(self, out: &mut [f64], radial: impl Fn(i64, i64, &mut [Complex64]) -> bool + Sync) {
        let SymmetricGrid {
            n,
            pitch,
            c_count,
            degree,
            parallel,
        } = self;
        let half = (n / 2) as i64;
        let lo = -half;
        let hi = n as i64 - 1 - half;
        let amax = half.max(hi);
        // one task per b ≥ 0: returns the rows for +b (row half − b) and −b (row half + b)
        let rows_for = |b: i64| -> (Vec<f64>, Vec<f64>) {
            let mut g = vec![Complex64::default(); c_count];
            let mut up = vec![0.0; n];
            let mut down = vec![0.0; n];
            for a in 0..=amax {
                if !radial(a, b, &mut g) {
                    continue;
                }
                let u = RadialAmplitude::quad_sums(&g, degree, a as f64 * pitch, b as f64 * pitch);
                // u: (a, b), (−a, −b), (a, −b), (−a, b)
                let put = |row: &mut [f64], aa: i64, v: Complex64| {
                    if (lo..=hi).contains(&aa) {
                        row[(aa + half) as usize] = v.norm_sqr();
                    }
                };
                put(&mut up, a, u[0]);
                put(&mut up, -a, u[3]);
                put(&mut down, -a, u[1]);
                put(&mut down, a, u[2]);
            }
            (up, down)
        };
        let bs: Vec<i64> = (0..=amax).collect();
        let rows: Vec<(Vec<f64>, Vec<f64>)> = if parallel {
            bs.par_iter().map(|&b| rows_for(b)).collect()
        } else {
            bs.iter().map(|&b| rows_for(b)).collect()
        };
        for (b, (up, down)) in bs.iter().zip(rows) {
            // +y is up: y = +b is row half − b (needs b ≤ half), y = −b is row half + b (b ≤ hi)
            if *b <= half {
                let r = (half - b) as usize;
                out[r * n..(r + 1) * n].copy_from_slice(&up);
            }
            if *b <= hi {
                let r = (half + b) as usize;
                out[r * n..(r + 1) * n].copy_from_slice(&down);
            }
        }
    }
}

/// Cost of one pixel·combination·tap in units of radial work (see `synthesize`).
const PIXEL_WEIGHT: f64 = 4.5;

/// The pupil part of a request, expanded once and reusable for any defocus and grid with the
/// same wavefront, pupil, wavelength and apodisation (e.g. a through-focus series).
#[derive(Debug, Clone)]
pub struct Pupil {
    pub beta: BetaExpansion,
    /// f contributed by the wavefront's own c(2,0).
    pub base_f: f64,
    pub tilt_shift: (f64, f64),
    pub pupil_diameter_mm: f64,
    pub wavelength_nm: f64,
    pub stiles_crawford: Option<StilesCrawford>,
    pub seconds: f64,
}

/// Expand the pupil of `req` (wavefront, pupil, wavelength, apodisation, β settings); the grid
/// fields and `defocus_f` are validated but not used.
pub fn expand_pupil(req: &PsfRequest) -> Result<Pupil, OpticsError> {
    validate(req)?;
    let split = split_wavefront(
        &req.coefficients_um,
        req.wavelength_nm,
        0.0,
        req.include_tilt,
    );
    let t0 = Instant::now();
    let beta = beta_from_alpha(
        &split.alpha_um,
        req.wavelength_nm,
        req.pupil_diameter_mm,
        req.stiles_crawford,
        req.beta_tolerance,
        req.max_degree,
    );
    Ok(Pupil {
        beta,
        base_f: split.f,
        tilt_shift: split.tilt_shift,
        pupil_diameter_mm: req.pupil_diameter_mm,
        wavelength_nm: req.wavelength_nm,
        stiles_crawford: req.stiles_crawford,
        seconds: t0.elapsed().as_secs_f64(),
    })
}

/// PSF of an expanded pupil at total defocus `pupil.base_f + req.defocus_f` on the grid of
/// `req` (size, pitch, radial settings, parallelism); the wavefront fields of `req` are ignored.
pub fn psf_from_pupil(pupil: &Pupil, req: &PsfRequest) -> Result<Psf, OpticsError> {
    validate(req)?;
    let f = pupil.base_f + req.defocus_f;
    let extent =
        (req.size as f64 / 2.0 + 1.0) * req.pitch_lambda_over_na * std::f64::consts::SQRT_2
            + pupil.tilt_shift.0.hypot(pupil.tilt_shift.1);
    check_range(
        "grid extent (size/2 * pitch * sqrt(2) + tilt shift)",
        extent,
        0.0,
        super::enz::MAX_R,
        "at most 20000 lambda/NA",
    )?;
    check_range(
        "total defocus f",
        f,
        -MAX_ABS_F,
        MAX_ABS_F,
        "|f| <= 5000 (requested f plus 4*sqrt(3)*pi*c(2,0)/lambda)",
    )?;
    let be = &pupil.beta;
    let t1 = Instant::now();
    let n = req.size;
    let rf = RadialAmplitude::new(&be.beta, be.degree, f);
    let t1b = Instant::now();
    let (intensity, radial_step, radial_taps, radial_nodes, t2) =
        synthesize(&rf, req, pupil.tilt_shift);
    let t3 = Instant::now();
    let peak = intensity.iter().cloned().fold(0.0, f64::max);
    let sum: f64 = intensity.iter().sum();
    let beta_energy: f64 = be.beta.iter().map(|b| b.norm_sqr()).sum();
    let energy_in_grid =
        sum * req.pitch_lambda_over_na * req.pitch_lambda_over_na * PI / be.pupil_energy;
    Ok(Psf {
        size: n,
        pitch_lambda_over_na: req.pitch_lambda_over_na,
        intensity,
        defocus_f: f,
        tilt_shift: pupil.tilt_shift,
        beta_degree: be.degree,
        beta_truncation_error: be.truncation_error,
        beta_energy,
        strehl: peak / ideal_peak(pupil.stiles_crawford, pupil.pupil_diameter_mm),
        peak_intensity: peak,
        energy_in_grid,
        radial_step,
        radial_taps,
        radial_nodes,
        seconds_beta: pupil.seconds,
        seconds_coefficients: (t1b - t1).as_secs_f64(),
        seconds_table: (t2 - t1b).as_secs_f64(),
        seconds_synthesis: (t3 - t2).as_secs_f64(),
    })
}

/// Compute one PSF ([`expand_pupil`] then [`psf_from_pupil`]). Errors name the offending
/// field; nothing here panics on bad input.
pub fn compute_psf(req: &PsfRequest) -> Result<Psf, OpticsError> {
    let pupil = expand_pupil(req)?;
    psf_from_pupil(&pupil, req)
}
