//! Bessel functions against independent values: power series, asymptotic forms, known
//! values and identities, at orders up to 3000+ and arguments up to 5000+.

use ocular::optics::{bessel_j, bessel_j_sequence, spherical_j, spherical_j_sequence};
use std::f64::consts::PI;

/// Power series Σ_k (−1)^k (x/2)^{2k+n}/(k!(n+k)!) — accurate for moderate x.
fn series(n: u32, x: f64) -> f64 {
    let h = 0.5 * x;
    let mut term = (0..n).fold(1.0, |t, k| t * h / (k + 1) as f64);
    let mut s = term;
    for k in 1..200 {
        term *= -h * h / (k as f64 * (n as f64 + k as f64));
        s += term;
        if term.abs() < 1e-18 * s.abs() {
            break;
        }
    }
    s
}

#[test]
fn matches_power_series_small_x() {
    for n in [0u32, 1, 2, 5, 10, 30] {
        for x in [1e-8, 1e-4, 0.01, 0.5, 1.0, 3.7, 8.0] {
            let a = bessel_j(n as i32, x);
            let b = series(n, x);
            assert!(
                (a - b).abs() <= 1e-14 * (1.0 + b.abs()),
                "J{n}({x}) {a} vs {b}"
            );
        }
    }
}

#[test]
fn known_values() {
    // 17-digit values from an arbitrary-precision evaluation (mpmath, 40 digits)
    let v = [
        (0, 1.0, 0.765_197_686_557_966_6),
        (1, 2.5, 0.497_094_102_464_274_04),
        (2, 10.0, 0.254_630_313_685_120_6),
        (10, 10.0, 0.207_486_106_633_358_86),
        (50, 100.0, -0.038_698_339_728_525_383),
        (100, 100.0, 0.096_366_673_295_861_56),
        (0, 1000.0, 0.024_786_686_152_420_175),
        (500, 500.0, 0.056_357_003_281_836_94),
        (1500, 1500.0, 0.039_075_863_570_585_185),
        (3000, 3000.0, 0.031_014_547_810_126_578),
        (7, 4999.5, 0.004_863_200_977_370_202),
        (2999, 4000.25, 0.015_378_042_721_426_254),
    ];
    for (n, x, e) in v {
        let a = bessel_j(n, x);
        assert!((a - e).abs() < 1e-13, "J{n}({x}) = {a}, expected {e}");
    }
}

#[test]
fn zero_argument_negative_order_and_parity() {
    let mut b = vec![0.0; 3001];
    bessel_j_sequence(3000, 0.0, &mut b);
    assert_eq!(b[0], 1.0);
    assert!(b[1..].iter().all(|&v| v == 0.0));
    for n in [1, 2, 7, 40] {
        for x in [0.3, 12.0, 450.0] {
            let s = if n % 2 == 1 { -1.0 } else { 1.0 };
            assert_eq!(bessel_j(-n, x), s * bessel_j(n, x));
            assert!((bessel_j(n, -x) - s * bessel_j(n, x)).abs() < 1e-16);
        }
    }
    assert_eq!(spherical_j(0, 0.0), 1.0);
    assert_eq!(spherical_j(5, 0.0), 0.0);
}

#[test]
fn large_argument_asymptotic() {
    // Hankel asymptotic expansion, two correction terms; error ~ (4n²/8x)^3 is negligible here.
    for &x in &[2000.0, 5000.0, 7000.5] {
        for n in [0u32, 1, 3, 5] {
            let mu = 4.0 * (n as f64).powi(2);
            let w = x - (0.5 * n as f64 + 0.25) * PI;
            let p = 1.0 - (mu - 1.0) * (mu - 9.0) / (2.0 * (8.0 * x).powi(2));
            let q = (mu - 1.0) / (8.0 * x)
                - (mu - 1.0) * (mu - 9.0) * (mu - 25.0) / (6.0 * (8.0 * x).powi(3));
            let e = (2.0 / (PI * x)).sqrt() * (p * w.cos() - q * w.sin());
            let a = bessel_j(n as i32, x);
            assert!((a - e).abs() < 1e-12, "J{n}({x}) = {a} vs {e}");
        }
    }
}

