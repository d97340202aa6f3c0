//! The crate-wide error: every failure a user can see, with the exit code it maps to.

use crate::gpu::GpuError;

#[derive(Debug, thiserror::Error)]
pub enum Error {
    /// Bad input from the user: an option, a file's field, a value out of range.
    #[error("{0}")]
    Input(String),
    /// A file that could not be read or written.
    #[error("{path}: {message}")]
    File { path: String, message: String },
    #[error(transparent)]
    Gpu(#[from] GpuError),
    /// An eye whose parameters are impossible or out of range.
    #[error(transparent)]
    Eye(#[from] crate::eye::EyeError),
    /// Invalid optics input (coefficients, pupil, wavelength, settings).
    #[error(transparent)]
    Optics(#[from] crate::optics::OpticsError),
    /// A Zernike file or preset that cannot be read or is malformed.
    #[error(transparent)]
    Aberrations(#[from] crate::aberrations::AberrationError),
}

pub type Result<T, E = Error> = std::result::Result<T, E>;

impl Error {
    pub fn input(message: impl Into<String>) -> Error {
        Error::Input(message.into())
    }

    pub fn file(path: impl AsRef<std::path::Path>, message: impl std::fmt::Display) -> Error {
        Error::File {
            path: path.as_ref().display().to_string(),
            message: message.to_string(),
        }
    }

    /// 2 for anything the user can fix in what they typed or gave (input, options, files);
    /// 1 for failures of the machine or the program.
    pub fn exit_code(&self) -> i32 {
        match self {
            Error::Input(_)
            | Error::File { .. }
            | Error::Eye(_)
            | Error::Optics(_)
            | Error::Aberrations(_) => 2,
            Error::Gpu(GpuError::DeviceNotFound { .. } | GpuError::DeviceUnsuitable { .. }) => 2,
            Error::Gpu(_) => 1,
        }
    }
}
