//! `Renderer`: one Vulkan device and what it keeps between frames — the rasteriser, and the
//! kernels, pipelines and PSF texture of the current eye state (`FrameRenderer`), reused
//! while the eye, focus, pupil, screen and settings hold and the frame's depth range lies
//! inside the planned one (the same kernel grid). The eye, focus and pupil are resolved as
//! `ocular render` resolves them, with the same messages ([`super::frame_options`]).

use std::path::PathBuf;
use std::sync::Mutex;

use numpy::PyArray3;
use pyo3::prelude::*;
use pyo3::types::PyDict;

use super::arrays::{color_layers, depth_layers, rgb_out};
use super::eye::PyEye;
use super::frame_options::{focus_dioptres, options, physiology, pupil_diameter, Options};
use super::guarded;
use crate::eye::Eye;
use crate::gpu::{Context, ContextOptions};
use crate::render::frame::{EyeState, FrameRenderer, HostFrame, KernelOptions, Method};
use crate::render::frame_plan::SceneEye;
use crate::render::splat::SplatSettings;
use crate::render::Rasterizer;
use crate::scene::Scene;
use crate::{Error, Result};

/// What makes kernels and the splatter reusable from one frame to the next.
#[derive(Clone, PartialEq)]
struct Key {
    eye: Eye,
    state: EyeState,
    fov_y_deg: f64,
    height_px: u32,
    field_width_px: Option<u32>,
    splat: SplatSettings,
}

struct Prepared {
    key: Key,
    /// The grid the kernels were planned on: a frame whose own plan is the same grid would
    /// get these very kernels.
    axes: crate::psf::axes::GridAxes,
    /// Where the eye actually focuses (D): traced once per eye state.
    focus_reached_d: f64,
    renderer: FrameRenderer,
}

#[derive(Default)]
struct Counters {
    frames: u64,
    kernel_preparations: u64,
}

struct Inner {
    prepared: Option<Prepared>,
    rasterizer: Option<Rasterizer>,
    scene: Option<(String, Scene)>,
    /// The last scene frame drawn to the host, by what drew it: a scene rendered again at the
    /// same time, size and magnification is not drawn to the host again (splat draws it in
    /// its own submission anyway).
    host: Option<(HostKey, HostFrame, Vec<String>)>,
    counters: Counters,
    last: Option<FrameReport>,
}

/// How one frame was rendered, for `Renderer.last_frame`.
#[derive(Clone)]
struct FrameReport {
    focus_d: f64,
    focus_from: String,
    focus_reached_d: f64,
    pupil_mm: f64,
    pupil_from: String,
    method: Method,
    seconds: f64,
    kernels_reused: bool,
    /// Planning, loading or computing the kernels of a new eye state (0 when reused).
    seconds_kernels: f64,
    accommodation_max_d: Option<f64>,
    warnings: Vec<String>,
}

/// Renders colour + depth frames (and scenes) as an eye sees them on one Vulkan device.
#[pyclass(name = "Renderer", module = "ocular_render")]
pub struct PyRenderer {
    ctx: Context,
    cache_dir: Option<PathBuf>,
    inner: Mutex<Inner>,
}

/// Scene name, time (bits), size and spectacle magnification of a host frame.
type HostKey = (String, u64, (u32, u32), Option<[[f64; 2]; 2]>);

impl PyRenderer {
    fn kernel_options(&self, o: &Options, width: u32) -> KernelOptions {
        KernelOptions {
            cache_dir: self.cache_dir.clone(),
            field_width_px: o.off_axis.then_some(width),
            ..KernelOptions::default()
        }
    }

