//! Zernike polynomials in the OSA/ANSI convention (Thibos et al. 2002).
//!
//! Conventions used everywhere in ocular:
//! - single index j = (n(n+2)+m)/2, starting at 0 for piston;
//! - orthonormal over the unit disk: (1/π)∫∫ Z_j Z_k dA = δ_jk, i.e. the normalisation
//!   N_n^m = sqrt(2(n+1)/(1+δ_m0));
//! - θ = atan2(y, x), counter-clockwise from +x; m ≥ 0 carries cos(mθ), m < 0 carries sin(|m|θ);
//! - coefficients in µm, pupil sizes as diameters in mm.
//!
//! This file depends on `std` only so that other parts of the project (the eye model) can
//! compile it on its own.

use std::f64::consts::PI;
use std::fmt;

/// OSA/ANSI single index of (n, m). The pair must satisfy [`is_valid_nm`].
#[inline]
pub fn osa_index(n: u32, m: i32) -> usize {
    debug_assert!(is_valid_nm(n, m), "invalid Zernike (n, m) = ({n}, {m})");
    let n = n as i64;
    ((n * (n + 2) + m as i64) / 2) as usize
}

/// (n, m) of an OSA/ANSI single index.
#[inline]
pub fn osa_nm(j: usize) -> (u32, i32) {
    // Float guess, then integer correction, so large j never lands in the wrong row.
    let mut n = ((-3.0 + (9.0 + 8.0 * j as f64).sqrt()) / 2.0)
        .ceil()
        .max(0.0) as i64;
    let j = j as i64;
    while n > 0 && (n - 1) * (n + 2) / 2 >= j {
        n -= 1;
    }
    while n * (n + 3) / 2 < j {
        n += 1;
    }
    let m = 2 * j - n * (n + 2);
    (n as u32, m as i32)
}

/// Number of terms of all orders 0..=max_order: (N+1)(N+2)/2.
#[inline]
pub fn num_terms(max_order: u32) -> usize {
    let n = max_order as usize;
    (n + 1) * (n + 2) / 2
}

/// Whether (n, m) names a Zernike polynomial: |m| ≤ n and n − |m| even.
#[inline]
pub fn is_valid_nm(n: u32, m: i32) -> bool {
    let am = m.unsigned_abs();
    am <= n && (n - am).is_multiple_of(2)
}

/// (n, m) of a Noll index (1-based). Noll orders terms by increasing |m| within an order and
/// gives cos terms (m > 0) even indices, sin terms (m < 0) odd ones.
pub fn noll_nm(noll: usize) -> (u32, i32) {
    assert!(noll >= 1, "Noll indices start at 1");
    let mut n: usize = 0;
    while (n + 1) * (n + 2) / 2 < noll {
        n += 1;
    }
    let p = noll - n * (n + 1) / 2; // 1-based position within the order
    let am = if n.is_multiple_of(2) {
        2 * (p / 2)
    } else {
        2 * ((p - 1) / 2) + 1
    };
    let m = if am == 0 {
        0
    } else if noll.is_multiple_of(2) {
        am as i32
    } else {
        -(am as i32)
    };
    (n as u32, m)
}

/// Noll index (1-based) → OSA index (0-based).
pub fn noll_to_osa(noll: usize) -> usize {
    let (n, m) = noll_nm(noll);
    osa_index(n, m)
}

/// OSA index (0-based) → Noll index (1-based).
pub fn osa_to_noll(j: usize) -> usize {
    let (n, m) = osa_nm(j);
    let start = (n as usize) * (n as usize + 1) / 2;
    (start + 1..=start + n as usize + 1)
        .find(|&k| noll_nm(k) == (n, m))
        .expect("every OSA term has a Noll index in the same order")
}

/// Orthonormalising factor sqrt(2(n+1)/(1+δ_m0)).
#[inline]
pub fn normalization(n: u32, m: i32) -> f64 {
    let d = if m == 0 { 1.0 } else { 2.0 };
    (d * (n as f64 + 1.0)).sqrt()
}

