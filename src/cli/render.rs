//! `ocular render`: the main job — a scene (or colour + depth files from a renderer) as a
//! particular eye sees it. With no arguments: the `primitives` scene through the `myopia` eye
//! into ocular.png. File input is read and checked by `crate::inputs`.

use std::path::PathBuf;

use clap::Args;

use super::raster::{parse_size, TonemapArg};
use super::Cli;
use crate::eye::Eye;
use crate::gpu::Context;

use crate::psf::cache::CacheOutcome;
use crate::render::frame::{EyeState, FrameRenderer, HostFrame, Method};
pub use crate::render::frame_plan::PupilModel;
use crate::render::frame_plan::{self, FocusAsked, PupilAsked, PupilFallback, SceneEye};
use crate::render::Rasterizer;
use crate::scene::Scene;
use crate::{Error, Result};

#[derive(Debug, Args)]
#[command(after_help = "Examples:\n  \
    ocular render                                   # primitives, myopia eye → ocular.png\n  \
    ocular render --scene chart --eye keratoconus --focus-m 6 -o chart.png\n  \
    ocular render --color c.exr --depth d.exr --fov-y 60 --eye astigmatism --focus-m 7.5 --pupil-mm 5 -o out.exr\n  \
    ocular render --color blender.exr --fov-y 22.9 --eye myopia          # Combined + Depth.Z of one file\n  \
    ocular render --color photo.png --depth d.exr --fov-y 40 --white-cdm2 200\n  \
    ocular render --scene colonnade --focus-at 320,180 --luminance-cdm2 30 --timings\n  \
    ocular render --scene chart --binocular --headset quest3 --stereo side-by-side -o vr.png\n\n\
