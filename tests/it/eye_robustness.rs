//! Extreme but legal parameters give finite results; impossible ones give clear errors.

use ocular::eye::{
    accommodate, lens_geometry, max_volume_mm3, measure, Eye, EyeError, Measurement,
    LENS_THICKNESS_RATIO,
};

/// (name, setter, lower, upper) for every Table 1 parameter.
type Setter = fn(&mut Eye, f64);
fn table1() -> Vec<(&'static str, Setter, f64, f64)> {
    vec![
        ("axial length", |e, v| e.axial_length_mm = v, 21.82, 25.82),
        (
            "cornea thickness",
            |e, v| e.cornea.thickness_mm = v,
            0.4,
            0.7,
        ),
        (
            "anterior radius x",
            |e, v| e.cornea.anterior.radius_mm[0] = v,
            6.5,
            9.81,
        ),
        (
            "anterior radius y",
            |e, v| e.cornea.anterior.radius_mm[1] = v,
            6.5,
            9.81,
        ),
        (
            "posterior radius x",
            |e, v| e.cornea.posterior.radius_mm[0] = v,
            5.5,
            8.44,
        ),
        (
            "posterior radius y",
            |e, v| e.cornea.posterior.radius_mm[1] = v,
            5.5,
            8.44,
        ),
        (
            "anterior conic",
            |e, v| e.cornea.anterior.conic = v,
            -2.29,
            1.71,
        ),
        (
            "posterior conic",
            |e, v| e.cornea.posterior.conic = v,
            -2.34,
            1.66,
        ),
        (
            "anterior axis",
            |e, v| e.cornea.anterior.axis_deg = v,
            -45.0,
            45.0,
        ),
        (
            "posterior axis",
            |e, v| e.cornea.posterior.axis_deg = v,
            -45.0,
            45.0,
        ),
        ("aqueous depth", |e, v| e.aqueous_depth_mm = v, 2.2, 3.5),
        ("lens diameter", |e, v| e.lens.diameter_mm = v, 10.6, 11.6),
        ("lens volume", |e, v| e.lens.volume_mm3 = v, 153.1, 167.1),
        (
            "lens anterior conic",
            |e, v| e.lens.anterior_conic = v,
            -10.4,
            -1.0,
        ),
        (
            "lens posterior conic",
            |e, v| e.lens.posterior_conic = v,
            -10.0,
            -1.0,
        ),
        (
            "lens decentration x",
            |e, v| e.lens.decentration_mm[0] = v,
            -0.8,
            0.8,
        ),
        (
            "lens decentration y",
            |e, v| e.lens.decentration_mm[1] = v,
            -0.8,
            0.8,
        ),
        ("lens tilt x", |e, v| e.lens.tilt_deg[0] = v, -7.0, 7.0),
        ("lens tilt y", |e, v| e.lens.tilt_deg[1] = v, -7.0, 7.0),
        (
            "anterior elevation (orders 1-4, each term)",
            |e, v| {
                e.cornea.anterior.elevation = (1..=4u32)
                    .flat_map(|n| (0..=n).map(move |k| (n, 2 * k as i32 - n as i32)))
                    .map(|(n, m)| ocular::eye::ElevationTerm { n, m, mm: v / 14.0 })
                    .collect()
            },
            -0.1,
            0.1,
        ),
        (
            "anterior elevation (orders 5-6, each term)",
            |e, v| {
                e.cornea.anterior.elevation = (5..=6u32)
                    .flat_map(|n| (0..=n).map(move |k| (n, 2 * k as i32 - n as i32)))
                    .map(|(n, m)| ocular::eye::ElevationTerm { n, m, mm: v / 13.0 })
                    .collect()
            },
            -0.05,
            0.05,
        ),
    ]
}

fn finite(m: &Measurement) -> bool {
    m.coefficients_um.iter().all(|c| c.is_finite())
        && [
            m.power_d,
            m.refraction.m,
            m.refraction.j0,
            m.refraction.j45,
            m.exit_pupil_diameter_mm,
            m.pupil_retina_mm,
            m.image_numerical_aperture,
            m.iris_diameter_mm,
        ]
        .iter()
        .all(|v| v.is_finite())
}

