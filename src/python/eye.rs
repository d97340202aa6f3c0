//! `Eye`, `Refraction` and `psf`: eyes from presets, files, prescriptions and wavefronts, what
//! they measure, and one point-spread function through them.

use std::path::PathBuf;
use std::sync::atomic::AtomicBool;

use numpy::PyArray1;
use numpy::{IntoPyArray, PyArray2};
use pyo3::prelude::*;

use super::{guarded, missing_file, value_error};
use crate::aberrations::ZernikeSet;
use crate::eye::estimate::{self, EstimateError, Report, Settings};
use crate::eye::file as eye_file;
use crate::eye::Eye;
use crate::limits::{PUPIL_MM, WAVELENGTH_NM};
use crate::{Error, Result};

/// An eye: its structure and, for an estimated eye, the record of the fit.
#[pyclass(name = "Eye", module = "ocular_render", frozen)]
#[derive(Clone)]
pub struct PyEye {
    pub(crate) eye: Eye,
    estimate: Option<Report>,
    /// How it was made, for `repr` and the saved file's header.
    source: String,
}

pub(crate) fn check_pupil(option: &str, pupil_mm: f64) -> Result<f64> {
    PUPIL_MM.check(option, pupil_mm).map_err(Error::input)
}

pub(crate) fn check_wavelength(option: &str, wavelength_nm: f64) -> Result<f64> {
    WAVELENGTH_NM
        .check(option, wavelength_nm)
        .map_err(Error::input)
}

/// `vertex_mm` as `--vertex-mm` takes it.
fn check_vertex(vertex_mm: f64) -> PyResult<()> {
    let (lo, hi) = crate::eye::correction::VERTEX_RANGE_MM;
    if !(vertex_mm.is_finite() && (lo..=hi).contains(&vertex_mm)) {
        return Err(value_error(format!(
            "--vertex-mm: {vertex_mm} is outside {lo} to {hi} mm"
        )));
    }
    Ok(())
}

fn check_field(field_deg: Option<(f64, f64)>) -> Result<Option<[f64; 2]>> {
    let Some((h, v)) = field_deg else {
        return Ok(None);
    };
    crate::eye::field::check_field_deg([h, v]).map_err(|_| {
        Error::input(format!(
            "--field-deg \"{h},{v}\" is not allowed; need \"H,V\" in degrees, each within ±{m}° \
             and at most {m}° from the axis",
            m = crate::eye::field::MAX_FIELD_DEG
        ))
    })?;
    Ok(Some([h, v]))
}

fn estimate_error(e: EstimateError) -> Error {
    match e {
        EstimateError::Input(m) => Error::Input(m),
        EstimateError::Eye(e) => Error::Eye(e),
    }
}

fn settings(max_time_s: Option<f64>) -> Settings {
    Settings {
        max_time_s,
        ..Settings::default()
    }
}

fn fit(target: &ZernikeSet, max_time_s: Option<f64>) -> Result<estimate::Estimate> {
    estimate::estimate(
        target,
        &settings(max_time_s),
        &AtomicBool::new(false),
        &mut |_| {},
    )
    .map_err(estimate_error)
}

impl PyEye {
    fn estimated(
        py: Python<'_>,
        target: ZernikeSet,
        max_time_s: Option<f64>,
        source: String,
    ) -> PyResult<PyEye> {
        let est = guarded(py, move || {
            estimate::check_target(&target).map_err(|e| Error::input(e.to_string()))?;
            fit(&target, max_time_s)
        })?;
        Ok(PyEye {
            eye: est.eye,
            estimate: Some(est.report),
            source,
        })
    }

