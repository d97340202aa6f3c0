//! `Renderer`: one Vulkan device and what it keeps between frames (`render::live`): the
//! rasteriser, and the kernels, pipelines and PSF texture of the current eye state, reused
//! while the eye, focus, pupil, screen and settings hold and the frame's depth range lies
//! inside the planned one (the same kernel grid). The eye, focus and pupil are resolved as
//! `ocular render` resolves them, with the same messages ([`super::frame_options`]).

use std::path::PathBuf;

use numpy::PyArray3;
use pyo3::prelude::*;
use pyo3::types::PyDict;

use super::arrays::{color_layers, depth_layers, rgb_out};
use super::eye::PyEye;
use super::frame_options::options;
use super::guarded;
use crate::gpu::{Context, ContextOptions};
use crate::render::frame::HostFrame;
use crate::render::frame_plan::SceneEye;
use crate::render::headset::Headset;
use crate::render::live::{LiveRenderer, SceneArg};
use crate::scene::Scene;
use std::sync::Arc;

/// Renders colour + depth frames (and scenes) as an eye sees them on one Vulkan device.
#[pyclass(name = "Renderer", module = "ocular_render")]
pub struct PyRenderer {
    live: LiveRenderer,
    last_pair: std::sync::Mutex<Option<PairReport>>,
    /// The last scene seen through a headset's field (`headset=`), kept so that its frames
    /// and geometry stay cached while it is asked for again.
    headset_scene: std::sync::Mutex<Option<(String, Headset, Arc<Scene>)>>,
}

/// How the last binocular pair was rendered, for `Renderer.last_pair`.
#[derive(Clone, Copy)]
struct PairReport {
    driver: &'static str,
    accommodation_d: f64,
    focus_d: [f64; 2],
    residual_d: [f64; 2],
    far_point_d: [f64; 2],
    demand_d: [f64; 2],
    pupil_mm: f64,
}

/// `headset=`: a preset name (as `--headset` takes it), refused beside `size`.
fn parse_headset(name: Option<&str>, size: Option<(u32, u32)>) -> PyResult<Option<Headset>> {
    let Some(name) = name else {
        return Ok(None);
    };
    if size.is_some() {
        return Err(super::value_error(
            "headset= sets the frame's size: give headset or size, not both",
        ));
    }
    use clap::ValueEnum;
    Headset::from_str(name, true).map(Some).map_err(|_| {
        let names: Vec<String> = Headset::value_variants()
            .iter()
            .filter_map(|h| h.to_possible_value().map(|v| v.get_name().to_string()))
            .collect();
        super::value_error(format!(
            "headset={name:?}: no such headset ({})",
            names.join(", ")
        ))
    })
}

impl PyRenderer {
    /// The scene `name` through `headset`'s vertical field, loaded once and kept while asked
    /// for again (a new one is a new scene to the renderer's caches).
    fn headset_scene(&self, name: &str, headset: Headset) -> crate::Result<Arc<Scene>> {
        let mut kept = self.headset_scene.lock().unwrap_or_else(|p| p.into_inner());
        if let Some((n, h, scene)) = kept.as_ref() {
            if n == name && *h == headset {
                return Ok(Arc::clone(scene));
            }
        }
        let scene = Arc::new(headset.spec().frame(Scene::load(name)?).0);
        *kept = Some((name.to_string(), headset, Arc::clone(&scene)));
        Ok(scene)
    }
}

fn warn_all(py: Python<'_>, warnings: &[String]) -> PyResult<()> {
    let category = py.get_type::<pyo3::exceptions::PyUserWarning>();
    for w in warnings {
        let text = std::ffi::CString::new(w.replace('\0', " ")).expect("no NUL left");
        PyErr::warn(py, &category, &text, 1)?;
    }
    Ok(())
}

