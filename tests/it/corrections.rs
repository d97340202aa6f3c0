//! Corrections traced with the eye, the amplitude of accommodation by age, and objective
//! refraction, each checked against an independent computation written here: thin-lens
//! vergence formulas, a geometric spot diagram, the thin-lens IOL formula.

use ocular::eye::{
    emmetropic_iol_power_d, exerted_accommodation_d, eye_index, focus_within_range,
    hofstetter_amplitude_d, preset, refract, trace_range, Eye, FocusLimit, HofstetterLine, Iol,
    Measurer, Medium, Ray, Spectacle,
};

const NM: f64 = 549.0;

fn myopia() -> Eye {
    preset("myopia").unwrap().eye
}

fn far_refraction(eye: &Eye, pupil_mm: f64) -> (f64, f64, f64, f64) {
    let m = Measurer::standard()
        .measure(&eye.system().unwrap(), NM, pupil_mm, None)
        .unwrap();
    (
        m.refraction.m,
        m.refraction.j0,
        m.refraction.j45,
        m.entrance_pupil_z_mm,
    )
}

fn with_lens(eye: &Eye, sphere_d: f64, vertex_mm: f64) -> Eye {
    let mut e = eye.clone();
    e.correction = Some(Spectacle::new(sphere_d, 0.0, 180.0, vertex_mm).unwrap());
    e
}

#[test]
fn the_myopic_eye_through_its_own_prescription_measures_emmetropic() {
    let eye = myopia();
    let (m0, _, _, ep_z) = far_refraction(&eye, 4.0);
    // Negative control: uncorrected, the eye is about −6 D.
    assert!(m0 < -5.5, "uncorrected M {m0}");
    let rx = refract(&eye, 4.0, 12.0, NM).unwrap();
    // Vertex effect by the vergence formula: the eye's refraction K at its entrance pupil
    // becomes F = K / (1 + dK) at a lens d = 12 mm + the pupil's depth in front of it.
    let d = (12.0 + ep_z) * 1e-3;
    let expected = m0 / (1.0 + d * m0);
    assert!(
        (rx.sphere_d - expected).abs() < 0.03,
        "sphere {} vs vergence formula {expected}",
        rx.sphere_d
    );
    assert!(rx.cylinder_d.abs() < 0.02);
    // Without the vertex effect the prescription would be off by over 0.5 D.
    assert!((expected - m0).abs() > 0.5);
    let corrected = with_lens(&eye, rx.sphere_d, 12.0);
    let (m, j0, j45, _) = far_refraction(&corrected, 4.0);
    assert!(
        m.abs() < 0.1 && j0.abs() < 0.1 && j45.abs() < 0.1,
        "through {:.3} D: M {m}, J0 {j0}, J45 {j45}",
        rx.sphere_d
    );
    // The eye's own −6 D sphere at 12 mm leaves it measurably myopic (vertex effect).
    let naive = with_lens(&eye, m0, 12.0);
    assert!(far_refraction(&naive, 4.0).0 < -0.4);
}

#[test]
fn a_contact_lens_needs_no_vertex_correction_beyond_the_pupil_depth() {
    let eye = myopia();
    let (m0, _, _, ep_z) = far_refraction(&eye, 4.0);
    let rx = refract(&eye, 4.0, 0.0, NM).unwrap();
    let expected = m0 / (1.0 + ep_z * 1e-3 * m0);
    assert!(
        (rx.sphere_d - expected).abs() < 0.03,
        "{} vs {expected}",
        rx.sphere_d
    );
    let (m, _, _, _) = far_refraction(&with_lens(&eye, rx.sphere_d, 0.0), 4.0);
    assert!(m.abs() < 0.05, "through the contact lens M {m}");
}

