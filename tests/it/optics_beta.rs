//! β from α: first-order closed form, Parseval (Σ|β|² → pupil energy), adaptive degree,
//! apodisation.

use num_complex::Complex64;
use ocular::optics::zernike::{num_terms, osa_index};
use ocular::optics::{beta_from_alpha, StilesCrawford};
use std::f64::consts::PI;

fn alpha(order: u32, terms: &[(u32, i32, f64)]) -> Vec<f64> {
    let mut a = vec![0.0; num_terms(order)];
    for &(n, m, v) in terms {
        a[osa_index(n, m)] = v;
    }
    a
}

#[test]
fn first_order_closed_form() {
    // P = e^{ikαZ} ≈ 1 + ikαZ; Z(n,m) = N R e^{±imθ}-combination, so
    // β_{n,±m} = i k α N/(2√(n+1)) for m ≠ 0 (and sin terms carry ∓i/2).
    let lam_nm = 550.0;
    let k = 2.0 * PI / (lam_nm * 1e-3);
    let a = 1e-8;
    for &(n, m) in &[(2u32, 2i32), (3, -1), (4, 0), (5, 3)] {
        let be = beta_from_alpha(&alpha(5, &[(n, m, a)]), lam_nm, 5.0, None, 1e-14, 40);
        let nf = ocular::optics::zernike::normalization(n, m) / ((n + 1) as f64).sqrt();
        let mu = m.unsigned_abs() as i32;
        let (bp, bm) = (be.beta[osa_index(n, mu)], be.beta[osa_index(n, -mu)]);
        let expect = if m == 0 {
            (
                Complex64::new(0.0, k * a * nf),
                Complex64::new(0.0, k * a * nf),
            )
        } else if m > 0 {
            let v = Complex64::new(0.0, k * a * nf / 2.0);
            (v, v)
        } else {
            // sin μθ = (e^{iμθ} − e^{−iμθ})/(2i)
            let v = Complex64::new(k * a * nf / 2.0, 0.0);
            (v, -v)
        };
        assert!(
            (bp - expect.0).norm() < 1e-6 * k * a,
            "({n},{m}) +: {bp} vs {}",
            expect.0
        );
        assert!(
            (bm - expect.1).norm() < 1e-6 * k * a,
            "({n},{m}) -: {bm} vs {}",
            expect.1
        );
        assert!((be.beta[0].re - 1.0).abs() < 1e-6);
    }
}

#[test]
fn parseval_and_adaptive_degree() {
    let a = alpha(4, &[(2, 2, 0.3), (3, -1, 0.2), (4, 0, 0.1)]);
    let mut last_degree = 0;
    for tol in [1e-3, 1e-6, 1e-9, 1e-12] {
        let be = beta_from_alpha(&a, 550.0, 5.0, None, tol, 160);
        let s: f64 = be.beta.iter().map(|b| b.norm_sqr()).sum();
        assert!((be.pupil_energy - 1.0).abs() < 1e-14);
        assert!(be.truncation_error <= tol, "{tol}: {}", be.truncation_error);
        assert!((1.0 - s - be.truncation_error).abs() < 1e-12);
        assert!(be.degree >= last_degree);
        last_degree = be.degree;
    }
    // a cap below the need reports the larger error instead of hiding it
    let be = beta_from_alpha(&a, 550.0, 5.0, None, 1e-12, 6);
    assert_eq!(be.degree, 6);
    assert!(be.truncation_error > 1e-6);
    for cap in [1, 2, 3] {
        let be = beta_from_alpha(&a, 550.0, 5.0, None, 1e-12, cap);
        assert_eq!(be.degree, cap);
        assert_eq!(be.beta.len(), num_terms(cap));
    }
}

#[test]
fn stiles_crawford_energy() {
    let sc = StilesCrawford { rho_per_mm2: 0.05 };
    let be = beta_from_alpha(&alpha(3, &[(3, 1, 0.2)]), 550.0, 7.0, Some(sc), 1e-10, 160);
    // E = (1/π)∫∫ A² dA = 2∫ 10^(−ρ_sc R² ρ²) ρ dρ = (1 − 10^(−ρ_sc R²))/(ρ_sc R² ln 10)
    let q = 0.05 * 3.5 * 3.5;
    let e = (1.0 - 10f64.powf(-q)) / (q * 10f64.ln());
    assert!(
        (be.pupil_energy - e).abs() < 1e-12,
        "{} vs {e}",
        be.pupil_energy
    );
    let s: f64 = be.beta.iter().map(|b| b.norm_sqr()).sum();
    assert!((s / e - 1.0).abs() <= 1e-10 + 1e-12);
    assert!((StilesCrawford::default().amplitude(1.0, 2.0) - 10f64.powf(-0.1)).abs() < 1e-15);
}