#[pymethods]
impl PyRenderer {
    /// Opens a Vulkan device: `device` is an index or a name substring as `ocular devices`
    /// lists them (default: $OCULAR_DEVICE, else the most capable). Kernels are cached under
    /// `cache_dir` (default: the user cache, as the CLI), or nowhere with `kernel_cache=False`.
    #[new]
    #[pyo3(signature = (device = None, *, cache_dir = None, kernel_cache = true))]
    fn new(
        py: Python<'_>,
        device: Option<&Bound<'_, PyAny>>,
        cache_dir: Option<PathBuf>,
        kernel_cache: bool,
    ) -> PyResult<PyRenderer> {
        let query = match device {
            None => std::env::var("OCULAR_DEVICE").ok(),
            Some(d) => Some(d.str()?.to_string()),
        }
        .filter(|d| !d.trim().is_empty());
        let ctx = guarded(py, move || {
            Ok(Context::new(&ContextOptions {
                device: query,
                ..ContextOptions::default()
            })?)
        })?;
        let cache_dir = if kernel_cache {
            cache_dir.or_else(crate::psf::cache::default_cache_dir)
        } else {
            None
        };
        // two eye states kept (a binocular pair's): a script sweeping a parameter would
        // otherwise hold the GPU memory of several
        Ok(PyRenderer {
            live: LiveRenderer::new(ctx, cache_dir, 2),
            last_pair: std::sync::Mutex::new(None),
            headset_scene: std::sync::Mutex::new(None),
        })
    }

    /// The device's name and driver.
    #[getter]
    fn device(&self) -> String {
        self.live.device()
    }

