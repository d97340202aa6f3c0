//! ENZ pupil coefficients β from wavefront coefficients α.
//!
//! The pupil function P(ρ, θ) = A(ρ)·exp(i2πW(ρ, θ)/λ) is expanded as
//! P = Σ β_nm √(n+1) R_n^{|m|}(ρ) e^{imθ}. These functions are orthonormal under
//! (1/π)∫∫ dA, so Σ|β|² = (1/π)∫∫|P|² dA (= 1 without apodisation) and the shortfall of the
//! truncated sum is exactly the relative energy the expansion misses: the truncation error.
//!
//! The inner products are taken on a cosine-sampled pupil: radii ρ_j = cos(π(K−j−½)/(2K)),
//! uniform θ. In t = ρ² these radii are Chebyshev points, so Fejér's first rule in t integrates
//! the radial products spectrally; the angular part is an FFT per ring.
//!
//! Piston, tilt and defocus are not put into β: piston is a global phase, tilt is an exact
//! translation of the PSF and defocus is carried by f (see [`super::psf`]).

use super::quadrature::fejer1_01;
use super::zernike::{num_terms, order_for_len, osa_index, radial_family};
use num_complex::Complex64;
use rustfft::FftPlanner;
use std::f64::consts::PI;

/// Stiles–Crawford amplitude apodisation. The directional sensitivity of the cones is usually
/// quoted for intensity as η(r) = 10^(−ρ_sc·r²), r the pupil radius in mm; the amplitude is its
/// square root: A(ρ) = 10^(−ρ_sc·(ρR)²/2), R the pupil radius in mm, ρ ∈ [0, 1].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StilesCrawford {
    /// ρ_sc in mm⁻²; 0.05 is the usual foveal value.
    pub rho_per_mm2: f64,
}

impl Default for StilesCrawford {
    fn default() -> Self {
        StilesCrawford { rho_per_mm2: 0.05 }
    }
}

impl StilesCrawford {
    /// Amplitude at normalised radius ρ for a pupil of the given radius (mm).
    pub fn amplitude(&self, rho: f64, pupil_radius_mm: f64) -> f64 {
        let r = rho * pupil_radius_mm;
        10f64.powf(-0.5 * self.rho_per_mm2 * r * r)
    }
}

/// Result of expanding a pupil function.
#[derive(Debug, Clone)]
pub struct BetaExpansion {
    /// Chosen expansion degree N (terms of orders 0..=N).
    pub degree: u32,
    /// β in OSA order, num_terms(degree) entries.
    pub beta: Vec<Complex64>,
    /// 1 − Σ|β|²/E: relative pupil energy the truncated expansion misses (≥ 0).
    pub truncation_error: f64,
    /// E = (1/π)∫∫ A² dA (1 without apodisation).
    pub pupil_energy: f64,
    /// Degree of the sampling that produced the coefficients (≥ degree).
    pub sampled_degree: u32,
}

/// β of all orders ≤ `degree` for the phase 2π/λ·W (W from `alpha_um`, OSA order, terms to skip
/// already zeroed) and amplitude `amp(ρ)`, on a cosine-sampled pupil fine enough for that degree.
/// Returns (β, E).
fn project(
    alpha_um: &[f64],
    wavelength_um: f64,
    amp: &dyn Fn(f64) -> f64,
    degree: u32,
) -> (Vec<Complex64>, f64) {
    let kr = degree as usize + 16;
    let m_theta = (2 * degree as usize + 32).next_power_of_two();
    let (ts, ws) = fejer1_01(kr);
    let aorder = order_for_len(alpha_um.len());
    let nt = num_terms(degree);
    let mut beta = vec![Complex64::new(0.0, 0.0); nt];
    let mut ring = vec![Complex64::new(0.0, 0.0); m_theta];
    // one plan for every ring; rustfft's forward transform is Σ_k x_k e^{−2πi jk/M}, unscaled
    let fft = FftPlanner::<f64>::new().plan_fft_forward(m_theta);
    let mut scratch = vec![Complex64::new(0.0, 0.0); fft.get_inplace_scratch_len()];
    let mut rad = vec![0.0; degree.max(aorder) as usize / 2 + 1];
    let k2pi = 2.0 * PI / wavelength_um;
    // cos(μθ_k), sin(μθ_k) for the wavefront's azimuthal orders, shared by every ring
    let na = aorder as usize + 1;
    let mut trig = vec![(0.0, 0.0); m_theta * na];
    for k in 0..m_theta {
        let th = 2.0 * PI * k as f64 / m_theta as f64;
        for mu in 0..na {
            let (s, c) = (mu as f64 * th).sin_cos();
            trig[k * na + mu] = (c, s);
        }
    }
    let mut acos = vec![0.0; na];
    let mut asin = vec![0.0; na];
    let mut energy = 0.0;
    for (&t, &w) in ts.iter().zip(&ws) {
        let rho = t.sqrt();
        let a = amp(rho);
        energy += w * a * a;
        // W(ρ, θ) = Σ_μ acos_μ(ρ) cos μθ + asin_μ(ρ) sin μθ
        for mu in 0..na as u32 {
            radial_family(aorder, mu, rho, &mut rad);
            let (mut c, mut s) = (0.0, 0.0);
            for (k, rv) in rad
                .iter()
                .enumerate()
                .take(((aorder - mu) / 2) as usize + 1)
            {
                let n = mu + 2 * k as u32;
                let norm = super::zernike::normalization(n, mu as i32);
                c += alpha_um[osa_index(n, mu as i32)] * norm * rv;
                if mu > 0 {
                    s += alpha_um[osa_index(n, -(mu as i32))] * norm * rv;
                }
            }
            acos[mu as usize] = c;
            asin[mu as usize] = s;
        }
        for (k, slot) in ring.iter_mut().enumerate() {
            let tr = &trig[k * na..(k + 1) * na];
            let wf: f64 = tr
                .iter()
                .zip(acos.iter().zip(&asin))
                .map(|((c, s), (ac, as_))| ac * c + as_ * s)
                .sum();
            *slot = Complex64::from_polar(a, k2pi * wf);
        }
        // ring[m] = Σ_k P_k e^{−imθ_k}; P_m(ρ) = ring[m]/M (negative m wrap around).
        fft.process_with_scratch(&mut ring, &mut scratch);
        let scale = w / m_theta as f64;
        for mu in 0..=degree {
            radial_family(degree, mu, rho, &mut rad);
            let pp = ring[mu as usize] * scale;
            let pm = ring[(m_theta - mu as usize) % m_theta] * scale;
            for (k, rv) in rad
                .iter()
                .enumerate()
                .take(((degree - mu) / 2) as usize + 1)
            {
                let n = mu + 2 * k as u32;
                let f = rv * ((n + 1) as f64).sqrt();
                beta[osa_index(n, mu as i32)] += pp * f;
                if mu > 0 {
                    beta[osa_index(n, -(mu as i32))] += pm * f;
                }
            }
        }
    }
    (beta, energy)
}

