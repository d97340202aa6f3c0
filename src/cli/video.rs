//! `ocular video`: renders a scene's keyframed animation (or a focus sweep) frame by frame to
//! numbered PNG or EXR files.
//!
//! - Resumable and trusted: the folder's manifest records everything that determines a frame
//!   and every frame's SHA-256 (see `video_manifest`); a run with another configuration is
//!   refused, and a frame is skipped only if its bytes match a recorded digest.
//! - Splittable: kernels are planned from the whole animation (never from the requested range),
//!   and every frame's eye state depends only on its own index, so `--frames 0..50` and
//!   `--frames 50..100` produce byte-identical files (PNG and EXR) to one run over `0..100`.

use std::path::PathBuf;
use std::time::Instant;

use clap::{Args, ValueEnum};

use super::raster::parse_frame_size;
use super::video_files::{
    check_mp4, encode_mp4, probe_writable, remove_stale_temporaries, write_frame,
};
use super::video_frame::{self, compose};
use super::video_manifest::{self as manifest, DigestLog, ExportConfig};
use super::video_pair;
use super::{sha256, Cli};
use crate::eye::Eye;
use crate::gpu::Context;
use crate::image_io::{self, Tonemap, TonemapMode};
use crate::render::frame::FrameRenderer;
use crate::render::frame_plan::load_eye;
use crate::render::timeline::{animation_needs, planning_frames, Timeline};
use crate::render::Rasterizer;
use crate::scene::Scene;
use crate::{Error, Result};

#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum FrameFormat {
    Png,
    Exr,
}

#[derive(Debug, Args)]
#[command(after_help = "Examples:\n  \
    ocular video --scene walk --eye myopia -o frames/ --mp4 walk.mp4\n  \
    ocular video --scene walk --eye healthy --side-by-side keratoconus -o cmp/\n  \
    ocular video --scene primitives --eye healthy --focus-sweep 0.2..7.5 --duration 4 -o sweep/\n  \
    ocular video --scene walk --binocular --eye healthy --eye-right near.toml --age 55 -o pair/\n\n\
