//! `ocular compare`: the seed paper's Table 2 for one scene and eye — ground truth, tiled
//! splatting and depth slices from the same kernels and inputs, with PSNR, MSSIM, time per
//! method and speed ratios; optionally the images and false-colour SSIM maps (Figure 12).

use std::path::PathBuf;

use clap::Args;

use super::outputs::Outputs;
use super::raster::parse_frame_size;
use super::render::load_eye;
use super::Cli;
use crate::gpu::Context;
use crate::image_io::{self, ImageRgba, Tonemap, TonemapMode};
use crate::metrics::flip::{ldr_flip, FlipStats};
use crate::metrics::{psnr, ssim, ssim_false_colour, ImageView};
use crate::render::frame::{FrameRenderer, Method, RenderedFrame};
use crate::render::splat::FrameInput;
use crate::scene::Scene;
use crate::{Error, Result};

#[derive(Debug, Args)]
#[command(after_help = "Examples:\n  \
    ocular compare --scene primitives --eye myopia --size 320x180\n  \
    ocular compare --scene primitives --eye keratoconus --json kc.json --maps maps/\n\n\
Quality is measured against the ground truth on the displayed image: linear values at the input \
frame's automatic exposure, clamped to [0, 1] (PSNR with a peak of 1; SSIM with Wang et al.'s \
settings; FLIP is LDR-FLIP at --flip-ppd; in JSON a PSNR of null means identical images). The ground truth computes one exact PSF per 0.001 D \
bin and channel, on the CPU: it is slow by design.")]
pub struct CompareArgs {
    /// Built-in scene or a scene .toml file (rendered at t = 0).
    #[arg(long, value_name = "NAME|FILE", default_value = "primitives")]
    pub scene: String,
    /// Eye preset or eye .toml file.
    #[arg(long, value_name = "NAME|FILE", default_value = "myopia")]
    pub eye: String,
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
    /// Kernel cache folder (default: $XDG_CACHE_HOME/ocular or ~/.cache/ocular).
    #[arg(long, value_name = "DIR", conflicts_with = "no_cache")]
    pub cache: Option<PathBuf>,
    /// Neither read nor write the kernel cache.
    #[arg(long)]
    pub no_cache: bool,
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

/// How far the views truth is from converged: the change when its views double (the even
/// half against all of them), on the displayed image.
#[derive(Clone, Debug, serde::Serialize)]
pub struct ViewsConvergence {
    pub views: u32,
    pub half_views: u32,
    /// PSNR (dB) and MSSIM of the half-views image against the full one.
    pub psnr_db: f64,
    pub mssim: f64,
    /// Largest change of a displayed channel value (0–1).
    pub max_abs_change: f64,
    pub seconds_raster: f64,
    pub seconds_accumulate: f64,
}

#[derive(Clone, Debug, serde::Serialize)]
pub struct MethodResult {
    pub method: String,
    pub seconds: f64,
    pub psnr_db: f64,
    pub mssim: f64,
    pub speedup_vs_reference: f64,
    /// Mean LDR-FLIP of the displayed image against the truth's, at the report's `flip_ppd`.
    pub flip_mean: f64,
    /// GPU time of all passes (splat only).
    pub gpu_ms: Option<f64>,
    /// Depth layers the method saw.
    pub layers: u32,
    /// Quality over the occlusion-edge band (pixels within the local blur radius of a depth
    /// discontinuity).
    pub edge_band: super::edge_band::BandQuality,
}

#[derive(serde::Serialize)]
struct Report {
    scene: String,
    eye: String,
    width: u32,
    height: u32,
    focus_d: f64,
    pupil_mm: f64,
    device: String,
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

/// What the ground truth has in common with splat, printed with every comparison.
const TRUTH_SHARES: &str = "ground truth: the exact PSF of every pixel's vergence; it shares the \
blend (depth groups), the pinhole's local layout and the PSFs with splat, so it judges splat's \
kernel approximations (interpolation over distance and radius, merging, half-float texels), \
not the blend or the optics";

/// What the off-axis reference has in common with off-axis splat.
const FIELD_TRUTH_SHARES: &str = "ground truth: the exact PSF of every pixel's vergence and \
direction (the eye traced for every 1° field bin, no lattice); it shares the blend, the \
pinhole's local layout and the PSF computation of a direction with splat, so it judges the \
field lattice and its interpolation as well as the kernel approximations, not the optics";

/// A truth read with --truth-in: what it shares is what the run that saved it shared.
const LOADED_TRUTH_SHARES: &str = "ground truth: read with --truth-in; it shares with these \
methods what the run that saved it said (e.g. an off-axis reference judging on-axis splat \
measures what the field's aberrations change)";

/// What the views truth has in common with the methods it judges.
const VIEWS_SHARES: &str = "ground truth: multi-view accumulation over the pupil (geometric \
optics, rasterised from each pupil point, each channel shifted by the eye's ray aberration); it \
shares the scene, the focused eye and its Zernike coefficients per wavelength with splat, not \
the kernels, the blend or the single visible layer; it leaves out diffraction, so it judges \
where geometric blur dominates";

/// The displayed image: linear values scaled by the exposure, clamped to [0, 1].
fn exposed(image: &[[f32; 4]], scale: f32) -> Vec<[f32; 4]> {
    image
        .iter()
        .map(|p| [0, 1, 2].map(|c| (p[c] * scale).clamp(0.0, 1.0)))
        .map(|v| [v[0], v[1], v[2], 1.0])
        .collect()
}

pub fn run(cli: &Cli, args: &CompareArgs) -> Result<()> {
    let splat = args.splat.settings()?;
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
    // Declared before the outputs so that it is dropped after their temporaries are.
    let maps_created = match &args.maps {
        Some(dir) => Some(maps_folder(dir)?),
        None => None,
    };
    let mut outputs = Outputs::new();
    if let Some(path) = &args.truth_out {
        outputs.add("--truth-out", path, &["exr"])?;
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
            outputs.add("--maps", &dir.join(format!("{name}.png")), &["png"])?;
        }
        for name in args.judge.iter().map(|p| judged_name(p)) {
            outputs.add("--maps", &dir.join(format!("{name}.png")), &["png"])?;
            outputs.add("--maps", &dir.join(format!("ssim_{name}.png")), &["png"])?;
        }
    }
    outputs.probe()?;
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
    let judged: Vec<(String, ImageRgba)> = args
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
    let eye = args.correction.apply(&load_eye(&args.eye)?, None)?.0;
    let scene = Scene::load(&args.scene)?;
    let ctx = Context::new(&cli.context_options())?;
    let (width, height) = args.size;
    let (frame, eye_state, screen) =
        super::measured_scene_frame(&ctx, &scene, args.size, args.pupil_mm)?;
    let (focus_d, pupil_mm) = (eye_state.focus_d, eye_state.pupil_mm);
    let mut options = super::kernel_options(args.cache.as_ref(), args.no_cache);
    options.reference_axes.objects =
        crate::psf::kernels::DioptreAxis::spanning(0.125, 10.125, args.object_samples);
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
    options.field_width_px = args.splat.off_axis.then_some(width);
    let kernels = super::frame_kernels(&eye, &frame, eye_state, screen, &options)?;
    let mut notes = Vec::new();
    let layers = super::occlusion::scene_layers(&ctx, args.layers, args.size, &mut notes);
    for n in &notes {
        println!("note: {n}");
    }
    let mut renderer = FrameRenderer::new(&ctx, eye, kernels, options.settings.clone(), splat);
    renderer.slice_count = args.slices;
    if let Some(bin) = args.truth_bin_d {
        renderer.reference_dioptre_bin_d = bin;
    }
    let input = FrameInput {
        width,
        height,
        color: &frame.color,
        depth_m: &frame.depth_m,
        fov_y_deg: screen.fov_y_deg,
        hidden_layers: &[],
    };

