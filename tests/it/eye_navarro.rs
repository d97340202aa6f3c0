//! The relaxed and accommodating Navarro eye against published figures.

use ocular::eye::{
    eye_index, measure, navarro_accommodated, paraxial, refractive_index, Eye, Medium,
    NAVARRO_VITREOUS_MM,
};

#[test]
fn dispersion_matches_escudero_sanz_table() {
    let table = [
        (458.0, [1.3828, 1.3445, 1.4292, 1.3428]),
        (543.0, [1.3777, 1.3391, 1.4222, 1.3377]),
        (589.3, [1.376, 1.3374, 1.42, 1.336]),
        (632.8, [1.3747, 1.336, 1.4183, 1.3347]),
    ];
    let media = [
        Medium::Cornea,
        Medium::Aqueous,
        Medium::Lens,
        Medium::Vitreous,
    ];
    // The source table's aqueous entry at 458 nm (1.3445) lies 1.5e-4 above what its own
    // coefficients give (1.34435); every other entry agrees to 1e-4.
    let tol = |m: Medium, l: f64| {
        if m == Medium::Aqueous && l == 458.0 {
            1.6e-4
        } else {
            1e-4
        }
    };
    for (l, row) in table {
        for (m, want) in media.iter().zip(row) {
            for got in [refractive_index(*m, l), eye_index(*m, l)] {
                println!("{m:?} {l} nm: {got:.6} vs {want} ({:+.1e})", got - want);
                assert!(
                    (got - want).abs() <= tol(*m, l),
                    "{m:?} at {l} nm: {got} vs {want}"
                );
            }
        }
    }
}

#[test]
fn relaxed_power_and_back_focus() {
    let sys = Eye::navarro().system().unwrap();
    let p = paraxial(&sys, 589.3, 0.0);
    println!("power {} D, bfd {} mm", p.power_d, p.back_focal_distance_mm);
    assert!((p.power_d - 60.416).abs() < 0.01, "power {}", p.power_d);
    assert!((p.back_focal_distance_mm - NAVARRO_VITREOUS_MM).abs() < 0.005);
    // The preset system for A = 0 is the same eye.
    let q = paraxial(&navarro_accommodated(0.0).unwrap(), 589.3, 0.0);
    assert!((q.power_d - p.power_d).abs() < 1e-9);
}

#[test]
fn spherical_aberration_matches_reference() {
    let sys = Eye::navarro().system().unwrap();
    for (pupil, want) in [
        (3.0, 0.0128),
        (4.0, 0.0421),
        (5.0, 0.108),
        (6.0, 0.239),
        (7.0, 0.476),
    ] {
        let m = measure(&sys, 555.0, pupil, None, 6).unwrap();
        let c40 = m.coefficient_um(4, 0);
        println!(
            "pupil {pupil}: c40 {c40:.5} (ref {want}) c20 {:.4} c60 {:.5}",
            m.coefficient_um(2, 0),
            m.coefficient_um(6, 0)
        );
        assert!(
            ((c40 - want) / want).abs() < 0.02,
            "pupil {pupil}: c(4,0) {c40} vs {want}"
        );
    }
}

#[test]
fn longitudinal_chromatic_aberration() {
    let sys = Eye::navarro().system().unwrap();
    let r = |l: f64| paraxial(&sys, l, 0.0).refraction_d;
    let lca = r(450.0) - r(650.0);
    let lca2 = r(400.0) - r(700.0);
    println!("LCA 450-650 {lca} D, 400-700 {lca2} D");
    assert!((lca.abs() - 1.35).abs() < 0.05, "LCA {lca}");
    assert!((lca2.abs() - 2.48).abs() < 0.1, "LCA 400-700 {lca2}");
}

#[test]
fn navarro_accommodation_powers() {
    for (a, want) in [(1.0, 61.834), (4.0, 64.925), (8.0, 68.924)] {
        let p = paraxial(&navarro_accommodated(a).unwrap(), 589.3, 0.0).power_d;
        println!("A = {a}: {p} D");
        assert!((p - want).abs() < 0.02, "A = {a}: {p} vs {want}");
    }
}
