//! `ocular bench`: the GPU timing harness. A scene's frame is drawn and splatted M times after
//! N warm-up frames, the draw in splat's own submission (the frame stays on the GPU); every
//! pass is timed with GPU timestamp queries, and mean / median / p95 are reported per pass and
//! for the total, beside the precomputation times, in the layout of the seed paper's Table 3.
//! `--compare-methods` adds the ground truth and the slice method.

use std::path::PathBuf;
use std::time::Instant;

use clap::Args;

use super::raster::parse_frame_size;
use super::render::load_eye;
use super::Cli;
use crate::gpu::Context;
use crate::render::frame::{EyeState, FrameRenderer, Method};
use crate::render::splat::FrameInput;
use crate::render::Rasterizer;
use crate::scene::{FrameState, Scene};
use crate::{Error, Result};

#[derive(Clone, Debug, Args)]
#[command(after_help = "Examples:\n  \
    ocular bench --scene primitives --eye myopia --size 1280x720\n  \
    ocular bench --scene colonnade --eye keratoconus --frames 20 --compare-methods --json bench.json\n\n\
GPU times come from timestamp queries around each pass; the total is the sum of the passes of \
one frame. On a CPU implementation (lavapipe) the figures measure the CPU, not a GPU.")]
pub struct BenchArgs {
    /// Built-in scene or a scene .toml file.
    #[arg(long, value_name = "NAME|FILE", default_value = "primitives")]
    pub scene: String,
    /// Eye preset or eye .toml file.
    #[arg(long, value_name = "NAME|FILE", default_value = "myopia")]
    pub eye: String,
    /// Frame size.
    #[arg(long, value_name = "WxH", value_parser = parse_frame_size, default_value = "1280x720")]
    pub size: (u32, u32),
    /// Time each eye's frame at a headset's panel size and vertical field (the scene's camera
    /// takes the headset's field): quest3 (2064×2208, 96°), vive-pro (1440×1600, 110°). With
    /// --binocular the report sets the pair against the headset's refresh interval.
    #[arg(long, value_enum, conflicts_with = "size")]
    pub headset: Option<crate::render::headset::Headset>,
    /// Frames rendered before timing starts (shader compilation, caches).
    #[arg(long, default_value_t = 5)]
    pub warmup: usize,
    /// Timed frames.
    #[arg(long, default_value_t = 100)]
    pub frames: usize,
    /// Depth layers splat takes (1–8; default 1): the scene is depth-peeled to K layers, each
    /// drawn in splat's own submission, so the per-layer cost shows in the passes.
    #[arg(long, value_name = "K", value_parser = super::occlusion::parse_layers)]
    pub layers: Option<u32>,
    /// Pupil diameter (default: the scene's, else 5 mm as in the seed paper's tests).
    #[arg(long, value_name = "MM")]
    pub pupil_mm: Option<f64>,
    #[command(flatten)]
    pub splat: super::SplatArgs,
    /// Also time the ground truth and the slice method once each, and print speed ratios.
    #[arg(long)]
    pub compare_methods: bool,
    /// Also time the same frames through the previous engine and method (the seed paper's
    /// per-fragment blend and narrow-field geometry, the frame read back to the host and
    /// uploaded again, lists planned on the host and the PSF texture rebuilt every frame, no
    /// early exit) and print the ratio.
    #[arg(long)]
    pub baseline: bool,
    /// Also time the scene through two eyes, one submission each, in the same run, and print
    /// the pair's cost against one eye's (docs/binocular.md). Both eyes keep the one-eye run's
    /// focus and pupil.
    #[arg(long)]
    pub binocular: bool,
    /// A diagnostic of the draw: shade nothing (each surface its reflectance, unlit), so the
    /// raster pass times the fixed-function work alone (rasterising, writing 4 samples a pixel,
    /// resolving). The frame is not the scene's, and the splat's passes see other colours.
    #[arg(long)]
    pub draw_unshaded: bool,
    /// A diagnostic of the draw: samples per pixel (2, 4 or 8; every frame uses 4), to see how
    /// its time follows them. Edges and mixed pixels are only as fine as the samples.
    #[arg(long, value_name = "N", value_parser = parse_draw_samples)]
    pub draw_samples: Option<u32>,
    /// A diagnostic of the draw: its multisampled colour in half floats (8 bytes a sample
    /// instead of 16), to see how its time follows the bytes it writes. Light over 65504
    /// cd/m² clips, so the frame is not every frame's.
    #[arg(long)]
    pub draw_half_colour: bool,
    /// With --binocular: the right eye (a preset or an eye file); --eye is then the left.
    #[arg(long, value_name = "NAME|FILE")]
    pub eye_right: Option<String>,
    /// With --binocular: the interpupillary distance in mm (40 to 80; default 63).
    #[arg(long, value_name = "MM", allow_negative_numbers = true)]
    pub ipd_mm: Option<f64>,
    #[command(flatten)]
    pub cache: super::CacheArgs,
    /// Write the results as JSON.
    #[arg(long, value_name = "FILE")]
    pub json: Option<PathBuf>,
}

