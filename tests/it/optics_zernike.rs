//! Zernike algebra: indices, orthonormality, fits, pupil rescaling, prescriptions.

use ocular::optics::gauss_legendre_01;
use ocular::optics::zernike::*;
use std::f64::consts::PI;

#[test]
fn osa_and_noll_tables() {
    // OSA j → (n, m) for the first orders
    let expect = [
        (0, 0),
        (1, -1),
        (1, 1),
        (2, -2),
        (2, 0),
        (2, 2),
        (3, -3),
        (3, -1),
        (3, 1),
        (3, 3),
    ];
    for (j, &(n, m)) in expect.iter().enumerate() {
        assert_eq!(osa_nm(j), (n, m));
        assert_eq!(osa_index(n, m), j);
    }
    // Noll 1..11 → OSA
    let noll = [0, 2, 1, 4, 3, 5, 7, 8, 6, 9, 12];
    for (k, &j) in noll.iter().enumerate() {
        assert_eq!(noll_to_osa(k + 1), j, "Noll {}", k + 1);
        assert_eq!(osa_to_noll(j), k + 1);
    }
    assert_eq!(num_terms(0), 1);
    assert_eq!(num_terms(10), 66);
    assert!(is_valid_nm(4, -2) && !is_valid_nm(4, -3) && !is_valid_nm(1, 3));
}

/// (1/π)∫∫ Z_j Z_k dA = δ_jk, by Gauss–Legendre in ρ and the trapezoid rule in θ (exact here).
#[test]
fn orthonormal_over_unit_disk() {
    let order = 12;
    let nt = num_terms(order);
    let (xs, ws) = gauss_legendre_01(20);
    let nth = 64;
    let mut gram = vec![0.0; nt * nt];
    let mut z = vec![0.0; nt];
    for (&r, &w) in xs.iter().zip(&ws) {
        for k in 0..nth {
            let th = 2.0 * PI * k as f64 / nth as f64;
            basis_values(order, r * th.cos(), r * th.sin(), &mut z);
            let wt = w * r * 2.0 * PI / nth as f64 / PI;
            for a in 0..nt {
                for b in 0..nt {
                    gram[a * nt + b] += wt * z[a] * z[b];
                }
            }
        }
    }
    for a in 0..nt {
        for b in 0..nt {
            let e = if a == b { 1.0 } else { 0.0 };
            assert!(
                (gram[a * nt + b] - e).abs() < 1e-12,
                "({a},{b}) = {}",
                gram[a * nt + b]
            );
        }
    }
}

#[test]
fn radial_stable_at_order_60_and_beyond() {
    // Endpoint values R(1) = 1 and R'(1) = (n(n+2) − m²)/2 hold for every n; the polynomial
    // stays within [−1, 1] on the disk. An explicit factorial sum loses all digits here.
    for n in [60u32, 61, 100] {
        for m in [n % 2, 4 + n % 2, 20 + n % 2] {
            let (r1, d1) = radial_with_derivative(n, m as i32, 1.0);
            assert!((r1 - 1.0).abs() < 1e-11);
            let expect = (n * (n + 2) - m * m) as f64 / 2.0;
            assert!((d1 - expect).abs() < 1e-9 * expect);
            for i in 0..=500 {
                assert!(radial(n, m as i32, i as f64 / 500.0).abs() <= 1.0 + 1e-10);
            }
        }
    }
    // orthogonality of the high-order radial family: ∫ R_n R_n' ρ dρ = δ/(2(n+1))
    let (xs, ws) = gauss_legendre_01(80);
    for (n1, n2) in [(60u32, 60u32), (60, 58), (62, 60), (70, 70)] {
        let s: f64 = xs
            .iter()
            .zip(&ws)
            .map(|(&x, &w)| w * x * radial(n1, 2, x) * radial(n2, 2, x))
            .sum();
        let e = if n1 == n2 {
            1.0 / (2.0 * (n1 as f64 + 1.0))
        } else {
            0.0
        };
        assert!((s - e).abs() < 1e-12, "{n1},{n2}: {s}");
    }
}

fn sample_coeffs(order: u32) -> Vec<f64> {
    (0..num_terms(order))
        .map(|j| ((j as f64 * 1.618).sin() * 0.7 + 0.05 * j as f64).cos() * 0.3)
        .collect()
}

