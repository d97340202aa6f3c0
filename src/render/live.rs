//! `LiveRenderer`: one Vulkan device and what it keeps between frames, for the front doors
//! that render many frames in one process (the Python `Renderer`, `ocular serve`). It keeps
//! the rasteriser, the loaded scene, the last host frames and the prepared kernels of the
//! most recent eye states (`FrameRenderer`: kernels, pipelines, PSF texture), each reused while
//! its eye, focus, pupil, screen and settings hold and the frame's depth range lies inside the
//! planned one (the same kernel grid). Focus and pupil are resolved as `ocular render`
//! resolves them, with the same messages.

use std::path::PathBuf;
use std::sync::{Arc, Mutex};
use std::time::Instant;

use crate::eye::age::HofstetterLine;
use crate::eye::Eye;
use crate::gpu::Context;
use crate::psf::axes::GridAxes;
use crate::render::focus::{effective_focus, FocusOutcome};
use crate::render::frame::{EyeState, FrameRenderer, HostFrame, KernelOptions, Method};
use crate::render::frame_plan::{
    self, Correction, FocusAsked, Physiology, PupilAsked, PupilFallback, PupilModel, SceneEye,
};
use crate::render::splat::{Quality, SplatSettings};
use crate::render::Rasterizer;
use crate::scene::Camera;
use crate::scene::Scene;
use crate::{Error, Result};

/// One frame's options, already checked (each front door parses its own spelling of them).
#[derive(Clone, Debug)]
pub struct LiveOptions {
    /// `--focus-m`, `--focus-d` or `--focus-at`; None: the scene's, else the frame's centre.
    pub focus: Option<FocusAsked>,
    pub pupil_mm: Option<f64>,
    /// Adapting luminance for the pupil model (None: the scene's, else the frame's mean).
    pub luminance_cdm2: Option<f64>,
    pub age: f64,
    pub method: Method,
    pub layers: u32,
    pub off_axis: bool,
    /// The exposure the image will be shown at (EV; None: the frame's automatic one).
    pub exposure_ev: Option<f64>,
    pub quality: Quality,
    /// Spectacle, contact lens or IOL, and the amplitude of accommodation asked.
    pub correction: Correction,
}

impl Default for LiveOptions {
    /// `ocular render`'s defaults: a 30-year-old's eye through splat at `balanced`.
    fn default() -> LiveOptions {
        LiveOptions {
            focus: None,
            pupil_mm: None,
            luminance_cdm2: None,
            age: 30.0,
            method: Method::Splat,
            layers: 1,
            off_axis: false,
            exposure_ev: None,
            quality: Quality::default(),
            correction: Correction::default(),
        }
    }
}

/// How one frame was rendered: what `ocular render` prints, for a live front door.
#[derive(Clone, Debug, serde::Serialize)]
pub struct FrameReport {
    pub width: u32,
    pub height: u32,
    /// The focus asked (D; 0 = infinity) and the words naming where it came from.
    pub focus_d: f64,
    pub focus_from: String,
    /// Where the eye actually focuses: the request, or its far or near point.
    pub focus: FocusOutcome,
    /// The eye's far point (D; 0 = infinity or beyond), relaxed, at this pupil.
    pub far_point_d: f64,
    pub pupil_mm: f64,
    pub pupil_from: String,
    #[serde(flatten)]
    pub physiology: Physiology,
    pub method: &'static str,
    pub quality: &'static str,
    /// The exposure the frame is shown at (EV): the one asked, else the scene's automatic one.
    pub exposure_ev: f32,
    pub seconds_render: f64,
    pub kernels_reused: bool,
    /// Planning, loading or computing the kernels of a new eye state (0 when reused).
    pub seconds_kernels: f64,
    /// PSFs computed for these kernels (0 when reused or loaded from the disk cache).
    pub psfs_computed: usize,
    pub warnings: Vec<String>,
}

/// The scene of a frame: one `Scene::load` finds (a built-in's name or a file's path), or one
/// loaded already (a front door that must not open paths its clients name).
#[derive(Clone, Copy)]
pub enum SceneArg<'a> {
    Name(&'a str),
    Loaded(&'a Arc<Scene>),
}

/// The scene frames are drawn from, and the name that loaded it (None: given loaded).
struct CurrentScene {
    named: Option<String>,
    scene: Arc<Scene>,
}

/// A rendered frame: linear RGBA and how it was made.
pub struct LiveFrame {
    pub color: Vec<[f32; 4]>,
    pub report: FrameReport,
}

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
    axes: GridAxes,
    focus: FocusOutcome,
    far_point_d: f64,
    renderer: FrameRenderer,
}

