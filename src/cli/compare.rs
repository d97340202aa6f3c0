//! `ocular compare`: the seed paper's Table 2 for one scene and eye — ground truth, tiled
//! splatting and depth slices from the same kernels and inputs, with PSNR, MSSIM, time per
//! method and speed ratios; optionally the images and false-colour SSIM maps (Figure 12).

use std::path::PathBuf;

use clap::Args;

use super::compare_files::{judged_name, map_file, map_names, maps_folder, read_truth, write_maps};
use super::compare_pair;
use super::outputs::Outputs;
use super::raster::parse_frame_size;
use super::render::load_eye;
use super::Cli;
use crate::gpu::Context;
use crate::image_io::{self, ImageRgba};
use crate::render::edge_band::edge_band;
use crate::render::frame::{EyeState, FrameRenderer, KernelOptions, Method, RenderedFrame};
use crate::render::judge::{exposed, truth_shares, Judge, MethodResult, ViewsConvergence};
use crate::render::splat::FrameInput;
use crate::render::views::ViewsImage;
use crate::scene::Scene;
use crate::{Error, Result};

#[derive(Debug, Args)]
#[command(after_help = "Examples:\n  \
    ocular compare --scene primitives --eye myopia --size 320x180\n  \
    ocular compare --scene primitives --eye keratoconus --json kc.json --maps maps/\n  \
    ocular compare --scene chart --eye healthy --eye-right myopia --json pair.json\n\n\
