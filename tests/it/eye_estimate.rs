//! Eye estimation: round trips from eyes drawn within the population statistics, a
//! prescription-only input, determinism, bounds, and an interrupted run.

use ocular::aberrations::{preset, ZernikeSet};
use ocular::eye::{
    estimate, measure, prior_centre, Estimate, Eye, Groups, Method, ParamMap, ParamSpec, Settings,
};
use ocular::optics::zernike::{osa_nm, Prescription};
use std::sync::atomic::AtomicBool;

fn run(target: &ZernikeSet, settings: &Settings) -> Estimate {
    estimate(target, settings, &AtomicBool::new(false), &mut |_| {}).unwrap()
}

/// xorshift64*: a fixed, dependency-free stream of uniform numbers in [0, 1).
struct Rng(u64);
impl Rng {
    fn next(&mut self) -> f64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        (self.0.wrapping_mul(0x2545_f491_4f6c_dd1d) >> 11) as f64 / (1u64 << 53) as f64
    }
}

/// An eye whose structural parameters lie within one deviation of the prior (the population
/// statistics this model uses), drawn until the model can build it.
fn random_eye(rng: &mut Rng) -> Eye {
    let groups = Groups {
        lens_pose: false,
        anterior_elevation_order: 0,
        posterior_elevation: false,
    };
    let map = ParamMap::new(ParamSpec::table(groups), &prior_centre());
    loop {
        let unit: Vec<f64> = map
            .specs
            .iter()
            .map(|s| {
                let v = s.mean + s.sigma * (2.0 * rng.next() - 1.0);
                s.normalise(v.clamp(s.lower, s.upper))
            })
            .collect();
        let eye = map.eye(&unit);
        if eye.validate().is_ok() {
            return eye;
        }
    }
}

fn wavefront_of(eye: &Eye, pupil_mm: f64, wavelength_nm: f64) -> ZernikeSet {
    let m = measure(&eye.system().unwrap(), wavelength_nm, pupil_mm, None, 6).unwrap();
    ZernikeSet {
        pupil_diameter_mm: pupil_mm,
        wavelength_nm,
        coefficients: m
            .coefficients_um
            .iter()
            .enumerate()
            .skip(1)
            .map(|(j, &c)| {
                let (n, mm) = osa_nm(j);
                (n, mm, c)
            })
            .collect(),
    }
}

#[test]
fn random_population_eyes_round_trip() {
    let mut rng = Rng(0x5eed_1234_abcd_0001);
    for k in 0..3 {
        let truth = random_eye(&mut rng);
        let target = wavefront_of(&truth, 5.0, 555.0);
        let settings = Settings {
            max_time_s: Some(60.0),
            ..Settings::default()
        };
        let e = run(&target, &settings);
        let r = &e.report;
        println!(
            "eye {k}: c20 {:.3} c40 {:.4} → loss {:.3e}, RMS {:.5} µm, {} evals, {:.2} s",
            target.coefficients[3].2,
            target.coefficients[11].2,
            r.loss,
            r.rms_error_um,
            r.evaluations,
            r.time_s
        );
        // The true eye is a zero-loss point of the box, so the fit must come close to zero:
        // a loss of 0.05 is a weighted residual of about 0.001 µm per term.
        assert!(r.loss < 0.05, "eye {k}: loss {}", r.loss);
        assert!(r.rms_error_um < 0.002, "eye {k}: RMS {}", r.rms_error_um);
        assert!(r.all_in_bounds);
        // The fitted eye, measured afresh, carries the coefficients.
        let again = wavefront_of(&e.eye, 5.0, 555.0);
        for (a, b) in again.coefficients.iter().zip(&target.coefficients) {
            assert!(
                (a.2 - b.2).abs() < 0.01,
                "({}, {}) {} vs {}",
                a.0,
                a.1,
                a.2,
                b.2
            );
        }
    }
}

