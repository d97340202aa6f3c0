//! Extended Nijboer–Zernike radial integrals
//! V_n^m(r, f) = ∫₀¹ e^{ifρ²} R_n^{|m|}(ρ) J_m(2πrρ) ρ dρ  (r in units of λ/NA).
//!
//! Main method (Bessel–Bessel series, after Janssen, Braat & Dirksen 2004), derived here as:
//! 1. e^{ifρ²} = e^{if/2} e^{i(f/2)s} with s = 2ρ² − 1 = P_1-argument, and the plane-wave
//!    expansion e^{izs} = Σ_k (2k+1) i^k j_k(z) P_k(s), z = f/2. Since P_k(2ρ²−1) = R_{2k}^0(ρ)
//!    this is an expansion in radial Zernike polynomials with spherical-Bessel weights, which
//!    decay super-exponentially once k exceeds |f|/2.
//! 2. Products P_k(s)·H(ρ), with H expanded in Q_l = R^μ_{μ+2l} (μ = |m|), are expanded in the
//!    same Q_l basis by the Legendre recurrence in k, where multiplication by s is the
//!    (tridiagonal) Jacobi operator of P^{(0,μ)}. This keeps every step bounded and avoids
//!    factorial-size linearisation coefficients.
//! 3. ∫₀¹ Q_l(ρ) J_μ(vρ) ρ dρ = (−1)^l J_{μ+2l+1}(v)/v, and J_ν(v)/v = (J_{ν−1}(v)+J_{ν+1}(v))/(2ν)
//!    needs no division by v.
//!
//! So V = Σ_l D_l J_{μ+2l+1}(v)/v with D independent of r: the coefficients are computed once
//! per (aberration, f) and the r-dependence costs one Bessel sequence per radius.

use super::bessel::{bessel_j, bessel_j_sequence, spherical_j_sequence};
use super::error::{check_range, OpticsError};
use super::quadrature::gauss_legendre_01;
use super::zernike::{is_valid_nm, osa_index, osa_nm, radial};
use num_complex::Complex64;
use std::f64::consts::PI;

const C0: Complex64 = Complex64 { re: 0.0, im: 0.0 };

/// Largest |f| the engine accepts: the series needs ≈ |f|/2 terms per coefficient.
pub const MAX_ABS_F: f64 = 5000.0;
/// Largest r (λ/NA) the engine accepts.
pub const MAX_R: f64 = 20000.0;

/// Tridiagonal operator "multiply by s = 2ρ² − 1" in the basis Q_l = R^μ_{μ+2l}:
/// s·Q_l = up[l] Q_{l+1} + diag[l] Q_l + down[l] Q_{l−1}.
struct SOperator {
    up: Vec<f64>,
    diag: Vec<f64>,
    down: Vec<f64>,
}

impl SOperator {
    fn new(mu: u32, len: usize) -> Self {
        let m = mu as f64;
        let mut up = vec![0.0; len];
        let mut diag = vec![0.0; len];
        let mut down = vec![0.0; len];
        for l in 0..len {
            if l == 0 {
                up[0] = 2.0 / (m + 2.0);
                diag[0] = m / (m + 2.0);
            } else {
                // From a P_{l+1} = (b s + c) P_l − d P_{l−1} (Jacobi, α = 0, β = μ).
                let k = l as f64;
                let t = 2.0 * k + m;
                let a = 2.0 * (k + 1.0) * (k + m + 1.0) * t;
                let b = (t + 1.0) * (t + 2.0) * t;
                let c = -(t + 1.0) * m * m;
                let d = 2.0 * k * (k + m) * (t + 2.0);
                up[l] = a / b;
                diag[l] = -c / b;
                down[l] = d / b;
            }
        }
        SOperator { up, diag, down }
    }

    /// out[0..=len] = s · e[0..len]
    #[inline]
    fn apply(&self, e: &[Complex64], len: usize, out: &mut [Complex64]) {
        out[..=len].iter_mut().for_each(|v| *v = C0);
        for l in 0..len {
            let x = e[l];
            out[l + 1] += x * self.up[l];
            out[l] += x * self.diag[l];
            if l > 0 {
                out[l - 1] += x * self.down[l];
            }
        }
    }
}