    /// The measurement behind `refraction` and `wavefront`: the eye relaxed (or focused at
    /// `focus_m`), the object where it focuses.
    fn measure(
        &self,
        pupil_mm: f64,
        wavelength_nm: f64,
        field_deg: Option<(f64, f64)>,
        focus_m: Option<f64>,
        order: u32,
    ) -> Result<crate::eye::Measurement> {
        let field = check_field(field_deg)?;
        check_pupil("--pupil-mm", pupil_mm)?;
        check_wavelength("--wavelength-nm", wavelength_nm)?;
        if !(1..=10).contains(&order) {
            return Err(Error::input(format!(
                "--order {order} is not allowed; need 1 to 10"
            )));
        }
        if let Some(m) = focus_m {
            if !(m.is_finite() && m > 0.02) {
                return Err(Error::input(format!(
                    "--focus-m {m:?} is not allowed; need a distance beyond 0.02 m or \"inf\""
                )));
            }
        }
        let eye = &self.eye;
        let limited = eye.accommodation_max_d.is_some() || eye.iol.is_some();
        let focused = match focus_m {
            None => eye.clone(),
            Some(_) => {
                crate::eye::focus_within_range(eye, focus_m, pupil_mm, wavelength_nm, limited)?.eye
            }
        };
        let sys = focused.system()?;
        Ok(match field {
            None => crate::eye::measure(&sys, wavelength_nm, pupil_mm, focus_m, order)?,
            Some(f) => {
                crate::eye::field::measure_field(&sys, wavelength_nm, pupil_mm, focus_m, f, order)?
                    .measurement
            }
        })
    }
}

#[pymethods]
impl PyEye {
    /// A shipped eye by name (see `eye_presets()`).
    #[staticmethod]
    fn preset(name: &str) -> PyResult<PyEye> {
        match eye_file::preset(name) {
            Some(f) => Ok(PyEye {
                eye: f.eye,
                estimate: f.estimate,
                source: format!("Eye.preset({name:?})"),
            }),
            None => Err(value_error(format!(
                "eye {name:?} is not a preset; the presets are {}",
                eye_file::preset_names().join(", ")
            ))),
        }
    }

    /// An eye file (TOML, as `ocular eye estimate` and `Eye.save` write).
    #[staticmethod]
    fn load(py: Python<'_>, path: PathBuf) -> PyResult<PyEye> {
        if let Some(e) = missing_file(&path) {
            return Err(e);
        }
        let p = path.clone();
        let f = guarded(py, move || eye_file::load(&p))?;
        Ok(PyEye {
            eye: f.eye,
            estimate: f.estimate,
            source: format!("Eye.load({:?})", path.display().to_string()),
        })
    }

    /// A physical eye fitted to a spectacle prescription "S C x A" at `vertex_mm` in front of
    /// the cornea, over a `pupil_mm` entrance pupil, as `ocular eye estimate --rx` fits it
    /// (`wavelength_nm` None: 549 nm).
    #[staticmethod]
    #[pyo3(signature = (rx, pupil_mm = 4.0, wavelength_nm = None, vertex_mm = 12.0, max_time_s = None))]
    fn from_rx(
        py: Python<'_>,
        rx: &str,
        pupil_mm: f64,
        wavelength_nm: Option<f64>,
        vertex_mm: f64,
        max_time_s: Option<f64>,
    ) -> PyResult<PyEye> {
        check_pupil("--pupil-mm", pupil_mm).map_err(super::to_py)?;
        let target =
            estimate::prescription::RxTarget::new(rx, pupil_mm, wavelength_nm, Some(vertex_mm))
                .map_err(|e| super::to_py(estimate_error(e)))?;
        let source = format!(
            "Eye.from_rx({rx:?}, pupil_mm={pupil_mm}, wavelength_nm={}, vertex_mm={})",
            target.wavelength_nm, target.vertex_mm
        );
        let est = guarded(py, move || {
            target
                .estimate(&settings(max_time_s), &AtomicBool::new(false), &mut |_| {})
                .map_err(estimate_error)
        })?;
        Ok(PyEye {
            eye: est.eye,
            estimate: Some(est.report),
            source,
        })
    }