#[test]
fn evaluation_and_rms() {
    let c = sample_coeffs(5);
    // RMS from the coefficients equals the RMS of the sampled wavefront about its mean
    let (xs, ws) = gauss_legendre_01(12);
    let nth = 32;
    let (mut m1, mut m2) = (0.0, 0.0);
    for (&r, &w) in xs.iter().zip(&ws) {
        for k in 0..nth {
            let th = 2.0 * PI * k as f64 / nth as f64;
            let v = wavefront(&c, r * th.cos(), r * th.sin());
            let wt = w * r * 2.0 / nth as f64;
            m1 += wt * v;
            m2 += wt * v * v;
        }
    }
    assert!((m1 - c[0]).abs() < 1e-12);
    assert!(((m2 - m1 * m1).sqrt() - rms(&c)).abs() < 1e-12);
    // gradient against finite differences
    let (gx, gy) = wavefront_gradient(&c, 0.3, -0.4);
    let h = 1e-6;
    let fx = (wavefront(&c, 0.3 + h, -0.4) - wavefront(&c, 0.3 - h, -0.4)) / (2.0 * h);
    let fy = (wavefront(&c, 0.3, -0.4 + h) - wavefront(&c, 0.3, -0.4 - h)) / (2.0 * h);
    assert!((gx - fx).abs() < 1e-7 && (gy - fy).abs() < 1e-7);
    assert!(rms_from_order(&c, 3) < rms(&c));
}

fn scatter(npts: usize) -> Vec<(f64, f64)> {
    // a deterministic spiral covering the disk
    (0..npts)
        .map(|i| {
            let r = ((i as f64 + 0.5) / npts as f64).sqrt();
            let th = i as f64 * 2.399963229728653;
            (r * th.cos(), r * th.sin())
        })
        .collect()
}

/// Every fitted coefficient within 1e-9 of the one sampled.
fn assert_fits(fit: &[f64], sampled: &[f64]) {
    for (a, b) in fit.iter().zip(sampled) {
        assert!((a - b).abs() < 1e-9, "{a} vs {b}");
    }
}

#[test]
fn fit_from_wavefront_samples_reproduces_coefficients() {
    let order = 8;
    let c = sample_coeffs(order);
    let samples: Vec<(f64, f64, f64)> = scatter(400)
        .into_iter()
        .map(|(x, y)| (x, y, wavefront(&c, x, y)))
        .collect();
    assert_fits(&fit_wavefront(order, &samples).unwrap(), &c);
}

#[test]
fn fit_from_slopes_reproduces_coefficients() {
    let order = 8;
    let mut c = sample_coeffs(order);
    c[0] = 0.0; // piston is invisible to slopes
    let samples: Vec<(f64, f64, f64, f64)> = scatter(300)
        .into_iter()
        .map(|(x, y)| {
            let (gx, gy) = wavefront_gradient(&c, x, y);
            (x, y, gx, gy)
        })
        .collect();
    assert_fits(&fit_slopes(order, &samples).unwrap(), &c);
}

#[test]
fn fit_errors() {
    assert!(matches!(
        fit_wavefront(6, &[(0.1, 0.1, 1.0)]),
        Err(ZernikeError::RankDeficient { .. })
    ));
    assert!(matches!(
        fit_wavefront(1, &[(0.1, 0.1, f64::NAN), (0.2, 0.0, 1.0), (0.0, 0.3, 1.0)]),
        Err(ZernikeError::NonFinite(_))
    ));
    // all samples on one point: rank deficient, not a panic
    let same = vec![(0.2, 0.2, 1.0); 50];
    assert!(fit_wavefront(3, &same).is_err());
}