Focus: --focus-m/--focus-d, or --focus-at X,Y (the depth under that pixel), else the scene's \
focus, else the depth at the frame's centre; background is infinitely far and focus distances \
from 1e4 m on are infinity. Pupil: --pupil-mm, else from --luminance-cdm2, the \
scene's pupil or luminance, or the frame's mean luminance (linear RGB is in cd/m²). Kernels are \
computed only for what the frame needs and cached (see --cache).")]
pub struct RenderArgs {
    /// Built-in scene (primitives, chart, colonnade) or a scene .toml file.
    #[arg(long, value_name = "NAME|FILE", conflicts_with = "color")]
    pub scene: Option<String>,
    /// Colour instead of a scene: a linear EXR (Blender's multilayer included: its
    /// <layer>.Combined pass) or an sRGB PNG/JPEG/TIFF. Needs --fov-y.
    #[arg(long, value_name = "FILE")]
    pub color: Option<PathBuf>,
    /// Depth EXR along the view axis in scene units (see --depth-scale): a Depth pass
    /// (ViewLayer.Depth.Z, Depth.V), a channel Z or depth, or a one-channel file. Default: the
    /// --color EXR.
    #[arg(long, value_name = "FILE.exr", requires = "color")]
    pub depth: Option<PathBuf>,
    /// EXR colour layer when the file has several (ViewLayer, Composite.Combined, Image, …).
    #[arg(long, value_name = "NAME", requires = "color")]
    pub color_layer: Option<String>,
    /// EXR depth channel by its full name (ViewLayer.Depth.Z, Depth.V, Z, …).
    #[arg(long, value_name = "NAME", requires = "color")]
    pub depth_channel: Option<String>,
    /// Metres per scene unit of the depth file (Blender: Scene > Units > Unit Scale).
    #[arg(
        long,
        value_name = "M",
        default_value_t = 1.0,
        allow_negative_numbers = true
    )]
    pub depth_scale: f64,
    /// Luminance of white in cd/m²: of sRGB white in PNG/JPEG/TIFF colour (default 80, the sRGB
    /// reference display), of 1.0 in EXR colour (default: EXR values are cd/m² already).
    #[arg(
        long,
        value_name = "CD/M2",
        requires = "color",
        allow_negative_numbers = true
    )]
    pub white_cdm2: Option<f64>,
    /// Render NaN or infinite colour samples of --color as black instead of refusing the file.
    #[arg(long, requires = "color")]
    pub repair_nonfinite: bool,
    /// With --binocular: the right eye's colour; --color (and --depth) is then the left's.
    /// Without it, --binocular reads the `left` and `right` views of a multi-view --color EXR
    /// (Blender's stereoscopy output). Both frames must have one size.
    #[arg(long, value_name = "FILE", requires = "color")]
    pub color_right: Option<PathBuf>,
    /// With --color-right: the right eye's depth EXR (default: the --color-right EXR).
    #[arg(long, value_name = "FILE.exr", requires = "color_right")]
    pub depth_right: Option<PathBuf>,
    /// Eye: a preset (see `ocular eye list`) or an eye .toml file. With --eye-right, the left
    /// eye.
    #[arg(long, value_name = "NAME|FILE", default_value = "myopia")]
    pub eye: String,
    #[command(flatten)]
    pub pair: super::binocular::PairArgs,
    /// How a binocular pair is written (default separate: -o view.png writes view-left.png
    /// and view-right.png).
    #[arg(long, value_enum)]
    pub stereo: Option<super::binocular::StereoOutput>,
    /// Focus distance in metres (`inf` for infinity).
    #[arg(long, value_name = "M", conflicts_with_all = ["focus_d", "focus_at"], allow_hyphen_values = true)]
    pub focus_m: Option<String>,
    /// Focus vergence in dioptres (0 = infinity).
    #[arg(
        long,
        value_name = "D",
        conflicts_with = "focus_at",
        allow_negative_numbers = true
    )]
    pub focus_d: Option<f64>,
    /// Focus on the depth under pixel X,Y (0-based, from the top left).
    #[arg(long, value_name = "X,Y", value_parser = parse_pixel)]
    pub focus_at: Option<(u32, u32)>,
    /// Entrance-pupil diameter in mm.
    #[arg(long, value_name = "MM", allow_negative_numbers = true)]
    pub pupil_mm: Option<f64>,
    /// Adapting luminance in cd/m² for the pupil model.
    #[arg(
        long,
        value_name = "CD/M2",
        conflicts_with = "pupil_mm",
        allow_negative_numbers = true
    )]
    pub luminance_cdm2: Option<f64>,
    /// Pupil formula for luminance-driven pupils.
    #[arg(long, value_enum, default_value = "watson-yellott")]
    pub pupil_model: PupilModel,
    /// Observer age (years), 20 to 83: the Watson–Yellott pupil and Hofstetter's amplitude
    /// of accommodation (unless the eye file or --accommodation-max-d sets one).
    #[arg(long, default_value_t = 30.0, value_parser = parse_age_years, allow_hyphen_values = true)]
    pub age: f64,
    /// Which of Hofstetter's age–amplitude lines --age reads.
    #[arg(long, value_enum, default_value = "mean")]
    pub accommodation_line: crate::eye::age::HofstetterLine,
    #[command(flatten)]
    pub correction: super::correction::CorrectionArgs,
    /// Vertical field of view in degrees; required with --color (scenes use their camera's).
    #[arg(
        long,
        value_name = "DEG",
        allow_negative_numbers = true,
        requires = "color"
    )]
    pub fov_y: Option<f64>,
    /// Frame size for scenes (default: the scene's `[camera] resolution`, 1280x720 for the
    /// shipped scenes); colour/depth files keep their own size.
    #[arg(long, value_name = "WxH", value_parser = parse_size, conflicts_with = "color")]
    pub size: Option<(u32, u32)>,
    /// Render each eye's frame at a headset's panel size and vertical field (scenes only; with
    /// --binocular, both eyes): quest3 (2064×2208, 96°), vive-pro (1440×1600, 110°).
    /// docs/binocular.md gives the published figures.
    #[arg(long, value_enum, conflicts_with_all = ["size", "color"])]
    pub headset: Option<crate::render::headset::Headset>,
    /// Scene time in seconds (keyframes).
    #[arg(long, value_name = "SECONDS", default_value_t = 0.0)]
    pub time: f64,
    /// Rendering method (views: scenes only).
    #[arg(long, value_enum, default_value = "splat")]
    pub method: Method,
    /// Views over the pupil for --method views (2–65536; default 256). The image converges
    /// as the views grow; compare --json reports the change when they double.
    #[arg(long, value_name = "N", value_parser = super::occlusion::parse_views)]
    pub views: Option<u32>,
    /// Depth layers splat takes (1–8; default 1, see docs/validation.md): a scene is
    /// depth-peeled to K layers, a layered EXR gives its own (at most K; default all). Hidden
    /// layers show through blurred edges; reference and slices use the visible layer only.
    #[arg(long, value_name = "K", value_parser = super::occlusion::parse_layers)]
    pub layers: Option<u32>,
    #[command(flatten)]
    pub splat: super::SplatArgs,
    #[command(flatten)]
    pub cache: super::CacheArgs,
    /// Print the GPU time of each splatting pass.
    #[arg(long)]
    pub timings: bool,
    /// Print a JSON summary to standard output.
    #[arg(long)]
    pub json: bool,
    /// Exposure in EV for PNG output (linear values × 2^EV; 1.0 maps to white). Default: the
    /// input frame's log-average luminance maps to middle grey.
    #[arg(long, allow_negative_numbers = true)]
    pub exposure: Option<f32>,
    /// Tone mapping for PNG output.
    #[arg(long, value_enum, default_value = "clamp")]
    pub tonemap: TonemapArg,
    /// Output image: .png (sRGB, tone-mapped) or .exr (linear).
    #[arg(short, long, value_name = "FILE", default_value = "ocular.png")]
    pub output: PathBuf,
}