Quality is measured against the ground truth on the displayed image: linear values at the input \
frame's automatic exposure, clamped to [0, 1] (PSNR with a peak of 1; SSIM with Wang et al.'s \
settings; FLIP is LDR-FLIP at --flip-ppd; in JSON a PSNR of null means identical images). The ground truth computes one exact PSF per 0.001 D \
bin and channel, on the CPU: it is slow by design.")]
pub struct CompareArgs {
    /// Built-in scene or a scene .toml file (rendered at t = 0).
    #[arg(long, value_name = "NAME|FILE", default_value = "primitives")]
    pub scene: String,
    /// Eye preset or eye .toml file. With --eye-right, the left eye.
    #[arg(long, value_name = "NAME|FILE", default_value = "myopia")]
    pub eye: String,
    /// Compare each eye of a pair (--binocular, --eye-right and the right eye's options, as
    /// in render), standing where `render --binocular` puts them for the scene's focus and
    /// sharing one accommodation: each eye's methods against its own truth
    /// (docs/binocular.md).
    #[command(flatten)]
    pub pair: super::binocular::PairArgs,
    /// Frame size.
    #[arg(long, value_name = "WxH", value_parser = parse_frame_size, default_value = "320x180")]
    pub size: (u32, u32),
    #[command(flatten)]
    pub correction: super::correction::CorrectionArgs,
    /// Pupil diameter in mm (default: the scene's, else 5 mm as in the seed paper).
    #[arg(long, value_name = "MM")]
    pub pupil_mm: Option<f64>,
    /// Depth slices for the slice method.
    #[arg(long, default_value_t = 41)]
    pub slices: usize,
    #[command(flatten)]
    pub splat: super::SplatArgs,
    /// Object-distance samples over the seed paper's 0.125–10.125 D range (its 41 by default).
    #[arg(long, default_value_t = 41)]
    pub object_samples: usize,
    /// Largest kernel radius in pixels (larger blur is clamped).
    #[arg(long, default_value_t = 64)]
    pub rmax_cap: u32,
    /// Highest β expansion degree of the PSFs.
    #[arg(long, default_value_t = 160)]
    pub beta_degree: u32,
    /// PSF sample size on the retina in µm (the seed paper's 4).
    #[arg(long, default_value_t = 4.0)]
    pub sample_um: f64,
    /// Save the ground truth (linear EXR) for later runs.
    #[arg(long, value_name = "FILE.exr")]
    pub truth_out: Option<PathBuf>,
    /// Use this ground truth (from --truth-out with the same scene, size, eye and state)
    /// instead of rendering it: sweeps keep one truth while the settings vary.
    #[arg(long, value_name = "FILE.exr")]
    pub truth_in: Option<PathBuf>,
    /// Also judge a saved linear EXR of this frame against the truth (repeatable; the row is
    /// named after the file): another renderer's output, or a truth saved with --truth-out at
    /// other settings, which measures the truth's own convergence.
    #[arg(long, value_name = "FILE.exr")]
    pub judge: Vec<PathBuf>,
    /// Dioptre bin of the reference truth: each pixel's vergence is rounded to it (0.0001 to
    /// 0.1; default 0.001, the seed paper's 3 decimals). Off axis every pair of vergence bin and
    /// 1° direction costs its own PSFs; 0.01 makes a deep 1280×720 scene affordable and moves a
    /// blur diameter by at most 0.005 D × the pupil diameter.
    #[arg(long, value_name = "D", value_parser = parse_truth_bin_d)]
    pub truth_bin_d: Option<f64>,
    /// Skip the slice method.
    #[arg(long)]
    pub no_slices: bool,
    /// How the reference reads a pixel a silhouette crosses: `whole` (one fragment of the
    /// pixel's mean colour at the nearest surface's depth, as every method does) or `split`
    /// (the nearest surface over its share of the pixel's samples and what lies behind over
    /// the rest, each with its own depth's kernel). Splat and slices always read the pixel
    /// whole: the split, measured against --truth views, moved the edge band away from it
    /// (docs/validation.md, "Mixed pixels").
    #[arg(long, value_enum, default_value = "whole")]
    pub edge_pixels: crate::render::blend::EdgePixels,
    /// Render splat once and time that frame (shader compilation and the kernels' upload
    /// included) instead of timing a second frame: halves splat's cost where one frame takes
    /// minutes (off axis at 1280×720 on a CPU device).
    #[arg(long)]
    pub no_warmup: bool,
    /// The ground truth: `reference` (exact per-pixel PSFs, the same blend as splat) or
    /// `views` (multi-view accumulation over the pupil: geometric optics, sees hidden
    /// surfaces, shares neither kernels nor blend; the reference is then judged too).
    #[arg(long, value_enum, default_value = "reference")]
    pub truth: TruthArg,
    /// Views over the pupil for --truth views (2–65536; default 256).
    #[arg(long, value_name = "N", value_parser = super::occlusion::parse_views)]
    pub views: Option<u32>,
    /// Also judge splat over K depth-peeled layers ("splat-layers", 2–8; 1, the default,
    /// adds no row). "splat" stays one layer.
    #[arg(long, value_name = "K", value_parser = super::occlusion::parse_layers)]
    pub layers: Option<u32>,
    /// Write the results as JSON.
    #[arg(long, value_name = "FILE")]
    pub json: Option<PathBuf>,
    /// Write truth.png, splat.png, slices.png and the SSIM maps (ssim_splat.png, ssim_slices.png).
    #[arg(long, value_name = "DIR")]
    pub maps: Option<PathBuf>,
    #[command(flatten)]
    pub cache: super::CacheArgs,
    /// Viewing condition of the FLIP column in pixels per degree (default: FLIP's 67.02,
    /// 0.7 m from a 0.7 m wide monitor 3840 pixels across).
    #[arg(long, value_name = "N", default_value_t = crate::metrics::flip::DEFAULT_PPD)]
    pub flip_ppd: f64,
}

/// Which image the others are judged against.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum TruthArg {
    Reference,
    Views,
}

#[derive(serde::Serialize)]
struct Report {
    scene: String,
    eye: String,
    /// `left` or `right` in a pair's report (absent for one eye).
    #[serde(skip_serializing_if = "Option::is_none")]
    side: Option<&'static str>,
    width: u32,
    height: u32,
    focus_d: f64,
    pupil_mm: f64,
    device: String,
    /// The `--quality` preset splat ran at.
    quality: &'static str,
    /// `reference` or `views`.
    truth: &'static str,
    /// What the ground truth shares with splat (what it cannot judge).
    truth_shares: &'static str,
    /// The reference's dioptre bin (null for the views truth or a truth from --truth-in).
    truth_bin_d: Option<f64>,
    /// The views truth's own convergence (null for the reference truth or --truth-in).
    views_convergence: Option<ViewsConvergence>,
    /// Whether splat's `seconds` is a second frame (true) or the first (`--no-warmup`).
    splat_warmed_up: bool,
    /// Pixels per degree of the FLIP column.
    flip_ppd: f64,
    /// Exposure (EV) of the displayed images every metric judges: linear × 2^EV, clamped.
    display_exposure_ev: f32,
    methods: Vec<MethodResult>,
}

