//! Sign conventions, consistency with the paraxial trace, accommodation, and the response of
//! the wavefront to toricity, lens placement and corneal elevation.

use ocular::eye::{accommodate, measure, paraxial, ElevationTerm, Eye};

fn c(m: &ocular::eye::Measurement, n: u32, mm: i32) -> f64 {
    m.coefficient_um(n, mm)
}

#[test]
fn longer_eye_is_myopic_with_positive_defocus() {
    let base = Eye::navarro();
    let mut long = base.clone();
    long.axial_length_mm += 0.5;
    let m0 = measure(&base.system().unwrap(), 589.3, 5.0, None, 6).unwrap();
    let m1 = measure(&long.system().unwrap(), 589.3, 5.0, None, 6).unwrap();
    println!(
        "c20 base {} long {}; M {} {}",
        c(&m0, 2, 0),
        c(&m1, 2, 0),
        m0.refraction.m,
        m1.refraction.m
    );
    assert!(c(&m1, 2, 0) > c(&m0, 2, 0) + 1.0);
    assert!(m1.refraction.m < -1.0, "a long eye needs a minus lens");
    // About 2.7 D of myopia per mm of axial length in a 60 D eye.
    let dm = m0.refraction.m - m1.refraction.m;
    assert!((dm - 1.35).abs() < 0.2, "0.5 mm longer → {dm} D");
}

#[test]
fn real_rays_agree_with_paraxial_trace() {
    for extra in [0.0, 0.6, -0.8] {
        let mut eye = Eye::navarro();
        eye.axial_length_mm += extra;
        let sys = eye.system().unwrap();
        for l in [450.0, 555.0, 650.0] {
            let m = measure(&sys, l, 0.5, None, 6).unwrap();
            let p = paraxial(&sys, l, 0.0);
            // Paraxial refraction at the cornea, moved to the entrance-pupil plane.
            let v = p.refraction_d / 1000.0;
            let at_ep = 1000.0 * v / (1.0 - m.entrance_pupil_z_mm * v);
            println!(
                "{extra} {l}: real {} paraxial {at_ep} (cornea {})",
                m.paraxial_sphere_d, p.refraction_d
            );
            assert!(
                (m.paraxial_sphere_d - at_ep).abs() < 1e-3,
                "{} vs {at_ep}",
                m.paraxial_sphere_d
            );
            assert!((m.power_d - p.power_d).abs() < 1e-12);
        }
    }
}

#[test]
fn accommodated_eye_focuses_near_and_not_far() {
    let eye = Eye::navarro();
    let acc = accommodate(&eye, Some(0.2), 4.0, 555.0).unwrap();
    println!(
        "diameter {} → {}, residual {} µm, {} it",
        eye.lens.diameter_mm, acc.diameter_mm, acc.residual_c20_um, acc.iterations
    );
    let sys = acc.eye.system().unwrap();
    let near = measure(&sys, 555.0, 4.0, Some(0.2), 6).unwrap();
    let far = measure(&sys, 555.0, 4.0, None, 6).unwrap();
    println!(
        "near c20 {} far c20 {} far M {} power {}",
        c(&near, 2, 0),
        c(&far, 2, 0),
        far.refraction.m,
        far.power_d
    );
    assert!(c(&near, 2, 0).abs() < 0.01);
    assert!(acc.residual_c20_um.abs() < 0.01);
    assert!(acc.diameter_mm < eye.lens.diameter_mm);
    // Infinity is now about 5 D out of focus (myopic, positive c(2,0)).
    assert!(c(&far, 2, 0) > 2.0, "far c20 {}", c(&far, 2, 0));
    assert!(
        (far.refraction.m + 5.0).abs() < 0.4,
        "far M {}",
        far.refraction.m
    );
    // And back: focusing at infinity again recovers the relaxed state.
    let back = accommodate(&acc.eye, None, 4.0, 555.0).unwrap();
    let m = measure(&back.eye.system().unwrap(), 555.0, 4.0, None, 6).unwrap();
    assert!(c(&m, 2, 0).abs() < 0.01);
}