/// The frame through its kernels (splat, reference or slices): a scene through splat stays on
/// the GPU, drawn again in splat's own submission.
fn render_frame(
    args: &RenderArgs,
    ctx: &Context,
    input: &mut Input,
    eye: Eye,
    (needs, options): (
        &crate::psf::plan::SceneNeeds,
        &crate::render::frame::KernelOptions,
    ),
    splat: crate::render::splat::SplatSettings,
    state: EyeState,
) -> Result<(
    crate::render::frame::RenderedFrame,
    super::render_output::KernelInfo,
)> {
    let kernels = super::prepare_kernels(&eye, needs, options)?;
    let from_cache = matches!(kernels.cache, CacheOutcome::Hit(_));
    let psfs = kernels.report.as_ref().map_or(0, |r| r.psfs_computed);
    let missed = kernels
        .report
        .as_ref()
        .map(|r| r.columns.iter().map(|c| c.missed_energy).collect());
    let seconds_kernels = kernels.seconds;
    let max_radius = kernels.grid.max_radius_px;
    let field = kernels.field.as_ref().map(|f| f.plan.clone());
    let mut renderer = FrameRenderer::new(ctx, eye, kernels, options.settings.clone(), splat);
    let frame = match &mut input.raster {
        // the frame stays on the GPU: drawn again in splat's submission, not uploaded
        Some((rasterizer, scene, layers)) if args.method == Method::Splat => {
            let scene_state = scene.at_time(args.time);
            let size = (input.frame.width, input.frame.height);
            let gap_d = args.splat.blend.settings().group_tolerance_d;
            let mut recorded = rasterizer
                .scene_frame(ctx, &scene_state, size)
                .peeled(*layers, gap_d);
            renderer.render_recorded(&mut recorded, state)?
        }
        _ => input.frame.render(&mut renderer, state, args.method)?,
    };

    let info = super::render_output::KernelInfo {
        from_cache,
        psfs,
        missed,
        seconds: seconds_kernels,
        max_radius,
        field,
    };
    Ok((frame, info))
}