/// Coefficients (a, b, c, d) of the Jacobi recurrence for P_k^{(0,m)}:
/// a·P_{k+1}(s) = (b·s + c)·P_k(s) − d·P_{k−1}(s), for k ≥ 1 (k = 0 is the special first step).
/// R_n^m(ρ) = ρ^m P_k^{(0,m)}(2ρ² − 1) with k = (n − m)/2; this recurrence is stable in k, which
/// the explicit factorial sum is not beyond n ≈ 20.
#[inline]
fn jacobi_step(k: f64, m: f64) -> (f64, f64, f64, f64) {
    let t = 2.0 * k + m;
    let a = 2.0 * (k + 1.0) * (k + m + 1.0) * t;
    let b = (t + 1.0) * (t + 2.0) * t;
    let c = -(t + 1.0) * m * m;
    let d = 2.0 * k * (k + m) * (t + 2.0);
    (a, b, c, d)
}

/// P_k^{(0,m)}(s) and its derivative d/ds for k = 0..out.len(), written into `p` and `dp`.
#[inline]
fn jacobi_0m(m: u32, s: f64, p: &mut [f64], dp: Option<&mut [f64]>) {
    let len = p.len();
    if len == 0 {
        return;
    }
    let mf = m as f64;
    p[0] = 1.0;
    if len > 1 {
        p[1] = 1.0 + 0.5 * (mf + 2.0) * (s - 1.0);
    }
    for k in 1..len.saturating_sub(1) {
        let (a, b, c, d) = jacobi_step(k as f64, mf);
        p[k + 1] = ((b * s + c) * p[k] - d * p[k - 1]) / a;
    }
    if let Some(dp) = dp {
        dp[0] = 0.0;
        if len > 1 {
            dp[1] = 0.5 * (mf + 2.0);
        }
        for k in 1..len.saturating_sub(1) {
            let (a, b, c, d) = jacobi_step(k as f64, mf);
            dp[k + 1] = (b * p[k] + (b * s + c) * dp[k] - d * dp[k - 1]) / a;
        }
    }
}

/// R_n^|m|(ρ) and dR/dρ, by the stable Jacobi recurrence. Returns 0 for an invalid (n, m).
pub fn radial_with_derivative(n: u32, m: i32, rho: f64) -> (f64, f64) {
    if !is_valid_nm(n, m) {
        return (0.0, 0.0);
    }
    let am = m.unsigned_abs();
    let k = ((n - am) / 2) as usize;
    let s = 2.0 * rho * rho - 1.0;
    let mf = am as f64;
    // (P_k, P_{k-1}) and their s-derivatives, started at k = 0 with P_{-1} := 0.
    let (mut pk, mut pk1, mut dk, mut dk1) = (1.0, 0.0, 0.0, 0.0);
    for i in 0..k {
        let (pn, dn) = if i == 0 {
            (1.0 + 0.5 * (mf + 2.0) * (s - 1.0), 0.5 * (mf + 2.0))
        } else {
            let (a, b, c, d) = jacobi_step(i as f64, mf);
            (
                ((b * s + c) * pk - d * pk1) / a,
                (b * pk + (b * s + c) * dk - d * dk1) / a,
            )
        };
        pk1 = pk;
        pk = pn;
        dk1 = dk;
        dk = dn;
    }
    let rm = rho.powi(am as i32);
    let drm = if am == 0 {
        0.0
    } else {
        mf * rho.powi(am as i32 - 1)
    };
    // d/dρ [ρ^m P(2ρ²−1)] = mρ^{m−1} P + ρ^m · 4ρ · P'
    (rm * pk, drm * pk + rm * 4.0 * rho * dk)
}

/// Radial polynomial R_n^|m|(ρ) (unnormalised, R(1) = 1). 0 for an invalid (n, m).
#[inline]
pub fn radial(n: u32, m: i32, rho: f64) -> f64 {
    radial_with_derivative(n, m, rho).0
}

/// dR_n^|m|/dρ. 0 for an invalid (n, m).
#[inline]
pub fn radial_derivative(n: u32, m: i32, rho: f64) -> f64 {
    radial_with_derivative(n, m, rho).1
}

/// All radial polynomials R_n^|m|(ρ) for one |m| and n = |m|, |m|+2, …, ≤ max_order, in order
/// of increasing n. `out` must have at least (max_order − |m|)/2 + 1 entries.
pub fn radial_family(max_order: u32, m: u32, rho: f64, out: &mut [f64]) {
    if m > max_order {
        return;
    }
    let len = ((max_order - m) / 2 + 1) as usize;
    let out = &mut out[..len];
    jacobi_0m(m, 2.0 * rho * rho - 1.0, out, None);
    let rm = rho.powi(m as i32);
    for v in out.iter_mut() {
        *v *= rm;
    }
}