Split a long export across machines with --frames A..B (frames A to B−1): each job writes its own \
files into the same folder, and the union is identical to one run. The folder's ocular-video.json \
records the configuration: a run with another one is refused unless --overwrite. A frame is \
skipped only if its bytes match the SHA-256 recorded when it was written (ocular-video.sums/). \
See docs/video.md for Slurm, GNU parallel and Kubernetes recipes.")]
pub struct VideoArgs {
    /// Built-in scene or a scene .toml file.
    #[arg(long, value_name = "NAME|FILE")]
    pub scene: String,
    /// Eye preset or eye .toml file.
    #[arg(long, value_name = "NAME|FILE", default_value = "healthy")]
    pub eye: String,
    /// Frames per second.
    #[arg(long, default_value_t = 30.0)]
    pub fps: f64,
    /// Length in seconds (default: the scene's animation, or 2 s for a focus sweep).
    #[arg(long, value_name = "SECONDS")]
    pub duration: Option<f64>,
    /// Frames to render: A..B renders A to B−1; A.. and ..B are open ends. Default: all.
    #[arg(long, value_name = "A..B")]
    pub frames: Option<String>,
    /// Output folder (created if missing).
    #[arg(short, long, value_name = "DIR")]
    pub output: PathBuf,
    /// Frame file format.
    #[arg(long, value_enum, default_value = "png")]
    pub format: FrameFormat,
    /// Frame size (default: the scene's `resolution`).
    #[arg(long, value_name = "WxH", value_parser = parse_frame_size)]
    pub size: Option<(u32, u32)>,
    /// Render each frame (each eye's, with --binocular) at a headset's panel size and vertical
    /// field, the scene's camera taking that field throughout: quest3 (2064×2208, 96°),
    /// vive-pro (1440×1600, 110°). docs/binocular.md gives the published figures.
    #[arg(long, value_enum, conflicts_with = "size")]
    pub headset: Option<crate::render::headset::Headset>,
    /// Render every frame through this second eye as well, side by side and labelled;
    /// `uncorrected` is the --eye without --correct/--iol-d.
    #[arg(long, value_name = "NAME|FILE|uncorrected")]
    pub side_by_side: Option<String>,
    #[command(flatten)]
    pub pair: super::binocular::PairArgs,
    /// How a binocular pair is written (default side-by-side: one frame twice as wide, the left
    /// eye on the left; separate: frame_NNNNNN-left and -right files; anaglyph: red-cyan).
    #[arg(long, value_enum)]
    pub stereo: Option<super::binocular::StereoOutput>,
    #[command(flatten)]
    pub correction: super::correction::CorrectionArgs,
    /// Observer age (years), 20 to 83: the Watson–Yellott pupil and Hofstetter's mean
    /// amplitude of accommodation (unless the eye file or --accommodation-max-d sets one).
    #[arg(long, default_value_t = 30.0, value_parser = super::render::parse_age_years, allow_hyphen_values = true)]
    pub age: f64,
    /// Fixed camera (the scene at t = 0); focus moves from NEAR to FAR metres, linearly in
    /// dioptres.
    #[arg(long, value_name = "NEAR..FAR")]
    pub focus_sweep: Option<String>,
    /// Fixed pupil diameter in mm (default: the scene's pupil or luminance, else each frame's
    /// mean luminance through the Watson–Yellott formula).
    #[arg(long, value_name = "MM")]
    pub pupil_mm: Option<f64>,
    /// Also encode the frames to an MP4 with ffmpeg (needs ffmpeg on PATH; PNG frames).
    #[arg(long, value_name = "FILE.mp4")]
    pub mp4: Option<PathBuf>,
    /// Exposure in EV for PNG frames (default: from frame 0's log-average luminance, then
    /// fixed, so frames do not flicker and splits agree).
    #[arg(long, allow_negative_numbers = true)]
    pub exposure: Option<f32>,
    /// Aberrations across the visual field (as `render --off-axis`): each pixel gets the PSF of
    /// the eye traced for its own direction, mixed from a lattice planned from the frame.
    #[arg(long)]
    pub off_axis: bool,
    /// Speed against accuracy: exact, balanced or fast (as `render --quality`;
    /// docs/quality.md).
    #[arg(long, value_enum, default_value = "balanced")]
    pub quality: crate::render::splat::Quality,
    /// Depth layers splat takes (1–8; default 1): each frame is depth-peeled to K layers, and
    /// hidden surfaces show through blurred edges where the pupil sees past them (as `render
    /// --layers`).
    #[arg(long, value_name = "K", value_parser = super::occlusion::parse_layers)]
    pub layers: Option<u32>,
    #[command(flatten)]
    pub cache: super::CacheArgs,
    /// Replace an export of another configuration in the folder: its manifest, digests and
    /// frames are removed first (not for split jobs running at the same time).
    #[arg(long)]
    pub overwrite: bool,
}

/// Parses `A..B`, `A..`, `..B` or `A` into a half-open range within `0..total`.
pub fn parse_range(text: &str, total: usize) -> std::result::Result<(usize, usize), String> {
    let text = text.trim();
    let parse = |s: &str, default: usize| -> std::result::Result<usize, String> {
        if s.is_empty() {
            Ok(default)
        } else {
            s.parse::<usize>()
                .map_err(|_| format!("--frames {text}: \"{s}\" is not a frame number"))
        }
    };
    let (a, b) = match text.split_once("..") {
        Some((a, b)) => (parse(a, 0)?, parse(b, total)?),
        None => {
            let a = parse(text, 0)?;
            (a, a + 1)
        }
    };
    if a >= b {
        return Err(format!(
            "--frames {text}: the range is empty (A..B renders A to B−1)"
        ));
    }
    if b > total {
        return Err(format!(
            "--frames {text}: the animation has {total} frames (0..{total})"
        ));
    }
    Ok((a, b))
}