    /// Resolves focus and pupil, finds or prepares the kernels, and renders: from the host
    /// frame, or (a scene through splat) drawn again within splat's own submission.
    fn render_frame(
        &self,
        eye: &Eye,
        o: &Options,
        frame: &HostFrame,
        scene: Option<(&str, f64)>,
    ) -> Result<Vec<[f32; 4]>> {
        let (eye, physiology) = physiology(eye, o.age)?;
        let (focus_d, focus_from) = focus_dioptres(o, frame)?;
        let (pupil_mm, pupil_from) = pupil_diameter(o, frame)?;
        let options = self.kernel_options(o, frame.width);
        let state = EyeState { focus_d, pupil_mm };
        let key = Key {
            eye: eye.clone(),
            state,
            fov_y_deg: frame.fov_y_deg,
            height_px: frame.height,
            field_width_px: options.field_width_px,
            splat: o.quality.settings(),
        };
        let needs = frame.needs(state);
        let planned = crate::psf::plan::plan_for_scene(&needs, &options.reference_for(&needs))
            .map_err(Error::input)?;
        let mut inner = self.inner.lock().unwrap_or_else(|p| p.into_inner());
        let reusable = inner
            .prepared
            .as_ref()
            .is_some_and(|p| p.key == key && p.axes == planned.axes);
        let mut warnings = Vec::new();
        let kernels_started = std::time::Instant::now();
        if !reusable {
            inner.prepared = None;
            // Fails, with the options named, where the eye cannot focus at all.
            let focus = crate::render::focus::effective_focus(
                &eye,
                focus_d,
                pupil_mm,
                &options.settings,
                &focus_from,
            )?;
            let kernels = crate::render::frame::prepare_kernels(&eye, &needs, &options)?;
            warnings.extend(kernels.warnings.iter().cloned());
            let axes = kernels.plan.axes.clone();
            let renderer =
                FrameRenderer::new(&self.ctx, eye, kernels, options.settings.clone(), key.splat);
            inner.counters.kernel_preparations += 1;
            inner.prepared = Some(Prepared {
                key,
                axes,
                focus_reached_d: focus.actual_d,
                renderer,
            });
        }
        let seconds_kernels = if reusable {
            0.0
        } else {
            kernels_started.elapsed().as_secs_f64()
        };
        let Inner {
            prepared,
            rasterizer,
            scene: loaded,
            ..
        } = &mut *inner;
        let prepared = prepared.as_mut().expect("prepared above");
        let focus_reached_d = prepared.focus_reached_d;
        let renderer = &mut prepared.renderer;
        // The merge's colour bound is a fraction of the white the frame is shown at: the
        // exposure given, else its automatic one, as `ocular render` writes it.
        let exposure_ev = o.exposure_ev.map_or_else(
            || crate::image_io::Tonemap::auto_exposure_ev_of(&frame.color),
            |ev| ev as f32,
        );
        renderer.set_display_white(crate::render::splat::display_white(exposure_ev));
        let rendered = match (scene, rasterizer.as_mut(), loaded.as_ref()) {
            (Some((_, time_s)), Some(raster), Some((_, scene))) if o.method == Method::Splat => {
                let gap_d = crate::render::blend::DEFAULT_GROUP_TOLERANCE_D;
                let scene_state = scene.at_time(time_s);
                let mut recorded = raster
                    .scene_frame(&self.ctx, &scene_state, (frame.width, frame.height))
                    .peeled(o.layers, gap_d);
                renderer.render_recorded(&mut recorded, state)?
            }
            _ => frame.render(renderer, state, o.method)?,
        };
        inner.counters.frames += 1;
        inner.last = Some(FrameReport {
            focus_d,
            focus_from,
            focus_reached_d,
            pupil_mm,
            pupil_from,
            method: o.method,
            seconds: rendered.seconds,
            kernels_reused: reusable,
            seconds_kernels,
            accommodation_max_d: physiology.accommodation_max_d,
            warnings,
        });
        Ok(rendered.color)
    }

    /// The scene's layer 0 on the host (for depth range, focus and pupil, and the methods
    /// that read pixels), drawn through the eye's spectacle magnification.
    fn scene_frame(
        &self,
        name: &str,
        eye: Option<&Eye>,
        size: Option<(u32, u32)>,
        time_s: f64,
    ) -> Result<(HostFrame, Vec<String>)> {
        if !(time_s.is_finite() && time_s >= 0.0) {
            return Err(Error::input(format!(
                "--time {time_s} must be a non-negative number of seconds"
            )));
        }
        if let Some((w, h)) = size {
            if !(1..=16384).contains(&w) || !(1..=16384).contains(&h) {
                return Err(Error::input(format!(
                    "--size {w}x{h}: each side must be 1 to 16384 pixels"
                )));
            }
        }
        let magnification = match eye {
            Some(e) => crate::render::frame_plan::spectacle_magnification(e)?,
            None => None,
        };
        let mut inner = self.inner.lock().unwrap_or_else(|p| p.into_inner());
        if inner.scene.as_ref().is_none_or(|(n, _)| n != name) {
            inner.scene = Some((name.to_string(), Scene::load(name)?));
            inner.host = None;
        }
        let scene_resolution = inner.scene.as_ref().expect("loaded above").1.resolution;
        let size_px = size.unwrap_or((scene_resolution[0], scene_resolution[1]));
        let host_key: HostKey = (name.to_string(), time_s.to_bits(), size_px, magnification);
        if let Some((key, frame, warnings)) = &inner.host {
            if *key == host_key {
                return Ok((frame.clone(), warnings.clone()));
            }
        }
        if inner.rasterizer.is_none() {
            inner.rasterizer = Some(Rasterizer::new(&self.ctx)?);
        }
        let Inner {
            rasterizer, scene, ..
        } = &mut *inner;
        let (raster, scene) = (
            rasterizer.as_mut().expect("made above"),
            &scene.as_ref().expect("loaded above").1,
        );
        raster.set_view_magnification(magnification.unwrap_or([[1.0, 0.0], [0.0, 1.0]]));
        let state = scene.at_time(time_s);
        let (width, height) = size_px;
        let drawn = raster.render(&self.ctx, &state, width, height)?;
        let mut depth_m = drawn.depth_m;
        let warnings: Vec<String> =
            crate::render::frame_plan::clamp_near_depth(&mut depth_m, &format!("scene {name}"))
                .into_iter()
                .collect();
        let frame = HostFrame {
            width,
            height,
            fov_y_deg: state.camera.fov_y_deg,
            color: drawn.color,
            depth_m,
            hidden: Vec::new(),
            scene: SceneEye::of(&state),
        };
        inner.host = Some((host_key, frame.clone(), warnings.clone()));
        Ok((frame, warnings))
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
        Ok(PyRenderer {
            ctx,
            cache_dir,
            inner: Mutex::new(Inner {
                prepared: None,
                rasterizer: None,
                scene: None,
                host: None,
                counters: Counters::default(),
                last: None,
            }),
        })
    }

