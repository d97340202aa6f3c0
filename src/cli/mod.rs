//! Command-line front end: one file per subcommand; `main.rs` only parses and calls `run`.

use clap::{Parser, Subcommand};

use crate::gpu::ContextOptions;
use crate::Result;

mod bench;
mod bench_pair;
mod binocular;
mod compare;
mod compare_files;
mod compare_pair;
pub(crate) mod correction;
mod devices;
mod eye;
mod eye_plot;
mod kernels;
mod kernels_field;
mod metrics;
mod occlusion;
mod outputs;
mod psf;
mod raster;
mod refract;
pub(crate) mod render;
mod render_output;
mod serve;
mod sha256;
mod video;
mod video_files;
mod video_frame;
mod video_manifest;
mod video_pair;

#[derive(Debug, Parser)]
#[command(
    name = "ocular",
    version,
    about = "Render a 3D scene as a particular human eye sees it",
    long_about = "ocular turns a wavefront measurement (Zernike coefficients) or a spectacle \
                  prescription into a physical eye model, computes its point-spread functions \
                  through focus, and renders colour + depth frames through them on the GPU with \
                  tiled PSF splatting (Csoba & Kunkli 2021)."
)]
pub struct Cli {
    /// GPU to use: an index or a name substring as `ocular devices` lists them (default:
    /// $OCULAR_DEVICE, else the most capable device; a discrete GPU first, a CPU implementation
    /// last). The CPU-only commands (psf, kernels, eye) refuse it.
    #[arg(long, global = true, value_name = "INDEX|NAME")]
    pub device: Option<String>,

    #[command(subcommand)]
    pub command: Command,
}

#[derive(Debug, Subcommand)]
pub enum Command {
    /// Render a scene (or colour + depth files, e.g. from Blender) as an eye sees it — the main job.
    Render(Box<render::RenderArgs>),
    /// Export an animation (or a focus sweep) frame by frame; resumable and splittable.
    Video(Box<video::VideoArgs>),
    /// Time every GPU pass over many frames (mean / median / p95), with precomputation times.
    Bench(Box<bench::BenchArgs>),
    /// Ground truth vs splatting vs depth slices: PSNR, MSSIM, time, SSIM maps.
    Compare(Box<compare::CompareArgs>),
    /// List the Vulkan devices and mark the one ocular would use.
    Devices(devices::DevicesArgs),
    /// Compute one point-spread function from Zernike coefficients (EXR + JSON sidecar).
    Psf(psf::PsfArgs),
    /// Rasterise a scene to linear HDR colour and metric depth (EXR), plus an optional PNG.
    Raster(raster::RasterArgs),
    /// Precompute an eye's PSF kernel grid (cached), with an optional contact sheet and plot.
    Kernels(Box<kernels::KernelsArgs>),
    /// Eyes: estimate one from a wavefront or prescription, show, measure, draw, list presets.
    Eye(Box<eye::EyeArgs>),
    /// PSNR, SSIM and FLIP between two images (HDR-FLIP for EXR), with an error map.
    Metrics(Box<metrics::MetricsArgs>),
    /// The live viewer: a local web page that changes the eye, focus and pupil and shows the frame.
    Serve(Box<serve::ServeArgs>),
}

impl Cli {
    pub fn context_options(&self) -> ContextOptions {
        ContextOptions {
            device: self.device_query(),
            ..ContextOptions::default()
        }
    }

    /// `--device`, else `OCULAR_DEVICE`: the environment variable is read here rather than by
    /// the parser so that `device` holds only what the command line gave.
    pub fn device_query(&self) -> Option<String> {
        self.device
            .clone()
            .or_else(|| std::env::var("OCULAR_DEVICE").ok())
            .filter(|d| !d.trim().is_empty())
    }
}

/// The commands that compute on the CPU refuse `--device` rather than ignore it. A global
/// OCULAR_DEVICE is a preference for the GPU commands and is not an error here.
fn refuse_device(cli: &Cli, command: &str) -> Result<()> {
    match &cli.device {
        Some(d) => Err(crate::Error::input(format!(
            "--device {d}: `ocular {command}` computes on the CPU and uses no GPU; leave \
             --device out"
        ))),
        None => Ok(()),
    }
}

