//! Pupil diameter from scene luminance.
//!
//! Units: luminance in cd/m² (ocular's rendered linear RGB is luminance-calibrated: a pixel's
//! Y = 0.2126 R + 0.7152 G + 0.0722 B is its luminance in cd/m²), field area in square
//! degrees, age in years, diameters in mm (entrance pupil).

/// How many eyes see the field: Watson & Yellott's monocular effect M (0.1 for one eye, 1 for
/// both).
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Viewing {
    OneEye,
    BothEyes,
}

impl Viewing {
    fn effect(self) -> f64 {
        match self {
            Viewing::OneEye => 0.1,
            Viewing::BothEyes => 1.0,
        }
    }
}

/// Watson & Yellott (2012), the unified formula: the Stanley–Davies core driven by the
/// effective corneal flux density F = L·a·M, with the age correction (valid 20–83 years; the
/// age is clamped to that range). 60° × 60° binocular viewing at 28.58 years reduces to the
/// plain Stanley–Davies formula.
pub fn watson_yellott_mm(
    luminance_cdm2: f64,
    field_area_deg2: f64,
    age_years: f64,
    viewing: Viewing,
) -> f64 {
    let flux = luminance_cdm2.max(0.0) * field_area_deg2.max(0.0) * viewing.effect();
    let x = (flux / 846.0).powf(0.41);
    let d_sd = 7.75 - 5.75 * x / (x + 2.0);
    let age = age_years.clamp(20.0, 83.0);
    d_sd + (age - 28.58) * (0.02132 - 0.009562 * d_sd)
}

/// Moon & Spencer (1944) as Watson & Yellott (2012, Eq. 2) quote it:
/// D = 4.9 − 3·tanh(0.4·log10 L), L in cd/m² (no offset inside the tanh). Luminance is floored
/// at 1e-6 cd/m², where the formula has long saturated at 7.9 mm.
pub fn moon_spencer_mm(luminance_cdm2: f64) -> f64 {
    4.9 - 3.0 * (0.4 * luminance_cdm2.max(1e-6).log10()).tanh()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn moon_spencer_spans_its_range() {
        assert!((moon_spencer_mm(1.0) - 4.9).abs() < 1e-12);
        assert!((moon_spencer_mm(1e-6) - 7.9).abs() < 0.05);
        assert!((moon_spencer_mm(1e6) - 1.9).abs() < 0.05);
        assert!(moon_spencer_mm(100.0) < moon_spencer_mm(10.0));
    }

    #[test]
    fn watson_yellott_reduces_to_stanley_davies_and_ages() {
        // F = 846 cd/m²·deg² → X = 1 → D = 7.75 − 5.75/3.
        let d = watson_yellott_mm(846.0, 1.0, 28.58, Viewing::BothEyes);
        assert!((d - (7.75 - 5.75 / 3.0)).abs() < 1e-12);
        // Older eyes have smaller pupils in the dark.
        assert!(
            watson_yellott_mm(0.01, 3600.0, 70.0, Viewing::BothEyes)
                < watson_yellott_mm(0.01, 3600.0, 25.0, Viewing::BothEyes)
        );
        // One eye sees less flux: larger pupil.
        assert!(
            watson_yellott_mm(100.0, 3600.0, 30.0, Viewing::OneEye)
                > watson_yellott_mm(100.0, 3600.0, 30.0, Viewing::BothEyes)
        );
        assert!(watson_yellott_mm(0.0, 0.0, 30.0, Viewing::OneEye).is_finite());
    }
}