    /// A physical eye fitted to a wavefront: OSA/ANSI-ordered Zernike coefficients (µm,
    /// index j = 0, 1, 2, … up to order 10) over `pupil_mm` at `wavelength_nm`.
    #[staticmethod]
    #[pyo3(signature = (coefficients_um, pupil_mm, wavelength_nm, max_time_s = None))]
    fn from_zernike(
        py: Python<'_>,
        coefficients_um: Vec<f64>,
        pupil_mm: f64,
        wavelength_nm: f64,
        max_time_s: Option<f64>,
    ) -> PyResult<PyEye> {
        let most = crate::optics::zernike::num_terms(10);
        if coefficients_um.is_empty() || coefficients_um.len() > most {
            return Err(value_error(format!(
                "coefficients_um: {} values; need 1 to {most} (OSA order j = 0 … {}, up to \
                 order 10)",
                coefficients_um.len(),
                most - 1
            )));
        }
        check_pupil("--pupil-mm", pupil_mm).map_err(super::to_py)?;
        let target = ZernikeSet {
            pupil_diameter_mm: pupil_mm,
            wavelength_nm,
            coefficients: coefficients_um
                .iter()
                .enumerate()
                .map(|(j, &um)| {
                    let (n, m) = crate::optics::zernike::osa_nm(j);
                    (n, m, um)
                })
                .collect(),
        };
        let source = format!(
            "Eye.from_zernike({} coefficients, pupil_mm={pupil_mm}, wavelength_nm={wavelength_nm})",
            coefficients_um.len()
        );
        PyEye::estimated(py, target, max_time_s, source)
    }

    /// Writes the eye file (TOML) atomically.
    fn save(&self, py: Python<'_>, path: PathBuf) -> PyResult<()> {
        let text = self.to_toml();
        guarded(py, move || crate::image_io::write_text_atomic(&path, &text))
    }

    /// The eye file's text.
    fn to_toml(&self) -> String {
        let header = format!(
            "Eye made by ocular_render {}: {}",
            env!("CARGO_PKG_VERSION"),
            self.source
        );
        eye_file::to_toml(&self.eye, self.estimate.as_ref(), &header)
    }

    /// The eye with a spectacle lens "S C x A" at `vertex_mm` (0: a contact lens), traced
    /// with it.
    #[pyo3(signature = (rx, vertex_mm = 12.0))]
    fn with_correction(&self, rx: &str, vertex_mm: f64) -> PyResult<PyEye> {
        check_vertex(vertex_mm)?;
        let lens = crate::eye::correction::parse_rx(rx, vertex_mm)
            .map_err(|e| value_error(format!("--correct: {e}")))?;
        let mut eye = self.eye.clone();
        eye.correction = Some(lens);
        eye.validate()
            .map_err(|e| value_error(format!("--correct/--iol-d: {e}")))?;
        Ok(PyEye {
            eye,
            estimate: self.estimate.clone(),
            source: format!(
                "{}.with_correction({rx:?}, vertex_mm={vertex_mm})",
                self.source
            ),
        })
    }

    /// The spectacle prescription "S C x A" at `vertex_mm` in front of the cornea (0: a
    /// contact lens) that corrects the eye for a distant object: what `ocular eye refract`
    /// prints, and what `from_rx` and `with_correction` take (a correction the eye wears is
    /// removed first). Beside it, the eye as given (its correction included) at its entrance
    /// pupil: the minimum-RMS power vector `pupil_m_d`, `pupil_j0_d`, `pupil_j45_d`. At a
    /// field angle the prescription is that power vector carried to the lens meridian by
    /// meridian (paraxial; on axis it is traced through the lens).
    #[pyo3(signature = (pupil_mm = 4.0, wavelength_nm = 549.0, field_deg = None, vertex_mm = 12.0))]
    fn refraction(
        &self,
        py: Python<'_>,
        pupil_mm: f64,
        wavelength_nm: f64,
        field_deg: Option<(f64, f64)>,
        vertex_mm: f64,
    ) -> PyResult<PyRefraction> {
        check_vertex(vertex_mm)?;
        let ((sphere_d, cylinder_d, axis_deg), pupil) = guarded(py, || {
            let pupil = self
                .measure(pupil_mm, wavelength_nm, field_deg, None, 6)?
                .refraction;
            let rx = match field_deg {
                None => {
                    let r =
                        crate::eye::refract::refract(&self.eye, pupil_mm, vertex_mm, wavelength_nm)
                            .map_err(|e| Error::input(format!("cannot refract the eye: {e}")))?;
                    (r.sphere_d, r.cylinder_d, r.axis_deg)
                }
                Some(_) => {
                    let mut bare = self.clone();
                    bare.eye.correction = None;
                    let m = bare.measure(pupil_mm, wavelength_nm, field_deg, None, 6)?;
                    let r = m.refraction;
                    crate::eye::refract::pupil_to_spectacle_rx(
                        [r.m, r.j0, r.j45],
                        vertex_mm,
                        m.entrance_pupil_z_mm,
                    )
                }
            };
            Ok((rx, pupil))
        })?;
        Ok(PyRefraction {
            sphere_d,
            cylinder_d,
            axis_deg,
            vertex_mm,
            pupil_m_d: pupil.m,
            pupil_j0_d: pupil.j0,
            pupil_j45_d: pupil.j45,
            pupil_mm,
            wavelength_nm,
            field_deg,
        })
    }