/// Weights w_k = (2k+1) i^k j_k(f/2) of e^{i(f/2)s} = Σ_k w_k P_k(s), truncated where they
/// fall below 1e-18 past the turning point k ≈ |f|/2.
pub fn defocus_weights(f: f64) -> Vec<Complex64> {
    let z = 0.5 * f;
    let az = z.abs();
    let kmax = (az + 40.0 + 15.0 * az.cbrt()).ceil() as usize;
    let mut j = vec![0.0; kmax + 1];
    spherical_j_sequence(kmax, z, &mut j);
    let mut last = 0;
    for (k, v) in j.iter().enumerate() {
        if (2 * k + 1) as f64 * v.abs() > 1e-18 || (k as f64) < az {
            last = k;
        }
    }
    let ik = [
        Complex64::new(1.0, 0.0),
        Complex64::new(0.0, 1.0),
        Complex64::new(-1.0, 0.0),
        Complex64::new(0.0, -1.0),
    ];
    (0..=last)
        .map(|k| ik[k % 4] * ((2 * k + 1) as f64 * j[k]))
        .collect()
}

/// Bessel–Bessel coefficients for one |m| = μ: given H(ρ) = Σ_l h_l R^μ_{μ+2l}(ρ), returns D with
/// ∫₀¹ e^{ifρ²} H(ρ) J_μ(vρ) ρ dρ = Σ_l D_l J_{μ+2l+1}(v)/v  (the e^{if/2} and (−1)^l are in D).
pub fn bb_coefficients(mu: u32, h: &[Complex64], f: f64) -> Vec<Complex64> {
    let w = defocus_weights(f);
    bb_coefficients_with_weights(mu, h, &w, f)
}

/// [`bb_coefficients`] with precomputed [`defocus_weights`] (shared across μ and aberrations).
pub fn bb_coefficients_with_weights(
    mu: u32,
    h: &[Complex64],
    w: &[Complex64],
    f: f64,
) -> Vec<Complex64> {
    bb_coefficients_batch(mu, &[h], w, f)
        .pop()
        .unwrap_or_default()
}

/// [`bb_coefficients`] for several H sharing one μ (e.g. m = ±μ of one pupil): the recurrence
/// runs on real, contiguous arrays, so one pass serves the whole batch and vectorises.
pub fn bb_coefficients_batch(
    mu: u32,
    hs: &[&[Complex64]],
    w: &[Complex64],
    f: f64,
) -> Vec<Vec<Complex64>> {
    let p = hs.iter().map(|h| h.len()).max().unwrap_or(0);
    if p == 0 {
        return hs.iter().map(|_| Vec::new()).collect();
    }
    let kk = w.len();
    let total = p + kk;
    let op = SOperator::new(mu, total + 2);
    // Gather form of s·e: (s e)[l] = lo[l] e[l−1] + mid[l] e[l] + hi[l] e[l+1].
    let mut lo = vec![0.0; total + 2];
    let mut hi = vec![0.0; total + 2];
    for l in 0..total + 1 {
        lo[l + 1] = op.up[l];
        if l > 0 {
            hi[l - 1] = op.down[l];
        }
    }
    let mid = &op.diag;
    let nv = 2 * hs.len();
    // Each real vector is stored from index 1 with a zero at index 0 standing for e[−1].
    let sz = total + 3;
    let mut prev = vec![vec![0.0; sz]; nv];
    let mut cur = vec![vec![0.0; sz]; nv];
    let mut next = vec![vec![0.0; sz]; nv];
    for (b, h) in hs.iter().enumerate() {
        for (l, v) in h.iter().enumerate() {
            cur[2 * b][l + 1] = v.re;
            cur[2 * b + 1][l + 1] = v.im;
        }
    }
    let mut dre = vec![vec![0.0; total]; hs.len()];
    let mut dim = vec![vec![0.0; total]; hs.len()];
    for b in 0..hs.len() {
        for l in 0..p {
            let (er, ei) = (cur[2 * b][l + 1], cur[2 * b + 1][l + 1]);
            dre[b][l] = w[0].re * er - w[0].im * ei;
            dim[b][l] = w[0].re * ei + w[0].im * er;
        }
    }
    let mut len = p;
    for k in 0..kk.saturating_sub(1) {
        // P_{k+1} H = ((2k+1) s P_k H − k P_{k−1} H)/(k+1)
        let a = (2 * k + 1) as f64 / (k + 1) as f64;
        let bk = k as f64 / (k + 1) as f64;
        let m = len + 1;
        let (lo0, mid0, hi0) = (&lo[..m], &mid[..m], &hi[..m]);
        for v in 0..nv {
            // Equal-length slices so the loop runs without bounds checks and vectorises.
            let c = &cur[v];
            let (c0, c1, c2) = (&c[..m], &c[1..m + 1], &c[2..m + 2]);
            let pv = &prev[v][1..m + 1];
            let nx = &mut next[v][1..m + 1];
            for l in 0..m {
                let se = lo0[l] * c0[l] + mid0[l] * c1[l] + hi0[l] * c2[l];
                nx[l] = a * se - bk * pv[l];
            }
        }
        let (wr, wi) = (w[k + 1].re, w[k + 1].im);
        for b in 0..hs.len() {
            let (xr, xi) = (&next[2 * b][1..m + 1], &next[2 * b + 1][1..m + 1]);
            let (dr, di) = (&mut dre[b][..m], &mut dim[b][..m]);
            for l in 0..m {
                dr[l] += wr * xr[l] - wi * xi[l];
                di[l] += wr * xi[l] + wi * xr[l];
            }
        }
        len += 1;
        std::mem::swap(&mut prev, &mut cur);
        std::mem::swap(&mut cur, &mut next);
    }
    let ph = Complex64::from_polar(1.0, 0.5 * f);
    (0..hs.len())
        .map(|b| {
            (0..len)
                .map(|l| {
                    let v = Complex64::new(dre[b][l], dim[b][l]) * ph;
                    if l % 2 == 0 {
                        v
                    } else {
                        -v
                    }
                })
                .collect()
        })
        .collect()
}