pub fn run(cli: &Cli, args: &CompareArgs) -> Result<()> {
    let mut splat = args.splat.settings()?;
    check_args(args)?;
    // Declared before the outputs so that it is dropped after their temporaries are.
    let maps_created = match &args.maps {
        Some(dir) => Some(maps_folder(dir)?),
        None => None,
    };
    let mut outputs = planned_outputs(args)?;
    let (mut truth_in, mut judged) = read_images(args)?;
    let scene = Scene::load(&args.scene)?;
    let ctx = Context::new(&cli.context_options())?;
    splat.blend.edge_pixels = args.edge_pixels;
    let (views, pair) = if args.pair.asked() {
        let (views, pair) = compare_pair::views(&ctx, args, &scene)?;
        (views, Some(pair))
    } else {
        let eye = args.correction.apply(&load_eye(&args.eye)?, None)?.0;
        let view = compare_pair::EyeView {
            side: None,
            spec: args.eye.clone(),
            scene,
            eye,
            focus_d: None,
        };
        (vec![view], None)
    };
    let mut reports = Vec::new();
    for view in &views {
        let inputs = (truth_in.take(), std::mem::take(&mut judged));
        reports.push(compare_view(&ctx, args, view, splat, inputs, &mut outputs)?);
    }
    if let Some(path) = &args.json {
        let text = match pair {
            Some(pair) => serde_json::to_string_pretty(&PairReport {
                binocular: pair,
                eyes: reports,
            }),
            None => serde_json::to_string_pretty(&reports[0]),
        }
        .map_err(|e| Error::input(format!("cannot encode JSON: {e}")))?;
        image_io::write_text_atomic(outputs.temporary(path), &text)?;
    }
    outputs.commit()?;
    if let Some(mut created) = maps_created {
        created.keep();
    }
    print_written(args);
    Ok(())
}

/// `--json` of a pair: its state and each eye's report (left, right).
#[derive(serde::Serialize)]
struct PairReport {
    binocular: compare_pair::PairState,
    eyes: Vec<Report>,
}