#[derive(Clone, Debug, serde::Serialize)]
pub struct Stat {
    pub name: String,
    pub mean_ms: f64,
    pub median_ms: f64,
    pub p95_ms: f64,
}

/// Mean, median and 95th percentile (nearest rank) of samples in ms.
pub fn stat(name: &str, samples: &[f64]) -> Stat {
    let mut sorted = samples.to_vec();
    sorted.sort_by(f64::total_cmp);
    let n = sorted.len().max(1);
    let mean = sorted.iter().sum::<f64>() / n as f64;
    let median = if sorted.is_empty() {
        0.0
    } else if n % 2 == 1 {
        sorted[n / 2]
    } else {
        0.5 * (sorted[n / 2 - 1] + sorted[n / 2])
    };
    let rank = ((0.95 * n as f64).ceil() as usize).clamp(1, n);
    let p95 = sorted.get(rank - 1).copied().unwrap_or(0.0);
    Stat {
        name: name.to_string(),
        mean_ms: mean,
        median_ms: median,
        p95_ms: p95,
    }
}

#[derive(serde::Serialize)]
struct MethodTime {
    method: &'static str,
    seconds: f64,
    ratio_to_splat: f64,
}

#[derive(serde::Serialize)]
struct Report {
    device: String,
    driver: String,
    scene: String,
    eye: String,
    width: u32,
    height: u32,
    /// Depth layers splat took (1: the visible surface).
    layers: u32,
    /// The `--quality` preset, and the settings it became with the options given.
    quality: &'static str,
    settings: crate::render::splat::SplatSettings,
    warmup: usize,
    frames: usize,
    focus_d: f64,
    pupil_mm: f64,
    precompute: Precompute,
    passes: Vec<Stat>,
    total: Stat,
    wall_ms_per_frame: Stat,
    /// Wall minus GPU time per frame: what the host adds (reading the frame back above all).
    host_ms_per_frame: Stat,
    list_entries: u64,
    /// Fragments left after merging (the splat's level of detail).
    live_fragments: u64,
    /// (pixel, fragment) pairs within reach per frame: the convolution's work, read without a
    /// clock.
    kernel_evaluations: u64,
    /// Kernel evaluations per pixel (per visible pixel; hidden layers add to it).
    evaluations_per_pixel: f64,
    /// Filtered texture reads the GPU's convolution makes for those evaluations, at most
    /// (`SplatStats::texture_reads`): what its time follows.
    texture_reads: u64,
    texture_reads_per_pixel: f64,
    max_radius_px: u32,
    /// Device memory of the PSF texture (bytes).
    psf_texture_bytes: u64,
    /// Whether the convolution read each object distance's own kernel (one read per pixel and
    /// fragment) rather than the radius levels (`--level-kernels`, or radii too far apart).
    layer_kernels: bool,
    /// `--off-axis`: the field directions (degrees) the kernels were computed for.
    #[serde(skip_serializing_if = "Option::is_none")]
    field: Option<crate::psf::field::FieldAxes>,
    /// Per steady-state frame: queue submissions, GPU allocations, host↔device bytes.
    counters: Counters,
    baseline: Option<Baseline>,
    methods: Vec<MethodTime>,
    /// `--binocular`: both eyes' cost, beside this one eye's.
    binocular: Option<super::bench_pair::PairBench>,
    /// `--headset`: the panel and field each eye was timed at, and the refresh interval.
    #[serde(skip_serializing_if = "Option::is_none")]
    headset: Option<crate::render::headset::HeadsetSummary>,
    /// `--draw-unshaded`: the draw shaded nothing (a diagnostic of its fixed-function cost).
    draw_unshaded: bool,
    /// Samples per pixel the draw used (4 but under `--draw-samples`).
    draw_samples: u32,
    /// `--draw-half-colour`: the draw's multisampled colour was half floats.
    draw_half_colour: bool,
}