/// Highest Bessel order that is not negligible (< 1e-25 relative) at argument v.
#[inline]
pub fn bessel_order_cutoff(v: f64) -> usize {
    (v + 40.0 + 12.0 * v.cbrt()).ceil() as usize
}

/// b_ν = J_ν(v)/v for ν = 0..=nu_max (b_0 unused and set to 0), written without dividing by v.
/// Orders past the cutoff (negligible) are left out, so `out` may be shorter than nu_max + 1.
/// `jbuf` is scratch of any size.
pub fn bessel_over_v(v: f64, nu_max: usize, jbuf: &mut Vec<f64>, out: &mut Vec<f64>) {
    let top = nu_max.min(bessel_order_cutoff(v.abs())) + 1;
    out.clear();
    out.resize(top.min(nu_max + 1), 0.0);
    jbuf.clear();
    jbuf.resize(top + 1, 0.0);
    bessel_j_sequence(top, v, jbuf);
    for nu in 1..out.len() {
        out[nu] = (jbuf[nu - 1] + jbuf[nu + 1]) / (2.0 * nu as f64);
    }
}

/// Σ_l D_l b_{μ+2l+1}.
#[inline]
pub fn bb_sum(mu: u32, d: &[Complex64], b: &[f64]) -> Complex64 {
    let start = mu as usize + 1;
    if start >= b.len() {
        return C0;
    }
    let nterms = d.len().min((b.len() - start).div_ceil(2));
    let (mut re, mut im) = (0.0, 0.0);
    for l in 0..nterms {
        let bv = b[start + 2 * l];
        re += d[l].re * bv;
        im += d[l].im * bv;
    }
    Complex64::new(re, im)
}

fn validate_nmrf(n: u32, m: i32, r: f64, f: f64) -> Result<(), OpticsError> {
    if !is_valid_nm(n, m) || n > 400 {
        return Err(OpticsError::UnknownTerm { n, m, max_n: 400 });
    }
    check_range("r", r, -MAX_R, MAX_R, "|r| <= 20000 (units of lambda/NA)")?;
    check_range("f", f, -MAX_ABS_F, MAX_ABS_F, "|f| <= 5000")?;
    Ok(())
}

