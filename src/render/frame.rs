//! One frame from start to finish: what the frame needs from the eye (planned and cached
//! kernels), and one of the three rendering methods over a colour + depth input. The CLI's
//! `render`, `compare`, `video` and `bench` all go through here.

use std::path::PathBuf;
use std::time::Instant;

use crate::eye::Eye;
use crate::gpu::{Context, Timings};
use crate::psf::axes::{GridAxes, KernelSettings, Screen};
use crate::psf::cache::{self, CacheOutcome};
use crate::psf::exact::{ExactEye, ExactFieldEye};
use crate::psf::field_kernels::{compute_kernel_field, KernelField};
use crate::psf::field_plan::{plan_for_frame, FieldPlan};
use crate::psf::grid::{compute_grid, GridReport, Stage};
use crate::psf::kernels::KernelGrid;
use crate::psf::plan::{plan_for_scene, Plan, SceneNeeds};
use crate::render::blend::BlendSettings;
use crate::render::frame_plan::{self, FocusAsked, FrameView, PupilAsked, SceneEye};
use crate::render::splat::{
    FrameInput, HiddenLayer, RecordedInput, SplatSettings, SplatStats, Splatter, ViewState,
};
use crate::render::{reference, slices};
use crate::{Error, Result};

/// How a frame is rendered.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize, clap::ValueEnum)]
#[serde(rename_all = "lowercase")]
pub enum Method {
    /// Tiled PSF splatting on the GPU (the product).
    Splat,
    /// Exact per-pixel PSFs on the CPU (the ground truth; slow).
    Reference,
    /// Depth slices convolved with their centre PSF (the classic previous method).
    Slices,
    /// Multi-view accumulation over the pupil (geometric optics, sees hidden surfaces; scenes
    /// only).
    Views,
}

impl Method {
    pub fn name(self) -> &'static str {
        match self {
            Method::Splat => "splat",
            Method::Reference => "reference",
            Method::Slices => "slices",
            Method::Views => "views",
        }
    }
}

/// The eye's state for one frame: where it focuses and how wide its pupil is.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct EyeState {
    pub focus_d: f64,
    pub pupil_mm: f64,
}

/// Where kernels come from and how they are computed.
#[derive(Clone)]
pub struct KernelOptions {
    pub settings: KernelSettings,
    /// The grid whose spacing planned axes follow (the seed paper's by default).
    pub reference_axes: GridAxes,
    /// None: no cache.
    pub cache_dir: Option<PathBuf>,
    /// Told the stage and count as kernels are computed (the CLI draws a progress bar with it;
    /// the library prints nothing).
    pub progress: Option<ProgressHook>,
    /// Off-axis kernels for frames this wide (pixels): one grid per direction of a field
    /// lattice planned from the frame. None: the on-axis PSF everywhere.
    pub field_width_px: Option<u32>,
    /// On axis, the object step of `reference_axes` is halved where the frame's pixel scale
    /// needs it (`psf::plan::objects_for_screen`), so that the splat's layer kernels hold at
    /// 4K. Off for a caller that sets its own object axis to measure it (`compare`).
    pub objects_follow_screen: bool,
}

/// A progress callback: (stage, done, total).
pub type ProgressHook = std::sync::Arc<dyn Fn(Stage, usize, usize) + Send + Sync>;

impl std::fmt::Debug for KernelOptions {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("KernelOptions")
            .field("settings", &self.settings)
            .field("reference_axes", &self.reference_axes)
            .field("cache_dir", &self.cache_dir)
            .field("progress", &self.progress.is_some())
            .field("field_width_px", &self.field_width_px)
            .field("objects_follow_screen", &self.objects_follow_screen)
            .finish()
    }
}

impl Default for KernelOptions {
    fn default() -> Self {
        KernelOptions {
            settings: KernelSettings::default(),
            reference_axes: GridAxes::default(),
            cache_dir: cache::default_cache_dir(),
            progress: None,
            field_width_px: None,
            objects_follow_screen: true,
        }
    }
}

