//! Why an eye cannot be built: the one error of the eye's modules, kept apart from the model so
//! that the parts the model is built from (the lens's geometry, the lenses worn with it) can
//! report through it without depending on the model.

/// Why an eye cannot be built.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum EyeError {
    #[error("{name} must be finite, got {value}")]
    NonFinite { name: &'static str, value: f64 },
    #[error("lens cannot close: a volume of {volume_mm3:.2} mm³ exceeds the {max_volume_mm3:.2} mm³ two caps of diameter {diameter_mm} mm can hold")]
    LensCannotClose {
        volume_mm3: f64,
        diameter_mm: f64,
        max_volume_mm3: f64,
    },
    #[error("{0}")]
    Invalid(String),
}