#[derive(Clone, Copy, Debug, Default, serde::Serialize)]
struct Counters {
    submissions: u32,
    /// Bands of tile rows the frame's lists were processed in (1: the whole frame at once).
    bands: u32,
    allocations: u32,
    /// Vulkan objects created for the frame's submissions (0: all reused).
    submission_objects: u64,
    /// Commands recorded, and barriers their declared accesses called for.
    commands: u32,
    barriers: u32,
    upload_bytes: u64,
    readback_bytes: u64,
}

#[derive(serde::Serialize)]
struct Baseline {
    what: &'static str,
    wall_ms_per_frame: Stat,
    gpu_total: Stat,
    counters: Counters,
    /// Baseline wall time over this engine's, per frame.
    speedup: f64,
}

struct TimedFrames {
    per_pass: Vec<(String, Vec<f64>)>,
    totals: Vec<f64>,
    walls: Vec<f64>,
    /// Wall minus GPU time per frame: the host's share (recording, submitting, waiting on the
    /// fence, reading the frame back).
    hosts: Vec<f64>,
    list_entries: u64,
    live_fragments: u64,
    kernel_evaluations: u64,
    texture_reads: u64,
    psf_texture_bytes: u64,
    layer_kernels: bool,
    counters: Counters,
}

/// The scene frame every timed frame draws again.
pub(super) struct SceneInput<'a, 's> {
    pub ctx: &'a Context,
    pub raster: &'a mut Rasterizer,
    pub state: &'a FrameState<'s>,
    pub size: (u32, u32),
    /// Depth layers and the peeling gap (dioptres).
    pub layers: u32,
    pub gap_d: f32,
}

impl SceneInput<'_, '_> {
    /// One frame from the draw to the image: drawn in splat's own submission (`resident`, the
    /// engine), or drawn, read back to the host and uploaded again (the previous engine), with
    /// the raster's submission, bytes and passes added to what splat counted.
    pub fn render(
        &mut self,
        renderer: &mut FrameRenderer,
        eye: crate::render::frame::EyeState,
        resident: bool,
    ) -> Result<crate::render::frame::RenderedFrame> {
        if resident {
            let mut frame = self
                .raster
                .scene_frame(self.ctx, self.state, self.size)
                .peeled(self.layers, self.gap_d);
            return renderer.render_recorded(&mut frame, eye);
        }
        let (width, height) = self.size;
        let frames =
            self.raster
                .render_layers(self.ctx, self.state, self.size, self.layers, self.gap_d)?;
        let hidden: Vec<crate::render::splat::HiddenLayer<'_>> = frames[1..]
            .iter()
            .map(|f| crate::render::splat::HiddenLayer {
                color: &f.color,
                depth_m: &f.depth_m,
            })
            .collect();
        let input = FrameInput {
            width,
            height,
            color: &frames[0].color,
            depth_m: &frames[0].depth_m,
            fov_y_deg: self.state.camera.fov_y_deg,
            hidden_layers: &hidden,
            mixed: None,
        };
        let mut out = renderer.render(&input, eye, Method::Splat)?;
        // a pass drawn once per layer counts once per frame, its times summed
        let mut timings = crate::gpu::Timings::default();
        for pass in frames.iter().flat_map(|f| &f.timings.passes) {
            match timings.passes.iter_mut().find(|p| p.name == pass.name) {
                Some(p) => p.ms += pass.ms,
                None => timings.passes.push(pass.clone()),
            }
        }
        if let Some(t) = out.timings.take() {
            timings.extend(t);
        }
        out.timings = Some(timings);
        if let Some(s) = &mut out.stats {
            // per layer: its draw and read-back; per later layer: the previous layer's depth
            // uploaded (a submission of its own)
            let layers = u64::from(self.layers);
            let pixels = u64::from(width) * u64::from(height);
            s.submissions += (2 * layers - 1) as u32;
            s.upload_bytes +=
                layers * crate::render::raster::FRAME_UNIFORM_BYTES + (layers - 1) * pixels * 4;
            s.readback_bytes += layers * pixels * 20;
        }
        Ok(out)
    }
}