impl KernelOptions {
    /// The axes a frame with `needs` is planned against: `reference_axes`, on axis with its
    /// object step refined for the frame's pixel scale and largest pupil where
    /// `objects_follow_screen`.
    pub fn reference_for(&self, needs: &SceneNeeds) -> GridAxes {
        let mut axes = self.reference_axes.clone();
        if self.objects_follow_screen && self.field_width_px.is_none() {
            let pupil_mm = needs.pupils_mm.iter().copied().fold(0.0, f64::max);
            axes.objects =
                crate::psf::plan::objects_for_screen(axes.objects, &needs.screen, pupil_mm);
        }
        axes
    }
}

/// Kernels for a set of frames, with how they were obtained.
#[derive(Clone)]
pub struct PreparedKernels {
    pub grid: KernelGrid,
    pub plan: Plan,
    /// None when loaded from the cache.
    pub report: Option<GridReport>,
    pub cache: CacheOutcome,
    pub seconds: f64,
    /// Off-axis frames: the kernels over the field and how their directions were planned.
    pub field: Option<FieldKernels>,
    /// What a user must hear about these kernels: PSFs that miss pupil energy beyond the
    /// limit, a cache that could not be written.
    pub warnings: Vec<String>,
}

/// Kernels over the visual field and the plan of their directions.
#[derive(Clone)]
pub struct FieldKernels {
    pub kernels: KernelField,
    pub plan: FieldPlan,
}

/// Smallest and largest object vergence (along each pixel's ray; infinity = 0 D) of a
/// `width`×`height` view-axis depth buffer seen with a vertical field of `fov_y_deg`.
pub fn dioptre_range(depth_m: &[f32], width: u32, height: u32, fov_y_deg: f64) -> (f64, f64) {
    let projection = crate::render::projection::Projection {
        width,
        height,
        fov_y_deg,
    };
    let (mut lo, mut hi) = (f64::INFINITY, 0.0f64);
    for v in projection.dioptres(depth_m) {
        lo = lo.min(v);
        hi = hi.max(v);
    }
    if lo > hi {
        (0.0, 0.0)
    } else {
        (lo, hi)
    }
}

/// What frames with these depth ranges and eye states need, on this screen.
pub fn scene_needs(ranges: &[(f64, f64)], states: &[EyeState], screen: Screen) -> SceneNeeds {
    let lo = ranges.iter().map(|r| r.0).fold(f64::INFINITY, f64::min);
    let hi = ranges.iter().map(|r| r.1).fold(0.0, f64::max);
    let mut focus: Vec<f64> = states.iter().map(|s| s.focus_d).collect();
    let mut pupils: Vec<f64> = states.iter().map(|s| s.pupil_mm).collect();
    for v in [&mut focus, &mut pupils] {
        v.sort_by(f64::total_cmp);
        v.dedup_by(|a, b| (*a - *b).abs() < 1e-9);
    }
    SceneNeeds {
        dioptre_min: if lo.is_finite() { lo } else { 0.0 },
        dioptre_max: hi,
        focus_d: focus,
        pupils_mm: pupils,
        screen,
    }
}

/// A frame on the host, from a scene or from files: what the methods read, and what focus and
/// pupil are resolved from (`ocular render` and the Python renderer alike).
#[derive(Clone)]
pub struct HostFrame {
    pub width: u32,
    pub height: u32,
    pub fov_y_deg: f64,
    pub color: Vec<[f32; 4]>,
    pub depth_m: Vec<f32>,
    /// Hidden depth layers (colour, depth), nearest first.
    pub hidden: Vec<(Vec<[f32; 4]>, Vec<f32>)>,
    /// A scene's own focus, pupil and luminance (none for files).
    pub scene: SceneEye,
}