#[test]
fn toric_cornea_gives_astigmatism_on_its_axis() {
    let mut eye = Eye::navarro();
    // Horizontal meridian steeper by 0.2 mm: more power horizontally.
    eye.cornea.anterior.radius_mm = [7.62, 7.82];
    let sys = eye.system().unwrap();
    let m = measure(&sys, 555.0, 5.0, None, 6).unwrap();
    let px = paraxial(&sys, 555.0, 0.0);
    let py = paraxial(&sys, 555.0, 90.0);
    // J0 = (M_y − M_x)/2 with M the meridional refractions: here the x meridian is more myopic.
    let j0_parax = (px.refraction_d - py.refraction_d) / 2.0;
    println!(
        "c22 {} c2-2 {} J0 {} parax J0 {j0_parax}",
        c(&m, 2, 2),
        c(&m, 2, -2),
        m.refraction.j0
    );
    assert!(
        c(&m, 2, 2) > 0.3,
        "steeper horizontal meridian → positive c(2,2)"
    );
    assert!(c(&m, 2, -2).abs() < 1e-6);
    // Over a small pupil the Zernike astigmatism is the paraxial one.
    let small = measure(&sys, 555.0, 1.0, None, 6).unwrap();
    println!("J0 1 mm {}", small.refraction.j0);
    assert!(
        (small.refraction.j0 - j0_parax).abs() < 0.01 * j0_parax.abs(),
        "{} vs {j0_parax}",
        small.refraction.j0
    );
    assert!(m.refraction.j0 < 0.0 && (m.refraction.j0 - j0_parax).abs() < 0.05 * j0_parax.abs());
    // As a spectacle prescription: the too-strong horizontal meridian needs a minus cylinder
    // acting horizontally, i.e. axis 90°.
    let rx = ocular::optics::zernike::Prescription::from_zernike(
        c(&m, 2, -2),
        c(&m, 2, 0),
        c(&m, 2, 2),
        5.0,
    );
    println!("Rx {rx:?}");
    assert!(rx.cylinder_d < -1.0 && (rx.axis_deg - 90.0).abs() < 0.01);
    // Rotating the cornea by 45° moves the astigmatism into c(2,−2), same magnitude.
    let mut rot = eye.clone();
    rot.cornea.anterior.axis_deg = 45.0;
    let r = measure(&rot.system().unwrap(), 555.0, 5.0, None, 6).unwrap();
    println!("rotated c22 {} c2-2 {}", c(&r, 2, 2), c(&r, 2, -2));
    assert!(c(&r, 2, 2).abs() < 1e-3 * c(&m, 2, 2));
    assert!((c(&r, 2, -2) - c(&m, 2, 2)).abs() < 1e-3 * c(&m, 2, 2));
    // 30°: the astigmatism axis turns by 30°, i.e. its angle 2A by 60°.
    rot.cornea.anterior.axis_deg = 30.0;
    let r = measure(&rot.system().unwrap(), 555.0, 5.0, None, 6).unwrap();
    let angle = c(&r, 2, -2).atan2(c(&r, 2, 2)).to_degrees() / 2.0;
    assert!((angle - 30.0).abs() < 0.1, "axis {angle}");
    let rx = ocular::optics::zernike::Prescription::from_zernike(
        c(&r, 2, -2),
        c(&r, 2, 0),
        c(&r, 2, 2),
        5.0,
    );
    assert!(
        (rx.axis_deg - 120.0).abs() < 0.1,
        "rotated axis {}",
        rx.axis_deg
    );
}

