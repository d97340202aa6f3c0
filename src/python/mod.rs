//! The Python extension module `ocular_render._ocular_render` (feature "python", built by
//! maturin from pyproject.toml). It is a thin layer over the library: eyes ([`eye`]), one PSF
//! and the metrics ([`measures`]), the renderer ([`renderer`]). The Python package
//! (python/ocular_render/) re-exports it with docstrings and type stubs.
//!
//! Errors keep the library's one-line messages (the CLI's): what a user could fix raises
//! ValueError (TypeError for a wrong type), the machine's failures RuntimeError. No panic
//! crosses into Python: every call into the library runs under [`guarded`].

use pyo3::exceptions::{PyFileNotFoundError, PyRuntimeError, PyTypeError, PyValueError};
use pyo3::prelude::*;

mod arrays;
mod eye;
mod frame_options;
mod measures;
mod renderer;

/// A library error as the Python exception a user expects, with the CLI's message.
pub(crate) fn to_py(error: crate::Error) -> PyErr {
    use crate::gpu::GpuError;
    match &error {
        // Which device to use is an argument; a missing driver or loader is the machine's.
        crate::Error::Gpu(GpuError::DeviceNotFound { .. }) => {
            PyValueError::new_err(error.to_string())
        }
        crate::Error::Gpu(_) => PyRuntimeError::new_err(error.to_string()),
        _ if error.exit_code() == 2 => PyValueError::new_err(error.to_string()),
        _ => PyRuntimeError::new_err(error.to_string()),
    }
}

pub(crate) fn value_error(message: impl Into<String>) -> PyErr {
    PyValueError::new_err(message.into())
}

pub(crate) fn type_error(message: impl Into<String>) -> PyErr {
    PyTypeError::new_err(message.into())
}

pub(crate) fn missing_file(path: &std::path::Path) -> Option<PyErr> {
    (!path.exists())
        .then(|| PyFileNotFoundError::new_err(format!("{}: no such file", path.display())))
}

/// Runs library code with the GIL released, turning a panic into RuntimeError (a panic would
/// otherwise surface as pyo3's PanicException, which `except Exception` does not catch).
pub(crate) fn guarded<T, F>(py: Python<'_>, work: F) -> PyResult<T>
where
    T: Send,
    F: FnOnce() -> crate::Result<T> + Send,
{
    let outcome = py.allow_threads(|| std::panic::catch_unwind(std::panic::AssertUnwindSafe(work)));
    match outcome {
        Ok(Ok(value)) => Ok(value),
        Ok(Err(error)) => Err(to_py(error)),
        Err(panic) => {
            let what = panic
                .downcast_ref::<String>()
                .map(String::as_str)
                .or_else(|| panic.downcast_ref::<&str>().copied())
                .unwrap_or("unknown panic");
            Err(PyRuntimeError::new_err(format!(
                "internal error in ocular (please report it): {what}"
            )))
        }
    }
}

#[pymodule]
#[pyo3(name = "_ocular_render")]
fn ocular_render_module(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    m.add_class::<eye::PyEye>()?;
    m.add_class::<eye::PyRefraction>()?;
    m.add_class::<renderer::PyRenderer>()?;
    m.add_function(wrap_pyfunction!(eye::psf, m)?)?;
    m.add_function(wrap_pyfunction!(eye::eye_presets, m)?)?;
    m.add_function(wrap_pyfunction!(measures::psnr, m)?)?;
    m.add_function(wrap_pyfunction!(measures::ssim, m)?)?;
    m.add_function(wrap_pyfunction!(measures::flip, m)?)?;
    m.add_function(wrap_pyfunction!(measures::read_exr, m)?)?;
    m.add_function(wrap_pyfunction!(measures::write_exr, m)?)?;
    m.add_function(wrap_pyfunction!(renderer::scenes, m)?)?;
    Ok(())
}