impl HostFrame {
    pub fn view(&self) -> FrameView<'_> {
        FrameView {
            width: self.width,
            height: self.height,
            fov_y_deg: self.fov_y_deg,
            color: &self.color,
            depth_m: &self.depth_m,
        }
    }

    /// The focus vergence and the words naming its source (see [`frame_plan::focus_d`]).
    pub fn focus_d(&self, asked: Option<FocusAsked>) -> Result<(f64, String)> {
        frame_plan::focus_d(asked, &self.scene, &self.view())
    }

    /// The pupil diameter and the words naming its source (see [`frame_plan::pupil_mm`]).
    pub fn pupil_mm(&self, asked: &PupilAsked<'_>) -> Result<(f64, String)> {
        frame_plan::pupil_mm(asked, &self.scene, &self.view())
    }

    /// The kernels this frame needs seen in eye state `state`.
    pub fn needs(&self, state: EyeState) -> SceneNeeds {
        let range = dioptre_range(&self.depth_m, self.width, self.height, self.fov_y_deg);
        let screen = Screen {
            fov_y_deg: self.fov_y_deg,
            height_px: self.height,
        };
        scene_needs(&[range], &[state], screen)
    }

    /// Renders this frame through `renderer` with `method`; its hidden layers go to splat
    /// only (the other methods see the visible layer).
    pub fn render(
        &self,
        renderer: &mut FrameRenderer,
        state: EyeState,
        method: Method,
    ) -> Result<RenderedFrame> {
        let hidden: Vec<HiddenLayer<'_>> = match method {
            Method::Splat => self
                .hidden
                .iter()
                .map(|(color, depth_m)| HiddenLayer { color, depth_m })
                .collect(),
            _ => Vec::new(),
        };
        let input = FrameInput {
            width: self.width,
            height: self.height,
            color: &self.color,
            depth_m: &self.depth_m,
            fov_y_deg: self.fov_y_deg,
            hidden_layers: &hidden,
            mixed: None,
        };
        renderer.render(&input, state, method)
    }
}

/// Plans, then loads or computes (and caches) the kernels `needs` calls for.
pub fn prepare_kernels(
    eye: &Eye,
    needs: &SceneNeeds,
    options: &KernelOptions,
) -> Result<PreparedKernels> {
    let started = Instant::now();
    let plan = plan_for_scene(needs, &options.reference_for(needs)).map_err(Error::input)?;
    let progress = |stage: Stage, done: usize, total: usize| {
        if let Some(hook) = &options.progress {
            hook(stage, done, total);
        }
    };
    if let Some(width_px) = options.field_width_px {
        return prepare_field_kernels(eye, plan, width_px, options, started, &progress);
    }
    let key = cache::grid_key(eye, &plan.axes, &plan.screen, &options.settings);
    let (grid, report, outcome) = cache::cached(options.cache_dir.as_deref(), &key, || {
        compute_grid(eye, &plan.axes, &plan.screen, &options.settings, &progress)
    })?;
    // a kernel whose PSF misses pupil energy beyond the limit is never silent
    let mut warnings: Vec<String> = report.iter().flat_map(|r| r.warnings.clone()).collect();
    warnings.extend(cache_warning(&outcome));
    Ok(PreparedKernels {
        grid,
        plan,
        report,
        cache: outcome,
        seconds: started.elapsed().as_secs_f64(),
        field: None,
        warnings,
    })
}

fn cache_warning(outcome: &CacheOutcome) -> Option<String> {
    match outcome {
        CacheOutcome::Stored {
            warning: Some(w), ..
        } => Some(w.clone()),
        CacheOutcome::WriteFailed(w) => Some(format!("kernels not cached: {w}")),
        _ => None,
    }
}