#[test]
fn an_over_correction_by_one_dioptre_needs_the_vergence_formulas_accommodation() {
    let eye = myopia();
    let pupil = 4.0;
    let f = refract(&eye, pupil, 12.0, NM).unwrap().sphere_d;
    let over = with_lens(&eye, f - 1.0, 12.0);
    // Relaxed, the over-corrected eye is 1 D hyperopic at the lens: its far point lies 1 m
    // behind the lens, so at the system's entrance pupil the refraction is 1/(1 − s) D, s
    // in metres from the lens to that pupil.
    let (m, _, _, ep_z) = far_refraction(&over, pupil);
    let s = (ep_z + 12.0) * 1e-3;
    assert!(
        (m - 1.0 / (1.0 - s)).abs() < 0.03,
        "M {m} vs {}",
        1.0 / (1.0 - s)
    );
    // Focusing far through it takes the ocular accommodation the vergence formula gives at
    // the eye's entrance pupil: K(F) − K(F − 1), K(F) = F / (1 − dF).
    let focused = focus_within_range(&over, None, pupil, NM, true).unwrap();
    assert_eq!(focused.limit, FocusLimit::Reached);
    let exerted = exerted_accommodation_d(&eye, focused.eye.lens.diameter_mm, pupil, NM).unwrap();
    let (_, _, _, eye_ep) = far_refraction(&eye, pupil);
    let d = (12.0 + eye_ep) * 1e-3;
    let k = |p: f64| p / (1.0 - d * p);
    let expected = k(f) - k(f - 1.0);
    assert!(
        (exerted - expected).abs() < 0.05,
        "exerted {exerted} D vs vergence formula {expected} D"
    );
    // For this −6.8 D lens the formula is well below 1 D: the check discriminates.
    assert!((1.0 - expected) > 0.1);
    // And it is the same lens as focusing 1 m in front of the right correction (thin-lens
    // vergence identity).
    let right = with_lens(&eye, f, 12.0);
    let near = focus_within_range(&right, Some(1.012), pupil, NM, true).unwrap();
    let exerted_near = exerted_accommodation_d(&eye, near.eye.lens.diameter_mm, pupil, NM).unwrap();
    assert!(
        (exerted - exerted_near).abs() < 0.03,
        "{exerted} vs {exerted_near}"
    );
    // An amplitude below it cannot focus far through the over-correction.
    let mut weak = over.clone();
    weak.accommodation_max_d = Some(0.5 * expected);
    let clamped = focus_within_range(&weak, None, pupil, NM, true).unwrap();
    assert_eq!(clamped.limit, FocusLimit::NearPoint);
    weak.accommodation_max_d = Some(expected + 0.1);
    assert_eq!(
        focus_within_range(&weak, None, pupil, NM, true)
            .unwrap()
            .limit,
        FocusLimit::Reached
    );
}

/// Geometric 50 % encircled-energy radius (arcmin) of the on-axis point at `distance_m`
/// through `eye` over a `pupil_mm` entrance pupil: rays traced to the retina, counted about
/// their centroid; 288 µm per degree on the retina.
fn spot_r50_arcmin(eye: &Eye, distance_m: f64, pupil_mm: f64) -> f64 {
    let sys = eye.system().unwrap();
    let m = Measurer::standard()
        .measure(&sys, NM, pupil_mm, Some(distance_m))
        .unwrap();
    let n = sys.indices(NM);
    let mut pts = Vec::new();
    let k = 41;
    for i in 0..k {
        for j in 0..k {
            let u = 2.0 * (i as f64 + 0.5) / k as f64 - 1.0;
            let v = 2.0 * (j as f64 + 0.5) / k as f64 - 1.0;
            if u * u + v * v > 1.0 {
                continue;
            }
            let r = pupil_mm / 2.0;
            let mut ray = Ray::towards(
                [0.0, 0.0, -1000.0 * distance_m],
                [r * u, r * v, m.entrance_pupil_z_mm],
            );
            trace_range(&sys, &n, &mut ray, 0..sys.surfaces.len()).unwrap();
            let p = ray.at(ray.to_plane(sys.retina_z_mm));
            pts.push([p[0], p[1]]);
        }
    }
    let c = pts
        .iter()
        .fold([0.0, 0.0], |a, p| [a[0] + p[0], a[1] + p[1]]);
    let c = [c[0] / pts.len() as f64, c[1] / pts.len() as f64];
    let mut r: Vec<f64> = pts
        .iter()
        .map(|p| (p[0] - c[0]).hypot(p[1] - c[1]))
        .collect();
    r.sort_by(|a, b| a.partial_cmp(b).unwrap());
    r[r.len() / 2] * 1000.0 / 288.0 * 60.0
}