#[test]
fn table1_bounds_give_finite_results() {
    let mut refused = Vec::new();
    for (name, set, lo, hi) in table1() {
        for v in [lo, hi] {
            let mut eye = Eye::population_mean();
            set(&mut eye, v);
            let sys = match eye.system() {
                Ok(s) => s,
                Err(e) => {
                    println!("{name} = {v}: {e}");
                    refused.push((name, v, e));
                    continue;
                }
            };
            for (pupil, l) in [
                (1.0, 400.0),
                (1.0, 700.0),
                (8.0, 400.0),
                (8.0, 700.0),
                (4.0, 555.0),
            ] {
                for d in [None, Some(0.25)] {
                    match measure(&sys, l, pupil, d, 6) {
                        Ok(m) => assert!(finite(&m), "{name} = {v}, {pupil} mm, {l} nm: {m:?}"),
                        // A pupil wider than the surfaces may be refused, clearly, at 8 mm only.
                        Err(e) => {
                            println!("{name} = {v}, {pupil} mm, {l} nm, {d:?}: {e}");
                            assert!(pupil > 7.0, "{name} = {v} {pupil} mm: {e}");
                        }
                    }
                }
            }
        }
    }
    // Two caps with the mean conics (−4.4, −4.0) cannot hold the mean 160.1 mm³ at a 10.6 mm
    // equator, nor can a k = −10 posterior cap at 11.1 mm: a strongly hyperboloidal cap of
    // positive vertex radius reaches the equator only if t < a/√(−(1+k)). Those corners of
    // Table 1 lie outside the model and must be refused as such; nothing else may be.
    let names: Vec<_> = refused.iter().map(|r| (r.0, r.1)).collect();
    assert_eq!(
        names,
        vec![("lens diameter", 10.6), ("lens posterior conic", -10.0)]
    );
    for (_, _, e) in &refused {
        assert!(matches!(e, EyeError::LensCannotClose { .. }), "{e}");
    }
}

#[test]
fn extreme_pupils_and_wavelengths_on_navarro() {
    let sys = Eye::navarro().system().unwrap();
    for pupil in [1.0, 8.0] {
        for l in [400.0, 700.0] {
            for d in [None, Some(0.1), Some(10.0)] {
                let m = measure(&sys, l, pupil, d, 10).unwrap();
                assert!(finite(&m));
                assert_eq!(m.vignetted_rays, 0);
                assert_eq!(m.coefficients_um.len(), 66);
            }
        }
    }
    // Accommodation at the extremes also finishes.
    let a = accommodate(&Eye::navarro(), Some(0.5), 8.0, 700.0).unwrap();
    assert!(a.residual_c20_um.abs() < 0.01 && a.diameter_mm.is_finite());
}

fn message(r: Result<(), EyeError>) -> String {
    let e = r.expect_err("must be rejected");
    let s = e.to_string();
    assert!(!s.is_empty() && !s.contains('\n'), "one-line message: {s}");
    s
}

#[test]
fn impossible_parameters_are_rejected_clearly() {
    let base = Eye::navarro();
    let mut e = base.clone();
    e.cornea.thickness_mm = -0.1;
    assert!(message(e.validate()).contains("cornea.thickness_mm must be positive"));
    let mut e = base.clone();
    e.aqueous_depth_mm = 0.0;
    assert!(message(e.validate()).contains("aqueous_depth_mm"));
    let mut e = base.clone();
    e.lens.volume_mm3 = 400.0;
    e.lens.anterior_conic = -8.0;
    e.lens.posterior_conic = -8.0;
    assert!(message(e.validate()).contains("lens cannot close"));
    let mut e = base.clone();
    e.axial_length_mm = 12.0;
    assert!(message(e.validate()).contains("vitreous"));
    let mut e = base.clone();
    e.cornea.posterior.radius_mm = [9.5, 9.5];
    e.cornea.anterior.radius_mm = [6.0, 6.0];
    e.cornea.thickness_mm = 0.3;
    assert!(message(e.validate()).contains("cross"));
    let mut e = base.clone();
    e.lens.diameter_mm = f64::NAN;
    assert!(message(e.validate()).contains("finite"));
    let mut e = base.clone();
    e.cornea.anterior.elevation = vec![ocular::eye::ElevationTerm {
        n: 3,
        m: 2,
        mm: 0.01,
    }];
    assert!(message(e.validate()).contains("not a Zernike term"));
    let sys = base.system().unwrap();
    assert!(measure(&sys, 555.0, -1.0, None, 6).is_err());
    assert!(measure(&sys, f64::NAN, 4.0, None, 6).is_err());
    assert!(measure(&sys, 555.0, 4.0, Some(0.0), 6).is_err());
}

#[test]
fn lens_geometry_round_trips_navarro() {
    let eye = Eye::navarro();
    let g = eye.lens_geometry().unwrap();
    assert!((g.anterior_radius_mm - 10.2).abs() < 1e-9);
    assert!((g.posterior_radius_mm + 6.0).abs() < 1e-9);
    assert!((g.thickness_mm() - 4.0).abs() < 1e-9);
    assert!(
        (g.anterior_thickness_mm / g.posterior_thickness_mm - LENS_THICKNESS_RATIO).abs() < 1e-12
    );
    // Constant volume: a smaller diameter makes a thicker, steeper lens.
    let small = lens_geometry(10.6, eye.lens.volume_mm3, -3.1316, -1.0).unwrap();
    assert!(small.thickness_mm() > 4.0 && small.anterior_radius_mm < 10.2);
    // The refusal threshold is the largest volume the caps can hold.
    let vmax = max_volume_mm3(10.6, -4.4, -4.0);
    assert!(lens_geometry(10.6, vmax * 0.999, -4.4, -4.0).is_ok());
    assert!(matches!(
        lens_geometry(10.6, vmax * 1.001, -4.4, -4.0),
        Err(EyeError::LensCannotClose { .. })
    ));
    // The paper's Table 1 mean lens is a plausible 3–4.5 mm thick.
    let mean = Eye::population_mean().lens_geometry().unwrap();
    println!("mean lens {mean:?}");
    assert!(mean.thickness_mm() > 3.0 && mean.thickness_mm() < 4.5);
}

