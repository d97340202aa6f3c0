//! Hand-derived test eyes standing in for the seed paper's estimated presets until eye
//! estimation provides them: Navarro's eye made myopic by a longer axis, and a
//! keratoconus-like eye (steep, toric, irregular cornea). Not fits to any measurement.

use super::model::{ElevationTerm, Eye};

/// Names accepted by [`test_eye`].
pub const TEST_EYE_NAMES: [&str; 3] = ["myopia-like", "keratoconus-like", "myopia10-like"];

/// A test eye by name.
pub fn test_eye(name: &str) -> Option<Eye> {
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
