//! Invalid input to the optics engine, and the range check every entry point makes.

/// Invalid input to the optics engine. Each message names the field and what is allowed.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum OpticsError {
    #[error("{field} must be a finite number (got {value})")]
    NonFinite { field: String, value: f64 },
    #[error("{field} = {value} is out of range; allowed: {allowed}")]
    OutOfRange {
        field: String,
        value: f64,
        allowed: &'static str,
    },
    #[error(
        "unknown Zernike term (n, m) = ({n}, {m}); allowed: |m| <= n, n - |m| even, n <= {max_n}"
    )]
    UnknownTerm { n: u32, m: i32, max_n: u32 },
}

/// Check that `value` is finite and inside [lo, hi].
pub(crate) fn check_range(
    field: &str,
    value: f64,
    lo: f64,
    hi: f64,
    allowed: &'static str,
) -> Result<f64, OpticsError> {
    if !value.is_finite() {
        return Err(OpticsError::NonFinite {
            field: field.to_string(),
            value,
        });
    }
    if value < lo || value > hi {
        return Err(OpticsError::OutOfRange {
            field: field.to_string(),
            value,
            allowed,
        });
    }
    Ok(value)
}