/// Value of one orthonormal Zernike term at a Cartesian point of the unit disk.
pub fn zernike_value(n: u32, m: i32, x: f64, y: f64) -> f64 {
    if !is_valid_nm(n, m) {
        return 0.0;
    }
    let rho = x.hypot(y);
    let theta = y.atan2(x);
    let ang = if m >= 0 {
        (m as f64 * theta).cos()
    } else {
        ((-m) as f64 * theta).sin()
    };
    normalization(n, m) * radial(n, m, rho) * ang
}

/// All orthonormal Zernike values of orders 0..=max_order at (x, y), in OSA order.
/// `out` must hold at least [`num_terms`]`(max_order)` values. Works off the disk too
/// (the polynomials are simply continued), which fitting code may rely on.
///
/// Uses ρ^m cos(mθ) = Re (x+iy)^m and ρ^m sin(mθ) = Im (x+iy)^m, so no angle, no division
/// and no special case at the origin.
pub fn basis_values(max_order: u32, x: f64, y: f64, out: &mut [f64]) {
    let nt = num_terms(max_order);
    assert!(out.len() >= nt, "basis_values: out too short");
    let s = 2.0 * (x * x + y * y) - 1.0;
    let mut p = [0.0f64; 64];
    let mut p_heap;
    let pbuf: &mut [f64] = if (max_order as usize) / 2 < p.len() {
        &mut p[..]
    } else {
        p_heap = vec![0.0; max_order as usize / 2 + 1];
        &mut p_heap[..]
    };
    // (re, im) = (x + iy)^m
    let (mut re, mut im) = (1.0f64, 0.0f64);
    for m in 0..=max_order {
        let len = ((max_order - m) / 2 + 1) as usize;
        jacobi_0m(m, s, &mut pbuf[..len], None);
        for (k, &pk) in pbuf[..len].iter().enumerate() {
            let n = m + 2 * k as u32;
            let norm = normalization(n, m as i32);
            let ni = n as usize;
            if m == 0 {
                out[ni * (ni + 2) / 2] = norm * pk;
            } else {
                let jp = (ni * (ni + 2) + m as usize) / 2;
                let jn = (ni * (ni + 2) - m as usize) / 2;
                out[jp] = norm * pk * re;
                out[jn] = norm * pk * im;
            }
        }
        let nre = re * x - im * y;
        im = re * y + im * x;
        re = nre;
    }
}

/// Partial derivatives ∂Z/∂x and ∂Z/∂y of all orthonormal terms of orders 0..=max_order at
/// (x, y), OSA order. Both outputs must hold [`num_terms`]`(max_order)` values.
pub fn basis_gradients(max_order: u32, x: f64, y: f64, out_dx: &mut [f64], out_dy: &mut [f64]) {
    let nt = num_terms(max_order);
    assert!(
        out_dx.len() >= nt && out_dy.len() >= nt,
        "basis_gradients: outputs too short"
    );
    let s = 2.0 * (x * x + y * y) - 1.0;
    let kmax = max_order as usize / 2 + 1;
    // Stack buffers for the usual orders: this runs inside optimisers' inner loops.
    let (mut ps, mut dps) = ([0.0f64; 64], [0.0f64; 64]);
    let (mut ph, mut dph);
    let (p, dp): (&mut [f64], &mut [f64]) = if kmax <= 64 {
        (&mut ps[..], &mut dps[..])
    } else {
        ph = vec![0.0; kmax];
        dph = vec![0.0; kmax];
        (&mut ph[..], &mut dph[..])
    };
    // z^m and z^(m-1) with z = x + iy; d/dx z^m = m z^(m-1), d/dy z^m = i m z^(m-1).
    let (mut re, mut im) = (1.0f64, 0.0f64);
    let (mut re1, mut im1) = (0.0f64, 0.0f64);
    for m in 0..=max_order {
        let len = ((max_order - m) / 2 + 1) as usize;
        jacobi_0m(m, s, &mut p[..len], Some(&mut dp[..len]));
        let mf = m as f64;
        for k in 0..len {
            let n = m + 2 * k as u32;
            let norm = normalization(n, m as i32);
            let ni = n as usize;
            // Z = N · T(x,y) · P(s), s = 2(x²+y²) − 1, ∂s/∂x = 4x, ∂s/∂y = 4y.
            let (pk, dpk) = (p[k], dp[k]);
            if m == 0 {
                let j = ni * (ni + 2) / 2;
                out_dx[j] = norm * dpk * 4.0 * x;
                out_dy[j] = norm * dpk * 4.0 * y;
            } else {
                let jp = (ni * (ni + 2) + m as usize) / 2;
                let jn = (ni * (ni + 2) - m as usize) / 2;
                // cos part: T = Re z^m; ∂T/∂x = m Re z^(m-1), ∂T/∂y = −m Im z^(m-1)
                out_dx[jp] = norm * (mf * re1 * pk + re * dpk * 4.0 * x);
                out_dy[jp] = norm * (-mf * im1 * pk + re * dpk * 4.0 * y);
                // sin part: T = Im z^m; ∂T/∂x = m Im z^(m-1), ∂T/∂y = m Re z^(m-1)
                out_dx[jn] = norm * (mf * im1 * pk + im * dpk * 4.0 * x);
                out_dy[jn] = norm * (mf * re1 * pk + im * dpk * 4.0 * y);
            }
        }
        re1 = re;
        im1 = im;
        let nre = re * x - im * y;
        im = re * y + im * x;
        re = nre;
    }
}