#[test]
fn rescale_to_smaller_pupil_is_exact() {
    let order = 10;
    let c = sample_coeffs(order);
    for ratio in [0.8, 0.5, 0.3] {
        let s = rescale_pupil(&c, ratio).unwrap();
        for &(x, y) in &scatter(50) {
            let a = wavefront(&c, ratio * x, ratio * y);
            let b = wavefront(&s, x, y);
            assert!((a - b).abs() < 1e-11, "ratio {ratio}: {a} vs {b}");
        }
    }
    // known closed form: defocus and spherical aberration (Schwiegerling 2002)
    let mut c = vec![0.0; num_terms(4)];
    c[osa_index(4, 0)] = 0.2;
    c[osa_index(2, 0)] = 1.0;
    let e: f64 = 0.6;
    let s = rescale_pupil(&c, e).unwrap();
    let c40 = 0.2 * e.powi(4);
    let c20 = e * e * (1.0 + 0.2 * 15f64.sqrt() * (e * e - 1.0));
    assert!((s[osa_index(4, 0)] - c40).abs() < 1e-13);
    assert!((s[osa_index(2, 0)] - c20).abs() < 1e-13);
    assert!(rescale_pupil(&c, 0.0).is_err() && rescale_pupil(&c, f64::NAN).is_err());
}

#[test]
fn prescription_to_zernike_sign_convention() {
    // −6 D sphere at 5 mm → c(2,0) = +5.4127 µm (myopic eyes have positive c(2,0))
    let z = Prescription::new(-6.0, 0.0, 0.0).to_zernike(5.0);
    assert!((z[1] - 5.4127).abs() < 5e-5, "{}", z[1]);
    assert!(z[0] == 0.0 && z[2] == 0.0);
    // −6/−3×102 at 5 mm against the formula evaluated by hand
    let z = Prescription::new(-6.0, -3.0, 102.0).to_zernike(5.0);
    let r2 = 6.25;
    let a = (204.0f64).to_radians();
    assert!((z[1] - (-r2 * (-7.5) / (4.0 * 3f64.sqrt()))).abs() < 1e-12);
    assert!((z[0] - r2 * -3.0 * a.sin() / (4.0 * 6f64.sqrt())).abs() < 1e-12);
    assert!((z[2] - r2 * -3.0 * a.cos() / (4.0 * 6f64.sqrt())).abs() < 1e-12);
    assert!((z[1] - 6.76582).abs() < 1e-4);
}

#[test]
fn prescription_round_trips() {
    for &(s, c, a) in &[
        (-6.0, -3.0, 102.0),
        (1.5, 0.0, 0.0),
        (-0.25, -0.75, 0.0),
        (2.0, -1.25, 179.0),
        (-10.0, -4.0, 45.0),
        (0.0, -0.5, 90.0),
    ] {
        for pupil in [3.0, 5.0, 7.0] {
            let rx = Prescription::new(s, c, a);
            let z = rx.to_zernike(pupil);
            let back = Prescription::from_zernike(z[0], z[1], z[2], pupil);
            assert!((back.sphere_d - s).abs() < 1e-12, "{rx:?} -> {back:?}");
            assert!((back.cylinder_d - c).abs() < 1e-12);
            if c != 0.0 {
                assert!((back.axis_deg - a).abs() < 1e-9, "{rx:?} -> {back:?}");
            }
        }
    }
    // plus-cylinder input comes back in minus-cylinder form, same refraction
    let plus = Prescription::new(-9.0, 3.0, 12.0);
    let z = plus.to_zernike(5.0);
    let back = Prescription::from_zernike(z[0], z[1], z[2], 5.0);
    let minus = plus.to_minus_cylinder();
    assert!((back.sphere_d - minus.sphere_d).abs() < 1e-12 && (minus.sphere_d + 6.0).abs() < 1e-12);
    assert!((back.cylinder_d + 3.0).abs() < 1e-12 && (back.axis_deg - 102.0).abs() < 1e-9);
    let osa = Prescription::new(-2.0, -1.0, 30.0).to_osa_coefficients(6.0);
    let rx = Prescription::from_osa_coefficients(&osa, 6.0).unwrap();
    assert!((rx.sphere_d + 2.0).abs() < 1e-12 && (rx.axis_deg - 30.0).abs() < 1e-9);
}