/// One eye's comparison: its frame, kernels, truth and methods, judged, printed, and its
/// truth and maps written into `outputs`; returns its report.
fn compare_view(
    ctx: &Context,
    args: &CompareArgs,
    view: &compare_pair::EyeView,
    mut splat: crate::render::splat::SplatSettings,
    (truth_in, judged): (Option<ImageRgba>, Judged),
    outputs: &mut Outputs,
) -> Result<Report> {
    let (width, height) = args.size;
    let split = args.edge_pixels == crate::render::blend::EdgePixels::Split;
    let (frame, mut eye_state, screen) =
        super::measured_scene_frame(ctx, &view.scene, args.size, args.pupil_mm, split)?;
    if let Some(focus_d) = view.focus_d {
        eye_state.focus_d = focus_d;
    }
    // Compare what a person sees: every image at the input frame's automatic exposure, which
    // is also the white splat's merge bounds its colour error by.
    let exposure_ev = crate::image_io::Tonemap::auto_exposure_ev_of(&frame.color);
    splat.merge.white = crate::render::splat::display_white(exposure_ev);
    let options = kernel_options(args)?;
    let kernels = super::frame_kernels(&view.eye, &frame, eye_state, screen, &options)?;
    let mut notes = Vec::new();
    let layers = super::occlusion::scene_layers(ctx, args.layers, args.size, &mut notes);
    for n in &notes {
        println!("note: {n}");
    }
    let mut renderer = FrameRenderer::new(
        ctx,
        view.eye.clone(),
        kernels,
        options.settings.clone(),
        splat,
    );
    renderer.slice_count = args.slices;
    if let Some(bin) = args.truth_bin_d {
        renderer.reference_dioptre_bin_d = bin;
    }
    let input = frame.input(screen.fov_y_deg);
    let at = Frames {
        ctx,
        scene: &view.scene,
        input: &input,
        eye_state,
        gap_d: splat.blend.group_tolerance_d,
    };
    let (truth, convergence_images) = render_truth(&at, &mut renderer, args, truth_in, &options)?;
    let rendered = render_methods(&at, &mut renderer, args, truth.method, layers)?;
    let band = edge_band(
        &frame.depth_m,
        (width, height),
        screen.fov_y_deg,
        &renderer.kernels().grid,
        (eye_state.pupil_mm, eye_state.focus_d),
        f64::from(splat.blend.group_tolerance_d),
    );
    let scale = 2f32.powf(exposure_ev);
    let judge = Judge {
        width: width as usize,
        height: height as usize,
        scale,
        truth: exposed(&truth.color, scale),
        band: &band,
        flip_ppd: args.flip_ppd,
        reference_seconds: rendered.reference.as_ref().unwrap_or(&truth).seconds,
    };
    let views_convergence = convergence_images
        .as_ref()
        .map(|i| judge.views_convergence(i));
    let judged_frames: Vec<(RenderedFrame, String)> = judged
        .into_iter()
        .map(|(name, image)| (read_frame(image, truth.method), name))
        .collect();
    let frames = rendered.rows(&truth, layers, &judged_frames);
    let (methods, maps) = judge_rows(&judge, &frames)?;
    let truth_shares = shares(args, truth.method);
    print_table(
        args,
        (&at, view),
        truth_shares,
        &views_convergence,
        &methods,
    );
    if let Some(path) = &args.truth_out {
        image_io::write_exr_rgba(
            outputs.temporary(&compare_pair::eye_path(path, view.side)),
            &ImageRgba::new(width, height, truth.color.clone()),
        )?;
    }
    if let Some(dir) = &args.maps {
        let maps_at = (dir.as_path(), view.side);
        write_maps(outputs, maps_at, args.size, &frames, &maps, exposure_ev)?;
    }
    Ok(Report {
        scene: args.scene.clone(),
        eye: view.spec.clone(),
        side: view.side,
        width,
        height,
        focus_d: eye_state.focus_d,
        pupil_mm: eye_state.pupil_mm,
        device: ctx.device_info().name.clone(),
        quality: args.splat.quality.name(),
        truth: if truth.method == Method::Views {
            "views"
        } else {
            "reference"
        },
        truth_shares,
        truth_bin_d: (truth.method == Method::Reference && args.truth_in.is_none())
            .then_some(renderer.reference_dioptre_bin_d),
        views_convergence,
        splat_warmed_up: !args.no_warmup,
        flip_ppd: args.flip_ppd,
        display_exposure_ev: exposure_ev,
        methods,
    })
}

fn print_written(args: &CompareArgs) {
    if let Some(dir) = &args.maps {
        println!(
            "wrote images and SSIM maps (1.0 → navy, ≤ 0.9 → red) to {}",
            dir.display()
        );
    }
    if let Some(path) = &args.truth_out {
        if args.pair.asked() {
            for side in crate::render::binocular::SIDES {
                let file = compare_pair::eye_path(path, Some(side));
                println!("wrote {}", file.display());
            }
        } else {
            println!("wrote {}", path.display());
        }
    }
    if let Some(path) = &args.json {
        println!("wrote {}", path.display());
    }
}

/// Options out of range or at odds with each other, refused before anything is read.
fn check_args(args: &CompareArgs) -> Result<()> {
    compare_pair::check(args)?;
    if args.views.is_some() && args.truth != TruthArg::Views {
        return Err(Error::input("--views applies to --truth views"));
    }
    if !crate::metrics::flip::ppd_in_range(args.flip_ppd) {
        let (lo, hi) = crate::metrics::flip::PPD_RANGE;
        return Err(Error::input(format!(
            "--flip-ppd {} is outside {lo} to {hi} pixels per degree",
            args.flip_ppd
        )));
    }
    if args.slices == 0 {
        return Err(Error::input("--slices must be at least 1"));
    }
    if !(2..=1024).contains(&args.object_samples) {
        return Err(Error::input(format!(
            "--object-samples {} is outside 2 to 1024",
            args.object_samples
        )));
    }
    let mut rows: Vec<String> = [
        "truth",
        "reference",
        "views",
        "splat",
        "splat-layers",
        "slices",
    ]
    .map(String::from)
    .to_vec();
    for path in &args.judge {
        let name = judged_name(path);
        if rows.contains(&name) {
            return Err(Error::input(format!(
                "--judge {}: its row would be named `{name}`, which another row has; rename the \
                 file",
                path.display()
            )));
        }
        rows.push(name);
    }
    Ok(())
}