    let truth_method = match args.truth {
        TruthArg::Reference => Method::Reference,
        TruthArg::Views => Method::Views,
    };
    let mut convergence_images = None;
    let truth = match (&args.truth_in, truth_in) {
        (Some(path), Some(image)) => {
            if (image.width, image.height) != (width, height) {
                return Err(Error::input(format!(
                    "--truth-in {} is {}×{}, the frame is {width}×{height}",
                    path.display(),
                    image.width,
                    image.height
                )));
            }
            RenderedFrame {
                color: image.pixels,
                method: truth_method,
                seconds: f64::NAN,
                timings: None,
                stats: None,
            }
        }
        _ if truth_method == Method::Views => {
            let started = std::time::Instant::now();
            let state = scene.at_time(0.0);
            let column = crate::psf::defocus::ColumnOptics::new(
                renderer.eye(),
                pupil_mm,
                focus_d,
                renderer.kernels().grid.wavelengths_nm,
                &options.settings,
            )?;
            let image = crate::render::views::render(
                &ctx,
                &mut crate::render::Rasterizer::new(&ctx)?,
                &state,
                (width, height),
                &column,
                focus_d,
                args.views.unwrap_or(crate::render::views::DEFAULT_VIEWS),
            )?;
            let seconds = started.elapsed().as_secs_f64();
            let color = image.color.clone();
            convergence_images = Some(image);
            RenderedFrame {
                color,
                method: Method::Views,
                seconds,
                timings: None,
                stats: None,
            }
        }
        _ => renderer.render(&input, eye_state, Method::Reference)?,
    };
    let reference_frame = if truth_method == Method::Views {
        Some(renderer.render(&input, eye_state, Method::Reference)?)
    } else {
        None
    };
    // The first splat frame compiles shaders and uploads the kernels: time the second.
    if !args.no_warmup {
        renderer.render(&input, eye_state, Method::Splat)?;
    }
    let splat_frame = renderer.render(&input, eye_state, Method::Splat)?;
    // The layered frame is peeled and splatted in one submission, its layers never on the
    // host (tests/engine.rs: the same image as the layers read back and uploaded).
    let layered_frame = if layers > 1 {
        let state = scene.at_time(0.0);
        let mut raster = crate::render::Rasterizer::new(&ctx)?;
        let gap_d = splat.blend.group_tolerance_d;
        let mut layered = || {
            let mut recorded = raster
                .scene_frame(&ctx, &state, args.size)
                .peeled(layers, gap_d);
            renderer.render_recorded(&mut recorded, eye_state)
        };
        layered()?;
        Some(layered()?)
    } else {
        None
    };
    // slices have no off-axis variant: leave them out rather than compare the on-axis PSF
    let slices_frame = if args.no_slices || args.splat.off_axis {
        None
    } else {
        Some(renderer.render(&input, eye_state, Method::Slices)?)
    };