#[test]
fn decentred_or_tilted_lens_gives_coma() {
    let base = measure(&Eye::navarro().system().unwrap(), 555.0, 6.0, None, 6).unwrap();
    assert!(c(&base, 3, 1).abs() < 1e-9 && c(&base, 3, -1).abs() < 1e-9);
    let coma = |dx: f64, dy: f64, tx: f64, ty: f64| {
        let mut e = Eye::navarro();
        e.lens.decentration_mm = [dx, dy];
        e.lens.tilt_deg = [tx, ty];
        let m = measure(&e.system().unwrap(), 555.0, 6.0, None, 6).unwrap();
        (c(&m, 3, 1), c(&m, 3, -1))
    };
    let (x, y0) = coma(0.4, 0.0, 0.0, 0.0);
    let (xm, _) = coma(-0.4, 0.0, 0.0, 0.0);
    let (x0, y) = coma(0.0, 0.4, 0.0, 0.0);
    println!("decentre x: c31 {x} c3-1 {y0}; -x {xm}; y: c3-1 {y} c31 {x0}");
    assert!(
        x.abs() > 0.02,
        "0.4 mm decentration must give visible coma: {x}"
    );
    assert!(y0.abs() < 1e-6 * x.abs().max(1.0) && x0.abs() < 1e-6);
    assert!((x + xm).abs() < 1e-3 * x.abs(), "odd in the decentration");
    assert!(
        (x - y).abs() < 1e-6,
        "x and y decentration are the same by symmetry"
    );
    // Linear for small decentration; the sign (+x shift → negative c(3,1) here) is recorded
    // as a regression value for the Navarro lens.
    let (half, _) = coma(0.2, 0.0, 0.0, 0.0);
    assert!((half / x - 0.5).abs() < 0.03, "linearity {half} vs {x}");
    assert!(x < 0.0);
    let (tx, _) = coma(0.0, 0.0, 3.0, 0.0);
    let (_, ty) = coma(0.0, 0.0, 0.0, 3.0);
    let (txm, _) = coma(0.0, 0.0, -3.0, 0.0);
    println!("tilt: c31 {tx} c3-1 {ty} -tilt {txm}");
    assert!(tx.abs() > 0.01);
    assert!((tx + txm).abs() < 1e-3 * tx.abs());
    assert!((tx - ty).abs() < 1e-6);
}

#[test]
fn corneal_elevation_maps_into_the_wavefront() {
    let r_norm = 5.0;
    let pupil: f64 = 6.0;
    for (n, m_) in [(3u32, -3i32), (3, 3), (4, 4), (5, 1)] {
        let mut eye = Eye::navarro();
        let e_mm = 0.002;
        eye.cornea.anterior.elevation = vec![ElevationTerm { n, m: m_, mm: e_mm }];
        eye.cornea.elevation_radius_mm = r_norm;
        let sys = eye.system().unwrap();
        let meas = measure(&sys, 589.3, pupil, None, 6).unwrap();
        // A raised sag shortens the air path and lengthens the corneal one: W ≈ (n_c − 1)·e.
        let scale = (pupil / 2.0 / r_norm).powi(n as i32);
        let want = (1.376 - 1.0) * e_mm * 1000.0 * scale;
        let got = c(&meas, n, m_);
        println!("({n},{m_}): got {got} want {want}");
        if n == 5 {
            // Z(5,1) over the cornea also holds lower-order content over the smaller pupil.
            assert!(got > 0.0 && (got - want).abs() < 0.15 * want);
        } else {
            assert!(
                (got - want).abs() < 0.1 * want,
                "({n},{m_}): {got} vs {want}"
            );
        }
    }
}

#[test]
fn cross_section_svg_draws_both_focus_states() {
    let svg = ocular::eye::cross_section_svg(&Eye::navarro(), &Default::default()).unwrap();
    assert!(svg.starts_with("<svg") && svg.trim_end().ends_with("</svg>"));
    assert!(svg.contains("focused at infinity") && svg.contains("focused at 0.2 m"));
    assert!(svg.matches("<polyline").count() >= 2 * (4 + 9));
    assert!(!svg.contains("NaN"));
}

#[test]
fn describe_and_coefficient_list() {
    let text = ocular::eye::describe(&Eye::navarro(), 589.3, 4.0).unwrap();
    println!("{text}");
    assert!(text.contains("power 60.41") && text.contains("anterior lens"));
    let m = measure(&Eye::navarro().system().unwrap(), 555.0, 4.0, None, 6).unwrap();
    let list = m.coefficient_list();
    assert_eq!(list.len(), 28);
    assert_eq!((list[12].n, list[12].m), (4, 0));
    assert_eq!(list[12].um, m.coefficient_um(4, 0));
}