/// `NEAR..FAR` in metres.
fn parse_sweep(text: &str) -> std::result::Result<(f64, f64), String> {
    let (a, b) = text
        .split_once("..")
        .ok_or_else(|| format!("--focus-sweep \"{text}\" is not NEAR..FAR (metres)"))?;
    let near: f64 = a
        .trim()
        .parse()
        .map_err(|_| format!("--focus-sweep: \"{a}\" is not a distance in metres"))?;
    let far: f64 = b
        .trim()
        .parse()
        .map_err(|_| format!("--focus-sweep: \"{b}\" is not a distance in metres"))?;
    if !(near.is_finite() && near > 0.0 && far > 0.0) {
        return Err(format!(
            "--focus-sweep {text}: distances must be positive metres (far may be inf)"
        ));
    }
    Ok((near, far))
}

pub fn frame_name(index: usize, format: FrameFormat) -> String {
    match format {
        FrameFormat::Png => format!("frame_{index:06}.png"),
        FrameFormat::Exr => format!("frame_{index:06}.exr"),
    }
}

fn sha256_of_debug(values: &[&dyn std::fmt::Debug]) -> String {
    use std::fmt::Write;
    let mut h = sha256::Sha256::default();
    for v in values {
        // Writing into the hasher cannot fail.
        let _ = write!(h, "{v:?}\u{1f}");
    }
    h.finish_hex()
}

/// The scene as this export sees it: its geometry, lights and background, and its state at
/// every frame time (so a changed keyframe or a moved OBJ vertex changes the hash).
fn scene_sha256(timeline: &Timeline) -> String {
    use std::fmt::Write;
    let scene = &timeline.scene;
    let mut h = sha256::Sha256::default();
    let _ = write!(
        h,
        "{:?}|{:?}|{:?}|{:?}|{:?}|{:?}|{:?}",
        scene.geometry,
        scene.lights,
        scene.background_rgb,
        scene.base_camera,
        scene.focus_dpt,
        scene.pupil_mm,
        scene.luminance_cd_m2
    );
    for i in 0..timeline.count {
        let state = timeline.state(i);
        let _ = write!(
            h,
            "|{:?}{:?}{:?}{:?}{:?}",
            state.camera,
            state.focus_m,
            state.pupil_mm,
            state.luminance_cd_m2,
            timeline.focus_d(i, &state)
        );
    }
    h.finish_hex()
}

fn eye_sha256(eye: &Eye) -> Result<String> {
    serde_json::to_string(eye)
        .map(|text| sha256::hex(text.as_bytes()))
        .map_err(|e| Error::input(format!("cannot encode the eye: {e}")))
}