/// Frames rendered and kernel preparations made.
#[derive(Clone, Copy, Debug, Default, serde::Serialize)]
pub struct Counters {
    pub frames: u64,
    pub kernel_preparations: u64,
}

/// Scene id, time (bits), size, spectacle magnification and camera (bits) of a host frame.
type HostKey = (
    u64,
    u64,
    (u32, u32),
    Option<[[f64; 2]; 2]>,
    Option<[u64; 7]>,
);

/// A camera as exact bits, for cache keys.
fn camera_bits(c: Camera) -> [u64; 7] {
    [
        c.position_m[0],
        c.position_m[1],
        c.position_m[2],
        c.yaw_deg,
        c.pitch_deg,
        c.fov_y_deg,
        c.near_m,
    ]
    .map(f64::to_bits)
}

/// Host frames kept: a preview and a full frame, for each of two eyes in a comparison.
const HOST_FRAMES_KEPT: usize = 4;

struct Inner {
    /// Most recently used last.
    prepared: Vec<Prepared>,
    rasterizer: Option<Rasterizer>,
    scene: Option<CurrentScene>,
    /// The last scene frames drawn to the host, by what drew them (most recent last): a scene
    /// rendered again at the same time, size and magnification is not drawn to the host again
    /// (splat draws it in its own submission anyway).
    host: Vec<(HostKey, HostFrame, Vec<String>)>,
    counters: Counters,
    last: Option<FrameReport>,
}

/// Renders frames and scenes as eyes see them on one device, keeping the kernels of the
/// `kept_states` most recent eye states.
pub struct LiveRenderer {
    // Declared (and so dropped) before the device its GPU objects belong to.
    inner: Mutex<Inner>,
    ctx: Context,
    cache_dir: Option<PathBuf>,
    kept_states: usize,
}

/// The eye as the CLI renders it: `correction` applied and its accommodation limited by `age`
/// (Hofstetter's mean line) unless the correction or its file sets an amplitude.
pub fn physiology(eye: &Eye, o: &LiveOptions) -> Result<(Eye, Physiology)> {
    frame_plan::corrected_eye(eye, &o.correction, Some((o.age, HofstetterLine::Mean)))
}

/// The pupil as `ocular render` picks it: given, else Watson–Yellott at the luminance given,
/// the scene's pupil or luminance, or the frame's mean luminance.
pub fn pupil_diameter(o: &LiveOptions, f: &HostFrame) -> Result<(f64, String)> {
    let asked = PupilAsked {
        given_mm: o.pupil_mm,
        luminance_cdm2: o.luminance_cdm2.map(|l| (l, "--luminance-cdm2")),
        model: PupilModel::WatsonYellott,
        age_years: o.age,
        fallback: PupilFallback::Luminance,
    };
    f.pupil_mm(&asked)
}

impl LiveRenderer {
    pub fn new(ctx: Context, cache_dir: Option<PathBuf>, kept_states: usize) -> LiveRenderer {
        LiveRenderer {
            ctx,
            cache_dir,
            kept_states: kept_states.max(1),
            inner: Mutex::new(Inner {
                prepared: Vec::new(),
                rasterizer: None,
                scene: None,
                host: Vec::new(),
                counters: Counters::default(),
                last: None,
            }),
        }
    }

    pub fn context(&self) -> &Context {
        &self.ctx
    }

    /// The device, once everything made on it is gone (a test checks its validation log).
    pub fn into_context(self) -> Context {
        let LiveRenderer { inner, ctx, .. } = self;
        drop(inner);
        ctx
    }

    /// The device's name and driver.
    pub fn device(&self) -> String {
        let info = self.ctx.device_info();
        format!("{} ({})", info.name, info.driver)
    }

    pub fn counters(&self) -> Counters {
        self.lock().counters
    }

    /// How the last frame was rendered, or None before the first.
    pub fn last(&self) -> Option<FrameReport> {
        self.lock().last.clone()
    }