pub fn run(cli: Cli) -> Result<()> {
    match &cli.command {
        Command::Render(args) => render::run(&cli, args),
        Command::Video(args) => video::run(&cli, args),
        Command::Bench(args) => bench::run(&cli, args),
        Command::Compare(args) => compare::run(&cli, args),
        Command::Devices(args) => devices::run(&cli, args),
        Command::Raster(args) => raster::run(&cli, args),
        Command::Psf(args) => refuse_device(&cli, "psf").and_then(|()| psf::run(args)),
        Command::Kernels(args) => refuse_device(&cli, "kernels").and_then(|()| kernels::run(args)),
        Command::Eye(args) => refuse_device(&cli, "eye").and_then(|()| eye::run(args)),
        Command::Metrics(args) => refuse_device(&cli, "metrics").and_then(|()| metrics::run(args)),
        Command::Serve(args) => serve::run(&cli, args),
    }
}

/// How fragments combine and the wide-field geometry (render, bench, compare).
#[derive(Debug, Clone, clap::Args)]
pub struct BlendArgs {
    /// How the fragments reaching a pixel combine: `grouped` adds the fragments of one depth
    /// group linearly and composites groups front to back (conserves light: a plane is its
    /// convolution); `per-fragment` is the seed paper's blend, kept for comparison.
    #[arg(long, value_enum, default_value = "grouped")]
    pub blend: crate::render::blend::BlendMode,
    /// Largest vergence step (D) between consecutive fragments of one depth group.
    #[arg(
        long,
        value_name = "D",
        default_value_t = crate::render::blend::DEFAULT_GROUP_TOLERANCE_D,
        allow_hyphen_values = true
    )]
    pub group_tolerance_d: f32,
    /// Use the seed paper's narrow-field geometry: vergence from view-axis depth and every
    /// kernel at the image centre's scale (default: vergence along each pixel's ray and
    /// kernels at the pinhole's local scale, which a wide field of view needs).
    #[arg(long)]
    pub narrow_field: bool,
}

impl BlendArgs {
    pub fn settings(&self) -> crate::render::blend::BlendSettings {
        crate::render::blend::BlendSettings {
            mode: self.blend,
            group_tolerance_d: self.group_tolerance_d,
            wide_field: !self.narrow_field,
            edge_pixels: crate::render::blend::EdgePixels::Whole,
        }
    }
}

/// Splat settings from the command line, validated (errors name the options).
/// The splatting options of render, bench and compare: one struct, flattened into each.
#[derive(Debug, Clone, clap::Args)]
pub struct SplatArgs {
    /// Speed against accuracy: `exact` (no merging, no early exit: what the tests judge
    /// against), `balanced` (merges only what cannot show) or `fast` (merges blocks as wide as
    /// the blur under a colour rule about 10× looser: 1.9–2.4× faster at 640×360 on lavapipe;
    /// docs/quality.md measures its error scene by scene).
    /// The --merge-* options below refine the preset.
    #[arg(long, value_enum, default_value = "balanced")]
    pub quality: crate::render::splat::Quality,
    /// Screen tile side for splatting in pixels: 8, 16 or 32.
    #[arg(long, default_value_t = 8)]
    pub tile_size: u32,
    /// Storage of the PSF texture the splatting samples.
    /// auto: rgba16f on a GPU, rgba32f on a CPU implementation (lavapipe), where it is faster.
    #[arg(long, value_enum, default_value = "auto")]
    pub texture_format: crate::render::splat::PsfTextureFormat,
    /// Fragment merging: 0 = off, 1 = 2×2 blocks, 2 = also 4×4 blocks, … 5 = up to 32×32
    /// (preset: 0 for exact, else 5). A merged block reads its pixels' kernel summed over the
    /// block (exact for one colour).
    #[arg(long)]
    pub merge_levels: Option<u32>,
    /// Level of detail by blur: merge a block of side s only where every kernel in it is at
    /// least this many times s in radius (preset: 2 balanced, 1 fast; 0 = any side, the seed
    /// paper's rule); its colours must also agree within --merge-color-error and its depths
    /// within their tolerance.
    #[arg(long, value_name = "K", allow_hyphen_values = true)]
    pub merge_blur_per_block: Option<f32>,
    /// Merge a block only if its smallest blur radius is at least this (px; preset: 5
    /// balanced, 1.5 fast).
    #[arg(long, value_name = "PX", allow_hyphen_values = true)]
    pub merge_min_radius: Option<f32>,
    /// The most that averaging one merged block's colours may change any pixel, block by block,
    /// as a fraction of the white the image is shown at (--exposure, else the frame's automatic
    /// exposure; preset: balanced 1/16320, a quarter of an 8-bit step shared by the 16 or so
    /// blocks a kernel's rim crosses, since their errors add; fast 1/1602, a whole step shared by
    /// the 2π blocks a rim crosses when blocks are as wide as the blur). A block of side s
    /// under blur radius r merges when its parts' colours differ by at most 4π·E·(r/s)²: the
    /// wider the blur against the block, the larger the difference that cannot show.
    #[arg(long, value_name = "E", allow_hyphen_values = true)]
    pub merge_color_error: Option<f32>,
    /// In the wide field, where a merged block makes one kernel read (with the radius levels
    /// or the per-fragment blend), the most (px) that read may misplace its edge pixels: off
    /// the centre a block's pixels lie cos²θ·δ apart in kernel space, not δ, so a block of side
    /// s merges only where (1 − cos²θ)·s/2 is at most this (default 0.02; 0 merges only at the
    /// centre of the frame; a large value ignores the local scale). With the layer kernels and
    /// depth groups (the default) a merged block reads its pixels where they lie: no bound.
    #[arg(long, value_name = "PX", allow_hyphen_values = true)]
    pub merge_scale_error: Option<f32>,
    /// Read kernels at the radius levels around each fragment's radius (up to three filtered
    /// reads per pixel and fragment) instead of each object distance's own kernel (one read).
    /// By default the layer kernels are used where neighbouring distances' radii differ by at
    /// most half a pixel (the default grid's 1/16 D steps), on axis.
    #[arg(long)]
    pub level_kernels: bool,
    #[command(flatten)]
    pub blend: BlendArgs,
    /// Aberrations across the visual field: each pixel gets the PSF of the eye traced for its
    /// own direction, mixed from a lattice of directions planned from the frame (splat and
    /// reference). Off: the on-axis PSF everywhere.
    #[arg(long)]
    pub off_axis: bool,
}