#[test]
fn a_sixty_year_old_emmetrope_cannot_read_the_card_at_forty_centimetres_a_twenty_year_old_can() {
    // The chart scene's card: lines down to logMAR 0.0 at 0.4 m; print a reader must manage
    // (logMAR 0.4, about N5) has strokes 10^0.4 = 2.5 arcmin wide.
    let stroke_arcmin = 10f64.powf(0.4);
    let pupil = 3.5; // the chart scene's Watson–Yellott pupil at these ages is 3.4–4.3 mm
    let base = preset("healthy").unwrap().eye;
    let blur_at = |age: Option<f64>| {
        let mut eye = base.clone();
        eye.accommodation_max_d = age.map(|a| hofstetter_amplitude_d(a, HofstetterLine::Mean));
        let f = focus_within_range(&eye, Some(0.4), pupil, NM, true).unwrap();
        (spot_r50_arcmin(&f.eye, 0.4, pupil), f.limit)
    };
    let (young, young_limit) = blur_at(Some(20.0));
    let (old, old_limit) = blur_at(Some(60.0));
    let (unlimited, _) = blur_at(None);
    assert_eq!(young_limit, FocusLimit::Reached);
    assert_eq!(old_limit, FocusLimit::NearPoint);
    assert!(young < 0.5 * stroke_arcmin, "20 years: r50 {young:.2}′");
    assert!(old > 2.0 * stroke_arcmin, "60 years: r50 {old:.2}′");
    // Negative control: without the amplitude the 60-year-old's lens would focus the card.
    assert!(unlimited < 0.5 * stroke_arcmin);
    // Independent estimate of the old eye's blur: 0.5 D of amplitude leaves ≈ 2 D of defocus,
    // a blur disc of angular radius ΔD·(pupil/2) rad; its r50 is that over √2.
    let mut eye = base.clone();
    eye.accommodation_max_d = Some(0.5);
    let f = focus_within_range(&eye, Some(0.4), pupil, NM, true).unwrap();
    let m = Measurer::standard()
        .measure(&f.eye.system().unwrap(), NM, pupil, Some(0.4))
        .unwrap();
    let defocus_d = m.refraction.m.abs();
    let disc_r50 =
        defocus_d * pupil / 2.0 * 1e-3 / 2f64.sqrt() * (180.0 / std::f64::consts::PI) * 60.0;
    assert!(defocus_d > 1.5, "defocus {defocus_d} D");
    assert!(
        (old - disc_r50).abs() < 0.25 * disc_r50,
        "r50 {old} vs disc {disc_r50}"
    );
}

#[test]
fn hofstetter_near_points_follow_the_amplitude() {
    // The near point (reached focus) of an emmetrope is its amplitude in dioptres.
    let mut eye = preset("healthy").unwrap().eye;
    let (far, _, _, _) = far_refraction(&eye, 3.0);
    eye.accommodation_max_d = Some(3.0);
    let f = focus_within_range(&eye, Some(0.1), 3.0, NM, true).unwrap();
    assert_eq!(f.limit, FocusLimit::NearPoint);
    let exerted = exerted_accommodation_d(&eye, f.eye.lens.diameter_mm, 3.0, NM).unwrap();
    assert!((exerted - 3.0).abs() < 0.01, "{exerted}");
    // The clamped eye focuses at far-point vergence + 3 D (near the pupil plane).
    let m = Measurer::standard()
        .measure(&f.eye.system().unwrap(), NM, 3.0, Some(1.0 / (3.0 - far)))
        .unwrap();
    assert!(m.refraction.m.abs() < 0.1, "{}", m.refraction.m);
}

#[test]
fn the_emmetropic_iol_agrees_with_the_thin_lens_vergence_formula_and_does_not_accommodate() {
    let eye = preset("healthy").unwrap().eye;
    let p = emmetropic_iol_power_d(&eye, 1.0, NM).unwrap();
    // Paraxial vergences through the cornea to the IOL plane, and what the retina needs.
    let c = &eye.cornea;
    let (n_c, n_a, n_v) = (
        eye_index(Medium::Cornea, NM),
        eye_index(Medium::Aqueous, NM),
        eye_index(Medium::Vitreous, NM),
    );
    let r1 = 0.5 * (c.anterior.radius_mm[0] + c.anterior.radius_mm[1]) * 1e-3;
    let r2 = 0.5 * (c.posterior.radius_mm[0] + c.posterior.radius_mm[1]) * 1e-3;
    let mut v = (n_c - 1.0) / r1;
    v = v / (1.0 - c.thickness_mm * 1e-3 / n_c * v);
    v += (n_a - n_c) / r2;
    let z_iol = Iol::plane_z_mm(&eye).unwrap();
    let gap = (z_iol - c.thickness_mm) * 1e-3;
    v = v / (1.0 - gap / n_a * v);
    let needed = n_v / ((eye.axial_length_mm - z_iol) * 1e-3);
    let formula = needed - v;
    assert!(
        (p - formula).abs() < 0.15,
        "traced {p} D vs formula {formula} D"
    );
    let mut pseudo = eye.clone();
    pseudo.iol = Some(Iol { power_d: p });
    let (m, _, _, _) = far_refraction(&pseudo, 1.0);
    assert!(m.abs() < 0.01);
    let near = focus_within_range(&pseudo, Some(0.4), 3.0, NM, true).unwrap();
    assert_eq!(near.limit, FocusLimit::NearPoint);
    assert_eq!(near.eye, pseudo);
    // A +2.5 D reading spectacle on the pseudophakic eye focuses the card.
    let mut reading = pseudo.clone();
    reading.correction = Some(Spectacle::new(2.5, 0.0, 180.0, 12.0).unwrap());
    let m = Measurer::standard()
        .measure(&reading.system().unwrap(), NM, 3.0, Some(0.4))
        .unwrap();
    assert!(m.refraction.m.abs() < 0.15, "{}", m.refraction.m);
}