    let (w, h) = (width as usize, height as usize);
    // Compare what a person sees: every image at the input frame's automatic exposure.
    let exposure_ev =
        Tonemap::auto_exposure_ev(&ImageRgba::new(width, height, frame.color.clone()));
    let scale = 2f32.powf(exposure_ev);
    let truth01 = exposed(&truth.color, scale);
    let reference_seconds = reference_frame.as_ref().unwrap_or(&truth).seconds;
    let views_convergence = convergence_images.as_ref().map(|image| {
        let full = exposed(&image.color, scale);
        let half = exposed(&image.half_color, scale);
        let quality = ssim(
            ImageView::new(w, h, &half),
            ImageView::new(w, h, &full),
            1.0,
        );
        let max_abs_change = half
            .iter()
            .zip(&full)
            .flat_map(|(a, b)| (0..3).map(move |c| f64::from((a[c] - b[c]).abs())))
            .fold(0.0, f64::max);
        ViewsConvergence {
            views: image.views,
            half_views: image.views.div_ceil(2),
            psnr_db: psnr(
                ImageView::new(w, h, &half),
                ImageView::new(w, h, &full),
                1.0,
            ),
            mssim: quality.mean,
            max_abs_change,
            seconds_raster: image.seconds_raster,
            seconds_accumulate: image.seconds_accumulate,
        }
    });
    let mut methods = Vec::new();
    let mut maps = Vec::new();
    let mut window_px = 11;
    let judged_frames: Vec<(RenderedFrame, String)> = judged
        .into_iter()
        .map(|(name, image)| {
            let frame = RenderedFrame {
                color: image.pixels,
                method: truth_method,
                seconds: f64::NAN,
                timings: None,
                stats: None,
            };
            (frame, name)
        })
        .collect();
    let frames: Vec<(&RenderedFrame, String, u32)> = [
        Some((&truth, truth_method.name().to_string(), 1)),
        reference_frame.as_ref().map(|f| (f, "reference".into(), 1)),
        Some((&splat_frame, "splat".into(), 1)),
        layered_frame
            .as_ref()
            .map(|f| (f, "splat-layers".into(), layers)),
        slices_frame.as_ref().map(|f| (f, "slices".into(), 1)),
    ]
    .into_iter()
    .flatten()
    .chain(judged_frames.iter().map(|(f, name)| (f, name.clone(), 1)))
    .collect();
    let band = super::edge_band::edge_band(
        &frame.depth_m,
        (width, height),
        screen.fov_y_deg,
        &renderer.kernels().grid,
        (pupil_mm, focus_d),
        f64::from(splat.blend.group_tolerance_d),
    );
    for (frame, name, frame_layers) in &frames {
        let (frame, frame_layers) = (*frame, *frame_layers);
        if let Some((count, first)) = non_finite(&frame.color, w) {
            return Err(Error::input(format!(
                "the {} image has {count} pixels that are not finite (first at x = {}, y = {}); \
                 no metric is computed from them",
                frame.method.name(),
                first.0,
                first.1
            )));
        }
        let image = exposed(&frame.color, scale);
        let quality = ssim(
            ImageView::new(w, h, &image),
            ImageView::new(w, h, &truth01),
            1.0,
        );
        let edge_band = super::edge_band::band_quality(&image, &truth01, &quality.map, &band, w);
        methods.push(MethodResult {
            method: name.clone(),
            layers: frame_layers,
            edge_band,
            seconds: frame.seconds,
            psnr_db: psnr(
                ImageView::new(w, h, &image),
                ImageView::new(w, h, &truth01),
                1.0,
            ),
            mssim: quality.mean,
            flip_mean: FlipStats::of(&ldr_flip(
                ImageView::new(w, h, &truth01),
                ImageView::new(w, h, &image),
                args.flip_ppd,
            ))
            .mean,
            // a truth read with --truth-in has no time (NaN), nor a speed-up
            speedup_vs_reference: if frame.seconds.is_nan() {
                f64::NAN
            } else {
                reference_seconds / frame.seconds.max(1e-12)
            },
            gpu_ms: frame.timings.as_ref().map(|t| t.total_ms()),
        });
        maps.push(quality.map);
        window_px = quality.window_px;
    }
    if window_px != 11 {
        println!(
            "note: the frame is under SSIM's 11-pixel window; MSSIM uses a {window_px}×{window_px} window"
        );
    }
    println!(
        "{} through eye {} at {width}×{height}, focus {focus_d:.3} D, pupil {pupil_mm:.2} mm ({})",
        args.scene,
        args.eye,
        ctx.device_info().name
    );
    let truth_shares = if args.truth_in.is_some() {
        LOADED_TRUTH_SHARES
    } else if truth_method == Method::Views {
        VIEWS_SHARES
    } else if args.splat.off_axis {
        FIELD_TRUTH_SHARES
    } else {
        TRUTH_SHARES
    };
    println!("  {truth_shares}");
    if let Some(c) = &views_convergence {
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
    for m in &methods {
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
    if let Some(path) = &args.truth_out {
        image_io::write_exr_rgba(
            outputs.temporary(path),
            &ImageRgba::new(width, height, truth.color.clone()),
        )?;
    }
    if let Some(dir) = &args.maps {
        let shown = Tonemap {
            exposure_ev,
            mode: TonemapMode::Clamp,
        };
        for (i, frame) in frames.iter().enumerate() {
            let name = if i == 0 { "truth" } else { frame.1.as_str() };
            let image = ImageRgba::new(width, height, frame.0.color.clone());
            image_io::write_png(
                outputs.temporary(&dir.join(format!("{name}.png"))),
                &image,
                shown,
            )?;
        }
        let flat = Tonemap {
            exposure_ev: 0.0,
            mode: TonemapMode::Clamp,
        };
        for (frame, map) in frames[1..].iter().zip(&maps[1..]) {
            let name = format!("ssim_{}", frame.1);
            let rgb: Vec<[f32; 4]> = ssim_false_colour(map, 0.9)
                .iter()
                .map(|p| [0, 1, 2].map(|c| image_io::srgb_decode(p[c])))
                .map(|v| [v[0], v[1], v[2], 1.0])
                .collect();
            image_io::write_png(
                outputs.temporary(&dir.join(format!("{name}.png"))),
                &ImageRgba::new(width, height, rgb),
                flat,
            )?;
        }
    }
    if let Some(path) = &args.json {
        let report = Report {
            scene: args.scene.clone(),
            eye: args.eye.clone(),
            width,
            height,
            focus_d,
            pupil_mm,
            device: ctx.device_info().name.clone(),
            truth: if truth_method == Method::Views {
                "views"
            } else {
                "reference"
            },
            truth_shares,
            truth_bin_d: (truth_method == Method::Reference && args.truth_in.is_none())
                .then_some(renderer.reference_dioptre_bin_d),
            views_convergence,
            splat_warmed_up: !args.no_warmup,
            flip_ppd: args.flip_ppd,
            display_exposure_ev: exposure_ev,
            methods,
        };
        let text = serde_json::to_string_pretty(&report)
            .map_err(|e| Error::input(format!("cannot encode JSON: {e}")))?;
        image_io::write_text_atomic(outputs.temporary(path), &text)?;
    }
    outputs.commit()?;
    if let Some(mut created) = maps_created {
        created.keep();
    }
    if let Some(dir) = &args.maps {
        println!(
            "wrote images and SSIM maps (1.0 → navy, ≤ 0.9 → red) to {}",
            dir.display()
        );
    }
    for path in [&args.truth_out, &args.json].into_iter().flatten() {
        println!("wrote {}", path.display());
    }
    Ok(())
}

/// The files `--maps` writes, without extension.
fn map_names(no_slices: bool, views: bool, layers: bool) -> Vec<&'static str> {
    let mut names = vec!["truth"];
    let mut judged = vec![];
    if views {
        judged.push(("reference", "ssim_reference"));
    }
    judged.push(("splat", "ssim_splat"));
    if layers {
        judged.push(("splat-layers", "ssim_splat-layers"));
    }
    if !no_slices {
        judged.push(("slices", "ssim_slices"));
    }
    names.extend(judged.iter().map(|j| j.0));
    names.extend(judged.iter().map(|j| j.1));
    names
}

/// A `--maps` folder this run created, removed again (if still empty) unless kept.
struct CreatedFolder(Option<PathBuf>);

impl CreatedFolder {
    fn keep(&mut self) {
        self.0 = None;
    }
}

impl Drop for CreatedFolder {
    fn drop(&mut self) {
        if let Some(dir) = &self.0 {
            let _ = std::fs::remove_dir(dir);
        }
    }
}

/// The `--maps` folder: an existing folder, or a new one in an existing folder.
fn maps_folder(dir: &std::path::Path) -> Result<CreatedFolder> {
    if dir.is_dir() {
        return Ok(CreatedFolder(None));
    }
    if dir.exists() {
        return Err(Error::input(format!(
            "--maps {}: is a file; give a folder",
            dir.display()
        )));
    }
    std::fs::create_dir(dir)
        .map_err(|e| Error::input(format!("--maps {}: cannot create it ({e})", dir.display())))?;
    Ok(CreatedFolder(Some(dir.to_path_buf())))
}

/// An image for `--truth-in` or `--judge`, refused if any colour value is not finite (metrics
/// of NaN are not numbers).
fn read_truth(option: &str, path: &PathBuf) -> Result<ImageRgba> {
    let image = image_io::read_exr_rgba(path)?;
    if let Some((count, (x, y))) = non_finite(&image.pixels, image.width as usize) {
        return Err(Error::input(format!(
            "{option} {}: {count} pixels are not finite (first at x = {x}, y = {y}); an image \
             to judge or judge by must hold finite colour",
            path.display()
        )));
    }
    Ok(image)
}

/// The row of a `--judge` image: its file name without the extension.
fn judged_name(path: &std::path::Path) -> String {
    let stem = path.file_stem().map(|s| s.to_string_lossy().into_owned());
    stem.filter(|s| !s.is_empty())
        .unwrap_or_else(|| "judged".to_string())
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

/// How many pixels have a non-finite R, G or B, and the first one's (x, y).
fn non_finite(pixels: &[[f32; 4]], width: usize) -> Option<(usize, (usize, usize))> {
    let bad = |p: &[f32; 4]| !(p[0].is_finite() && p[1].is_finite() && p[2].is_finite());
    let first = pixels.iter().position(bad)?;
    let count = pixels.iter().filter(|p| bad(p)).count();
    Some((count, (first % width.max(1), first / width.max(1))))
}