/// V_n^m(r, f) by the Bessel–Bessel series, with input checks.
pub fn try_vnm(n: u32, m: i32, r: f64, f: f64) -> Result<Complex64, OpticsError> {
    validate_nmrf(n, m, r, f)?;
    let mu = m.unsigned_abs();
    let p = ((n - mu) / 2) as usize;
    let mut h = vec![C0; p + 1];
    h[p] = Complex64::new(1.0, 0.0);
    let d = bb_coefficients(mu, &h, f);
    let v = 2.0 * PI * r.abs();
    let nu_max = mu as usize + 2 * d.len() + 1;
    let (mut jb, mut b) = (Vec::new(), Vec::new());
    bessel_over_v(v, nu_max, &mut jb, &mut b);
    let mut val = bb_sum(mu, &d, &b);
    // J_{−μ} = (−1)^μ J_μ, and J_μ(−x) = (−1)^μ J_μ(x) for r < 0.
    let flips = (m < 0) as u32 + (r < 0.0) as u32;
    if flips == 1 && mu % 2 == 1 {
        val = -val;
    }
    Ok(val)
}

/// V_n^m(r, f) by the Bessel–Bessel series. The number of terms follows from (r, f): about
/// |f|/2 + O(|f|^{1/3}) defocus terms and Bessel orders up to ≈ 2πr + O(r^{1/3}).
/// Returns 0 for an invalid (n, m) or out-of-range input (use [`try_vnm`] for the reason).
pub fn vnm(n: u32, m: i32, r: f64, f: f64) -> Complex64 {
    try_vnm(n, m, r, f).unwrap_or(C0)
}

/// V_n^m(r, f) by the power series in f: Σ_s (if)^s/s! ∫ ρ^{2s} R J ρ dρ, each moment exact via
/// the same Q_l expansion. Accurate only for small |f| (≲ 10): the terms grow like e^{|f|}
/// before they cancel. Kept as an independent check and for tiny f.
pub fn vnm_power_series(n: u32, m: i32, r: f64, f: f64) -> Complex64 {
    if validate_nmrf(n, m, r, f).is_err() {
        return C0;
    }
    let mu = m.unsigned_abs();
    let p = ((n - mu) / 2) as usize;
    let smax = (3.0 * f.abs() + 40.0).ceil() as usize;
    let total = p + smax + 2;
    let op = SOperator::new(mu, total + 1);
    let mut e = vec![C0; total + 1];
    let mut se = vec![C0; total + 1];
    e[p] = Complex64::new(1.0, 0.0);
    let mut d = e.clone();
    let mut len = p + 1;
    let mut coef = Complex64::new(1.0, 0.0);
    for s in 1..=smax {
        // ρ² = (1 + s_op)/2
        op.apply(&e, len, &mut se);
        for l in 0..=len {
            e[l] = 0.5 * (e[l] + se[l]);
        }
        len += 1;
        coef *= Complex64::new(0.0, f / s as f64);
        let mut mag = 0.0f64;
        for l in 0..len {
            let t = coef * e[l];
            d[l] += t;
            mag = mag.max(t.norm());
        }
        if s as f64 > f.abs() && mag < 1e-18 {
            break;
        }
    }
    d.truncate(len);
    for (l, v) in d.iter_mut().enumerate() {
        if l % 2 == 1 {
            *v = -*v;
        }
    }
    let v = 2.0 * PI * r.abs();
    let (mut jb, mut b) = (Vec::new(), Vec::new());
    bessel_over_v(v, mu as usize + 2 * d.len() + 1, &mut jb, &mut b);
    let mut val = bb_sum(mu, &d, &b);
    let flips = (m < 0) as u32 + (r < 0.0) as u32;
    if flips == 1 && mu % 2 == 1 {
        val = -val;
    }
    val
}

/// Number of Gauss–Legendre nodes that resolves e^{ifρ²} J_m(2πrρ) on [0, 1] to machine
/// precision: the integrand's local frequency is at most |f|·2 + 2πr rad per unit ρ.
pub fn quadrature_nodes(n: u32, r: f64, f: f64) -> usize {
    (0.6 * (2.0 * f.abs() + 2.0 * PI * r.abs()) + n as f64 + 60.0).ceil() as usize
}

/// V_n^m(r, f) by Gauss–Legendre quadrature with `nodes` points (None: [`quadrature_nodes`]).
pub fn vnm_quadrature(n: u32, m: i32, r: f64, f: f64, nodes: Option<usize>) -> Complex64 {
    if validate_nmrf(n, m, r, f).is_err() {
        return C0;
    }
    let q = nodes.unwrap_or_else(|| quadrature_nodes(n, r, f));
    let (xs, ws) = gauss_legendre_01(q);
    let v = 2.0 * PI * r;
    let mut s = C0;
    for (&x, &w) in xs.iter().zip(&ws) {
        let ph = Complex64::from_polar(1.0, f * x * x);
        s += ph * (w * radial(n, m, x) * bessel_j(m, v * x) * x);
    }
    s
}