/// `--mp4` is checked before any frame is rendered: ffmpeg, the extension, the folder.
pub fn run(cli: &Cli, args: &VideoArgs) -> Result<()> {
    check_args(args)?;
    let (timeline, headset_size) = timeline_of(args)?;
    let count = timeline.count;
    let (first, end) = match &args.frames {
        Some(text) => parse_range(text, count).map_err(Error::input)?,
        None => (0, count),
    };
    // The pupil model's age also sets the amplitude of accommodation, as in render.
    let pair = args
        .pair
        .asked()
        .then(|| video_pair::PairSetup::from_args(args))
        .transpose()?;
    let eyes = match &pair {
        Some(p) => (0..2)
            .map(|e| (p.specs[e].clone(), p.eyes[e].0.clone()))
            .collect(),
        None => args.correction.labelled_eyes(
            &args.eye,
            load_eye("--eye", &args.eye)?,
            args.side_by_side.as_deref(),
            |spec| load_eye("--side-by-side", spec),
            Some((args.age, crate::eye::age::HofstetterLine::Mean)),
        )?,
    };
    prepare_folder(&args.output)?;
    let (width, height) = args
        .size
        .or(headset_size)
        .unwrap_or((timeline.scene.resolution[0], timeline.scene.resolution[1]));
    let mut options = args.cache.kernel_options();
    options.field_width_px = args.off_axis.then_some(width);
    let config = export_config(args, &timeline, &eyes, (width, height), &options)?;
    // Checked before the manifest is published: a refused run leaves the folder as it was.
    let ctx = Context::new(&cli.context_options())?;
    if let Some(k) = args.layers {
        let fit = crate::render::splat::max_layers(&ctx, width, height).max(1);
        if k > fit {
            return Err(Error::input(format!(
                "--layers {k}: at {width}×{height} this device fits {fit} (its storage-buffer \
                 limit); lower --layers or --size"
            )));
        }
    }
    let removed = manifest::open(&args.output, &config, args.overwrite)?;
    if removed > 0 {
        eprintln!(
            "--overwrite: removed {removed} frames of the previous export in {}",
            args.output.display()
        );
    }
    let todo = frames_to_render(args, first..end);
    let skipped = (end - first) - todo.len();
    let mut log = DigestLog::create(&args.output)?;
    let mut rasterizer = Rasterizer::new(&ctx)?;
    let mut renderers = Vec::new();
    let mut pair_export = None;
    let mut exposure_ev = args.exposure;
    if let (false, Some(setup)) = (todo.is_empty(), pair) {
        let (needs, auto_ev) = video_pair::plan(
            &ctx,
            &mut rasterizer,
            &setup,
            &timeline,
            (width, height),
            args,
        )?;
        exposure_ev = exposure_ev.or(auto_ev);
        let splat = splat_settings(args, exposure_ev);
        pair_export = Some(video_pair::PairExport::new(
            &ctx, setup, needs, options, splat,
        )?);
    } else if !todo.is_empty() {
        let (needs, auto_ev) = animation_needs(
            &ctx,
            &mut rasterizer,
            &timeline,
            (width, height),
            &video_frame::pupil_asked(args),
            args.exposure.is_none(),
        )?;
        exposure_ev = exposure_ev.or(auto_ev);
        let splat = splat_settings(args, exposure_ev);
        for (_, eye) in &eyes {
            let kernels = super::prepare_kernels(eye, &needs, &options)?;
            renderers.push(FrameRenderer::new(
                &ctx,
                eye.clone(),
                kernels,
                options.settings.clone(),
                splat,
            ));
        }
    }
    let mut export = Export {
        ctx: &ctx,
        rasterizer: &mut rasterizer,
        timeline: &timeline,
        size: (width, height),
        eyes: &eyes,
        renderers: &mut renderers,
        pair: pair_export.as_mut(),
        exposure_ev: exposure_ev.unwrap_or(0.0),
    };
    let started = Instant::now();
    export.render(args, &todo, &mut log)?;
    let seconds = started.elapsed().as_secs_f64();
    println!(
        "frames {first}..{end} of {count}: rendered {}, skipped {skipped} already complete (SHA-256 verified), in {seconds:.1} s ({:.2} frames/s) → {}",
        todo.len(),
        todo.len() as f64 / seconds.max(1e-9),
        args.output.display()
    );
    if let Some(mp4) = &args.mp4 {
        encode_mp4(&args.output, args.fps, mp4)?;
    }
    Ok(())
}

/// The scene's animation (or the sweep) as frames, and the headset's panel if one is asked (the
/// scene then seen through its field).
fn timeline_of(args: &VideoArgs) -> Result<(Timeline, Option<(u32, u32)>)> {
    let sweep = args
        .focus_sweep
        .as_deref()
        .map(parse_sweep)
        .transpose()
        .map_err(Error::input)?;
    let (scene, headset_size) = match args.headset.map(|h| h.spec()) {
        Some(h) => {
            let (scene, size) = h.frame(Scene::load(&args.scene)?);
            (scene, Some(size))
        }
        None => (Scene::load(&args.scene)?, None),
    };
    let duration = args.duration.unwrap_or(if sweep.is_some() {
        2.0
    } else {
        scene.duration_s()
    });
    if !(duration.is_finite() && duration >= 0.0) {
        return Err(Error::input(format!(
            "--duration {duration} must be a non-negative number of seconds"
        )));
    }
    let count = ((duration * args.fps).round() as usize).max(1);
    let timeline = Timeline {
        scene,
        fps: args.fps,
        count,
        sweep,
    };
    Ok((timeline, headset_size))
}

/// The splatter's settings: the preset's, with the merge's colour bound a fraction of the white
/// the frames are shown at: frame 0's automatic exposure unless --exposure fixes it (EXR frames
/// too, where it is how they would be viewed).
fn splat_settings(
    args: &VideoArgs,
    exposure_ev: Option<f32>,
) -> crate::render::splat::SplatSettings {
    let mut splat = args.quality.settings();
    if let Some(ev) = exposure_ev {
        splat.merge.white = crate::render::splat::display_white(ev);
    }
    splat
}