/// Renders the frame `warmup + frames` times; keeps the timings of the last `frames`.
fn time_frames(
    renderer: &mut FrameRenderer,
    scene: &mut SceneInput<'_, '_>,
    resident: bool,
    state: crate::render::frame::EyeState,
    args: &BenchArgs,
    bar: &indicatif::ProgressBar,
) -> Result<TimedFrames> {
    let mut t = TimedFrames {
        per_pass: Vec::new(),
        totals: Vec::with_capacity(args.frames),
        walls: Vec::with_capacity(args.frames),
        hosts: Vec::with_capacity(args.frames),
        list_entries: 0,
        live_fragments: 0,
        kernel_evaluations: 0,
        texture_reads: 0,
        psf_texture_bytes: 0,
        layer_kernels: false,
        counters: Counters::default(),
    };
    for i in 0..args.warmup + args.frames {
        let started = Instant::now();
        let allocations_before = scene.ctx.allocations();
        let out = scene.render(renderer, state, resident)?;
        let allocations = (scene.ctx.allocations() - allocations_before) as u32;
        let wall_ms = started.elapsed().as_secs_f64() * 1e3;
        bar.inc(1);
        if i < args.warmup {
            continue;
        }
        let timings = out.timings.unwrap_or_default();
        for pass in &timings.passes {
            match t.per_pass.iter_mut().find(|(n, _)| *n == pass.name) {
                Some((_, v)) => v.push(pass.ms),
                None => t.per_pass.push((pass.name.clone(), vec![pass.ms])),
            }
        }
        t.totals.push(timings.total_ms());
        t.walls.push(wall_ms);
        t.hosts.push(wall_ms - timings.total_ms());
        if let Some(s) = out.stats {
            t.list_entries = s.list_entries;
            t.live_fragments = s.live_fragments;
            t.kernel_evaluations = s.kernel_evaluations;
            t.texture_reads = s.texture_reads;
            t.psf_texture_bytes = s.psf_texture_bytes;
            t.layer_kernels = s.layer_kernels;
            t.counters = Counters {
                submissions: s.submissions,
                bands: s.bands,
                // the device's own count: raster, splat and transfers alike
                allocations,
                submission_objects: s.submission_objects,
                commands: s.commands,
                barriers: s.barriers,
                upload_bytes: s.upload_bytes,
                readback_bytes: s.readback_bytes,
            };
        }
    }
    Ok(t)
}

#[derive(serde::Serialize)]
struct Precompute {
    from_cache: bool,
    psfs: usize,
    seconds_eye_optics: f64,
    seconds_psfs: f64,
    seconds_kernels: f64,
    seconds_total: f64,
}

impl Precompute {
    fn of(kernels: &crate::render::frame::PreparedKernels) -> Precompute {
        let report = kernels.report.as_ref();
        Precompute {
            from_cache: report.is_none(),
            psfs: report.map_or(0, |r| r.psfs_computed),
            seconds_eye_optics: report.map_or(0.0, |r| r.seconds_optics),
            seconds_psfs: report.map_or(0.0, |r| r.seconds_psfs),
            seconds_kernels: report.map_or(0.0, |r| r.seconds_kernels),
            seconds_total: kernels.seconds,
        }
    }
}

/// What the report says of the kernels.
struct KernelFacts {
    precompute: Precompute,
    max_radius_px: u32,
    field: Option<crate::psf::field::FieldAxes>,
}

