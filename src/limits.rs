//! The ranges of the eye's physical inputs that every command and every file format accepts.
//!
//! One table, so that a pupil a scene file accepts is one `render --pupil-mm` accepts, the
//! kernels can be planned for, and `eye measure` can trace. The bounds are physiological or
//! set by the models' validity, not by any one code path:
//! - pupil 1–9 mm: the range of human entrance pupils (Watson & Yellott 2012 put the
//!   light-adapted minimum near 2 mm and the dark-adapted maximum of young eyes near 8–9 mm);
//!   below 1 mm diffraction hides every aberration the eye model carries;
//! - wavelength 380–1000 nm: the visible band plus the near infrared that aberrometers measure
//!   in (840–940 nm), the span the ocular-media dispersion of the eye models covers;
//! - vertical field of view 0.1–170°: a pinhole frame's scale grows as 1/cos²θ, and beyond
//!   170° its corners would be more than 130× stretched.

/// A closed interval of one physical quantity, with its unit for messages.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Limit {
    pub min: f64,
    pub max: f64,
    pub unit: &'static str,
}

pub const PUPIL_MM: Limit = Limit {
    min: 1.0,
    max: 9.0,
    unit: "mm",
};

pub const WAVELENGTH_NM: Limit = Limit {
    min: 380.0,
    max: 1000.0,
    unit: "nm",
};

pub const FOV_Y_DEG: Limit = Limit {
    min: 0.1,
    max: 170.0,
    unit: "degrees",
};

impl Limit {
    /// Whether `value` is finite and inside the interval (bounds included).
    pub fn contains(&self, value: f64) -> bool {
        value.is_finite() && value >= self.min && value <= self.max
    }

    /// "1 to 9 mm": the allowed range as messages and `--help` state it.
    pub fn allowed(&self) -> String {
        format!("{} to {} {}", self.min, self.max, self.unit)
    }

    /// `Ok(value)` inside the range, else the one-line message "`what` `value` is outside
    /// `allowed`" (what names the option or field: `--pupil-mm`, `pupil_mm =`).
    pub fn check(&self, what: &str, value: f64) -> Result<f64, String> {
        if self.contains(value) {
            Ok(value)
        } else {
            Err(format!("{what} {value} is outside {}", self.allowed()))
        }
    }
}

/// Smallest frame side the eye-rendering front doors accept: the kernel grid's screen needs at
/// least 16 pixels of height, and the SSIM window 11 pixels of each side.
pub const MIN_FRAME_SIDE: u32 = 16;

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bounds_are_inclusive_and_non_finite_values_are_refused() {
        assert!(PUPIL_MM.contains(1.0) && PUPIL_MM.contains(9.0));
        assert!(!PUPIL_MM.contains(0.999) && !PUPIL_MM.contains(9.001));
        assert!(!WAVELENGTH_NM.contains(f64::NAN) && !FOV_Y_DEG.contains(f64::INFINITY));
        let msg = PUPIL_MM.check("--pupil-mm", 12.0).unwrap_err();
        assert!(msg.starts_with("--pupil-mm 12 is outside"), "{msg}");
        assert!(msg.contains("1 to 9 mm"), "{msg}");
    }
}