/// Every file this run writes, checked writable before minutes of rendering.
fn planned_outputs(args: &CompareArgs) -> Result<Outputs> {
    let mut outputs = Outputs::new();
    let sides: Vec<Option<&str>> = if args.pair.asked() {
        crate::render::binocular::SIDES
            .iter()
            .map(|s| Some(*s))
            .collect()
    } else {
        vec![None]
    };
    if let Some(path) = &args.truth_out {
        for side in &sides {
            outputs.add(
                "--truth-out",
                &compare_pair::eye_path(path, *side),
                &["exr"],
            )?;
        }
    }
    if let Some(path) = &args.json {
        outputs.add("--json", path, &["json"])?;
    }
    if let Some(dir) = &args.maps {
        for name in map_names(
            args.no_slices,
            args.truth == TruthArg::Views,
            args.layers.unwrap_or(crate::render::raster::DEFAULT_LAYERS) > 1,
        ) {
            for side in &sides {
                let file = map_file(dir, *side, name);
                outputs.add("--maps", &file, &["png"])?;
            }
        }
        for name in args.judge.iter().map(|p| judged_name(p)) {
            outputs.add("--maps", &dir.join(format!("{name}.png")), &["png"])?;
            outputs.add("--maps", &dir.join(format!("ssim_{name}.png")), &["png"])?;
        }
    }
    outputs.probe()?;
    Ok(outputs)
}

/// The `--judge` images, each with its row's name.
type Judged = Vec<(String, ImageRgba)>;

/// The `--truth-in` image and the `--judge` images (named by their rows), checked against the
/// frame's size.
fn read_images(args: &CompareArgs) -> Result<(Option<ImageRgba>, Judged)> {
    if args.truth_bin_d.is_some() && args.truth_in.is_some() && args.truth == TruthArg::Reference {
        return Err(Error::input(
            "--truth-bin-d applies to a rendered reference; --truth-in reads one",
        ));
    }
    let truth_in = args
        .truth_in
        .as_ref()
        .map(|p| read_truth("--truth-in", p))
        .transpose()?;
    let judged: Judged = args
        .judge
        .iter()
        .map(|p| Ok((judged_name(p), read_truth("--judge", p)?)))
        .collect::<Result<_>>()?;
    for (path, (_, image)) in args.judge.iter().zip(&judged) {
        if (image.width, image.height) != args.size {
            return Err(Error::input(format!(
                "--judge {} is {}×{}, the frame is {}×{}",
                path.display(),
                image.width,
                image.height,
                args.size.0,
                args.size.1
            )));
        }
    }
    Ok((truth_in, judged))
}

/// The kernel options the comparison's flags set, validated with the flags named.
fn kernel_options(args: &CompareArgs) -> Result<KernelOptions> {
    let mut options = args.cache.kernel_options();
    options.reference_axes.objects =
        crate::psf::kernels::DioptreAxis::spanning(0.125, 10.125, args.object_samples);
    // --object-samples is the axis measured, at every size
    options.objects_follow_screen = false;
    options.settings.max_radius_cap = args.rmax_cap;
    options.settings.max_beta_degree = args.beta_degree;
    options.settings.sample_um = args.sample_um;
    options.settings.validate().map_err(|e| {
        Error::input(
            e.replace("max_radius_cap", "--rmax-cap")
                .replace("max_beta_degree", "--beta-degree")
                .replace("sample_um", "--sample-um"),
        )
    })?;
    if args.splat.off_axis && matches!(args.truth, TruthArg::Views) {
        return Err(Error::input(
            "--off-axis is judged against --truth reference (the views truth traces the eye on \
             axis only)",
        ));
    }
    options.field_width_px = args.splat.off_axis.then_some(args.size.0);
    Ok(options)
}

/// What every method renders from.
struct Frames<'a> {
    ctx: &'a Context,
    scene: &'a Scene,
    input: &'a FrameInput<'a>,
    eye_state: EyeState,
    /// The blend's group tolerance (D), which peeling separates layers by.
    gap_d: f32,
}

/// A frame read from a file: no time, so no speed-up either.
fn read_frame(image: ImageRgba, method: Method) -> RenderedFrame {
    RenderedFrame {
        color: image.pixels,
        method,
        seconds: f64::NAN,
        timings: None,
        stats: None,
    }
}