#[test]
fn prescription_only_input_gives_that_refraction() {
    let rx = Prescription::parse("-2.5 -1.25 x 30").unwrap();
    let pupil = 4.0;
    let [cm, c0, cp] = rx.to_zernike(pupil);
    let target = ZernikeSet {
        pupil_diameter_mm: pupil,
        wavelength_nm: 555.0,
        coefficients: vec![(2, -2, cm), (2, 0, c0), (2, 2, cp)],
    };
    let e = run(&target, &Settings::default());
    let m = measure(&e.eye.system().unwrap(), 555.0, pupil, None, 6).unwrap();
    let a = 2.0 * rx.axis_deg.to_radians();
    let (want_m, want_j0, want_j45) = (
        rx.spherical_equivalent_d(),
        -0.5 * rx.cylinder_d * a.cos(),
        -0.5 * rx.cylinder_d * a.sin(),
    );
    println!(
        "M {} J0 {} J45 {} (want {want_m} {want_j0} {want_j45}); report {:?}",
        m.refraction.m, m.refraction.j0, m.refraction.j45, e.report.rms_error_um
    );
    assert!((m.refraction.m - want_m).abs() < 0.05);
    assert!((m.refraction.j0 - want_j0).abs() < 0.05);
    assert!((m.refraction.j45 - want_j45).abs() < 0.05);
    assert!(e.report.all_in_bounds && e.report.converged);
}

#[test]
fn same_input_same_eye_whatever_the_thread_count() {
    let target = preset("astigmatism").unwrap();
    for method in [Method::Hybrid, Method::PatternSearch] {
        let s = |threads| Settings {
            method,
            threads: Some(threads),
            max_evaluations: 3000,
            ..Settings::default()
        };
        let a = run(&target, &s(1));
        let b = run(&target, &s(2));
        assert_eq!(a.eye, b.eye, "{method:?}");
        assert_eq!(a.report.loss.to_bits(), b.report.loss.to_bits());
        assert_eq!(a.report.evaluations, b.report.evaluations);
    }
    // The opportunistic poll polls in fixed chunks, so it too ignores the thread count.
    let s = |threads| Settings {
        method: Method::PatternSearch,
        opportunistic: true,
        threads: Some(threads),
        max_evaluations: 2000,
        ..Settings::default()
    };
    let (a, b) = (run(&target, &s(1)), run(&target, &s(3)));
    assert_eq!(a.eye, b.eye);
    assert_eq!(a.report.evaluations, b.report.evaluations);
}

#[test]
fn time_limit_returns_the_best_eye_so_far_not_converged() {
    let target = preset("keratoconus").unwrap();
    let settings = Settings {
        max_time_s: Some(0.3),
        ..Settings::default()
    };
    let t = std::time::Instant::now();
    let e = run(&target, &settings);
    assert!(t.elapsed().as_secs_f64() < 5.0);
    assert!(!e.report.converged);
    assert_eq!(e.report.stop, "time");
    e.eye.validate().unwrap();
    assert!(e.report.loss.is_finite());
    // Cancelling before the start stops at once, with the start eye.
    let c = estimate(
        &target,
        &Settings::default(),
        &AtomicBool::new(true),
        &mut |_| {},
    )
    .unwrap();
    assert!(!c.report.converged);
    assert_eq!(c.report.stop, "cancelled");
}

#[test]
fn bad_targets_are_refused() {
    let good = preset("myopia").unwrap();
    let cases = [
        (
            ZernikeSet {
                pupil_diameter_mm: 0.5,
                ..good.clone()
            },
            "pupil",
        ),
        (
            ZernikeSet {
                pupil_diameter_mm: 9.5,
                ..good.clone()
            },
            "pupil",
        ),
        (
            ZernikeSet {
                wavelength_nm: f64::NAN,
                ..good.clone()
            },
            "wavelength",
        ),
        (
            ZernikeSet {
                coefficients: vec![(2, 0, f64::NAN)],
                ..good.clone()
            },
            "finite",
        ),
        (
            ZernikeSet {
                coefficients: vec![(2, 1, 0.1)],
                ..good.clone()
            },
            "(2, 1)",
        ),
    ];
    for (t, word) in cases {
        let err = estimate(
            &t,
            &Settings::default(),
            &AtomicBool::new(false),
            &mut |_| {},
        )
        .unwrap_err()
        .to_string();
        assert!(err.contains(word), "{err}");
    }
}