/// The options checked on their own, before any file or device is opened; the splat
/// settings they give.
pub(super) fn check_args(args: &RenderArgs) -> Result<crate::render::splat::SplatSettings> {
    let output_ext = args
        .output
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase);
    if !matches!(output_ext.as_deref(), Some("png") | Some("exr")) {
        return Err(Error::input(format!(
            "-o {}: the output must end in .png or .exr",
            args.output.display()
        )));
    }
    let splat = args.splat.settings()?;
    if let Some(fov) = args.fov_y {
        check_fov(fov)?;
    }
    if args.method == Method::Views && args.color.is_some() {
        return Err(Error::input(
            "--method views rasterises a scene from points across the pupil; it cannot render \
             a --color frame (one view): give a scene",
        ));
    }
    if args.views.is_some() && args.method != Method::Views {
        return Err(Error::input("--views applies to --method views"));
    }
    if args.layers.is_some() && args.method != Method::Splat {
        return Err(Error::input(
            "--layers applies to --method splat (reference and slices see the visible layer only)",
        ));
    }
    check_file_options(args)?;
    if let Some(ev) = args.exposure {
        if !(ev.is_finite() && (-64.0..=64.0).contains(&ev)) {
            return Err(Error::input(format!(
                "--exposure {ev} must be a number of EV in [-64, 64]"
            )));
        }
    }
    Ok(splat)
}

/// Options that only mean something for file input are refused with a scene rather than
/// ignored (clap's `requires` is not checked once --scene is given).
fn check_file_options(args: &RenderArgs) -> Result<()> {
    if args.color.is_some() {
        return Ok(());
    }
    let given = [
        ("--fov-y", args.fov_y.is_some()),
        ("--depth", args.depth.is_some()),
        ("--color-layer", args.color_layer.is_some()),
        ("--depth-channel", args.depth_channel.is_some()),
        ("--depth-scale", args.depth_scale != 1.0),
        ("--white-cdm2", args.white_cdm2.is_some()),
        ("--repair-nonfinite", args.repair_nonfinite),
    ];
    match given.iter().find(|(_, on)| *on) {
        Some((name, _)) => Err(Error::input(format!(
            "{name} applies to --color input; a scene has its own camera, depth and colour"
        ))),
        None => Ok(()),
    }
}

/// The scene `name` as `--headset` (if any) shows it, and the frame size: the headset's panel,
/// else `--size`, else the scene's own.
pub fn scene_and_size(args: &RenderArgs, name: &str) -> Result<(Scene, (u32, u32))> {
    let scene = Scene::load(name)?;
    Ok(match args.headset.map(|h| h.spec()) {
        Some(h) => h.frame(scene),
        None => {
            let size = args
                .size
                .unwrap_or((scene.resolution[0], scene.resolution[1]));
            (scene, size)
        }
    })
}

fn check_fov(fov_y_deg: f64) -> Result<()> {
    crate::limits::FOV_Y_DEG
        .check("--fov-y", fov_y_deg)
        .map(|_| ())
        .map_err(Error::input)
}

fn parse_pixel(text: &str) -> std::result::Result<(u32, u32), String> {
    let (x, y) = text
        .split_once(',')
        .ok_or_else(|| format!("\"{text}\" is not X,Y"))?;
    let x = x
        .trim()
        .parse()
        .map_err(|_| format!("\"{x}\" is not a pixel column"))?;
    let y = y
        .trim()
        .parse()
        .map_err(|_| format!("\"{y}\" is not a pixel row"))?;
    Ok((x, y))
}

/// A frame to render, from a scene or from files.
pub(super) struct Input {
    pub(super) frame: HostFrame,
    pub(super) label: String,
    /// Where the depth came from, and what the depth policy found (file input).
    pub(super) depth_source: Option<String>,
    pub(super) depth_report: Option<crate::inputs::DepthReport>,
    pub(super) warnings: Vec<String>,
    /// A scene: its rasteriser, the scene and the depth layers splat takes, so that splat
    /// draws the frame (every layer) again inside its own submission instead of uploading
    /// pixels.
    pub(super) raster: Option<(Rasterizer, Scene, u32)>,
}