#[test]
fn prescription_parsing() {
    let cases = [
        ("-6 -3 x 102", (-6.0, -3.0, 102.0)),
        ("-6.00/-3.00x102", (-6.0, -3.0, 102.0)),
        ("+1.5 DS", (1.5, 0.0, 0.0)),
        ("-2.00 DS / -0.75 DC x 180", (-2.0, -0.75, 180.0)),
        ("plano", (0.0, 0.0, 0.0)),
        ("pl -1.00 x 90", (0.0, -1.0, 90.0)),
        ("-1 -0.5 @ 45", (-1.0, -0.5, 45.0)),
        ("+0.75-1.25×10", (0.75, -1.25, 10.0)),
        ("  -4.25  ", (-4.25, 0.0, 0.0)),
    ];
    for (text, (s, c, a)) in cases {
        let rx = Prescription::parse(text).unwrap_or_else(|e| panic!("{text}: {e}"));
        assert_eq!(
            (rx.sphere_d, rx.cylinder_d, rx.axis_deg),
            (s, c, a),
            "{text}"
        );
    }
    for bad in [
        "",
        "abc",
        "-6 -3",
        "-6 -3 x",
        "-6 -3 x 200",
        "-6 -3 -1",
        "-6 x 90 x 3",
        "nan",
    ] {
        let e = Prescription::parse(bad);
        assert!(e.is_err(), "{bad:?} should fail");
        assert!(e.unwrap_err().to_string().contains("prescription"));
    }
    // display is minus-cylinder friendly and parses back
    let rx = Prescription::new(-6.0, -3.0, 102.0);
    assert_eq!(Prescription::parse(&rx.to_string()).unwrap(), rx);
}

fn radial_factorial(n: u32, m: u32, rho: f64) -> f64 {
    let fact = |k: u32| (1..=k).map(|v| v as f64).product::<f64>();
    let mut s = 0.0;
    for k in 0..=(n - m) / 2 {
        let num = if k % 2 == 0 { 1.0 } else { -1.0 } * fact(n - k);
        let den = fact(k) * fact((n + m) / 2 - k) * fact((n - m) / 2 - k);
        s += num / den * rho.powi((n - 2 * k) as i32);
    }
    s
}

#[test]
fn radial_matches_factorial_sum_at_low_order() {
    for n in 0..=12u32 {
        for m in (n % 2..=n).step_by(2) {
            for &rho in &[0.0, 0.1, 0.37, 0.5, 0.81, 1.0] {
                let a = radial(n, m as i32, rho);
                let b = radial_factorial(n, m, rho);
                assert!((a - b).abs() < 1e-12, "n={n} m={m} rho={rho}: {a} vs {b}");
                let h = 1e-6;
                if rho > h && rho < 1.0 - h {
                    let d = (radial_factorial(n, m, rho + h) - radial_factorial(n, m, rho - h))
                        / (2.0 * h);
                    let got = radial_derivative(n, m as i32, rho);
                    assert!((got - d).abs() < 1e-6 * (1.0 + d.abs()));
                }
            }
        }
    }
}

#[test]
fn basis_values_and_gradients_match_direct_evaluation() {
    let order = 10;
    let nt = num_terms(order);
    let mut out = vec![0.0; nt];
    let (mut gx, mut gy) = (vec![0.0; nt], vec![0.0; nt]);
    for &(x, y) in &[
        (0.3, -0.2),
        (-0.7, 0.5),
        (0.0, 0.0),
        (0.0, 0.9),
        (-0.1, -0.95),
    ] {
        basis_values(order, x, y, &mut out);
        basis_gradients(order, x, y, &mut gx, &mut gy);
        for (j, &v) in out.iter().enumerate() {
            let (n, m) = osa_nm(j);
            assert!((v - zernike_value(n, m, x, y)).abs() < 1e-12, "j={j}");
            let h = 1e-6;
            let dx = (zernike_value(n, m, x + h, y) - zernike_value(n, m, x - h, y)) / (2.0 * h);
            let dy = (zernike_value(n, m, x, y + h) - zernike_value(n, m, x, y - h)) / (2.0 * h);
            assert!((gx[j] - dx).abs() < 1e-6 * (1.0 + dx.abs()), "j={j} dx");
            assert!((gy[j] - dy).abs() < 1e-6 * (1.0 + dy.abs()), "j={j} dy");
        }
    }
    // coefficients_from_pairs rejects what does not exist
    assert!(coefficients_from_pairs(4, &[(3, 0, 1.0)]).is_none());
    assert!(coefficients_from_pairs(4, &[(6, 0, 1.0)]).is_none());
    let c = coefficients_from_pairs(4, &[(3, 1, 1.0), (3, 1, 0.5)]).unwrap();
    assert_eq!(c[osa_index(3, 1)], 1.5);
}