impl Report {
    /// The one-eye run's report; the optional runs' parts empty.
    fn timed(
        args: &BenchArgs,
        info: &crate::gpu::DeviceInfo,
        splat: crate::render::splat::SplatSettings,
        eye_state: EyeState,
        layers: u32,
        facts: KernelFacts,
        timed: &TimedFrames,
    ) -> Report {
        Report {
            device: info.name.clone(),
            driver: info.driver.clone(),
            scene: args.scene.clone(),
            eye: args.eye.clone(),
            width: args.size.0,
            height: args.size.1,
            layers,
            quality: args.splat.quality.name(),
            settings: splat,
            warmup: args.warmup,
            frames: args.frames,
            focus_d: eye_state.focus_d,
            pupil_mm: eye_state.pupil_mm,
            precompute: facts.precompute,
            passes: timed.per_pass.iter().map(|(n, v)| stat(n, v)).collect(),
            total: stat("total", &timed.totals),
            wall_ms_per_frame: stat("wall", &timed.walls),
            host_ms_per_frame: stat("host", &timed.hosts),
            list_entries: timed.list_entries,
            live_fragments: timed.live_fragments,
            kernel_evaluations: timed.kernel_evaluations,
            evaluations_per_pixel: per_pixel(timed.kernel_evaluations, args.size),
            texture_reads: timed.texture_reads,
            texture_reads_per_pixel: per_pixel(timed.texture_reads, args.size),
            max_radius_px: facts.max_radius_px,
            psf_texture_bytes: timed.psf_texture_bytes,
            layer_kernels: timed.layer_kernels,
            field: facts.field,
            counters: timed.counters,
            baseline: None,
            methods: Vec::new(),
            binocular: None,
            headset: None,
            draw_unshaded: false,
            draw_samples: crate::render::MSAA_SAMPLES,
            draw_half_colour: false,
        }
    }
}

fn parse_draw_samples(s: &str) -> std::result::Result<u32, String> {
    use crate::render::RASTER_SAMPLE_COUNTS;
    s.trim()
        .parse::<u32>()
        .ok()
        .filter(|n| RASTER_SAMPLE_COUNTS.contains(n))
        .ok_or_else(|| "allowed 2, 4 or 8 samples per pixel".to_string())
}

/// The rasteriser of a bench run: every frame's, or the draw's diagnostics (`--draw-unshaded`,
/// `--draw-samples`, `--draw-half-colour`).
fn draw_rasterizer(ctx: &Context, args: &BenchArgs) -> Result<Rasterizer> {
    use crate::render::{SurfaceInputs, MSAA_SAMPLES};
    let inputs = if args.draw_unshaded {
        println!("note: --draw-unshaded: the draw shades nothing; only its time is meaningful");
        SurfaceInputs::Unshaded
    } else {
        SurfaceInputs::Covered
    };
    let samples = args.draw_samples.unwrap_or(MSAA_SAMPLES);
    if samples != MSAA_SAMPLES {
        println!("note: --draw-samples {samples}: edges are not every frame's; time the draw only");
    }
    if args.draw_half_colour {
        println!("note: --draw-half-colour: light over 65504 cd/m² clips; time the draw only");
    }
    Rasterizer::for_diagnostic(ctx, inputs, samples, args.draw_half_colour).map_err(|e| {
        if samples == MSAA_SAMPLES {
            e
        } else {
            Error::input(format!("--draw-samples {samples}: {e}"))
        }
    })
}

/// Checks the options that need no device, and the report's path, before minutes of
/// benchmarking, not after.
fn checked_outputs(args: &BenchArgs) -> Result<super::outputs::Outputs> {
    if args.frames == 0 {
        return Err(Error::input("--frames must be at least 1"));
    }
    let mut outputs = super::outputs::Outputs::new();
    if let Some(path) = &args.json {
        outputs.add("--json", path, &["json"])?;
    }
    outputs.probe()?;
    if args.binocular {
        super::bench_pair::ipd_mm(args)?;
    } else if let Some(option) = [
        ("--eye-right", args.eye_right.is_some()),
        ("--ipd-mm", args.ipd_mm.is_some()),
    ]
    .iter()
    .find_map(|(name, given)| given.then_some(name))
    {
        return Err(Error::input(format!("{option} needs --binocular")));
    }
    Ok(outputs)
}

/// Per pixel of a frame of `size`.
fn per_pixel(count: u64, (width, height): (u32, u32)) -> f64 {
    count as f64 / (f64::from(width) * f64::from(height))
}