/// A frame from files: `color_path` (and `depth_path`, else the colour file's depth), one
/// view of a multi-view EXR where `view` names it, read with the render options' choices.
pub(super) fn file_input(
    args: &RenderArgs,
    color_path: &std::path::Path,
    depth_path: Option<&std::path::PathBuf>,
    view: Option<&str>,
) -> Result<Input> {
    let fov_y_deg = args.fov_y.ok_or_else(|| {
        Error::input(
            "--fov-y DEG is required with --color: the camera's vertical field of view in \
             degrees (Blender shows the horizontal one for landscape frames: docs/inputs.md)",
        )
    })?;
    check_fov(fov_y_deg)?;
    let file = crate::inputs::load(&crate::inputs::FileInputOptions {
        color: color_path.to_path_buf(),
        depth: depth_path.cloned(),
        color_layer: args.color_layer.clone(),
        depth_channel: args.depth_channel.clone(),
        depth_scale: args.depth_scale,
        white_cdm2: args.white_cdm2,
        repair_nonfinite: args.repair_nonfinite,
        view: view.map(str::to_string),
    })?;
    Ok(Input {
        frame: HostFrame {
            width: file.color.width,
            height: file.color.height,
            color: file.color.pixels,
            depth_m: file.depth_m,
            fov_y_deg,
            hidden: file
                .hidden_layers
                .into_iter()
                .take(args.layers.unwrap_or(u32::MAX).saturating_sub(1) as usize)
                .collect(),
            scene: SceneEye::default(),
        },
        label: file.color_source,
        depth_source: Some(file.depth_source),
        depth_report: Some(file.depth_report),
        warnings: file.warnings,
        raster: None,
    })
}

fn load_input(
    cli: &Cli,
    args: &RenderArgs,
    ctx: &Context,
    magnification: Option<[[f64; 2]; 2]>,
) -> Result<Input> {
    if let Some(color_path) = &args.color {
        let mut input = file_input(args, color_path, args.depth.as_ref(), None)?;
        if magnification.is_some() {
            input.warnings.push(
                "--correct: the spectacle's magnification is applied to scenes; colour/depth files \
                 are shown at their own scale (its blur and aberrations are applied)"
                    .into(),
            );
        }
        return Ok(input);
    }
    let _ = cli;
    let name = args
        .scene
        .clone()
        .unwrap_or_else(|| "primitives".to_string());
    let (scene, (width, height)) = scene_and_size(args, &name)?;
    if !args.time.is_finite() || args.time < 0.0 {
        return Err(Error::input(format!(
            "--time {} must be a non-negative number of seconds",
            args.time
        )));
    }
    let state = scene.at_time(args.time);
    let mut rasterizer = Rasterizer::new(ctx)?;
    let mut warnings = Vec::new();
    // The world seen through the spectacle: its angular magnification moves every direction.
    if let Some(m) = magnification {
        rasterizer.set_view_magnification(m);
    }
    let k = if args.method == Method::Splat {
        super::occlusion::scene_layers(ctx, args.layers, (width, height), &mut warnings)
    } else {
        1
    };
    // Layer 0 comes to the host for the depth range, the near-clamp report and the other
    // methods; splat draws every layer again in its own submission (peeled there too).
    let frame = rasterizer.render(ctx, &state, width, height)?;
    let mut depth_m = frame.depth_m;
    warnings.extend(frame_plan::clamp_near_depth(
        &mut depth_m,
        &format!("scene {name}"),
    ));
    let frame = HostFrame {
        width,
        height,
        color: frame.color,
        depth_m,
        fov_y_deg: state.camera.fov_y_deg,
        hidden: Vec::new(),
        scene: SceneEye::of(&state),
    };
    Ok(Input {
        frame,
        label: format!("scene {name}"),
        raster: Some((rasterizer, scene, k)),
        depth_source: None,
        depth_report: None,
        warnings,
    })
}