/// The ground truth: read with --truth-in, or rendered (the reference, or the views truth
/// with the images its convergence is measured from).
fn render_truth(
    at: &Frames<'_>,
    renderer: &mut FrameRenderer,
    args: &CompareArgs,
    truth_in: Option<ImageRgba>,
    options: &KernelOptions,
) -> Result<(RenderedFrame, Option<ViewsImage>)> {
    let truth_method = match args.truth {
        TruthArg::Reference => Method::Reference,
        TruthArg::Views => Method::Views,
    };
    let (width, height) = args.size;
    if let (Some(path), Some(image)) = (&args.truth_in, truth_in) {
        if (image.width, image.height) != (width, height) {
            return Err(Error::input(format!(
                "--truth-in {} is {}×{}, the frame is {width}×{height}",
                path.display(),
                image.width,
                image.height
            )));
        }
        return Ok((read_frame(image, truth_method), None));
    }
    if truth_method != Method::Views {
        let truth = renderer.render(at.input, at.eye_state, Method::Reference)?;
        return Ok((truth, None));
    }
    let started = std::time::Instant::now();
    let state = at.scene.at_time(0.0);
    let column = crate::psf::defocus::ColumnOptics::new(
        renderer.eye(),
        at.eye_state.pupil_mm,
        at.eye_state.focus_d,
        renderer.kernels().grid.wavelengths_nm,
        &options.settings,
    )?;
    let image = crate::render::views::render(
        at.ctx,
        &mut crate::render::Rasterizer::new(at.ctx)?,
        &state,
        (width, height),
        &column,
        at.eye_state.focus_d,
        args.views.unwrap_or(crate::render::views::DEFAULT_VIEWS),
    )?;
    let truth = RenderedFrame {
        color: image.color.clone(),
        method: Method::Views,
        seconds: started.elapsed().as_secs_f64(),
        timings: None,
        stats: None,
    };
    Ok((truth, Some(image)))
}

/// The frames judged against the truth.
struct Rendered {
    /// The reference, where the views truth judges it.
    reference: Option<RenderedFrame>,
    splat: RenderedFrame,
    layered: Option<RenderedFrame>,
    slices: Option<RenderedFrame>,
}

impl Rendered {
    /// Every row in its order: the truth, the rendered methods, the judged files.
    fn rows<'a>(
        &'a self,
        truth: &'a RenderedFrame,
        layers: u32,
        judged: &'a [(RenderedFrame, String)],
    ) -> Vec<(&'a RenderedFrame, String, u32)> {
        [
            Some((truth, truth.method.name().to_string(), 1)),
            self.reference.as_ref().map(|f| (f, "reference".into(), 1)),
            Some((&self.splat, "splat".into(), 1)),
            self.layered
                .as_ref()
                .map(|f| (f, "splat-layers".into(), layers)),
            self.slices.as_ref().map(|f| (f, "slices".into(), 1)),
        ]
        .into_iter()
        .flatten()
        .chain(judged.iter().map(|(f, name)| (f, name.clone(), 1)))
        .collect()
    }
}

fn render_methods(
    at: &Frames<'_>,
    renderer: &mut FrameRenderer,
    args: &CompareArgs,
    truth_method: Method,
    layers: u32,
) -> Result<Rendered> {
    let (input, eye_state) = (at.input, at.eye_state);
    let reference = if truth_method == Method::Views {
        Some(renderer.render(input, eye_state, Method::Reference)?)
    } else {
        None
    };
    // The first splat frame compiles shaders and uploads the kernels: time the second.
    if !args.no_warmup {
        renderer.render(input, eye_state, Method::Splat)?;
    }
    let splat = renderer.render(input, eye_state, Method::Splat)?;
    // The layered frame is peeled and splatted in one submission, its layers never on the
    // host (tests/it/engine.rs: the same image as the layers read back and uploaded).
    let layered = if layers > 1 {
        let state = at.scene.at_time(0.0);
        let mut raster = crate::render::Rasterizer::new(at.ctx)?;
        let mut layered = || {
            let mut recorded = raster
                .scene_frame(at.ctx, &state, args.size)
                .peeled(layers, at.gap_d);
            renderer.render_recorded(&mut recorded, eye_state)
        };
        layered()?;
        Some(layered()?)
    } else {
        None
    };
    // slices have no off-axis variant: leave them out rather than compare the on-axis PSF
    let slices = if args.no_slices || args.splat.off_axis {
        None
    } else {
        Some(renderer.render(input, eye_state, Method::Slices)?)
    };
    Ok(Rendered {
        reference,
        splat,
        layered,
        slices,
    })
}

