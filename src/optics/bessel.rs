//! Bessel functions of integer order J_n(x) and spherical Bessel functions j_k(x).
//!
//! Both are computed as whole sequences by downward (Miller) recurrence, which is stable for
//! the minimal solution in both the oscillatory (n < x) and the decaying (n > x) regime. The
//! arbitrary start is removed by a normalisation identity that holds for every x:
//! J_0 + 2 Σ J_2k = 1 and Σ (2k+1) j_k² = 1. Orders up to several thousand and arguments up to
//! several thousand stay at close to machine precision (absolute).

/// Where to start the downward recurrence so the unwanted (growing) solution has died out
/// by the time we reach order `nmax`. Past the turning point n ≈ x the minimal solution falls
/// like an Airy function over a width ∝ x^(1/3); 12 such widths put it below 1e-30.
fn miller_start(nmax: usize, x: f64) -> usize {
    let base = (nmax as f64).max(x);
    let start = base + 30.0 + 12.0 * x.cbrt();
    let s = start.ceil() as usize;
    s + (s & 1) // even, so the J normalisation sum ends on an even index
}

const RESCALE_ABOVE: f64 = 1e250;
const RESCALE_BY: f64 = 1e-250;

/// Small-argument series J_n(x) = (x/2)^n/n! Σ_k (−x²/4)^k / (k! (n+1)_k), valid when
/// |x| ≪ 1 (a few terms reach full precision).
fn j_series_small(nmax: usize, x: f64, out: &mut [f64]) {
    let h = 0.5 * x;
    let q = -h * h;
    let mut lead = 1.0; // (x/2)^n / n!
    for (n, o) in out.iter_mut().enumerate().take(nmax + 1) {
        if n > 0 {
            lead *= h / n as f64;
        }
        let nf = n as f64;
        let mut term = 1.0;
        let mut sum = 1.0;
        for k in 1..6 {
            let kf = k as f64;
            term *= q / (kf * (nf + kf));
            sum += term;
        }
        *o = lead * sum;
    }
}

/// The arguments both sequences treat alike: non-finite x (all 0), x < 0 (the sequence at −x,
/// odd orders negated, by parity) and x = 0 (1, 0, 0, …). True where `out` is filled.
fn special_argument(
    nmax: usize,
    x: f64,
    out: &mut [f64],
    sequence: fn(usize, f64, &mut [f64]),
) -> bool {
    if !x.is_finite() {
        out.iter_mut().for_each(|v| *v = 0.0);
    } else if x < 0.0 {
        sequence(nmax, -x, out);
        for (n, v) in out.iter_mut().enumerate() {
            if n % 2 == 1 {
                *v = -*v;
            }
        }
    } else if x == 0.0 {
        out.iter_mut().for_each(|v| *v = 0.0);
        out[0] = 1.0;
    } else {
        return false;
    }
    true
}

/// J_0(x) … J_nmax(x) into `out[0..=nmax]`, for any finite x (negative x via parity).
pub fn bessel_j_sequence(nmax: usize, x: f64, out: &mut [f64]) {
    assert!(out.len() > nmax, "bessel_j_sequence: out too short");
    let out = &mut out[..=nmax];
    if special_argument(nmax, x, out, bessel_j_sequence) {
        return;
    }
    if x < 1e-3 {
        j_series_small(nmax, x, out);
        return;
    }
    let start = miller_start(nmax, x);
    let two_over_x = 2.0 / x;
    let (mut jp1, mut j) = (0.0f64, 1e-300f64); // J_{n+1}, J_n at n = start
    let mut norm = 0.0; // J_0 + 2 Σ J_2k, in the current scale
    for n in (0..=start).rev() {
        if n <= nmax {
            out[n] = j;
        }
        if n % 2 == 0 {
            norm += if n == 0 { j } else { 2.0 * j };
        }
        if n == 0 {
            break;
        }
        let jm1 = n as f64 * two_over_x * j - jp1;
        jp1 = j;
        j = jm1;
        if j.abs() > RESCALE_ABOVE {
            j *= RESCALE_BY;
            jp1 *= RESCALE_BY;
            norm *= RESCALE_BY;
            let lo = n.min(nmax + 1);
            for v in out[lo..].iter_mut() {
                *v *= RESCALE_BY;
            }
        }
    }
    let inv = 1.0 / norm;
    out.iter_mut().for_each(|v| *v *= inv);
}