    /// The eye's wavefront: OSA/ANSI Zernike coefficients (µm, j = 0 … up to `order`) over
    /// the entrance pupil, for an object where it focuses (`focus_m`, default infinity).
    #[pyo3(signature = (pupil_mm = 4.0, wavelength_nm = 555.0, field_deg = None, focus_m = None, order = 6))]
    fn wavefront<'py>(
        &self,
        py: Python<'py>,
        pupil_mm: f64,
        wavelength_nm: f64,
        field_deg: Option<(f64, f64)>,
        focus_m: Option<f64>,
        order: u32,
    ) -> PyResult<Bound<'py, PyArray1<f64>>> {
        let m = guarded(py, || {
            self.measure(pupil_mm, wavelength_nm, field_deg, focus_m, order)
        })?;
        Ok(m.coefficients_um.into_pyarray(py))
    }

    /// Amplitude of accommodation (D) the eye file sets, or None (renderers then use the
    /// age model).
    #[getter]
    fn accommodation_max_d(&self) -> Option<f64> {
        self.eye.accommodation_max_d
    }

    /// Whether the eye came from a fit that converged (None: not estimated).
    #[getter]
    fn converged(&self) -> Option<bool> {
        self.estimate.as_ref().map(|r| r.converged)
    }

    fn __eq__(&self, other: &Bound<'_, PyAny>) -> bool {
        other
            .downcast::<PyEye>()
            .is_ok_and(|o| o.get().eye == self.eye)
    }

    fn __repr__(&self) -> String {
        format!("<ocular_render.Eye {}>", self.source)
    }
}

/// A spectacle prescription at a vertex distance, and the eye's power vector at its entrance
/// pupil beside it (dioptres).
#[pyclass(name = "Refraction", module = "ocular_render", frozen, get_all)]
#[derive(Clone)]
pub struct PyRefraction {
    sphere_d: f64,
    cylinder_d: f64,
    axis_deg: f64,
    vertex_mm: f64,
    pupil_m_d: f64,
    pupil_j0_d: f64,
    pupil_j45_d: f64,
    pupil_mm: f64,
    wavelength_nm: f64,
    field_deg: Option<(f64, f64)>,
}

#[pymethods]
impl PyRefraction {
    /// "S C x A" at `vertex_mm`, as `Eye.from_rx` and `Eye.with_correction` take it (with the
    /// same `vertex_mm`).
    fn rx(&self) -> String {
        crate::eye::correction::format_rx(self.sphere_d, self.cylinder_d, self.axis_deg)
    }

    fn __repr__(&self) -> String {
        format!(
            "<ocular_render.Refraction {} at a {} mm vertex (entrance pupil: M {:+.3} D, J0 {:+.3} D, \
             J45 {:+.3} D) over {} mm at {} nm>",
            self.rx(),
            self.vertex_mm,
            self.pupil_m_d,
            self.pupil_j0_d,
            self.pupil_j45_d,
            self.pupil_mm,
            self.wavelength_nm
        )
    }
}