/// The eye named by `--eye` (a preset or a file); errors name the option.
pub(crate) fn load_eye(spec: &str) -> Result<Eye> {
    frame_plan::load_eye("--eye", spec)
}

pub(crate) use crate::render::frame_plan::parse_age_years;

/// The focus the options ask for; the rest of the decision is `frame_plan::focus_d`'s.
pub(super) fn focus_asked(args: &RenderArgs) -> Result<Option<FocusAsked>> {
    if let Some(text) = &args.focus_m {
        let t = text.trim().to_ascii_lowercase();
        if t == "inf" || t == "infinity" {
            return Ok(Some(FocusAsked::DistanceM(f64::INFINITY)));
        }
        let m: f64 = t.parse().map_err(|_| {
            Error::input(format!(
                "--focus-m \"{text}\" is not a distance in metres or inf"
            ))
        })?;
        return Ok(Some(FocusAsked::DistanceM(m)));
    }
    Ok(args
        .focus_d
        .map(FocusAsked::Dioptres)
        .or(args.focus_at.map(|(x, y)| FocusAsked::AtPixel(x, y))))
}

fn pupil_asked(args: &RenderArgs) -> PupilAsked<'static> {
    PupilAsked {
        given_mm: args.pupil_mm,
        luminance_cdm2: args.luminance_cdm2.map(|l| (l, "--luminance-cdm2")),
        model: args.pupil_model,
        age_years: args.age,
        fallback: PupilFallback::Luminance,
    }
}

pub fn run(cli: &Cli, args: &RenderArgs) -> Result<()> {
    super::binocular::check(args)?;
    if args.pair.asked() {
        return super::binocular::run(cli, args);
    }
    let mut splat = check_args(args)?;
    let (eye, physiology) = args.correction.apply(
        &load_eye(&args.eye)?,
        Some((args.age, args.accommodation_line)),
    )?;
    let ctx = Context::new(&cli.context_options())?;
    let mut input = load_input(cli, args, &ctx, physiology.spectacle_magnification)?;
    for w in &input.warnings {
        eprintln!("warning: {w}");
    }
    let (focus_d, focus_from) = input.frame.focus_d(focus_asked(args)?)?;
    let (pupil_mm, pupil_source) = input.frame.pupil_mm(&pupil_asked(args))?;
    let mut options = args.cache.kernel_options();
    if args.splat.off_axis {
        if matches!(args.method, Method::Slices | Method::Views) {
            return Err(Error::input(
                "--off-axis applies to --method splat and reference (slices and views use the \
                 on-axis PSF)",
            ));
        }
        options.field_width_px = Some(input.frame.width);
    }
    let focus = crate::render::focus::effective_focus(
        &eye,
        focus_d,
        pupil_mm,
        &options.settings,
        &focus_from,
    )?;
    let state = EyeState { focus_d, pupil_mm };
    let needs = input.frame.needs(state);
    splat.merge.white =
        crate::render::splat::display_white(super::render_output::exposure_ev(args, &input));
    if args.method == Method::Views {
        let (scene, _) = scene_and_size(args, args.scene.as_deref().unwrap_or("primitives"))?;
        let frame = super::occlusion::render_views(
            &ctx,
            &scene.at_time(args.time),
            (input.frame.width, input.frame.height),
            &eye,
            (pupil_mm, focus_d),
            args.views,
            &options,
        )?;
        return super::render_output::finish(
            args,
            &ctx,
            &input,
            frame,
            focus,
            (focus_d, pupil_mm, pupil_source, physiology),
            None,
        );
    }
    let (frame, info) = render_frame(
        args,
        &ctx,
        &mut input,
        eye,
        (&needs, &options),
        splat,
        state,
    )?;
    super::render_output::finish(
        args,
        &ctx,
        &input,
        frame,
        focus,
        (focus_d, pupil_mm, pupil_source, physiology),
        Some(info),
    )
}