/// All V_n^m(r, f) for orders ≤ max_order (OSA order) by one Gauss–Legendre rule: Bessel
/// sequences are shared across (n, m), so tests can afford many nodes.
pub fn vnm_quadrature_all(max_order: u32, r: f64, f: f64, nodes: usize) -> Vec<Complex64> {
    let nt = super::zernike::num_terms(max_order);
    let (xs, ws) = gauss_legendre_01(nodes);
    let v = 2.0 * PI * r;
    let mut out = vec![C0; nt];
    let mut jseq = vec![0.0; max_order as usize + 1];
    let mut rad = vec![0.0; max_order as usize / 2 + 1];
    for (&x, &w) in xs.iter().zip(&ws) {
        bessel_j_sequence(max_order as usize, v * x, &mut jseq);
        let ph = Complex64::from_polar(1.0, f * x * x) * (w * x);
        for mu in 0..=max_order {
            super::zernike::radial_family(max_order, mu, x, &mut rad);
            let count = ((max_order - mu) / 2) as usize + 1;
            for (k, rk) in rad.iter().enumerate().take(count) {
                let n = mu + 2 * k as u32;
                let t = ph * (rk * jseq[mu as usize]);
                out[osa_index(n, mu as i32)] += t;
                if mu > 0 {
                    let sign = if mu % 2 == 1 { -1.0 } else { 1.0 };
                    out[osa_index(n, -(mu as i32))] += t * sign;
                }
            }
        }
    }
    out
}

/// Six-point Lagrange weights for nodes at offsets −2..=3 and a position t ∈ [0, 1).
#[inline]
pub fn lagrange6(t: f64) -> [f64; 6] {
    let d = [t + 2.0, t + 1.0, t, t - 1.0, t - 2.0, t - 3.0];
    // denominators Π_{j≠k}(k − j) for k = −2..3
    const DEN: [f64; 6] = [-120.0, 24.0, -12.0, 12.0, -24.0, 120.0];
    let mut w = [0.0; 6];
    for k in 0..6 {
        let mut p = 1.0;
        for (j, dj) in d.iter().enumerate() {
            if j != k {
                p *= dj;
            }
        }
        w[k] = p / DEN[k];
    }
    w
}

/// Radial step that keeps six-point Lagrange interpolation of an amplitude band-limited to one
/// cycle per unit r (every V_n^m is) within `tol` relative to its maximum. Error ≈ 5e-3 (2πh)^6.
pub fn interpolation_step(tol: f64) -> f64 {
    let tol = tol.clamp(1e-14, 1e-1);
    ((tol / 5e-3).powf(1.0 / 6.0) / (2.0 * PI)).min(0.25)
}

/// Table of V_n^m(r, f) for all (n, m) up to an order, at r_i = (i − 2)·step (two ghost nodes
/// below 0 filled by parity), for one f. Built with one Bessel sequence per node shared by all
/// terms; read back exactly at nodes or by six-point Lagrange interpolation between them.
pub struct VTable {
    pub f: f64,
    pub step: f64,
    pub max_order: u32,
    nodes: usize,
    /// values[node * terms + osa_j]
    values: Vec<Complex64>,
}