/// Highest order N whose full set (N+1)(N+2)/2 covers `len` coefficients.
pub fn order_for_len(len: usize) -> u32 {
    if len == 0 {
        return 0;
    }
    osa_nm(len - 1).0
}

/// Wavefront W(x, y) = Σ c_j Z_j(x, y) from OSA-ordered coefficients (units of c).
pub fn wavefront(coeffs: &[f64], x: f64, y: f64) -> f64 {
    if coeffs.is_empty() {
        return 0.0;
    }
    let order = order_for_len(coeffs.len());
    let mut z = vec![0.0; num_terms(order)];
    basis_values(order, x, y, &mut z);
    coeffs.iter().zip(&z).map(|(c, z)| c * z).sum()
}

/// Wavefront gradient (∂W/∂x, ∂W/∂y) in units of c per pupil radius.
pub fn wavefront_gradient(coeffs: &[f64], x: f64, y: f64) -> (f64, f64) {
    if coeffs.is_empty() {
        return (0.0, 0.0);
    }
    let order = order_for_len(coeffs.len());
    let nt = num_terms(order);
    let (mut dx, mut dy) = (vec![0.0; nt], vec![0.0; nt]);
    basis_gradients(order, x, y, &mut dx, &mut dy);
    coeffs
        .iter()
        .zip(dx.iter().zip(&dy))
        .fold((0.0, 0.0), |(ax, ay), (c, (gx, gy))| {
            (ax + c * gx, ay + c * gy)
        })
}

/// RMS wavefront error over the pupil: sqrt(Σ_{j≥1} c_j²) (piston excluded).
pub fn rms(coeffs: &[f64]) -> f64 {
    coeffs.iter().skip(1).map(|c| c * c).sum::<f64>().sqrt()
}

/// RMS of the terms of order ≥ `min_order` only (e.g. 3 for higher-order RMS).
pub fn rms_from_order(coeffs: &[f64], min_order: u32) -> f64 {
    coeffs
        .iter()
        .enumerate()
        .filter(|(j, _)| *j > 0 && osa_nm(*j).0 >= min_order)
        .map(|(_, c)| c * c)
        .sum::<f64>()
        .sqrt()
}

/// OSA-ordered coefficient vector of orders 0..=max_order from (n, m, value) triples.
/// Returns `None` if a pair is invalid or above `max_order`.
pub fn coefficients_from_pairs(max_order: u32, pairs: &[(u32, i32, f64)]) -> Option<Vec<f64>> {
    let mut c = vec![0.0; num_terms(max_order)];
    for &(n, m, v) in pairs {
        if !is_valid_nm(n, m) || n > max_order {
            return None;
        }
        c[osa_index(n, m)] += v;
    }
    Some(c)
}

/// Errors of the fitting and rescaling routines.
#[derive(Debug, Clone, PartialEq)]
pub enum ZernikeError {
    /// Fewer independent samples than unknowns, or samples that do not determine every term.
    RankDeficient { terms: usize, samples: usize },
    /// A sample or parameter was NaN or infinite.
    NonFinite(&'static str),
    /// A parameter outside its allowed range.
    OutOfRange(&'static str),
}

impl fmt::Display for ZernikeError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            ZernikeError::RankDeficient { terms, samples } => write!(
                f,
                "Zernike fit is under-determined: {terms} terms from {samples} samples \
                 (need samples spread over the pupil, at least as many as terms)"
            ),
            ZernikeError::NonFinite(what) => write!(f, "{what} must be finite (got NaN or Inf)"),
            ZernikeError::OutOfRange(what) => write!(f, "{what}"),
        }
    }
}