/// Every row judged, with its SSIM map; a note where the frame is under SSIM's window.
fn judge_rows(
    judge: &Judge<'_>,
    frames: &[(&RenderedFrame, String, u32)],
) -> Result<(Vec<MethodResult>, Vec<Vec<f32>>)> {
    let (mut methods, mut maps) = (Vec::new(), Vec::new());
    let mut window_px = 11;
    for (frame, name, layers) in frames {
        let row = judge.row(frame, name, *layers)?;
        methods.push(row.result);
        maps.push(row.ssim_map);
        window_px = row.window_px;
    }
    if window_px != 11 {
        println!(
            "note: the frame is under SSIM's 11-pixel window; MSSIM uses a {window_px}×{window_px} window"
        );
    }
    Ok((methods, maps))
}

/// What the truth shares with the methods it judges, as the report words it.
fn shares(args: &CompareArgs, truth_method: Method) -> &'static str {
    let views = truth_method == Method::Views;
    truth_shares(args.truth_in.is_some(), views, args.splat.off_axis)
}

fn print_table(
    args: &CompareArgs,
    (at, view): (&Frames<'_>, &compare_pair::EyeView),
    truth_shares: &str,
    views_convergence: &Option<ViewsConvergence>,
    methods: &[MethodResult],
) {
    let (width, height) = args.size;
    let (focus_d, pupil_mm) = (at.eye_state.focus_d, at.eye_state.pupil_mm);
    let side = view
        .side
        .map_or(String::new(), |s| format!(", the {s} eye of a pair"));
    println!(
        "{} through eye {}{side} at {width}×{height}, focus {focus_d:.3} D, pupil {pupil_mm:.2} mm ({})",
        args.scene,
        view.spec,
        at.ctx.device_info().name
    );
    println!("  {truth_shares}");
    if let Some(c) = views_convergence {
        println!(
            "  views: {} (doubling from {} changes the image by {:.2} dB PSNR, MSSIM {:.5}, at most {:.4})",
            c.views, c.half_views, c.psnr_db, c.mssim, c.max_abs_change
        );
    }
    println!(
        "  {:<13} {:>10} {:>10} {:>8} {:>10} {:>12}   edge band ({} px): {:>8} {:>8}",
        "method",
        "PSNR dB",
        "MSSIM",
        "FLIP",
        "seconds",
        "× faster",
        methods.first().map_or(0, |m| m.edge_band.pixels),
        "PSNR dB",
        "MSSIM"
    );
    for m in methods {
        let db = if m.psnr_db.is_infinite() {
            "∞".to_string()
        } else {
            format!("{:.2}", m.psnr_db)
        };
        let band_db = if m.edge_band.psnr_db.is_infinite() {
            "∞".to_string()
        } else {
            format!("{:.2}", m.edge_band.psnr_db)
        };
        // a truth read from a file has no time, so neither has a speed-up against it
        let shown = |v: f64, digits: usize| {
            if v.is_finite() {
                format!("{v:.digits$}")
            } else {
                "—".to_string()
            }
        };
        let (seconds, speedup) = (shown(m.seconds, 3), shown(m.speedup_vs_reference, 1));
        println!(
            "  {:<13} {:>10} {:>10.4} {:>8.4} {:>10} {:>12}   {:>28} {:>8.4}",
            m.method, db, m.mssim, m.flip_mean, seconds, speedup, band_db, m.edge_band.mssim
        );
    }
}

/// `--truth-bin-d`: a dioptre bin from 0.0001 to 0.1.
fn parse_truth_bin_d(text: &str) -> std::result::Result<f64, String> {
    let bin: f64 = text
        .trim()
        .parse()
        .map_err(|_| format!("`{text}` is not a number of dioptres"))?;
    if !(1e-4..=0.1).contains(&bin) {
        return Err(format!("{bin} is outside 0.0001 to 0.1 D"));
    }
    Ok(bin)
}