#[test]
fn toml_round_trip() {
    let mut eye = Eye::population_mean();
    eye.cornea.anterior.elevation = vec![ocular::eye::ElevationTerm {
        n: 3,
        m: -1,
        mm: 0.004,
    }];
    eye.lens.tilt_deg = [1.5, -2.0];
    let text = eye.to_toml_string();
    let back = Eye::from_toml_str(&text).unwrap();
    assert_eq!(back, eye);
    let err = Eye::from_toml_str("axial_length_mm = 24.0").unwrap_err();
    assert!(err.to_string().starts_with("eye file:"), "{err}");
    let bad = text.replace("thickness_mm = 0.55", "thickness_mm = -0.55");
    assert!(Eye::from_toml_str(&bad).is_err());
}

#[test]
fn every_corneal_elevation_term_at_its_bound() {
    // Table 1 bounds each coefficient: ±0.1 mm for orders 1–4, ±0.05 mm for orders 5–6.
    for n in 1..=6u32 {
        for k in 0..=n {
            let m = 2 * k as i32 - n as i32;
            let bound = if n <= 4 { 0.1 } else { 0.05 };
            for v in [-bound, bound] {
                let mut eye = Eye::population_mean();
                eye.cornea.anterior.elevation = vec![ocular::eye::ElevationTerm { n, m, mm: v }];
                let sys = eye.system().unwrap();
                for (pupil, l) in [(8.0, 400.0), (8.0, 700.0), (1.0, 555.0)] {
                    let r = measure(&sys, l, pupil, Some(0.25), 6).unwrap();
                    assert!(finite(&r), "({n},{m}) = {v}");
                }
            }
        }
    }
    // All of them at once (a wildly irregular cornea) still measures.
    let mut eye = Eye::population_mean();
    eye.cornea.anterior.elevation = (1..=6u32)
        .flat_map(|n| (0..=n).map(move |k| (n, 2 * k as i32 - n as i32)))
        .map(|(n, m)| ocular::eye::ElevationTerm {
            n,
            m,
            mm: if n <= 4 { 0.1 } else { 0.05 },
        })
        .collect();
    let r = measure(&eye.system().unwrap(), 555.0, 4.0, None, 6).unwrap();
    assert!(finite(&r));
}

/// A very distant object is infinity to within rounding: the wavefront of a point 10¹⁰ m away
/// is the plane wave's (it used to lose micrometres to paths of 10¹³ mm, and accommodation for
/// a focus of 10⁻⁸ D failed to converge). At 100 m the defocus term moves by the object's
/// vergence, −0.01 D, as the paraxial relation c(2,0) = −M·r²/(4√3) says.
#[test]
fn distant_objects_join_infinity_smoothly() {
    let sys = Eye::navarro().system().unwrap();
    let (wl, pupil) = (555.0, 6.0);
    let inf = measure(&sys, wl, pupil, None, 6).unwrap();
    for d_m in [1e4, 1e8, 1e10, 1e13] {
        let far = measure(&sys, wl, pupil, Some(d_m), 6).unwrap();
        for (a, b) in inf.coefficient_list().iter().zip(far.coefficient_list()) {
            // The vergence 1/d adds a ρ² wave: c(2,0) moves by −r²/(4√3)/d µm (a +1/d D
            // refraction) and piston by √3 times that.
            let dc20 = -9.0 / (4.0 * 3f64.sqrt()) / d_m;
            let expected = match (a.n, a.m) {
                (2, 0) => dc20,
                (0, 0) => 3f64.sqrt() * dc20,
                _ => 0.0,
            };
            assert!(
                (b.um - a.um - expected).abs() < 1e-7,
                "Z({},{}) at {d_m} m: {} vs infinity {}",
                a.n,
                a.m,
                b.um,
                a.um
            );
        }
    }
    let near = measure(&sys, wl, pupil, Some(100.0), 6).unwrap();
    let dc20 = near.coefficient_um(2, 0) - inf.coefficient_um(2, 0);
    let vergence = -9.0 / (4.0 * 3f64.sqrt()) / 100.0;
    assert!(
        (dc20 - vergence).abs() < 0.05 * vergence.abs(),
        "c(2,0) moved {dc20} µm for an object at 100 m; vergence predicts {vergence}"
    );
    let accommodated = accommodate(&Eye::navarro(), Some(1e8), 4.0, 555.0);
    assert!(accommodated.is_ok(), "{accommodated:?}");
}
