//! V_n^m(r, f): Bessel–Bessel series against the reference table, closed forms, the power
//! series and an independent Gauss–Legendre quadrature over a wide (n, m, r, f) grid.

use num_complex::Complex64;
use ocular::optics::zernike::{num_terms, osa_nm};
use ocular::optics::{
    quadrature_nodes, vnm, vnm_power_series, vnm_quadrature, vnm_quadrature_all, VTable,
};
use std::f64::consts::PI;

#[test]
fn closed_forms_v00() {
    for &f in &[1e-12f64, 1e-6, 0.5, -3.0, 40.0, -700.0, 1000.0] {
        // (e^{if} − 1)/(2if), written as e^{if/2} sin(f/2)/f to avoid cancellation at tiny f
        let exact = Complex64::from_polar(1.0, 0.5 * f) * ((0.5 * f).sin() / f);
        let naive = (Complex64::new(0.0, f).exp() - 1.0) / Complex64::new(0.0, 2.0 * f);
        if f.abs() > 0.1 {
            assert!((exact - naive).norm() < 1e-14);
        }
        let v = vnm(0, 0, 0.0, f);
        assert!((v - exact).norm() < 1e-12, "f={f}: {v} vs {exact}");
    }
    assert!((vnm(0, 0, 0.0, 0.0) - Complex64::new(0.5, 0.0)).norm() < 1e-15);
    for &r in &[0.0, 1e-9, 0.3, 1.0, 7.7, 150.0] {
        let v = 2.0 * PI * r;
        let exact = if r == 0.0 {
            0.5
        } else {
            ocular::optics::bessel_j(1, v) / v
        };
        assert!((vnm(0, 0, r, 0.0).re - exact).abs() < 1e-13, "r={r}");
        assert!(vnm(0, 0, r, 0.0).im.abs() < 1e-15);
    }
}

#[test]
fn conjugate_symmetry_and_parity() {
    for &(n, m, r, f) in &[
        (4u32, 2i32, 3.3, 17.0),
        (5, -3, 0.8, 250.0),
        (8, 0, 20.0, 5.5),
    ] {
        let a = vnm(n, m, r, f);
        let b = vnm(n, m, r, -f);
        assert!((a - b.conj()).norm() < 1e-13);
        let c = vnm(n, -m, r, f);
        let s = if m.unsigned_abs() % 2 == 1 { -1.0 } else { 1.0 };
        assert!((a * s - c).norm() < 1e-15);
    }
}

#[test]
fn power_series_agrees_for_small_f() {
    for &(n, m, r, f) in &[
        (0u32, 0i32, 0.5, 3.0),
        (6, -2, 2.5, 8.0),
        (7, 3, 1.1, -9.0),
        (3, 1, 0.0, 0.01),
    ] {
        let a = vnm(n, m, r, f);
        let b = vnm_power_series(n, m, r, f);
        assert!((a - b).norm() < 1e-11, "{n} {m} {r} {f}: {a} vs {b}");
    }
}

/// n ≤ 12, every m, r from 0 to 200, f from −1000 to 1000 (0, tiny and negative included),
/// against Gauss–Legendre with ample nodes (all terms share one rule per (r, f)).
#[test]
fn bessel_bessel_matches_quadrature_on_grid() {
    let rs = [0.0, 0.37, 1.7, 9.25, 33.0, 88.8, 200.0];
    let fs = [
        0.0f64, 1e-10, -1e-3, 2.5, -31.0, 150.0, -420.0, 777.0, -1000.0, 1000.0,
    ];
    let order = 12;
    let mut worst: f64 = 0.0;
    for (ir, &r) in rs.iter().enumerate() {
        for (iff, &f) in fs.iter().enumerate() {
            // thin the most expensive corner a little, keep every r and f represented
            if r > 100.0 && f.abs() > 500.0 && (ir + iff) % 2 == 0 {
                continue;
            }
            let nodes = quadrature_nodes(order, r, f) * 3 / 2;
            let q = vnm_quadrature_all(order, r, f, nodes);
            for (j, qv) in q.iter().enumerate().take(num_terms(order)) {
                let (n, m) = osa_nm(j);
                let v = vnm(n, m, r, f);
                let err = (v - qv).norm();
                worst = worst.max(err);
                assert!(
                    err < 1e-9,
                    "n={n} m={m} r={r} f={f}: {v} vs {qv} (err {err:e})"
                );
                assert!(v.re.is_finite() && v.im.is_finite());
            }
        }
    }
    eprintln!("worst |BB - GL| = {worst:e}");
}

#[test]
fn single_quadrature_agrees() {
    let v = vnm_quadrature(6, -2, 2.5, 25.0, None);
    assert!((v - Complex64::new(3.1942513235e-4, 5.6773161770e-3)).norm() < 1e-10);
}

#[test]
fn table_interpolation_accuracy() {
    let f = 60.0;
    let step = ocular::optics::interpolation_step(1e-6);
    let t = VTable::new(8, f, 40.0, step).unwrap();
    let mut worst: f64 = 0.0;
    for i in 0..400 {
        let r = 0.0973 * i as f64;
        for &(n, m) in &[(0u32, 0i32), (3, -1), (6, 4), (8, 0)] {
            let a = t.value(n, m, r);
            let b = vnm(n, m, r, f);
            worst = worst.max((a - b).norm());
        }
    }
    // V is at most 1/2 in magnitude; 1e-6 relative to that.
    assert!(
        worst < 0.5e-6,
        "interpolation error {worst:e} at step {step}"
    );
    assert!((t.node(3, -1, 7) - vnm(3, -1, 7.0 * step, f)).norm() < 1e-13);
}
