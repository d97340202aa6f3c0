//! Bad input gets a clear error naming the field (never a panic); extreme but valid input
//! never yields NaN or Inf.

use ocular::aberrations::preset;
use ocular::optics::{compute_psf, defocus_f_from_dioptres, try_vnm, vnm, OpticsError, PsfRequest};

fn base() -> PsfRequest {
    PsfRequest::new(vec![(3, 1, 0.1)], 5.0, 550.0, 0.5, 16)
}

/// One change that makes a valid request invalid.
type Spoil = fn(&mut PsfRequest);

fn err_of(req: PsfRequest) -> String {
    match compute_psf(&req) {
        Ok(_) => panic!("expected an error"),
        Err(e) => e.to_string(),
    }
}

#[test]
fn invalid_requests_are_errors() {
    let mut r = base();
    r.coefficients_um = vec![(3, 1, f64::NAN)];
    let e = err_of(r);
    assert!(
        e.contains("coefficient (3, 1)") && e.contains("finite"),
        "{e}"
    );
    let mut r = base();
    r.coefficients_um = vec![(2, 0, f64::INFINITY)];
    assert!(err_of(r).contains("finite"));
    for p in [0.0, -3.0, f64::NAN] {
        let mut r = base();
        r.pupil_diameter_mm = p;
        let e = err_of(r);
        assert!(e.contains("pupil_diameter_mm"), "{e}");
    }
    for w in [349.0, 1100.5, f64::NAN, -550.0] {
        let mut r = base();
        r.wavelength_nm = w;
        let e = err_of(r);
        assert!(
            e.contains("wavelength_nm") && (e.contains("350 to 1100") || e.contains("finite")),
            "{e}"
        );
    }
    let mut r = base();
    r.coefficients_um = vec![(3, 0, 0.1)];
    let e = err_of(r);
    assert!(e.contains("(3, 0)") && e.contains("n - |m| even"), "{e}");
    let cases: [(Spoil, &str); 9] = [
        (
            |r| r.coefficients_um = vec![(2, 4, 0.1)],
            "unknown Zernike term",
        ),
        (|r| r.coefficients_um = vec![(40, 0, 0.1)], "n <= 30"),
        (|r| r.pitch_lambda_over_na = 0.0, "pitch"),
        (|r| r.size = 0, "size"),
        (|r| r.defocus_f = f64::NAN, "defocus_f"),
        (|r| r.defocus_f = 1e6, "defocus_f"),
        (|r| r.beta_tolerance = 0.0, "beta_tolerance"),
        (
            |r| r.stiles_crawford = Some(ocular::optics::StilesCrawford { rho_per_mm2: -1.0 }),
            "stiles_crawford",
        ),
        // f from a huge c(2,0) is checked after it is folded in
        (
            |r| r.coefficients_um = vec![(2, 0, 500.0)],
            "total defocus f",
        ),
    ];
    for (spoil, want) in cases {
        let mut r = base();
        spoil(&mut r);
        let e = err_of(r);
        assert!(e.contains(want), "{want}: {e}");
    }
}

#[test]
fn vnm_rejects_bad_input_without_panicking() {
    assert!(matches!(
        try_vnm(3, 0, 1.0, 1.0),
        Err(OpticsError::UnknownTerm { .. })
    ));
    assert!(matches!(
        try_vnm(2, 0, f64::NAN, 1.0),
        Err(OpticsError::NonFinite { .. })
    ));
    assert!(matches!(
        try_vnm(2, 0, 1.0, f64::INFINITY),
        Err(OpticsError::NonFinite { .. })
    ));
    assert!(matches!(
        try_vnm(2, 0, 1.0, 1e7),
        Err(OpticsError::OutOfRange { .. })
    ));
    assert_eq!(vnm(3, 0, 1.0, 1.0).norm(), 0.0);
}

#[test]
fn extreme_valid_inputs_stay_finite() {
    // −10 D eye at a 7 mm pupil in blue light: |f| ≈ 960
    let f = defocus_f_from_dioptres(-10.0, 7.0, 400.0);
    assert!(f.abs() > 900.0);
    for &(n, m) in &[(0u32, 0i32), (6, -4), (12, 12), (30, 1)] {
        for &r in &[0.0, 0.5, 40.0, 350.0, 2000.0] {
            let v = vnm(n, m, r, f);
            assert!(
                v.re.is_finite() && v.im.is_finite() && v.norm() <= 0.5 + 1e-12,
                "{n} {m} {r}"
            );
        }
    }
    let mut r = PsfRequest::new(vec![(3, -1, 0.3), (4, 0, 0.15)], 7.0, 400.0, 12.0, 64);
    r.defocus_f = f;
    let psf = compute_psf(&r).unwrap();
    assert!(psf.intensity.iter().all(|v| v.is_finite() && *v >= 0.0));
    assert!(
        psf.energy_in_grid > 0.95 && psf.energy_in_grid < 1.001,
        "{}",
        psf.energy_in_grid
    );
    // keratoconus at 400 nm with a 7 mm pupil (coefficients reused as if measured there)
    let k = preset("keratoconus").unwrap();
    let mut r = PsfRequest::new(k.coefficients, 7.0, 400.0, 2.0, 48);
    r.beta_tolerance = 1e-4;
    r.max_degree = 60; // a cap below what it needs: the error is reported, not hidden
    let psf = compute_psf(&r).unwrap();
    assert!(psf.intensity.iter().all(|v| v.is_finite()));
    assert!(psf.beta_truncation_error > 1e-4 && psf.beta_degree == 60);
    // a grid reaching beyond r = 20000 λ/NA is refused, not attempted
    let mut r = PsfRequest::new(vec![], 5.0, 550.0, 900.0, 8000);
    r.size = 8000;
    assert!(compute_psf(&r)
        .unwrap_err()
        .to_string()
        .contains("grid extent"));
    assert!(ocular::optics::VTable::new(20, 10.0, 20000.0, 1e-4).is_err());
    // the smallest allowed cap still works
    let mut r = PsfRequest::new(vec![(3, 1, 0.1)], 5.0, 550.0, 0.5, 8);
    r.max_degree = 1;
    assert!(compute_psf(&r)
        .unwrap()
        .intensity
        .iter()
        .all(|v| v.is_finite()));
    let mut r = PsfRequest::new(vec![(3, 1, 0.1)], 5.0, 550.0, 0.5, 8);
    r.radial_taps = Some(7);
    assert!(compute_psf(&r)
        .unwrap_err()
        .to_string()
        .contains("radial_taps"));
    // Stiles–Crawford apodisation lowers the encircled light but keeps the PSF finite
    let mut r = PsfRequest::new(vec![], 7.0, 550.0, 0.25, 32);
    r.stiles_crawford = Some(Default::default());
    let psf = compute_psf(&r).unwrap();
    assert!(
        (psf.strehl - 1.0).abs() < 1e-9,
        "apodised, unaberrated: Strehl 1 by definition"
    );
    assert!(psf.peak_intensity < 1.0);
}