    /// `color` (H, W, 3) float32 linear RGB and `depth` (H, W) float32 metres along the view
    /// axis (0 or inf: background) as `eye` sees them; returns (H, W, 3) float32.
    #[pyo3(signature = (eye, color, depth, *, fov_y_deg, focus_m = None, focus_d = None, focus_at = None, pupil_mm = None, luminance_cdm2 = None, age = 30.0, method = "splat", layers = 1, off_axis = false, exposure_ev = None, quality = "balanced"))]
    #[allow(clippy::too_many_arguments)]
    fn render<'py>(
        &self,
        py: Python<'py>,
        eye: &PyEye,
        color: &Bound<'py, PyAny>,
        depth: &Bound<'py, PyAny>,
        fov_y_deg: f64,
        focus_m: Option<f64>,
        focus_d: Option<f64>,
        focus_at: Option<(u32, u32)>,
        pupil_mm: Option<f64>,
        luminance_cdm2: Option<f64>,
        age: f64,
        method: &str,
        layers: u32,
        off_axis: bool,
        exposure_ev: Option<f64>,
        quality: &str,
    ) -> PyResult<Bound<'py, PyArray3<f32>>> {
        let o = options(
            focus_m,
            focus_d,
            focus_at,
            pupil_mm,
            luminance_cdm2,
            age,
            method,
            layers,
            off_axis,
            exposure_ev,
            quality,
        )
        .map_err(super::to_py)?;
        crate::limits::FOV_Y_DEG
            .check("--fov-y", fov_y_deg)
            .map_err(super::value_error)?;
        let colors = color_layers(color)?;
        let (width, height) = (colors.width, colors.height);
        let (depths, depth_warnings) = depth_layers(depth, (width, height, colors.layers.len()))?;
        let mut pairs = colors.layers.into_iter().zip(depths);
        let (first_color, first_depth) = pairs.next().expect("at least one layer");
        let frame = HostFrame {
            width,
            height,
            fov_y_deg,
            color: first_color,
            depth_m: first_depth,
            hidden: pairs.take(o.layers as usize - 1).collect(),
            scene: SceneEye::default(),
        };
        let eye = eye.eye.clone();
        let pixels = guarded(py, || Ok(self.live.render(&eye, &o, &frame)?.color))?;
        warn_all(py, &depth_warnings)?;
        self.warn_last(py)?;
        Ok(rgb_out(py, width, height, &pixels))
    }

    /// A shipped scene (`scenes()`) or a scene .toml file as `eye` sees it; returns
    /// (H, W, 3) float32 linear RGB. Focus and pupil default to the scene's.
    /// `headset` ("quest3" or "vive-pro", instead of `size`) renders at a headset's panel and
    /// vertical field (docs/binocular.md).
    #[pyo3(signature = (scene, eye, *, size = None, time_s = 0.0, focus_m = None, focus_d = None, focus_at = None, pupil_mm = None, luminance_cdm2 = None, age = 30.0, method = "splat", layers = 1, off_axis = false, exposure_ev = None, quality = "balanced", headset = None))]
    #[allow(clippy::too_many_arguments)]
    fn render_scene<'py>(
        &self,
        py: Python<'py>,
        scene: &str,
        eye: &PyEye,
        size: Option<(u32, u32)>,
        time_s: f64,
        focus_m: Option<f64>,
        focus_d: Option<f64>,
        focus_at: Option<(u32, u32)>,
        pupil_mm: Option<f64>,
        luminance_cdm2: Option<f64>,
        age: f64,
        method: &str,
        layers: u32,
        off_axis: bool,
        exposure_ev: Option<f64>,
        quality: &str,
        headset: Option<&str>,
    ) -> PyResult<Bound<'py, PyArray3<f32>>> {
        let headset = parse_headset(headset, size)?;
        let o = options(
            focus_m,
            focus_d,
            focus_at,
            pupil_mm,
            luminance_cdm2,
            age,
            method,
            layers,
            off_axis,
            exposure_ev,
            quality,
        )
        .map_err(super::to_py)?;
        let eye = eye.eye.clone();
        let (frame, warnings) = guarded(py, || match headset {
            Some(h) => {
                let seen = self.headset_scene(scene, h)?;
                let size = Some(h.spec().size());
                self.live
                    .render_scene(SceneArg::Loaded(&seen), &eye, &o, size, time_s)
            }
            None => self
                .live
                .render_scene(SceneArg::Name(scene), &eye, &o, size, time_s),
        })?;
        let (pixels, (w, h)) = (frame.color, (frame.report.width, frame.report.height));
        warn_all(py, &warnings)?;
        self.warn_last(py)?;
        Ok(rgb_out(py, w, h, &pixels))
    }

    /// A scene through two eyes (`ocular render --binocular`): `left` and `right` (None: the
    /// left eye for both) `ipd_mm` apart, converging on the focus point and sharing one
    /// accommodation and one pupil. Returns (left, right), each (H, W, 3) float32 linear RGB;
    /// `last_pair` says which eye drove accommodation and each eye's defocus.
    /// `headset` ("quest3" or "vive-pro", instead of `size`) renders each eye at a headset's
    /// panel and vertical field (docs/binocular.md).
    #[pyo3(signature = (scene, left, right = None, *, ipd_mm = 63.0, size = None, time_s = 0.0, focus_m = None, focus_d = None, focus_at = None, pupil_mm = None, luminance_cdm2 = None, age = 30.0, exposure_ev = None, quality = "balanced", headset = None))]
    #[allow(clippy::too_many_arguments)]
    fn render_scene_pair<'py>(
        &self,
        py: Python<'py>,
        scene: &str,
        left: &PyEye,
        right: Option<&PyEye>,
        ipd_mm: f64,
        size: Option<(u32, u32)>,
        time_s: f64,
        focus_m: Option<f64>,
        focus_d: Option<f64>,
        focus_at: Option<(u32, u32)>,
        pupil_mm: Option<f64>,
        luminance_cdm2: Option<f64>,
        age: f64,
        exposure_ev: Option<f64>,
        quality: &str,
        headset: Option<&str>,
    ) -> PyResult<Bound<'py, PyAny>> {
        let headset = parse_headset(headset, size)?;
        let o = options(
            focus_m,
            focus_d,
            focus_at,
            pupil_mm,
            luminance_cdm2,
            age,
            "splat",
            1,
            false,
            exposure_ev,
            quality,
        )
        .map_err(super::to_py)?;
        crate::render::binocular::check_ipd_mm(ipd_mm).map_err(super::value_error)?;
        let eyes = [
            left.eye.clone(),
            right.map_or_else(|| left.eye.clone(), |r| r.eye.clone()),
        ];
        let scene_name = scene.to_string();
        let pair = guarded(py, || {
            // the renderer's current scene: loaded once, its frames and geometry kept
            let (loaded, size) = match headset {
                Some(h) => {
                    let seen = self.headset_scene(&scene_name, h)?;
                    (self.live.scene(SceneArg::Loaded(&seen))?, h.spec().size())
                }
                None => {
                    let loaded = self.live.scene(SceneArg::Name(&scene_name))?;
                    let size = size.unwrap_or((loaded.resolution[0], loaded.resolution[1]));
                    (loaded, size)
                }
            };
            crate::render::binocular::render_pair(
                &self.live,
                &crate::render::binocular::PairRequest {
                    scene: &loaded,
                    eyes: [&eyes[0], &eyes[1]],
                    options: o.clone(),
                    corrections: Default::default(),
                    size,
                    time_s,
                    ipd_m: ipd_mm * 1e-3,
                },
            )
        })?;
        warn_all(py, &pair.warnings)?;
        let (w, h) = (pair.frames[0].report.width, pair.frames[0].report.height);
        let report = PairReport {
            driver: crate::render::binocular::SIDES[pair.yoke.driver],
            accommodation_d: pair.yoke.accommodation_d,
            focus_d: pair.yoke.focus_d,
            residual_d: pair.yoke.residual_d,
            far_point_d: pair.far_point_d,
            demand_d: pair.demand_d,
            pupil_mm: pair.pupil_mm,
        };
        *self.last_pair.lock().unwrap_or_else(|p| p.into_inner()) = Some(report);
        let out = (
            rgb_out(py, w, h, &pair.frames[0].color),
            rgb_out(py, w, h, &pair.frames[1].color),
        );
        Ok(out.into_pyobject(py)?.into_any())
    }

    /// How the last pair was rendered (`render_scene_pair`): the eye that drove accommodation
    /// ("left" or "right"), the shared response, and per eye (left, right) where it focused,
    /// its far point, its demand and its defocus at the target (D); None before the first.
    #[getter]
    fn last_pair<'py>(&self, py: Python<'py>) -> PyResult<Option<Bound<'py, PyDict>>> {
        let Some(r) = *self.last_pair.lock().unwrap_or_else(|p| p.into_inner()) else {
            return Ok(None);
        };
        let d = PyDict::new(py);
        d.set_item("driver", r.driver)?;
        d.set_item("accommodation_d", r.accommodation_d)?;
        d.set_item("focus_d", r.focus_d.to_vec())?;
        d.set_item("residual_d", r.residual_d.to_vec())?;
        d.set_item("far_point_d", r.far_point_d.to_vec())?;
        d.set_item("demand_d", r.demand_d.to_vec())?;
        d.set_item("pupil_mm", r.pupil_mm)?;
        Ok(Some(d))
    }

    /// Rasterises a scene: (color (H, W, 3) float32 linear RGB, depth (H, W) float32 metres
    /// along the view axis, +inf for the background, fov_y_deg) — what `render` takes.
    #[pyo3(signature = (scene, *, size = None, time_s = 0.0))]
    fn rasterize<'py>(
        &self,
        py: Python<'py>,
        scene: &str,
        size: Option<(u32, u32)>,
        time_s: f64,
    ) -> PyResult<Bound<'py, PyAny>> {
        let (frame, warnings) = guarded(py, || {
            self.live
                .scene_frame(SceneArg::Name(scene), None, size, time_s)
        })?;
        warn_all(py, &warnings)?;
        let color = rgb_out(py, frame.width, frame.height, &frame.color);
        let depth = super::arrays::gray_out(
            py,
            frame.width as usize,
            frame.height as usize,
            frame.depth_m,
        );
        Ok((color, depth, frame.fov_y_deg)
            .into_pyobject(py)?
            .into_any())
    }

    /// How the last frame was rendered (focus and pupil and where they came from, seconds,
    /// whether the kernels were reused), or None before the first.
    #[getter]
    fn last_frame<'py>(&self, py: Python<'py>) -> PyResult<Option<Bound<'py, PyDict>>> {
        let Some(r) = self.live.last() else {
            return Ok(None);
        };
        let d = PyDict::new(py);
        d.set_item("focus_d", r.focus_d)?;
        d.set_item("focus_from", &r.focus_from)?;
        d.set_item("focus_reached_d", r.focus.actual_d)?;
        d.set_item("far_point_d", r.far_point_d)?;
        d.set_item("pupil_mm", r.pupil_mm)?;
        d.set_item("pupil_from", &r.pupil_from)?;
        d.set_item("method", r.method)?;
        d.set_item("quality", r.quality)?;
        d.set_item("seconds", r.seconds_render)?;
        d.set_item("seconds_kernels", r.seconds_kernels)?;
        d.set_item("kernels_reused", r.kernels_reused)?;
        d.set_item("accommodation_max_d", r.physiology.accommodation_max_d)?;
        Ok(Some(d))
    }

    /// Frames rendered and kernel preparations made by this renderer.
    #[getter]
    fn stats<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let counters = self.live.counters();
        let d = PyDict::new(py);
        d.set_item("frames", counters.frames)?;
        d.set_item("kernel_preparations", counters.kernel_preparations)?;
        Ok(d)
    }

    fn __repr__(&self) -> String {
        format!("<ocular_render.Renderer on {}>", self.device())
    }
}

impl PyRenderer {
    fn warn_last(&self, py: Python<'_>) -> PyResult<()> {
        let warnings = self.live.last().map(|r| r.warnings).unwrap_or_default();
        warn_all(py, &warnings)
    }
}

/// The shipped scenes `render_scene` and `rasterize` know by name.
#[pyfunction]
pub fn scenes() -> Vec<&'static str> {
    Scene::builtin_names()
}