#[test]
fn eye_files_carry_the_amplitude_and_the_correction_and_refuse_bad_values() {
    let base = preset("healthy").unwrap().eye.to_toml_string();
    let text = format!(
        "accommodation_max_d = 0.5\n{base}\n[correction]\nsphere_d = 2.0\nvertex_mm = 12.0\n"
    );
    let eye = Eye::from_toml_str(&text).unwrap();
    assert_eq!(eye.accommodation_max_d, Some(0.5));
    assert_eq!(eye.correction.unwrap().sphere_d, 2.0);
    assert_eq!(eye.correction.unwrap().axis_deg, 180.0);
    // Round trip through the writer.
    assert_eq!(Eye::from_toml_str(&eye.to_toml_string()).unwrap(), eye);
    for (bad, field) in [
        ("accommodation_max_d = 30.0\n", "accommodation_max_d"),
        ("accommodation_max_d = -1.0\n", "accommodation_max_d"),
    ] {
        let e = Eye::from_toml_str(&format!("{bad}{base}")).unwrap_err();
        assert!(e.to_string().contains(field), "{e}");
    }
    let e = Eye::from_toml_str(&format!(
        "{base}\n[correction]\nsphere_d = -2.0\nvertex_mm = 40.0\n"
    ))
    .unwrap_err();
    assert!(e.to_string().contains("correction.vertex_mm"), "{e}");
    let e = Eye::from_toml_str(&format!("{base}\n[iol]\npower_d = 60.0\n")).unwrap_err();
    assert!(e.to_string().contains("iol.power_d"), "{e}");
}

#[test]
fn an_ideal_lens_focuses_a_plane_wave_at_its_focal_length_with_equal_paths() {
    use ocular::eye::{Medium as M, OpticalSystem, Surface};
    // +5 D toric lens (+5 along 30°, +3 across) in air: each principal meridian focuses at
    // 1/P, and by Fermat every ray of a meridian reaches its focal line with the same
    // optical path (the added phase and the bending are one consistent lens).
    let axis = 30f64.to_radians();
    let sys = OpticalSystem {
        surfaces: vec![Surface::ideal_lens(0.0, [5.0, 3.0], axis)],
        media: vec![M::Air],
        stop_index: 0,
        stop_z_mm: 0.0,
        retina_z_mm: 1000.0,
        retina_radius_mm: f64::INFINITY,
        lens_index_offset: 0.0,
    };
    let n = sys.indices(NM);
    for (power_d, phi) in [(5.0, axis), (3.0, axis + std::f64::consts::FRAC_PI_2)] {
        let f_mm = 1000.0 / power_d;
        let (c, s) = (phi.cos(), phi.sin());
        let mut paths = Vec::new();
        for h in [0.5, 1.0, 2.0, 3.0] {
            let mut ray = Ray {
                p: [h * c, h * s, -10.0],
                d: [0.0, 0.0, 1.0],
                opl_mm: 0.0,
            };
            trace_range(&sys, &n, &mut ray, 0..1).unwrap();
            let t = ray.to_plane(f_mm);
            let at = ray.at(t);
            assert!(at[0].hypot(at[1]) < 1e-3 * h, "{power_d} D, h {h}: {at:?}");
            paths.push(ray.opl_mm + t);
        }
        let spread = paths.iter().cloned().fold(f64::MIN, f64::max)
            - paths.iter().cloned().fold(f64::MAX, f64::min);
        // A quadratic phase is a paraxial lens: against the exact sphere its paths fall
        // short by about h⁴/(8f³) (1.3 nm at 3 mm, 200 mm), and its rays, bent by sin θ = h/f,
        // cross the focal plane a little off; a few times that term bounds the spread, and a
        // phase and bending that disagreed (say a factor 2 in either) would miss by
        // h²/(2f) = 22 µm.
        let quartic = 3f64.powi(4) / (8.0 * f_mm.powi(3));
        assert!(
            spread < 4.0 * quartic,
            "{power_d} D: path spread {spread} mm, quartic term {quartic} mm"
        );
    }
}