pub fn run(cli: &Cli, args: &BenchArgs) -> Result<()> {
    let (args, scene) = &headset_frame(args)?;
    let outputs = checked_outputs(args)?;
    let mut splat = args.splat.settings()?;
    let eye = load_eye(&args.eye)?;
    let ctx = Context::new(&cli.context_options())?;
    let width = args.size.0;
    let (frame, eye_state, screen) =
        super::measured_scene_frame(&ctx, scene, args.size, args.pupil_mm, false)?;
    // the white `render` would show this frame at, as the unit of the merge's colour bound
    splat.merge.white = crate::render::splat::display_white(
        crate::image_io::Tonemap::auto_exposure_ev_of(&frame.color),
    );
    let mut options = args.cache.kernel_options();
    options.field_width_px = args.splat.off_axis.then_some(width);
    let kernels = super::frame_kernels(&eye, &frame, eye_state, screen, &options)?;
    let facts = KernelFacts {
        precompute: Precompute::of(&kernels),
        max_radius_px: kernels.grid.max_radius_px,
        field: kernels.field.as_ref().map(|f| f.plan.axes.clone()),
    };
    let baseline_inputs = args.baseline.then(|| (eye.clone(), kernels.clone()));
    let right_inputs =
        super::bench_pair::right_eye(args, &eye, &kernels, &frame, (eye_state, screen), &options)?;
    let mut notes = Vec::new();
    let layers = super::occlusion::scene_layers(&ctx, args.layers, args.size, &mut notes);
    notes.iter().for_each(|n| println!("note: {n}"));
    let gap_d = splat.blend.group_tolerance_d;
    let mut renderer = FrameRenderer::new(&ctx, eye, kernels, options.settings.clone(), splat);
    let input = frame.input(screen.fov_y_deg);
    let runs = 1 + usize::from(args.baseline) + usize::from(args.binocular);
    let bar = super::frame_progress_bar((runs * (args.warmup + args.frames)) as u64);
    let scene_state = scene.at_time(0.0);
    let mut raster = draw_rasterizer(&ctx, args)?;
    let mut scene_input = SceneInput {
        ctx: &ctx,
        raster: &mut raster,
        state: &scene_state,
        size: args.size,
        layers,
        gap_d,
    };
    let timed = time_frames(&mut renderer, &mut scene_input, true, eye_state, args, &bar)?;
    let baseline = match baseline_inputs {
        Some((eye, kernels)) => Some(
            BaselineRun {
                renderer: FrameRenderer::new(
                    &ctx,
                    eye,
                    kernels,
                    options.settings.clone(),
                    paper(splat),
                ),
                scene: &mut scene_input,
                eye_state,
                bar: &bar,
            }
            .time(args, &timed)?,
        ),
        None => None,
    };
    let binocular = match right_inputs {
        Some((eye, kernels)) => Some(
            super::bench_pair::PairRun {
                ctx: &ctx,
                raster: scene_input.raster,
                state: &scene_state,
                eye_state,
                layers,
                gap_d,
                one_eye_ms: (
                    stat("", &timed.totals).mean_ms,
                    stat("", &timed.walls).mean_ms,
                ),
            }
            .time(
                args,
                &mut renderer,
                (eye, kernels, options.settings.clone(), splat),
                &bar,
            )?,
        ),
        None => None,
    };
    bar.finish_and_clear();
    let methods = if args.compare_methods {
        method_times(
            &mut renderer,
            &input,
            eye_state,
            stat("wall", &timed.walls).mean_ms / 1e3,
        )?
    } else {
        Vec::new()
    };
    let mut report = Report::timed(
        args,
        ctx.device_info(),
        splat,
        eye_state,
        layers,
        facts,
        &timed,
    );
    (report.baseline, report.methods, report.binocular) = (baseline, methods, binocular);
    report.headset = args.headset.map(|h| h.summary());
    report.draw_unshaded = args.draw_unshaded;
    report.draw_samples = args.draw_samples.unwrap_or(crate::render::MSAA_SAMPLES);
    report.draw_half_colour = args.draw_half_colour;
    write_report(&report, args, outputs)
}

/// The options and scene as `--headset` (if any) makes them: its panel for the frame's size,
/// its vertical field for the scene's camera.
fn headset_frame(args: &BenchArgs) -> Result<(BenchArgs, Scene)> {
    let scene = Scene::load(&args.scene)?;
    Ok(match args.headset {
        Some(h) => {
            let (scene, size) = h.spec().frame(scene);
            let args = BenchArgs {
                size,
                ..args.clone()
            };
            (args, scene)
        }
        None => (args.clone(), scene),
    })
}

/// Prints the report and writes its JSON where asked.
fn write_report(report: &Report, args: &BenchArgs, outputs: super::outputs::Outputs) -> Result<()> {
    print_table(report);
    if let Some(p) = &report.binocular {
        super::bench_pair::print(p);
    }
    if let Some(h) = &report.headset {
        print_headset(h, report);
    }
    if let Some(path) = &args.json {
        let text = serde_json::to_string_pretty(report)
            .map_err(|e| Error::input(format!("cannot encode JSON: {e}")))?;
        crate::image_io::write_text_atomic(outputs.temporary(path), &text)?;
    }
    outputs.commit()?;
    if let Some(path) = &args.json {
        println!("wrote {}", path.display());
    }
    Ok(())
}