/// The options checked on their own, before the scene is read.
fn check_args(args: &VideoArgs) -> Result<()> {
    video_pair::check(args)?;
    if !(args.fps.is_finite() && args.fps > 0.0 && args.fps <= 1000.0) {
        return Err(Error::input(format!(
            "--fps {} must lie in (0, 1000]",
            args.fps
        )));
    }
    if let Some(p) = args.pupil_mm {
        crate::limits::PUPIL_MM
            .check("--pupil-mm", p)
            .map_err(Error::input)?;
    }
    if let Some(ev) = args.exposure {
        if !ev.is_finite() {
            return Err(Error::input(format!(
                "--exposure {ev} must be a finite number of stops"
            )));
        }
        if args.format == FrameFormat::Exr {
            return Err(Error::input(
                "--exposure applies to PNG frames only; EXR frames keep linear values",
            ));
        }
    }
    check_mp4(args)
}

/// The output folder, created if missing and checked writable; temporaries an interrupted
/// run left are removed.
fn prepare_folder(output: &std::path::Path) -> Result<()> {
    if output.exists() && !output.is_dir() {
        return Err(Error::file(
            output,
            "-o names a file; the frames need a folder",
        ));
    }
    std::fs::create_dir_all(output)
        .map_err(|e| Error::file(output, format!("cannot create the output folder: {e}")))?;
    probe_writable(output)?;
    remove_stale_temporaries(output);
    Ok(())
}

/// Everything that determines a frame, as the manifest records it.
fn export_config(
    args: &VideoArgs,
    timeline: &Timeline,
    eyes: &[(String, Eye)],
    (width, height): (u32, u32),
    options: &crate::render::frame::KernelOptions,
) -> Result<ExportConfig> {
    let splat = args.quality.settings();
    let planned = planning_frames(timeline.count);
    let mut parts: Vec<&dyn std::fmt::Debug> = vec![
        &options.settings,
        &options.reference_axes,
        &splat,
        &planned,
        &args.age,
    ];
    // on-axis exports keep the hash they always had
    if args.off_axis {
        parts.push(&"off-axis");
    }
    Ok(ExportConfig {
        ocular_version: env!("CARGO_PKG_VERSION").to_string(),
        scene: args.scene.clone(),
        scene_sha256: scene_sha256(timeline),
        eye: args.eye.clone(),
        eye_sha256: eye_sha256(&eyes[0].1)?,
        side_by_side: args.side_by_side.clone(),
        side_by_side_sha256: match &args.side_by_side {
            Some(_) => eyes.get(1).map(|(_, e)| eye_sha256(e)).transpose()?,
            None => None,
        },
        size: [width, height],
        fps: args.fps,
        frame_count: timeline.count,
        format: match args.format {
            FrameFormat::Png => "png".to_string(),
            FrameFormat::Exr => "exr".to_string(),
        },
        focus_sweep_m: timeline.sweep.map(|(a, b)| [a, b]),
        pupil_mm: args.pupil_mm,
        exposure_ev: args.exposure,
        layers: args.layers.filter(|&k| k > 1),
        binocular: if args.pair.asked() {
            Some(manifest::PairConfig {
                eye_right: args
                    .pair
                    .eye_right
                    .clone()
                    .unwrap_or_else(|| args.eye.clone()),
                eye_right_sha256: eye_sha256(&eyes[1].1)?,
                ipd_mm: args
                    .pair
                    .ipd_mm
                    .unwrap_or(crate::render::binocular::DEFAULT_IPD_MM),
                stereo: video_pair::stereo_name(args).to_string(),
            })
        } else {
            None
        },
        settings_sha256: sha256_of_debug(&parts),
    })
}