impl SplatArgs {
    /// The validated settings: the preset, refined by the options given; errors name the
    /// options.
    pub(crate) fn settings(&self) -> Result<crate::render::splat::SplatSettings> {
        let preset = self.quality.settings();
        let merge = preset.merge;
        let settings = crate::render::splat::SplatSettings {
            tile_size: self.tile_size,
            texture_format: self.texture_format,
            merge: crate::render::splat::MergeSettings {
                levels: self.merge_levels.unwrap_or(merge.levels),
                blur_per_block: self.merge_blur_per_block.unwrap_or(merge.blur_per_block),
                min_radius_px: self.merge_min_radius.unwrap_or(merge.min_radius_px),
                color_error: self.merge_color_error.unwrap_or(merge.color_error),
                scale_error_px: self.merge_scale_error.unwrap_or(merge.scale_error_px),
                ..merge
            },
            blend: self.blend.settings(),
            layer_kernels: !self.level_kernels,
            ..preset
        };
        settings.validate().map_err(|e| {
            crate::Error::input(format!(
                "--tile-size / --merge-* / --group-tolerance-d: {e}"
            ))
        })?;
        Ok(settings)
    }
}

/// The kernel cache options of the commands that compute kernels: one struct, flattened into
/// each.
#[derive(Debug, Clone, clap::Args)]
pub struct CacheArgs {
    /// Kernel cache folder (default: $XDG_CACHE_HOME/ocular or ~/.cache/ocular).
    #[arg(long, value_name = "DIR", conflicts_with = "no_cache")]
    pub cache: Option<std::path::PathBuf>,
    /// Neither read nor write the kernel cache.
    #[arg(long)]
    pub no_cache: bool,
}

impl CacheArgs {
    /// The cache folder: none with `--no-cache`, else `--cache DIR`, else the user's cache.
    pub(crate) fn dir(&self) -> Option<std::path::PathBuf> {
        if self.no_cache {
            None
        } else {
            self.cache
                .clone()
                .or_else(crate::psf::cache::default_cache_dir)
        }
    }

    /// Kernel options with this cache and a progress bar on a terminal.
    pub(crate) fn kernel_options(&self) -> crate::render::frame::KernelOptions {
        crate::render::frame::KernelOptions {
            progress: Some(kernel_progress_bar()),
            cache_dir: self.dir(),
            ..crate::render::frame::KernelOptions::default()
        }
    }
}

/// A progress bar for kernel computation on a terminal (hidden otherwise); it clears itself
/// when the last stage completes.
fn kernel_progress_bar() -> crate::render::frame::ProgressHook {
    use crate::psf::grid::Stage;
    let bar = terminal_bar(0, "{msg:>10} [{bar:30}] {pos}/{len} ETA {eta}");
    std::sync::Arc::new(move |stage: Stage, done: usize, total: usize| {
        let label = match stage {
            Stage::Optics => "eye optics",
            Stage::Psfs => "PSFs",
            Stage::Kernels => "kernels",
        };
        bar.set_message(label);
        bar.set_length(total as u64);
        bar.set_position(done as u64);
        if matches!(stage, Stage::Kernels) && done >= total {
            bar.finish_and_clear();
        }
    })
}