/// The names `Eye.preset` accepts.
#[pyfunction]
pub fn eye_presets() -> Vec<&'static str> {
    eye_file::preset_names()
}

fn check_vergence(option: &str, d: f64) -> Result<f64> {
    let most = crate::render::focus::MAX_OBJECT_VERGENCE_D;
    if d.is_finite() && (0.0..=most).contains(&d) {
        Ok(d)
    } else {
        Err(Error::input(format!(
            "{option} {d} must be a vergence from 0 (infinity) to {most} D"
        )))
    }
}

/// The PSF of `eye` (normalised to sum 1; row 0 at the top, optical axis at (size/2,
/// size/2)), focused at `focus_d` dioptres and seeing a point at `object_d` (default: where
/// it focuses), through a `pupil_mm` pupil at `wavelength_nm`, sampled every `pitch_arcmin`.
#[pyfunction]
#[pyo3(signature = (eye, pupil_mm, wavelength_nm, *, focus_d = 0.0, object_d = None, size = 256, pitch_arcmin = 0.25))]
#[allow(clippy::too_many_arguments)]
pub fn psf<'py>(
    py: Python<'py>,
    eye: &PyEye,
    pupil_mm: f64,
    wavelength_nm: f64,
    focus_d: f64,
    object_d: Option<f64>,
    size: usize,
    pitch_arcmin: f64,
) -> PyResult<Bound<'py, PyArray2<f64>>> {
    let eye = eye.eye.clone();
    let values = guarded(py, move || {
        eye_psf(
            &eye,
            pupil_mm,
            wavelength_nm,
            (focus_d, object_d),
            size,
            pitch_arcmin,
        )
    })?;
    Ok(super::arrays::gray_out(py, size, size, values))
}

fn eye_psf(
    eye: &Eye,
    pupil_mm: f64,
    wavelength_nm: f64,
    (focus_d, object_d): (f64, Option<f64>),
    size: usize,
    pitch_arcmin: f64,
) -> Result<Vec<f64>> {
    use crate::optics::psf::{compute_psf, pitch_from_arcmin, PsfRequest};
    check_pupil("--pupil-mm", pupil_mm)?;
    check_wavelength("--wavelength-nm", wavelength_nm)?;
    let focus_d = check_vergence("--focus-d", focus_d)?;
    let object_d = check_vergence("object_d", object_d.unwrap_or(focus_d))?;
    if !(8..=8192).contains(&size) {
        return Err(Error::input(format!(
            "--size {size} is outside 8–8192 pixels"
        )));
    }
    if !(pitch_arcmin.is_finite() && pitch_arcmin > 0.0) {
        return Err(Error::input(format!(
            "--pitch-arcmin must be a positive number (got {pitch_arcmin})"
        )));
    }
    // The renderer's optics: the eye accommodates at its accommodation wavelength, is measured
    // at this one, and an object off the focus adds the ENZ defocus of its vergence.
    let settings = crate::psf::axes::KernelSettings::default();
    let column = crate::psf::defocus::ColumnOptics::new(
        eye,
        pupil_mm,
        focus_d,
        [wavelength_nm; 3],
        &settings,
    )?;
    let channel = &column.channels[0];
    let coefficients = channel
        .alpha_um
        .iter()
        .enumerate()
        .filter(|(_, um)| **um != 0.0)
        .map(|(j, &um)| {
            let (n, m) = crate::optics::zernike::osa_nm(j);
            (n, m, um)
        })
        .collect();
    let pitch = pitch_from_arcmin(pitch_arcmin, pupil_mm, wavelength_nm);
    let mut request = PsfRequest::new(coefficients, pupil_mm, wavelength_nm, pitch, size);
    request.defocus_f = channel.defocus_f(object_d);
    request.parallel = true;
    let psf = compute_psf(&request)?;
    let total: f64 = psf.intensity.iter().sum();
    if !(total.is_finite() && total > 0.0) {
        return Err(Error::input(
            "the PSF has no energy on this grid: enlarge --size or --pitch-arcmin",
        ));
    }
    Ok(psf.intensity.iter().map(|v| v / total).collect())
}