impl std::error::Error for ZernikeError {}

/// Least-squares solution of A x = b (A: rows × cols, row-major) by Householder QR, which keeps
/// the accuracy of the data (the normal equations would square the condition number).
fn least_squares(
    mut a: Vec<f64>,
    rows: usize,
    cols: usize,
    mut b: Vec<f64>,
) -> Result<Vec<f64>, ZernikeError> {
    if rows < cols {
        return Err(ZernikeError::RankDeficient {
            terms: cols,
            samples: rows,
        });
    }
    let mut diag = vec![0.0; cols];
    let scale = a.iter().fold(0.0f64, |s, v| s.max(v.abs())).max(1e-300);
    for k in 0..cols {
        let mut norm = 0.0;
        for i in k..rows {
            norm += a[i * cols + k] * a[i * cols + k];
        }
        let norm = norm.sqrt();
        if norm <= 1e-12 * scale {
            return Err(ZernikeError::RankDeficient {
                terms: cols,
                samples: rows,
            });
        }
        let alpha = if a[k * cols + k] > 0.0 { -norm } else { norm };
        // v = a_k − alpha e_k, stored in place in column k
        a[k * cols + k] -= alpha;
        let vnorm2: f64 = (k..rows).map(|i| a[i * cols + k] * a[i * cols + k]).sum();
        diag[k] = alpha;
        if vnorm2 == 0.0 {
            continue;
        }
        for j in k + 1..cols {
            let dot: f64 = (k..rows).map(|i| a[i * cols + k] * a[i * cols + j]).sum();
            let f = 2.0 * dot / vnorm2;
            for i in k..rows {
                a[i * cols + j] -= f * a[i * cols + k];
            }
        }
        let dot: f64 = (k..rows).map(|i| a[i * cols + k] * b[i]).sum();
        let f = 2.0 * dot / vnorm2;
        for i in k..rows {
            b[i] -= f * a[i * cols + k];
        }
    }
    let mut x = vec![0.0; cols];
    for k in (0..cols).rev() {
        let mut s = b[k];
        for j in k + 1..cols {
            s -= a[k * cols + j] * x[j];
        }
        x[k] = s / diag[k];
    }
    Ok(x)
}

/// Least-squares fit of OSA coefficients of orders 0..=max_order to wavefront samples
/// (x, y, W) with (x, y) in pupil-radius units. Result has the units of W.
pub fn fit_wavefront(
    max_order: u32,
    samples: &[(f64, f64, f64)],
) -> Result<Vec<f64>, ZernikeError> {
    let nt = num_terms(max_order);
    let mut a = Vec::with_capacity(samples.len() * nt);
    let mut b = Vec::with_capacity(samples.len());
    let mut z = vec![0.0; nt];
    for &(x, y, w) in samples {
        if !(x.is_finite() && y.is_finite() && w.is_finite()) {
            return Err(ZernikeError::NonFinite("wavefront sample"));
        }
        basis_values(max_order, x, y, &mut z);
        a.extend_from_slice(&z);
        b.push(w);
    }
    least_squares(a, samples.len(), nt, b)
}

/// Least-squares fit of OSA coefficients of orders 0..=max_order to slope samples
/// (x, y, ∂W/∂x, ∂W/∂y), slopes per pupil radius. Piston is not observable from slopes and is
/// returned as 0.
pub fn fit_slopes(
    max_order: u32,
    samples: &[(f64, f64, f64, f64)],
) -> Result<Vec<f64>, ZernikeError> {
    let nt = num_terms(max_order);
    if nt <= 1 {
        return Ok(vec![0.0; nt]);
    }
    let cols = nt - 1;
    let mut a = Vec::with_capacity(2 * samples.len() * cols);
    let mut b = Vec::with_capacity(2 * samples.len());
    let (mut gx, mut gy) = (vec![0.0; nt], vec![0.0; nt]);
    for &(x, y, sx, sy) in samples {
        if !(x.is_finite() && y.is_finite() && sx.is_finite() && sy.is_finite()) {
            return Err(ZernikeError::NonFinite("slope sample"));
        }
        basis_gradients(max_order, x, y, &mut gx, &mut gy);
        a.extend_from_slice(&gx[1..]);
        b.push(sx);
        a.extend_from_slice(&gy[1..]);
        b.push(sy);
    }
    let x = least_squares(a, b.len(), cols, b)?;
    let mut c = vec![0.0; nt];
    c[1..].copy_from_slice(&x);
    Ok(c)
}