#[test]
fn high_order_transition_region() {
    // Debye/Airy: J_ν(ν) ≈ 0.4473073 ν^{−1/3}(1 − 0.00067/ν^{4/3}·…) ; relative 1e-6 is plenty
    // to catch a wrong normalisation or start index.
    for nu in [500u32, 1500, 3000] {
        let a = bessel_j(nu as i32, nu as f64);
        let e = 0.447_307_379_6 / (nu as f64).cbrt();
        assert!((a / e - 1.0).abs() < 1e-4, "J{nu}({nu}) = {a} vs {e}");
    }
    // deep in the decaying region: tiny but finite and positive, no NaN
    let a = bessel_j(3000, 100.0);
    assert!(a >= 0.0 && a.is_finite());
}

#[test]
fn sum_identities_hold_at_extremes() {
    for &x in &[0.001, 1.0, 37.3, 1000.0, 5000.0] {
        let n = (x as usize) + 200;
        let mut b = vec![0.0; n + 1];
        bessel_j_sequence(n, x, &mut b);
        // J0 + 2ΣJ_2k = 1 is the normalisation; Σ_all J_n² = 1 (J0² + 2ΣJ_n²) is independent.
        let sq: f64 = b[0] * b[0] + 2.0 * b[1..].iter().map(|v| v * v).sum::<f64>();
        assert!((sq - 1.0).abs() < 1e-12, "x={x}: {sq}");
        // Σ (−1)^k J_2k ·2 + J0 = cos x
        let c: f64 = b[0]
            + 2.0
                * (1..=n / 2)
                    .map(|k| if k % 2 == 0 { b[2 * k] } else { -b[2 * k] })
                    .sum::<f64>();
        assert!((c - x.cos()).abs() < 1e-12, "x={x}");
        // Wronskian-type recurrence check: J_{n-1} + J_{n+1} = (2n/x) J_n
        for k in [1usize, 10, n / 2] {
            let lhs = b[k - 1] + b[k + 1];
            let rhs = 2.0 * k as f64 / x * b[k];
            assert!((lhs - rhs).abs() < 1e-12 * (1.0 + rhs.abs()), "x={x} k={k}");
        }
    }
}

#[test]
fn spherical_bessel() {
    for &x in &[0.0005, 0.3, 2.0, 9.42477796076938, 55.0, 600.0, 2500.0] {
        let (s, c) = f64::sin_cos(x);
        let j0 = s / x;
        let j1 = s / (x * x) - c / x;
        let j2 = (3.0 / (x * x) - 1.0) * s / x - 3.0 * c / (x * x);
        let mut b = vec![0.0; 4];
        spherical_j_sequence(3, x, &mut b);
        assert!((b[0] - j0).abs() < 1e-15, "j0({x})");
        if x > 0.1 {
            // the closed forms cancel catastrophically at small x; checked by series below
            assert!((b[1] - j1).abs() < 1e-14, "j1({x}) {} vs {j1}", b[1]);
            assert!((b[2] - j2).abs() < 1e-14, "j2({x}) {} vs {j2}", b[2]);
        }
        // j_k = sqrt(π/2x) J_{k+1/2}: for integer checks use Σ(2k+1)j_k² = 1
        let n = (x as usize) + 100;
        let mut all = vec![0.0; n + 1];
        spherical_j_sequence(n, x, &mut all);
        let s2: f64 = all
            .iter()
            .enumerate()
            .map(|(k, v)| (2 * k + 1) as f64 * v * v)
            .sum();
        assert!((s2 - 1.0).abs() < 1e-12);
        assert!(
            (spherical_j(2, -x) - b[2]).abs() < 1e-15 && (spherical_j(1, -x) + b[1]).abs() < 1e-15
        );
    }
    // small-x series vs leading term x^k/(2k+1)!!
    for k in 0..5usize {
        let x: f64 = 5e-4;
        let dfact: f64 = (0..=k).map(|i| (2 * i + 1) as f64).product();
        let e = x.powi(k as i32) / dfact * (1.0 - x * x / (2.0 * (2 * k + 3) as f64));
        assert!((spherical_j(k, x) / e - 1.0).abs() < 1e-12, "k={k}");
    }
}