/// The headset's line: each eye's frame, and the frame (or pair) against its refresh interval.
fn print_headset(h: &crate::render::headset::HeadsetSummary, report: &Report) {
    let (what, gpu_ms) = match &report.binocular {
        Some(p) => ("both eyes", p.gpu_total.mean_ms),
        None => ("one eye", report.total.mean_ms),
    };
    println!();
    println!(
        "{}: {}×{} per eye, {:.1}° × {:.1}°; {what} take {gpu_ms:.3} ms of GPU time against \
         {:.1} ms at {} Hz ({:.2}× the budget{})",
        h.name,
        h.width_px,
        h.height_px,
        h.fov_x_deg,
        h.fov_y_deg,
        h.frame_budget_ms,
        h.refresh_hz,
        gpu_ms / h.frame_budget_ms,
        if report.binocular.is_none() {
            "; add --binocular for the pair"
        } else {
            ""
        }
    );
}

/// The splatting settings before this work: the seed paper's blend and narrow field, no
/// steady state, no early exit.
fn paper(splat: crate::render::splat::SplatSettings) -> crate::render::splat::SplatSettings {
    crate::render::splat::SplatSettings {
        blend: crate::render::blend::BlendSettings::paper(),
        saturation_epsilon: 0.0,
        steady_state: false,
        ..splat
    }
}

/// The baseline's frames, timed as the product's were.
struct BaselineRun<'r, 'a, 's> {
    renderer: FrameRenderer,
    scene: &'r mut SceneInput<'a, 's>,
    eye_state: EyeState,
    bar: &'r indicatif::ProgressBar,
}

impl BaselineRun<'_, '_, '_> {
    fn time(&mut self, args: &BenchArgs, timed: &TimedFrames) -> Result<Baseline> {
        let old_timed = time_frames(
            &mut self.renderer,
            &mut *self.scene,
            false,
            self.eye_state,
            args,
            self.bar,
        )?;
        let (new_ms, old_ms) = (
            stat("wall", &timed.walls).mean_ms,
            stat("wall", &old_timed.walls).mean_ms,
        );
        Ok(Baseline {
            what: "the seed paper's blend and narrow-field geometry, the frame read back to the \
                   host and uploaded again, lists planned on the host and the PSF texture \
                   rebuilt every frame, no early exit",
            wall_ms_per_frame: stat("wall", &old_timed.walls),
            gpu_total: stat("total", &old_timed.totals),
            counters: old_timed.counters,
            speedup: old_ms / new_ms,
        })
    }
}

/// Splat's wall time per frame against one frame of the reference and of the slices.
fn method_times(
    renderer: &mut FrameRenderer,
    input: &FrameInput<'_>,
    eye_state: EyeState,
    splat_seconds: f64,
) -> Result<Vec<MethodTime>> {
    let mut methods = vec![MethodTime {
        method: "splat",
        seconds: splat_seconds,
        ratio_to_splat: 1.0,
    }];
    for method in [Method::Reference, Method::Slices] {
        let out = renderer.render(input, eye_state, method)?;
        methods.push(MethodTime {
            method: method.name(),
            seconds: out.seconds,
            ratio_to_splat: out.seconds / splat_seconds,
        });
    }
    Ok(methods)
}