/// The frames of `range` not already there and intact (their bytes match the recorded
/// digest).
fn frames_to_render(args: &VideoArgs, range: std::ops::Range<usize>) -> Vec<usize> {
    let digests = manifest::recorded_digests(&args.output);
    let mut todo = Vec::new();
    let mut rejected = 0usize;
    for i in range {
        let names = video_pair::frame_names(args, i);
        let present = names.iter().any(|name| args.output.join(name).exists());
        let intact = names.iter().all(|name| {
            let path = args.output.join(name);
            path.exists() && manifest::verified(&path, digests.get(name))
        });
        if intact {
            continue;
        }
        if present {
            rejected += 1;
        }
        todo.push(i);
    }
    if rejected > 0 {
        eprintln!(
            "note: {rejected} frame files in {} do not match their recorded SHA-256 (damaged, \
             or never recorded): rendering them again",
            args.output.display()
        );
    }
    todo
}

/// What renders and writes the frames.
struct Export<'a> {
    ctx: &'a Context,
    rasterizer: &'a mut Rasterizer,
    timeline: &'a Timeline,
    size: (u32, u32),
    eyes: &'a [(String, Eye)],
    renderers: &'a mut [FrameRenderer],
    /// Two eyes (`--binocular`): the pair's renderers in place of `renderers`.
    pair: Option<&'a mut video_pair::PairExport>,
    exposure_ev: f32,
}

impl Export<'_> {
    fn render(&mut self, args: &VideoArgs, todo: &[usize], log: &mut DigestLog) -> Result<()> {
        let (width, height) = self.size;
        let fov_y_deg = self.timeline.state(0).camera.fov_y_deg;
        // Each panel sees the scene through its own spectacle (if any): its magnification
        // moves every direction, so such a panel gets its own raster.
        let magnifications = self
            .eyes
            .iter()
            .map(|(_, e)| crate::render::frame_plan::spectacle_magnification(e))
            .collect::<Result<Vec<_>>>()?;
        let labels: Vec<&str> = self.eyes.iter().map(|(name, _)| name.as_str()).collect();
        let bar = super::frame_progress_bar(todo.len() as u64);
        for &i in todo {
            let images = match self.pair.as_deref_mut() {
                Some(pair) => {
                    let [left, right] = pair.render(
                        self.ctx,
                        self.rasterizer,
                        self.timeline,
                        (i, self.size),
                        args,
                    )?;
                    super::binocular::stereo_images(
                        video_pair::stereo(args),
                        self.size,
                        &[&left, &right],
                    )
                }
                None => {
                    let state = self.timeline.state(i);
                    let panels = video_frame::render_panels(
                        self.ctx,
                        self.rasterizer,
                        &state,
                        self.size,
                        (args, self.timeline.focus_d(i, &state), fov_y_deg),
                        self.renderers,
                        &magnifications,
                    )?;
                    let shown = (panels.len() > 1).then_some(&labels[..]);
                    vec![compose(width, height, &panels, shown)]
                }
            };
            for (name, image) in video_pair::frame_names(args, i).iter().zip(&images) {
                self.write(args, name, image, log)?;
            }
            bar.inc(1);
        }
        bar.finish_and_clear();
        Ok(())
    }

    /// Encodes one frame file and writes it under `name`, its digest recorded first.
    fn write(
        &self,
        args: &VideoArgs,
        name: &str,
        image: &image_io::ImageRgba,
        log: &mut DigestLog,
    ) -> Result<()> {
        let path = args.output.join(name);
        let bytes = match args.format {
            FrameFormat::Png => image_io::png_bytes(
                image,
                Tonemap {
                    exposure_ev: self.exposure_ev,
                    mode: TonemapMode::Clamp,
                },
            ),
            FrameFormat::Exr => image_io::exr_rgba_bytes(image),
        }
        .map_err(|m| Error::file(&path, m))?;
        // The digest is durable before the frame has its final name, so every frame a later
        // run finds under a final name can be verified.
        log.record(name, &bytes)?;
        write_frame(&args.output, name, &bytes)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ranges_are_half_open_and_checked() {
        assert_eq!(parse_range("2..5", 10), Ok((2, 5)));
        assert_eq!(parse_range("..3", 10), Ok((0, 3)));
        assert_eq!(parse_range("7..", 10), Ok((7, 10)));
        assert_eq!(parse_range("4", 10), Ok((4, 5)));
        assert!(parse_range("5..5", 10).is_err());
        assert!(parse_range("3..11", 10)
            .unwrap_err()
            .contains("has 10 frames"));
        assert!(parse_range("a..3", 10).is_err());
    }
}