/// Off-axis: the field lattice the frame needs, then every node's grid (one largest radius).
/// `grid` is the node nearest the axis (what on-axis consumers of the kernels read).
fn prepare_field_kernels(
    eye: &Eye,
    plan: Plan,
    width_px: u32,
    options: &KernelOptions,
    started: Instant,
    progress: &(dyn Fn(Stage, usize, usize) + Sync),
) -> Result<PreparedKernels> {
    let field_plan = plan_for_frame(eye, &plan.axes, &plan.screen, width_px)?;
    let out = compute_kernel_field(
        eye,
        &plan.axes,
        &plan.screen,
        &options.settings,
        &field_plan.axes,
        options.cache_dir.as_deref(),
        progress,
    )?;
    let mut warnings: Vec<String> = Vec::new();
    for (node, r) in field_plan.axes.nodes().iter().zip(&out.reports) {
        for w in &r.warnings {
            warnings.push(format!("field ({}, {})°: {w}", node[0], node[1]));
        }
    }
    warnings.extend(field_plan.notes.iter().cloned());
    warnings.extend(cache_warning(&out.cache));
    let nearest = out.field.nearest_to_axis();
    Ok(PreparedKernels {
        grid: out.field.grids[nearest].clone(),
        plan,
        // the nearest node's report, counting every node's PSFs and time (the nodes are
        // computed one after another, so their times add up to the wall time)
        report: out.reports.get(nearest).cloned().map(|mut r| {
            r.psfs_computed = out.reports.iter().map(|r| r.psfs_computed).sum();
            r.seconds_optics = out.reports.iter().map(|r| r.seconds_optics).sum();
            r.seconds_psfs = out.reports.iter().map(|r| r.seconds_psfs).sum();
            r.seconds_kernels = out.reports.iter().map(|r| r.seconds_kernels).sum();
            r
        }),
        cache: out.cache,
        seconds: started.elapsed().as_secs_f64(),
        field: Some(FieldKernels {
            kernels: out.field,
            plan: field_plan,
        }),
        warnings,
    })
}

/// A rendered frame and what it cost.
pub struct RenderedFrame {
    pub color: Vec<[f32; 4]>,
    pub method: Method,
    /// Wall-clock seconds for the method (upload and read-back included for the GPU).
    pub seconds: f64,
    /// GPU time per pass (splat only).
    pub timings: Option<Timings>,
    pub stats: Option<SplatStats>,
}

/// Renders frames through one eye's prepared kernels with any method.
pub struct FrameRenderer {
    ctx: Context,
    eye: Eye,
    kernels: PreparedKernels,
    settings: KernelSettings,
    splat_settings: SplatSettings,
    splatter: Option<Splatter>,
    pub slice_count: usize,
    /// Off axis, the reference traces the eye for every field bin of this many degrees.
    pub reference_field_step_deg: f64,
    /// The reference rounds vergences to bins of this many dioptres.
    pub reference_dioptre_bin_d: f64,
}

/// Default field bin of the off-axis reference (degrees): a tenth of a typical lattice step,
/// well inside the λ/14 interpolation tolerance the lattice is planned to.
pub const REFERENCE_FIELD_STEP_DEG: f64 = 1.0;

impl FrameRenderer {
    pub fn new(
        ctx: &Context,
        eye: Eye,
        kernels: PreparedKernels,
        settings: KernelSettings,
        splat_settings: SplatSettings,
    ) -> FrameRenderer {
        FrameRenderer {
            ctx: ctx.clone(),
            eye,
            kernels,
            settings,
            splat_settings,
            splatter: None,
            slice_count: slices::DEFAULT_SLICES,
            reference_field_step_deg: REFERENCE_FIELD_STEP_DEG,
            reference_dioptre_bin_d: reference::DIOPTRE_BIN_D,
        }
    }

    pub fn eye(&self) -> &Eye {
        &self.eye
    }

    /// The value the frames will be shown as white (`MergeSettings::white`): the unit of the
    /// merge's colour bound. A non-positive or non-finite value leaves it unchanged.
    pub fn set_display_white(&mut self, white: f32) {
        if !(white.is_finite() && white > 0.0) {
            return;
        }
        self.splat_settings.merge.white = white;
        if let Some(s) = self.splatter.as_mut() {
            s.set_display_white(white);
        }
    }

    pub fn kernels(&self) -> &PreparedKernels {
        &self.kernels
    }