impl VTable {
    pub fn new(max_order: u32, f: f64, r_max: f64, step: f64) -> Result<VTable, OpticsError> {
        check_range("f", f, -MAX_ABS_F, MAX_ABS_F, "|f| <= 5000")?;
        check_range("r_max", r_max, 0.0, MAX_R, "0 <= r_max <= 20000")?;
        check_range("step", step, 1e-4, 10.0, "1e-4 <= step <= 10")?;
        if max_order > 200 {
            return Err(OpticsError::UnknownTerm {
                n: max_order,
                m: 0,
                max_n: 200,
            });
        }
        let nt = super::zernike::num_terms(max_order);
        let cells = (r_max / step + 7.0) * nt as f64;
        check_range(
            "table size (nodes x terms)",
            cells,
            0.0,
            5e7,
            "at most 5e7 values: raise step or lower r_max/max_order",
        )?;
        let w = defocus_weights(f);
        // D for (n, μ ≥ 0); negative m follow by parity.
        let mut coeffs: Vec<(usize, u32, Vec<Complex64>)> = Vec::new();
        let mut nu_max = 0;
        for j in 0..nt {
            let (n, m) = osa_nm(j);
            if m < 0 {
                continue;
            }
            let p = ((n - m as u32) / 2) as usize;
            let mut h = vec![C0; p + 1];
            h[p] = Complex64::new(1.0, 0.0);
            let d = bb_coefficients_with_weights(m as u32, &h, &w, f);
            nu_max = nu_max.max(m as usize + 2 * d.len() + 1);
            coeffs.push((j, m as u32, d));
        }
        let nodes = (r_max / step).ceil() as usize + 6;
        let mut values = vec![C0; nodes * nt];
        let (mut jb, mut b) = (Vec::new(), Vec::new());
        for i in 2..nodes {
            let r = (i - 2) as f64 * step;
            bessel_over_v(2.0 * PI * r, nu_max, &mut jb, &mut b);
            let row = &mut values[i * nt..(i + 1) * nt];
            for (j, mu, d) in &coeffs {
                let v = bb_sum(*mu, d, &b);
                row[*j] = v;
                if *mu > 0 {
                    let (n, _) = osa_nm(*j);
                    let jn = osa_index(n, -(*mu as i32));
                    row[jn] = if mu % 2 == 1 { -v } else { v };
                }
            }
        }
        // ghosts: V(−r) = (−1)^m V(r)
        for g in 0..2 {
            let src = 4 - g; // node for r = (2 − g)·step
            for j in 0..nt {
                let (_, m) = osa_nm(j);
                let v = values[src * nt + j];
                values[g * nt + j] = if m.unsigned_abs() % 2 == 1 { -v } else { v };
            }
        }
        Ok(VTable {
            f,
            step,
            max_order,
            nodes,
            values,
        })
    }

    /// Largest r the table can interpolate.
    pub fn r_max(&self) -> f64 {
        (self.nodes - 6) as f64 * self.step
    }

    /// Exact value at node `i` (r = i·step).
    pub fn node(&self, n: u32, m: i32, i: usize) -> Complex64 {
        let nt = super::zernike::num_terms(self.max_order);
        self.values[(i + 2) * nt + osa_index(n, m)]
    }

    /// Interpolated V_n^m(r, f), r ∈ [0, r_max]; 0 outside or for an unknown term.
    pub fn value(&self, n: u32, m: i32, r: f64) -> Complex64 {
        if !is_valid_nm(n, m) || n > self.max_order || !(0.0..=self.r_max()).contains(&r) {
            return C0;
        }
        let nt = super::zernike::num_terms(self.max_order);
        let j = osa_index(n, m);
        let u = r / self.step;
        let i = (u.floor() as usize).min(self.nodes - 6);
        let w = lagrange6(u - i as f64);
        let mut s = C0;
        for (k, wk) in w.iter().enumerate() {
            s += self.values[(i + k) * nt + j] * wk;
        }
        s
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reference_table() {
        let table: [(u32, i32, f64, f64, f64, f64); 7] = [
            (0, 0, 0.5, 0.0, 9.0595877494e-2, 0.0),
            (0, 0, 0.5, 3.0, 1.2913592693e-1, 4.0646677619e-2),
            (2, 0, 1.0, 2.0, -1.9352067130e-2, 1.3896862246e-2),
            (4, 0, 0.7, -5.0, 1.2743522118e-2, -3.2951487806e-2),
            (3, 1, 1.2, 4.0, -2.4554345458e-2, 4.9533527546e-3),
            (2, 2, 0.9, 10.0, 5.8911588931e-3, -7.0252255155e-3),
            (6, -2, 2.5, 25.0, 3.1942513235e-4, 5.6773161770e-3),
        ];
        for (n, m, r, f, re, im) in table {
            let v = vnm(n, m, r, f);
            assert!(
                (v.re - re).abs() < 1e-10 && (v.im - im).abs() < 1e-10,
                "{n} {m} {r} {f}: {v}"
            );
        }
    }
}