    /// The device's name and driver.
    #[getter]
    fn device(&self) -> String {
        let info = self.ctx.device_info();
        format!("{} ({})", info.name, info.driver)
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
        let pixels = guarded(py, || self.render_frame(&eye, &o, &frame, None))?;
        warn_all(py, &depth_warnings)?;
        self.warn_last(py)?;
        Ok(rgb_out(py, width, height, &pixels))
    }

    /// A shipped scene (`scenes()`) or a scene .toml file as `eye` sees it; returns
    /// (H, W, 3) float32 linear RGB. Focus and pupil default to the scene's.
    #[pyo3(signature = (scene, eye, *, size = None, time_s = 0.0, focus_m = None, focus_d = None, focus_at = None, pupil_mm = None, luminance_cdm2 = None, age = 30.0, method = "splat", layers = 1, off_axis = false, exposure_ev = None, quality = "balanced"))]
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
        let eye = eye.eye.clone();
        let (pixels, (w, h), warnings) = guarded(py, || {
            let (with_age, _) = physiology(&eye, o.age)?;
            let (frame, warnings) = self.scene_frame(scene, Some(&with_age), size, time_s)?;
            let pixels = self.render_frame(&eye, &o, &frame, Some((scene, time_s)))?;
            Ok((pixels, (frame.width, frame.height), warnings))
        })?;
        warn_all(py, &warnings)?;
        self.warn_last(py)?;
        Ok(rgb_out(py, w, h, &pixels))
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
        let (frame, warnings) = guarded(py, || self.scene_frame(scene, None, size, time_s))?;
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
        let inner = self.inner.lock().unwrap_or_else(|p| p.into_inner());
        let Some(r) = &inner.last else {
            return Ok(None);
        };
        let d = PyDict::new(py);
        d.set_item("focus_d", r.focus_d)?;
        d.set_item("focus_from", &r.focus_from)?;
        d.set_item("focus_reached_d", r.focus_reached_d)?;
        d.set_item("pupil_mm", r.pupil_mm)?;
        d.set_item("pupil_from", &r.pupil_from)?;
        d.set_item("method", r.method.name())?;
        d.set_item("seconds", r.seconds)?;
        d.set_item("seconds_kernels", r.seconds_kernels)?;
        d.set_item("kernels_reused", r.kernels_reused)?;
        d.set_item("accommodation_max_d", r.accommodation_max_d)?;
        Ok(Some(d))
    }

    /// Frames rendered and kernel preparations made by this renderer.
    #[getter]
    fn stats<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let inner = self.inner.lock().unwrap_or_else(|p| p.into_inner());
        let d = PyDict::new(py);
        d.set_item("frames", inner.counters.frames)?;
        d.set_item("kernel_preparations", inner.counters.kernel_preparations)?;
        Ok(d)
    }

    fn __repr__(&self) -> String {
        format!("<ocular_render.Renderer on {}>", self.device())
    }
}

impl PyRenderer {
    fn warn_last(&self, py: Python<'_>) -> PyResult<()> {
        let warnings = {
            let inner = self.inner.lock().unwrap_or_else(|p| p.into_inner());
            inner
                .last
                .as_ref()
                .map(|r| r.warnings.clone())
                .unwrap_or_default()
        };
        warn_all(py, &warnings)
    }
}

/// The shipped scenes `render_scene` and `rasterize` know by name.
#[pyfunction]
pub fn scenes() -> Vec<&'static str> {
    Scene::builtin_names()
}