    fn splatter(&mut self) -> Result<&mut Splatter> {
        if self.splatter.is_none() {
            self.splatter = Some(match &self.kernels.field {
                None => Splatter::new(&self.ctx, self.kernels.grid.clone(), self.splat_settings)?,
                Some(f) => Splatter::new_field(&self.ctx, f.kernels.clone(), self.splat_settings)?,
            });
        }
        Ok(self.splatter.as_mut().expect("just created"))
    }

    fn check_height(&self, height: u32) -> Result<()> {
        let screen = self.kernels.plan.screen;
        if height != screen.height_px {
            return Err(Error::input(format!(
                "frame height {height} differs from the {} px the kernels were projected for",
                screen.height_px
            )));
        }
        Ok(())
    }

    /// Splats a frame the GPU makes within splat's own submission (a rasterised scene,
    /// [`crate::render::Rasterizer::scene_frame`]): its pixels never cross to the host.
    pub fn render_recorded(
        &mut self,
        frame: &mut dyn RecordedInput,
        state: EyeState,
    ) -> Result<RenderedFrame> {
        self.check_height(frame.size().1)?;
        let started = Instant::now();
        let out = self.splatter()?.render_recorded(frame, view_state(state))?;
        Ok(RenderedFrame {
            color: out.color,
            method: Method::Splat,
            seconds: started.elapsed().as_secs_f64(),
            timings: Some(out.timings),
            stats: Some(out.stats),
        })
    }

    pub fn render(
        &mut self,
        input: &FrameInput<'_>,
        state: EyeState,
        method: Method,
    ) -> Result<RenderedFrame> {
        let screen = self.kernels.plan.screen;
        self.check_height(input.height)?;
        let started = Instant::now();
        match method {
            Method::Views => Err(Error::input(
                "--method views rasterises a scene from points across the pupil: it needs a \
                 scene, not a colour + depth frame",
            )),
            Method::Splat => {
                let out = self.splatter()?.render(input, view_state(state), false)?;
                Ok(RenderedFrame {
                    color: out.color,
                    method,
                    seconds: started.elapsed().as_secs_f64(),
                    timings: Some(out.timings),
                    stats: Some(out.stats),
                })
            }
            Method::Reference | Method::Slices => {
                let exact = ExactEye::new(
                    &self.eye,
                    state.pupil_mm,
                    state.focus_d,
                    self.kernels.grid.wavelengths_nm,
                    screen,
                    self.settings.clone(),
                    self.kernels.grid.max_radius_px,
                )?;
                // The reference keeps the default blend whatever splat's (it is the fixed
                // truth of the kernel pipeline), except how edge pixels enter it: the frame's
                // mixed pixels are part of its input, which both methods read alike.
                let blend = BlendSettings {
                    edge_pixels: self.splat_settings.blend.edge_pixels,
                    ..BlendSettings::default()
                };
                let color = if let (Some(_), Method::Reference) = (&self.kernels.field, method) {
                    let wavelengths = self.kernels.grid.wavelengths_nm;
                    let field =
                        ExactFieldEye::new(exact, wavelengths, self.reference_field_step_deg)?;
                    reference::render_binned(input, &field, &blend, self.reference_dioptre_bin_d)
                } else if self.kernels.field.is_some() {
                    return Err(Error::input(
                        "--off-axis applies to --method splat and reference; slices use one PSF \
                         per depth slice",
                    ));
                } else if method == Method::Reference {
                    reference::render_binned(input, &exact, &blend, self.reference_dioptre_bin_d)
                } else {
                    slices::render(input, &exact, self.slice_count)
                };
                Ok(RenderedFrame {
                    color,
                    method,
                    seconds: started.elapsed().as_secs_f64(),
                    timings: None,
                    stats: None,
                })
            }
        }
    }
}

fn view_state(state: EyeState) -> ViewState {
    ViewState {
        pupil_mm: state.pupil_mm,
        focus_d: state.focus_d,
    }
}