/// A progress bar of `total` steps drawn with `template` on a terminal; hidden otherwise.
fn terminal_bar(total: u64, template: &'static str) -> indicatif::ProgressBar {
    use std::io::IsTerminal;
    if !std::io::stderr().is_terminal() {
        return indicatif::ProgressBar::hidden();
    }
    indicatif::ProgressBar::new(total).with_style(
        indicatif::ProgressStyle::with_template(template)
            .expect("static template")
            .progress_chars("=> "),
    )
}

/// The frame counter of the commands that render many frames (video, bench).
pub(crate) fn frame_progress_bar(total: u64) -> indicatif::ProgressBar {
    terminal_bar(total, "frames [{bar:30}] {pos}/{len} {per_sec} ETA {eta}")
}

/// Loads or computes kernels (`render::frame::prepare_kernels`) and prints their warnings.
pub(crate) fn prepare_kernels(
    eye: &crate::eye::Eye,
    needs: &crate::psf::plan::SceneNeeds,
    options: &crate::render::frame::KernelOptions,
) -> Result<crate::render::frame::PreparedKernels> {
    let kernels = crate::render::frame::prepare_kernels(eye, needs, options)?;
    for w in &kernels.warnings {
        eprintln!("warning: {w}");
    }
    Ok(kernels)
}

/// A scene rasterised at t = 0 with the eye state the measuring commands (bench, compare)
/// use: the scene's focus, and the given pupil, else the scene's, else the seed paper's 5 mm.
pub(crate) fn measured_scene_frame(
    ctx: &crate::gpu::Context,
    scene: &crate::scene::Scene,
    (width, height): (u32, u32),
    pupil_mm: Option<f64>,
    mixed_pixels: bool,
) -> Result<(
    crate::render::Frame,
    crate::render::frame::EyeState,
    crate::psf::axes::Screen,
)> {
    use crate::render::frame_plan::{self, FrameView, PupilAsked, PupilFallback, SceneEye};
    let state = scene.at_time(0.0);
    let mut rasterizer = crate::render::Rasterizer::new(ctx)?;
    rasterizer.set_mixed_pixels(mixed_pixels);
    let frame = rasterizer.render(ctx, &state, width, height)?;
    let view = FrameView {
        width,
        height,
        fov_y_deg: state.camera.fov_y_deg,
        color: &frame.color,
        depth_m: &frame.depth_m,
    };
    let scene_eye = SceneEye::of(&state);
    let (focus_d, _) = frame_plan::focus_d(None, &scene_eye, &view)?;
    let asked = PupilAsked {
        given_mm: pupil_mm,
        luminance_cdm2: None,
        model: frame_plan::PupilModel::WatsonYellott,
        age_years: 30.0,
        fallback: PupilFallback::FixedMm(5.0),
    };
    let (pupil_mm, _) = frame_plan::pupil_mm(&asked, &scene_eye, &view)?;
    let screen = crate::psf::axes::Screen {
        fov_y_deg: state.camera.fov_y_deg,
        height_px: height,
    };
    Ok((
        frame,
        crate::render::frame::EyeState { focus_d, pupil_mm },
        screen,
    ))
}

/// The kernels one measured frame (from [`measured_scene_frame`]) needs: its depth range
/// along the rays, its eye state and screen.
pub(crate) fn frame_kernels(
    eye: &crate::eye::Eye,
    frame: &crate::render::Frame,
    state: crate::render::frame::EyeState,
    screen: crate::psf::axes::Screen,
    options: &crate::render::frame::KernelOptions,
) -> Result<crate::render::frame::PreparedKernels> {
    let range = crate::render::frame::dioptre_range(
        &frame.depth_m,
        frame.width,
        frame.height,
        screen.fov_y_deg,
    );
    let needs = crate::render::frame::scene_needs(&[range], &[state], screen);
    prepare_kernels(eye, &needs, options)
}

/// Writes `bytes` to `path` through a temporary file in the same folder and a rename, so a
/// reader never sees a partial file and a failed run leaves no file behind.
pub(crate) fn write_atomic(path: &std::path::Path, bytes: &[u8]) -> Result<()> {
    crate::image_io::write_atomic(path, |w| {
        std::io::Write::write_all(w, bytes).map_err(|e| format!("cannot write: {e}"))
    })
}