fn print_table(r: &Report) {
    println!(
        "ocular bench — {} through eye {} at {}×{} on {} ({})",
        r.scene, r.eye, r.width, r.height, r.device, r.driver
    );
    println!(
        "focus {:.3} D, pupil {:.2} mm, Rmax {} px, {} depth layer(s), PSF texture {:.1} MiB",
        r.focus_d,
        r.pupil_mm,
        r.max_radius_px,
        r.layers,
        r.psf_texture_bytes as f64 / f64::from(1u32 << 20)
    );
    println!(
        "per frame: {} fragments after merging, {} list entries, {} kernel evaluations ({:.1} per pixel), {}",
        r.live_fragments,
        r.list_entries,
        r.kernel_evaluations,
        r.evaluations_per_pixel,
        if r.layer_kernels {
            "layer kernels"
        } else {
            "radius levels"
        }
    );
    println!(
        "texture reads: {} ({:.1} per pixel, {:.2} per evaluation; the GPU walk's, at most)",
        r.texture_reads,
        r.texture_reads_per_pixel,
        r.texture_reads as f64 / (r.kernel_evaluations.max(1) as f64)
    );
    if let Some(f) = &r.field {
        println!(
            "off axis: {} × {} field directions (h {:+.1}..{:+.1}°, v {:+.1}..{:+.1}°)",
            f.h_deg.len(),
            f.v_deg.len(),
            f.h_deg[0],
            f.h_deg[f.h_deg.len() - 1],
            f.v_deg[0],
            f.v_deg[f.v_deg.len() - 1]
        );
    }
    println!();
    let p = &r.precompute;
    if p.from_cache {
        println!(
            "precomputation: kernels loaded from the cache in {:.2} s (--no-cache to time it)",
            p.seconds_total
        );
    } else {
        println!("precomputation ({} PSFs)", p.psfs);
        println!("  {:<22} {:>9.2} s", "eye optics", p.seconds_eye_optics);
        println!("  {:<22} {:>9.2} s", "PSFs", p.seconds_psfs);
        println!("  {:<22} {:>9.2} s", "kernels", p.seconds_kernels);
        println!("  {:<22} {:>9.2} s", "total (with I/O)", p.seconds_total);
    }
    println!();
    println!(
        "runtime over {} frames after {} warm-up (GPU timestamps, ms)",
        r.frames, r.warmup
    );
    println!(
        "  {:<22} {:>10} {:>10} {:>10}",
        "pass", "mean", "median", "p95"
    );
    for s in r.passes.iter().chain(std::iter::once(&r.total)) {
        println!(
            "  {:<22} {:>10.3} {:>10.3} {:>10.3}",
            s.name, s.mean_ms, s.median_ms, s.p95_ms
        );
    }
    let w = &r.wall_ms_per_frame;
    println!(
        "  {:<22} {:>10.3} {:>10.3} {:>10.3}   (CPU wall, upload and read-back included)",
        "wall per frame", w.mean_ms, w.median_ms, w.p95_ms
    );
    let h = &r.host_ms_per_frame;
    println!(
        "  {:<22} {:>10.3} {:>10.3} {:>10.3}   (wall − GPU: recording, waiting, read-back)",
        "host per frame", h.mean_ms, h.median_ms, h.p95_ms
    );
    let c = &r.counters;
    println!(
        "  per frame: {} submission(s), {} band(s), {} allocation(s), {} Vulkan object(s) created, {} barrier(s) for {} command(s), {} B up, {} B down",
        c.submissions, c.bands, c.allocations, c.submission_objects, c.barriers, c.commands, c.upload_bytes, c.readback_bytes
    );
    if let Some(b) = &r.baseline {
        println!();
        println!("baseline: {}", b.what);
        // speedup = baseline time / this time; say it the way round a reader expects.
        let verdict = if b.speedup >= 1.0 {
            format!("this engine is {:.2}× faster", b.speedup)
        } else {
            format!(
                "this engine takes {:.2}× the baseline's time",
                1.0 / b.speedup.max(1e-9)
            )
        };
        println!(
            "  wall per frame {:.3} ms mean ({} submissions, {} allocations): {verdict}",
            b.wall_ms_per_frame.mean_ms, b.counters.submissions, b.counters.allocations
        );
    }
    if !r.methods.is_empty() {
        println!();
        println!("methods (wall seconds per frame)");
        for m in &r.methods {
            println!(
                "  {:<22} {:>10.3} s  {:>8.1}× splat",
                m.method, m.seconds, m.ratio_to_splat
            );
        }
    }
}

#[cfg(test)]
mod tests {
    use super::stat;

    #[test]
    fn statistics_follow_their_definitions() {
        let s = stat("x", &[5.0, 1.0, 3.0, 2.0, 4.0]);
        assert_eq!((s.mean_ms, s.median_ms, s.p95_ms), (3.0, 3.0, 5.0));
        let even = stat("x", &[4.0, 1.0, 3.0, 2.0]);
        assert_eq!(even.median_ms, 2.5);
        let many: Vec<f64> = (1..=100).map(f64::from).collect();
        assert_eq!(stat("x", &many).p95_ms, 95.0);
    }
}