/// Captured energy Σ_{n ≤ N}|β_n|² for each N ≤ degree.
fn cumulative_energy(beta: &[Complex64], degree: u32) -> Vec<f64> {
    let mut per = vec![0.0; degree as usize + 1];
    for (j, b) in beta.iter().enumerate() {
        let (n, _) = super::zernike::osa_nm(j);
        per[n as usize] += b.norm_sqr();
    }
    let mut acc = 0.0;
    per.iter()
        .map(|v| {
            acc += v;
            acc
        })
        .collect()
}

/// Expand the pupil function for wavefront `alpha_um` (OSA, µm; every term is used, so zero the
/// ones carried elsewhere first) at `wavelength_nm`, choosing the smallest degree whose
/// truncation error is ≤ `tolerance`, up to `max_degree`. If the cap is reached the result
/// carries the (larger) error achieved; callers decide whether that is acceptable.
pub fn beta_from_alpha(
    alpha_um: &[f64],
    wavelength_nm: f64,
    pupil_diameter_mm: f64,
    stiles_crawford: Option<StilesCrawford>,
    tolerance: f64,
    max_degree: u32,
) -> BetaExpansion {
    let lam_um = wavelength_nm * 1e-3;
    let radius = 0.5 * pupil_diameter_mm;
    let amp = move |rho: f64| match stiles_crawford {
        Some(sc) => sc.amplitude(rho, radius),
        None => 1.0,
    };
    // Start at the degree of the wavefront itself (the pupil function needs at least that),
    // then double: the sampling cost grows with the degree, so small aberrations stay cheap.
    let max_degree = max_degree.max(1);
    let mut deg = order_for_len(alpha_um.len()).max(4).min(max_degree);
    loop {
        let (beta, energy) = project(alpha_um, lam_um, &amp, deg);
        let cum = cumulative_energy(&beta, deg);
        let err_at = |n: usize| (1.0 - cum[n] / energy).max(0.0);
        // Only trust a degree that leaves a margin of near-empty orders below the sampling
        // degree: with content beyond the sampling, aliasing could fake convergence.
        let found = (0..=deg as usize).find(|&n| err_at(n) <= tolerance);
        let trusted = found.filter(|&n| n + 8 <= deg as usize || deg >= max_degree);
        if let Some(n) = trusted {
            let nt = num_terms(n as u32);
            return BetaExpansion {
                degree: n as u32,
                beta: beta[..nt].to_vec(),
                truncation_error: err_at(n),
                pupil_energy: energy,
                sampled_degree: deg,
            };
        }
        if deg >= max_degree {
            return BetaExpansion {
                degree: deg,
                truncation_error: err_at(deg as usize),
                beta,
                pupil_energy: energy,
                sampled_degree: deg,
            };
        }
        deg = (deg * 2).min(max_degree);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `project` reads ring[m] as Σ_k P_k e^{−imθ_k}: rustfft's forward transform, unscaled.
    #[test]
    fn forward_fft_is_the_unscaled_negative_exponent_dft() {
        let n = 64;
        let data: Vec<Complex64> = (0..n)
            .map(|i| Complex64::new((i as f64 * 0.3).sin(), (i as f64).cos()))
            .collect();
        let mut f = data.clone();
        FftPlanner::<f64>::new().plan_fft_forward(n).process(&mut f);
        for (k, fk) in f.iter().enumerate() {
            let mut s = Complex64::new(0.0, 0.0);
            for (j, d) in data.iter().enumerate() {
                let a = -2.0 * PI * (j * k) as f64 / n as f64;
                s += d * Complex64::new(a.cos(), a.sin());
            }
            assert!((s - fk).norm() < 1e-12);
        }
    }
}