    fn lock(&self) -> std::sync::MutexGuard<'_, Inner> {
        self.inner.lock().unwrap_or_else(|p| p.into_inner())
    }

    fn kernel_options(&self, o: &LiveOptions, width: u32) -> KernelOptions {
        KernelOptions {
            cache_dir: self.cache_dir.clone(),
            field_width_px: o.off_axis.then_some(width),
            ..KernelOptions::default()
        }
    }

    /// `frame` (colour and depth from elsewhere) as `eye` sees it with options `o`.
    pub fn render(&self, eye: &Eye, o: &LiveOptions, frame: &HostFrame) -> Result<LiveFrame> {
        let (eye, physiology) = physiology(eye, o)?;
        self.render_corrected(&eye, physiology, o, frame, None)
    }

    /// A scene (a built-in's name or a scene file's path) as `eye` sees it; `size` None: the
    /// scene's own resolution. Returns the frame and what the scene's drawing warned of.
    pub fn render_scene(
        &self,
        scene: SceneArg<'_>,
        eye: &Eye,
        o: &LiveOptions,
        size: Option<(u32, u32)>,
        time_s: f64,
    ) -> Result<(LiveFrame, Vec<String>)> {
        self.render_scene_from(scene, eye, o, size, time_s, None)
    }

    /// [`render_scene`](Self::render_scene) from `camera` instead of the scene's own (an eye
    /// of a binocular pair: `render::binocular`).
    pub fn render_scene_from(
        &self,
        scene: SceneArg<'_>,
        eye: &Eye,
        o: &LiveOptions,
        size: Option<(u32, u32)>,
        time_s: f64,
        camera: Option<Camera>,
    ) -> Result<(LiveFrame, Vec<String>)> {
        let (eye, physiology) = physiology(eye, o)?;
        let (frame, warnings) = self.scene_frame_from(
            scene,
            physiology.spectacle_magnification,
            size,
            time_s,
            camera,
        )?;
        let id = self.scene(scene)?.id();
        let live =
            self.render_corrected(&eye, physiology, o, &frame, Some((id, time_s, camera)))?;
        Ok((live, warnings))
    }

    /// Resolves focus and pupil, finds or prepares the kernels, and renders: from the host
    /// frame, or (a scene through splat) drawn again within splat's own submission.
    fn render_corrected(
        &self,
        eye: &Eye,
        physiology: Physiology,
        o: &LiveOptions,
        frame: &HostFrame,
        scene: Option<(u64, f64, Option<Camera>)>,
    ) -> Result<LiveFrame> {
        let (focus_d, focus_from) = frame.focus_d(o.focus)?;
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
        let mut inner = self.lock();
        let found = inner
            .prepared
            .iter()
            .position(|p| p.key == key && p.axes == planned.axes);
        let mut warnings = Vec::new();
        let kernels_started = Instant::now();
        let mut psfs_computed = 0;
        let prepared = match found {
            Some(i) => inner.prepared.remove(i),
            None => {
                // Fails, with the options named, where the eye cannot focus at all.
                let focus =
                    effective_focus(eye, focus_d, pupil_mm, &options.settings, &focus_from)?;
                let far_point_d =
                    effective_focus(eye, 0.0, pupil_mm, &options.settings, "the far point")?
                        .actual_d;
                let kernels = crate::render::frame::prepare_kernels(eye, &needs, &options)?;
                warnings.extend(kernels.warnings.iter().cloned());
                psfs_computed = kernels.report.as_ref().map_or(0, |r| r.psfs_computed);
                let axes = kernels.plan.axes.clone();
                let renderer = FrameRenderer::new(
                    &self.ctx,
                    eye.clone(),
                    kernels,
                    options.settings.clone(),
                    key.splat,
                );
                inner.counters.kernel_preparations += 1;
                Prepared {
                    key,
                    axes,
                    focus,
                    far_point_d,
                    renderer,
                }
            }
        };
        let seconds_kernels = if found.is_some() {
            0.0
        } else {
            kernels_started.elapsed().as_secs_f64()
        };
        if inner.prepared.len() >= self.kept_states {
            // the least recently used first: its GPU memory goes before the next is made
            inner.prepared.remove(0);
        }
        inner.prepared.push(prepared);
        let Inner {
            prepared,
            rasterizer,
            scene: loaded,
            ..
        } = &mut *inner;
        let prepared = prepared.last_mut().expect("pushed above");
        let (focus, far_point_d) = (prepared.focus, prepared.far_point_d);
        let renderer = &mut prepared.renderer;
        // The merge's colour bound is a fraction of the white the frame is shown at: the
        // exposure given, else its automatic one, as `ocular render` writes it.
        let exposure_ev = o.exposure_ev.map_or_else(
            || crate::image_io::Tonemap::auto_exposure_ev_of(&frame.color),
            |ev| ev as f32,
        );
        renderer.set_display_white(crate::render::splat::display_white(exposure_ev));
        let rendered = match (scene, rasterizer.as_mut(), loaded.as_ref()) {
            (Some((id, time_s, camera)), Some(raster), Some(CurrentScene { scene, .. }))
                if o.method == Method::Splat && scene.id() == id =>
            {
                let gap_d = crate::render::blend::DEFAULT_GROUP_TOLERANCE_D;
                let mut scene_state = scene.at_time(time_s);
                if let Some(c) = camera {
                    scene_state.camera = c;
                }
                // the magnification the host frame was drawn with
                raster.set_view_magnification(
                    physiology
                        .spectacle_magnification
                        .unwrap_or([[1.0, 0.0], [0.0, 1.0]]),
                );
                let mut recorded = raster
                    .scene_frame(&self.ctx, &scene_state, (frame.width, frame.height))
                    .peeled(o.layers, gap_d);
                renderer.render_recorded(&mut recorded, state)?
            }
            _ => frame.render(renderer, state, o.method)?,
        };
        inner.counters.frames += 1;
        let report = FrameReport {
            width: frame.width,
            height: frame.height,
            focus_d,
            focus_from,
            focus,
            far_point_d,
            pupil_mm,
            pupil_from,
            physiology,
            method: o.method.name(),
            quality: o.quality.name(),
            exposure_ev,
            seconds_render: rendered.seconds,
            kernels_reused: found.is_some(),
            seconds_kernels,
            psfs_computed,
            warnings,
        };
        inner.last = Some(report.clone());
        Ok(LiveFrame {
            color: rendered.color,
            report,
        })
    }

    /// The scene `arg` names, loaded on first use and kept while it stays the current one
    /// (host frames and uploaded geometry follow it).
    pub fn scene(&self, arg: SceneArg<'_>) -> Result<Arc<Scene>> {
        let mut inner = self.lock();
        let current = match (&inner.scene, arg) {
            (Some(c), SceneArg::Name(n)) => c.named.as_deref() == Some(n),
            (Some(c), SceneArg::Loaded(s)) => c.scene.id() == s.id(),
            (None, _) => false,
        };
        if !current {
            let (named, scene) = match arg {
                SceneArg::Name(n) => (Some(n.to_string()), Arc::new(Scene::load(n)?)),
                SceneArg::Loaded(s) => (None, Arc::clone(s)),
            };
            inner.scene = Some(CurrentScene { named, scene });
            inner.host.clear();
        }
        Ok(Arc::clone(&inner.scene.as_ref().expect("set above").scene))
    }

    /// The scene's layer 0 on the host (for depth range, focus and pupil, and the methods
    /// that read pixels), drawn through the spectacle `magnification`.
    pub fn scene_frame(
        &self,
        scene: SceneArg<'_>,
        magnification: Option<[[f64; 2]; 2]>,
        size: Option<(u32, u32)>,
        time_s: f64,
    ) -> Result<(HostFrame, Vec<String>)> {
        self.scene_frame_from(scene, magnification, size, time_s, None)
    }

    /// [`scene_frame`](Self::scene_frame) from `camera` instead of the scene's own.
    pub fn scene_frame_from(
        &self,
        scene: SceneArg<'_>,
        magnification: Option<[[f64; 2]; 2]>,
        size: Option<(u32, u32)>,
        time_s: f64,
        camera: Option<Camera>,
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
        let loaded = self.scene(scene)?;
        let mut inner = self.lock();
        let scene_resolution = loaded.resolution;
        let size_px = size.unwrap_or((scene_resolution[0], scene_resolution[1]));
        let host_key: HostKey = (
            loaded.id(),
            time_s.to_bits(),
            size_px,
            magnification,
            camera.map(camera_bits),
        );
        if let Some(i) = inner.host.iter().position(|(k, _, _)| *k == host_key) {
            let kept = inner.host.remove(i);
            let out = (kept.1.clone(), kept.2.clone());
            inner.host.push(kept);
            return Ok(out);
        }
        if inner.rasterizer.is_none() {
            inner.rasterizer = Some(Rasterizer::new(&self.ctx)?);
        }
        let (raster, scene) = (inner.rasterizer.as_mut().expect("made above"), &loaded);
        raster.set_view_magnification(magnification.unwrap_or([[1.0, 0.0], [0.0, 1.0]]));
        let mut state = scene.at_time(time_s);
        if let Some(c) = camera {
            state.camera = c;
        }
        let (width, height) = size_px;
        let drawn = raster.render(&self.ctx, &state, width, height)?;
        let mut depth_m = drawn.depth_m;
        let warnings: Vec<String> =
            frame_plan::clamp_near_depth(&mut depth_m, &format!("scene {}", scene.name))
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
        if inner.host.len() >= HOST_FRAMES_KEPT {
            inner.host.remove(0);
        }
        inner.host.push((host_key, frame.clone(), warnings.clone()));
        Ok((frame, warnings))
    }
}