/// J_n(x) for any integer n (J_{−n} = (−1)^n J_n) and finite x.
pub fn bessel_j(n: i32, x: f64) -> f64 {
    let an = n.unsigned_abs() as usize;
    let mut buf = vec![0.0; an + 1];
    bessel_j_sequence(an, x, &mut buf);
    let v = buf[an];
    if n < 0 && an % 2 == 1 {
        -v
    } else {
        v
    }
}

/// Spherical Bessel j_0(x) … j_kmax(x) into `out[0..=kmax]` for any finite x.
pub fn spherical_j_sequence(kmax: usize, x: f64, out: &mut [f64]) {
    assert!(out.len() > kmax, "spherical_j_sequence: out too short");
    let out = &mut out[..=kmax];
    if special_argument(kmax, x, out, spherical_j_sequence) {
        return;
    }
    if x < 1e-3 {
        // j_k(x) = x^k/(2k+1)!! Σ_i (−x²/2)^i / (i! (2k+3)(2k+5)…(2k+2i+1))
        let q = -0.5 * x * x;
        let mut lead = 1.0;
        for (k, o) in out.iter_mut().enumerate() {
            if k > 0 {
                lead *= x / (2 * k + 1) as f64;
            }
            let mut term = 1.0;
            let mut sum = 1.0;
            for i in 1..6 {
                term *= q / (i as f64 * (2 * k + 2 * i + 1) as f64);
                sum += term;
            }
            *o = lead * sum;
        }
        return;
    }
    let start = miller_start(kmax, x);
    // Squares are summed, so values are kept within ±1e100 to keep them representable.
    let (mut jp1, mut j) = (0.0f64, 1e-100f64);
    let mut sumsq = 0.0;
    for k in (0..=start).rev() {
        if k <= kmax {
            out[k] = j;
        }
        sumsq += (2 * k + 1) as f64 * j * j;
        if k == 0 {
            break;
        }
        let jm1 = (2 * k + 1) as f64 / x * j - jp1;
        jp1 = j;
        j = jm1;
        if j.abs() > 1e100 {
            j *= 1e-100;
            jp1 *= 1e-100;
            sumsq *= 1e-200;
            let lo = k.saturating_sub(1).min(kmax + 1);
            for v in out[lo..].iter_mut() {
                *v *= 1e-100;
            }
        }
    }
    // Σ(2k+1) j_k² = 1 fixes the magnitude; the sign comes from the larger of the exact j_0, j_1
    // (near a zero of one the other is large and free of cancellation).
    let scale = 1.0 / sumsq.sqrt();
    let (s, c) = x.sin_cos();
    let j0 = s / x;
    let j1 = s / (x * x) - c / x;
    let sign = if j0.abs() >= j1.abs() {
        (j0 * out[0]).signum()
    } else if kmax >= 1 {
        (j1 * out[1]).signum()
    } else {
        // out[1] was not kept; recover it from the recurrence value just above index 0
        (j1 * jp1).signum()
    };
    out.iter_mut().for_each(|v| *v *= scale * sign);
}

/// Spherical Bessel j_k(x).
pub fn spherical_j(k: usize, x: f64) -> f64 {
    let mut buf = vec![0.0; k + 1];
    spherical_j_sequence(k, x, &mut buf);
    buf[k]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn known_values() {
        // Abramowitz & Stegun table 9.1 / standard values
        assert!((bessel_j(0, 1.0) - 0.765_197_686_557_966_6).abs() < 1e-15);
        assert!((bessel_j(1, 1.0) - 0.440_050_585_744_933_5).abs() < 1e-15);
        assert!((bessel_j(0, 10.0) - (-0.245_935_764_451_348_3)).abs() < 1e-15);
        assert!((bessel_j(5, 10.0) - (-0.234_061_528_186_793_6)).abs() < 1e-14);
        assert!((bessel_j(-1, 1.0) + 0.440_050_585_744_933_5).abs() < 1e-15);
        assert!((spherical_j(0, 2.0) - 2f64.sin() / 2.0).abs() < 1e-15);
    }
}