/// Gauss–Legendre nodes and weights on [0, 1] (Newton on the Legendre recurrence).
fn gauss_legendre_unit(npts: usize) -> (Vec<f64>, Vec<f64>) {
    let mut xs = vec![0.0; npts];
    let mut ws = vec![0.0; npts];
    let nf = npts as f64;
    for i in 0..npts {
        let mut x = (PI * (i as f64 + 0.75) / (nf + 0.5)).cos();
        let mut dp = 1.0;
        for _ in 0..100 {
            let (mut p0, mut p1) = (1.0, x);
            for k in 2..=npts {
                let kf = k as f64;
                let p2 = ((2.0 * kf - 1.0) * x * p1 - (kf - 1.0) * p0) / kf;
                p0 = p1;
                p1 = p2;
            }
            let p = if npts == 0 { 1.0 } else { p1 };
            let pm1 = if npts == 1 { 1.0 } else { p0 };
            dp = nf * (x * p - pm1) / (x * x - 1.0);
            let dx = p / dp;
            x -= dx;
            if dx.abs() < 1e-16 {
                break;
            }
        }
        xs[i] = 0.5 * (1.0 - x);
        ws[i] = 1.0 / ((1.0 - x * x) * dp * dp);
    }
    (xs, ws)
}

/// Rescale OSA coefficients measured over a pupil to a concentric pupil `ratio` = R_new/R_old
/// times its radius (ratio ≤ 1 shrinks; > 1 extrapolates the polynomial, which is exact as
/// algebra but only meaningful if the wavefront really continues). Exact for any order: the
/// projection integrals are polynomials evaluated with Gauss–Legendre quadrature of
/// sufficient degree.
pub fn rescale_pupil(coeffs: &[f64], ratio: f64) -> Result<Vec<f64>, ZernikeError> {
    if !ratio.is_finite() {
        return Err(ZernikeError::NonFinite("pupil ratio"));
    }
    if ratio <= 0.0 {
        return Err(ZernikeError::OutOfRange("pupil ratio must be > 0"));
    }
    if coeffs.is_empty() {
        return Ok(Vec::new());
    }
    let order = order_for_len(coeffs.len());
    let nt = num_terms(order);
    let mut c = coeffs.to_vec();
    c.resize(nt, 0.0);
    let mut out = vec![0.0; nt];
    // ∫₀¹ R_n(ερ) R_n'(ρ) ρ dρ has degree ≤ 2N+1 in ρ: N+1 nodes suffice; a few more are free.
    let (xs, ws) = gauss_legendre_unit(order as usize + 3);
    let kmax = order as usize / 2 + 1;
    let mut ra = vec![0.0; kmax];
    let mut rb = vec![0.0; kmax];
    for am in 0..=order {
        let len = ((order - am) / 2 + 1) as usize;
        // g[k][k'] = 2 sqrt((n+1)(n'+1)) ∫ R_n(ερ) R_n'(ρ) ρ dρ
        let mut g = vec![0.0; len * len];
        for (&x, &w) in xs.iter().zip(&ws) {
            radial_family(order, am, ratio * x, &mut ra);
            radial_family(order, am, x, &mut rb);
            for k in 0..len {
                for kp in 0..len {
                    g[k * len + kp] += w * x * ra[k] * rb[kp];
                }
            }
        }
        for k in 0..len {
            let n = am + 2 * k as u32;
            for kp in 0..len {
                let np = am + 2 * kp as u32;
                let f = 2.0 * ((n as f64 + 1.0) * (np as f64 + 1.0)).sqrt() * g[k * len + kp];
                let signs: &[i32] = if am == 0 { &[0] } else { &[1, -1] };
                for &sg in signs {
                    let m = sg * am as i32;
                    out[osa_index(np, m)] += f * c[osa_index(n, m)];
                }
            }
        }
    }
    Ok(out)
}

// The prescription lives in its own module; re-exported for the paths callers use.
pub use super::prescription::{Prescription, PrescriptionError};
