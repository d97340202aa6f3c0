//! Hand-made eyes, derived by hand rather than fitted to any measurement: Navarro's eye made
//! myopic by a longer axis, and a keratoconus-like eye (steep, toric, irregular cornea). They
//! stood in for the seed paper's estimated presets until eye estimation provided them, and are
//! still accepted wherever an eye is named (`eye::resolve`, not listed as presets) and
//! used by the kernel benchmarks and tests.

use super::model::{ElevationTerm, Eye};

/// Names accepted by [`hand_made_eye`].
pub const HAND_MADE_EYE_NAMES: [&str; 3] = ["myopia-like", "keratoconus-like", "myopia10-like"];

/// A hand-made eye by name.
pub fn hand_made_eye(name: &str) -> Option<Eye> {
    match name {
        "myopia-like" => Some(axial_myopia(2.2)),
        "myopia10-like" => Some(axial_myopia(3.7)),
        "keratoconus-like" => Some(keratoconus_like()),
        _ => None,
    }
}

/// Navarro's eye with the vitreous lengthened by `extra_mm` (about −2.7 D per mm).
pub fn axial_myopia(extra_mm: f64) -> Eye {
    let mut e = Eye::navarro();
    e.axial_length_mm += extra_mm;
    e
}

/// A cone below the centre: a steeper, toric anterior cornea with vertical coma and trefoil
/// in its elevation (magnitudes of the order of the seed paper's keratoconus preset).
pub fn keratoconus_like() -> Eye {
    let mut e = Eye::navarro();
    let a = &mut e.cornea.anterior;
    a.radius_mm = [7.25, 7.18];
    a.axis_deg = 15.0;
    a.conic = -0.6;
    a.elevation = [
        (3, -1, 0.0125),
        (3, -3, 0.011),
        (3, 1, -0.003),
        (4, 0, 0.001),
    ]
    .into_iter()
    .map(|(n, m, mm)| ElevationTerm { n, m, mm })
    .collect();
    e
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::eye::measure;

    fn refraction(eye: &Eye, pupil_mm: f64) -> (f64, f64, f64) {
        let sys = eye.system().unwrap();
        let m = measure(&sys, 549.0, pupil_mm, None, 6).unwrap();
        let coma = m.coefficient_um(3, -1).hypot(m.coefficient_um(3, 1));
        let astig = m.coefficient_um(2, -2).hypot(m.coefficient_um(2, 2));
        (m.refraction.m, coma, astig)
    }

    #[test]
    fn hand_made_eyes_have_the_intended_errors() {
        let (m, _, _) = refraction(&hand_made_eye("myopia-like").unwrap(), 4.0);
        assert!((-7.0..=-5.5).contains(&m), "myopia-like: {m} D");
        let (m, _, _) = refraction(&hand_made_eye("myopia10-like").unwrap(), 4.0);
        assert!((-11.0..=-9.0).contains(&m), "myopia10-like: {m} D");
        // the seed paper's keratoconus preset (5 mm): coma ≈ 0.6 µm, astigmatism ≈ 0.3 µm,
        // about −3 D
        let (m, coma, astig) = refraction(&hand_made_eye("keratoconus-like").unwrap(), 5.0);
        assert!((-4.5..=-2.0).contains(&m), "keratoconus-like: {m} D");
        assert!((0.4..=1.0).contains(&coma), "coma {coma} µm");
        assert!((0.15..=0.6).contains(&astig), "astigmatism {astig} µm");
    }
}
