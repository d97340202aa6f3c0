//! `ocular render --binocular` (or `--eye-right`): a scene through two eyes. The scene's camera
//! is the point between them; both eyes converge on the fixation point (the focus asked) and
//! accommodate by one shared response (`render::binocular`); their pupils are one too (the
//! consensual reflex: both from the same light). Written as two files, side by side, or a
//! red-cyan anaglyph.

use std::path::{Path, PathBuf};
use std::sync::Arc;

use super::render::RenderArgs;
use super::Cli;
use crate::eye::Eye;
use crate::gpu::Context;
use crate::image_io::{self, ImageRgba, Tonemap};
use crate::render::binocular::{self, FilePairRequest, PairRequest, Yoke, SIDES};
use crate::render::frame::HostFrame;
use crate::render::frame::Method;
use crate::render::frame_plan::{Correction, IolPower};
use crate::render::live::{LiveOptions, LiveRenderer};
use crate::{Error, Result};

/// How a binocular pair is written.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum StereoOutput {
    /// Two files: `-o view.png` writes view-left.png and view-right.png.
    Separate,
    /// One file, the left eye's frame on the left (for parallel free-viewing and most
    /// stereo viewers).
    SideBySide,
    /// One red-cyan anaglyph: red from the left eye, green and blue from the right.
    Anaglyph,
}

/// `--iol-d-right`: the right eye's own IOL, or none.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum RightIol {
    /// The right eye keeps its crystalline lens.
    None,
    Power(IolPower),
}

pub fn parse_right_iol(text: &str) -> std::result::Result<RightIol, String> {
    if text.trim().eq_ignore_ascii_case("none") {
        return Ok(RightIol::None);
    }
    IolPower::parse(text)
        .map(RightIol::Power)
        .map_err(|e| format!("{e} (or none)"))
}

/// The options of a pair of eyes, shared by `render`, `video` and `compare`.
#[derive(clap::Args, Debug, Clone, Default)]
pub struct PairArgs {
    /// Two eyes (--eye for both, or the left with --eye-right): the scene's camera is the
    /// point between them, both converge on the focus point and share one accommodation
    /// (docs/binocular.md).
    #[arg(long)]
    pub binocular: bool,
    /// The right eye of a binocular pair (a preset or an eye file); --eye is then the left.
    #[arg(long, value_name = "NAME|FILE")]
    pub eye_right: Option<String>,
    /// The right eye's own spectacle or contact lens, "S C x A" (as --correct, whose
    /// --vertex-mm and --correct-contact it shares); --correct is then the left eye's.
    #[arg(long, value_name = "S C x A", value_parser = super::correction::parse_correct, allow_hyphen_values = true)]
    pub correct_right: Option<crate::eye::correction::Spectacle>,
    /// The right eye's own intraocular lens: a power in dioptres (-10 to 40), `auto` (the
    /// emmetropic one) or `none` (the right eye keeps its crystalline lens); --iol-d is then
    /// the left eye's. A pseudophakic monovision pair: --iol-d auto --iol-d-right with a
    /// stronger lens.
    #[arg(long, value_name = "D|auto|none", value_parser = parse_right_iol, allow_hyphen_values = true)]
    pub iol_d_right: Option<RightIol>,
    /// Interpupillary distance of a binocular pair in mm (40 to 80; default 63, the adult mean).
    #[arg(long, value_name = "MM", allow_negative_numbers = true)]
    pub ipd_mm: Option<f64>,
}

impl PairArgs {
    /// Whether the options ask for two eyes.
    pub fn asked(&self) -> bool {
        self.binocular || self.eye_right.is_some()
    }

    /// Refuses a pair's options given without a pair (`others`: the command's own, named),
    /// and an interpupillary distance out of range.
    pub fn check(&self, others: &[(&str, bool)]) -> Result<()> {
        if !self.asked() {
            let stray = [
                ("--ipd-mm", self.ipd_mm.is_some()),
                ("--correct-right", self.correct_right.is_some()),
                ("--iol-d-right", self.iol_d_right.is_some()),
            ];
            if let Some((name, _)) = stray.iter().chain(others).find(|(_, on)| *on) {
                return Err(Error::input(format!(
                    "{name} applies to two eyes: add --binocular (or --eye-right)"
                )));
            }
        }
        if let Some(ipd) = self.ipd_mm {
            binocular::check_ipd_mm(ipd).map_err(Error::input)?;
        }
        Ok(())
    }

    /// The eyes' specs (left, right) and the eyes they load: `eye` (the command's --eye) for
    /// both, or the left with --eye-right; a file is named by the option that gave it.
    pub fn eyes(&self, eye: &str) -> Result<([String; 2], [Eye; 2])> {
        let right = self.eye_right.as_deref().unwrap_or(eye);
        let option = if self.eye_right.is_some() {
            "--eye-right"
        } else {
            "--eye"
        };
        let loaded = [
            crate::render::frame_plan::load_eye("--eye", eye)?,
            crate::render::frame_plan::load_eye(option, right)?,
        ];
        Ok(([eye.to_string(), right.to_string()], loaded))
    }

    /// The right eye's correction, `left`'s but for its own lenses ([`right_correction`]).
    pub fn right_correction(&self, left: &Correction) -> Correction {
        right_correction(left, self.correct_right, self.iol_d_right)
    }
}

/// The right eye's correction: the left eye's (`--correct`, `--iol-d` and what goes with them)
/// with `--correct-right` and `--iol-d-right` in place of the left's lens, where given. Every
/// command that takes a pair (render, video, compare) reads it so.
fn right_correction(
    left: &Correction,
    correct_right: Option<crate::eye::correction::Spectacle>,
    iol_d_right: Option<RightIol>,
) -> Correction {
    Correction {
        spectacle: correct_right.or(left.spectacle),
        iol: match iol_d_right {
            Some(RightIol::None) => None,
            Some(RightIol::Power(p)) => Some(p),
            None => left.iol,
        },
        ..left.clone()
    }
}

/// Refuses the binocular options without a binocular render, and what it cannot take yet.
pub fn check(args: &RenderArgs) -> Result<()> {
    args.pair.check(&[
        ("--stereo", args.stereo.is_some()),
        ("--color-right", args.color_right.is_some()),
    ])?;
    if !args.pair.asked() {
        return Ok(());
    }
    if args.method != Method::Splat {
        return Err(Error::input("--binocular renders with --method splat"));
    }
    if args.splat.off_axis {
        return Err(Error::input(
            "--binocular does not take --off-axis yet (each eye's field would need its own plan)",
        ));
    }
    if args.color.is_some() && args.pair.ipd_mm.is_some() {
        return Err(Error::input(
            "--ipd-mm places the eyes in a scene; a stereo pair from files was rendered with its \
             own camera separation",
        ));
    }
    Ok(())
}

/// The output file of one eye (`separate`) or of the pair.
pub fn eye_output(output: &Path, side: &str) -> PathBuf {
    let stem = output
        .file_stem()
        .map(|s| s.to_string_lossy().to_string())
        .unwrap_or_else(|| "ocular".into());
    let ext = output
        .extension()
        .map(|e| e.to_string_lossy().to_string())
        .unwrap_or_else(|| "png".into());
    output.with_file_name(format!("{stem}-{side}.{ext}"))
}

/// One eye's result.
#[derive(serde::Serialize)]
struct EyeSummary {
    side: &'static str,
    eye: String,
    output: Option<String>,
    /// Scene pairs only: where the eye sits and where it looks.
    position_m: Option<[f64; 3]>,
    yaw_deg: Option<f64>,
    pitch_deg: Option<f64>,
    demand_d: f64,
    far_point_d: f64,
    accommodation_max_d: Option<f64>,
    focus_d: f64,
    residual_defocus_d: f64,
    correction: Option<String>,
    seconds_render: f64,
    seconds_kernels: f64,
}

#[derive(serde::Serialize)]
struct Summary {
    /// The scene's name, or the pair's files.
    scene: String,
    width: u32,
    height: u32,
    /// `--headset`: each eye's panel and field, and the refresh interval both frames share.
    #[serde(skip_serializing_if = "Option::is_none")]
    headset: Option<crate::render::headset::HeadsetSummary>,
    /// Scene pairs only (a file pair's camera separation is its renderer's).
    ipd_mm: Option<f64>,
    fixation_m: Option<[f64; 3]>,
    fixation_from: String,
    /// Angle between the two lines of sight (degrees; scene pairs only).
    vergence_deg: Option<f64>,
    pupil_mm: f64,
    pupil_source: String,
    yoke: Yoke,
    driver: &'static str,
    stereo: &'static str,
    outputs: Vec<String>,
    eyes: Vec<EyeSummary>,
    device: String,
}

pub fn run(cli: &Cli, args: &RenderArgs) -> Result<()> {
    super::render::check_args(args)?;
    let quality = args.splat.quality;
    let (specs, eyes) = args.pair.eyes(&args.eye)?;
    let ipd_mm = args.pair.ipd_mm.unwrap_or(binocular::DEFAULT_IPD_MM);
    if !(args.time.is_finite() && args.time >= 0.0) {
        return Err(Error::input(format!(
            "--time {} must be a non-negative number of seconds",
            args.time
        )));
    }
    let correction = args.correction.correction();
    let base = LiveOptions {
        focus: super::render::focus_asked(args)?,
        pupil_mm: args.pupil_mm,
        luminance_cdm2: args.luminance_cdm2,
        age: args.age,
        layers: args.layers.unwrap_or(1),
        exposure_ev: args.exposure.map(f64::from),
        quality,
        correction,
        ..LiveOptions::default()
    };
    let corrections = [
        base.correction.clone(),
        args.pair.right_correction(&base.correction),
    ];
    // A stereo pair from files is read before anything is written or the GPU is started.
    let files_in = match &args.color {
        Some(color) => Some(file_pair(args, color)?),
        None => None,
    };
    // Every file of the pair is checked writable before rendering, and kept only if all are
    // written.
    let stereo = args.stereo.unwrap_or(StereoOutput::Separate);
    let paths = output_paths(args, stereo);
    let mut files = super::outputs::Outputs::new();
    for p in &paths {
        files.add("-o", p, &[])?;
    }
    files.probe()?;
    let ctx = Context::new(&cli.context_options())?;
    let live = LiveRenderer::new(ctx, args.cache.dir(), 2);
    let (name, size, pair) = match &files_in {
        Some((frames, label, warnings)) => {
            for w in warnings {
                eprintln!("warning: {w}");
            }
            let pair = binocular::render_file_pair(
                &live,
                &FilePairRequest {
                    frames: [&frames[0], &frames[1]],
                    eyes: [&eyes[0], &eyes[1]],
                    options: base,
                    corrections,
                },
            )?;
            (label.clone(), (frames[0].width, frames[0].height), pair)
        }
        None => {
            let name = args.scene.clone().unwrap_or_else(|| "primitives".into());
            let (scene, size) = super::render::scene_and_size(args, &name)?;
            let scene = Arc::new(scene);
            let pair = binocular::render_pair(
                &live,
                &PairRequest {
                    scene: &scene,
                    eyes: [&eyes[0], &eyes[1]],
                    options: base,
                    corrections,
                    size,
                    time_s: args.time,
                    ipd_m: ipd_mm * 1e-3,
                },
            )?;
            (name, size, pair)
        }
    };
    for w in &pair.warnings {
        eprintln!("warning: {w}");
    }
    let frames = [&pair.frames[0].color, &pair.frames[1].color];
    write(
        args,
        stereo,
        size,
        &frames,
        pair.exposure_ev,
        (&files, &paths),
    )?;
    files.commit()?;
    let mut summary = summarize(&pair, &specs, name, size, (stereo, &paths), live.device());
    summary.headset = args.headset.map(|h| h.summary());
    if args.json {
        println!("{}", super::eye::json(&summary)?);
        return Ok(());
    }
    print(&summary);
    Ok(())
}

/// What `--json` and the text summary say of a written pair.
fn summarize(
    pair: &binocular::Pair,
    specs: &[String; 2],
    name: String,
    size: (u32, u32),
    (stereo, paths): (StereoOutput, &[PathBuf]),
    device: String,
) -> Summary {
    let mut summaries: Vec<EyeSummary> = (0..2)
        .map(|e| EyeSummary {
            side: SIDES[e],
            eye: specs[e].clone(),
            output: None,
            position_m: pair.geometry.map(|g| g.positions_m[e]),
            yaw_deg: pair.geometry.map(|g| g.cameras[e].yaw_deg),
            pitch_deg: pair.geometry.map(|g| g.cameras[e].pitch_deg),
            demand_d: pair.demand_d[e],
            far_point_d: pair.far_point_d[e],
            accommodation_max_d: pair.amplitude_d[e],
            focus_d: pair.yoke.focus_d[e],
            residual_defocus_d: pair.yoke.residual_d[e],
            correction: pair.corrections[e].clone(),
            seconds_render: pair.frames[e].report.seconds_render,
            seconds_kernels: pair.frames[e].report.seconds_kernels,
        })
        .collect();
    let (geometry, yoke) = (pair.geometry, pair.yoke);
    let outputs: Vec<String> = paths.iter().map(|p| p.display().to_string()).collect();
    if stereo == StereoOutput::Separate {
        for (s, o) in summaries.iter_mut().zip(&outputs) {
            s.output = Some(o.clone());
        }
    }
    let vergence_deg = geometry.map(|g| {
        let lines_of_sight = g.cameras.map(|c| c.forward());
        let cos = (0..3)
            .map(|k| lines_of_sight[0][k] * lines_of_sight[1][k])
            .sum::<f64>()
            .clamp(-1.0, 1.0);
        cos.acos().to_degrees()
    });
    Summary {
        scene: name,
        width: size.0,
        height: size.1,
        headset: None,
        ipd_mm: geometry.map(|g| g.ipd_m * 1e3),
        fixation_m: pair.fixation_m,
        fixation_from: pair.fixation_from.clone(),
        vergence_deg,
        pupil_mm: pair.pupil_mm,
        pupil_source: pair.pupil_from.clone(),
        yoke,
        driver: SIDES[yoke.driver],
        stereo: match stereo {
            StereoOutput::Separate => "separate",
            StereoOutput::SideBySide => "side-by-side",
            StereoOutput::Anaglyph => "anaglyph",
        },
        outputs,
        eyes: summaries,
        device,
    }
}

/// The two frames of a stereo pair from files: `--color` and `--color-right` (each with its
/// depth), or the `left` and `right` views of one multi-view EXR. Returns them, a label
/// naming the files and the files' warnings (each naming its eye).
fn file_pair(args: &RenderArgs, color: &Path) -> Result<([HostFrame; 2], String, Vec<String>)> {
    let (left, right, label) = match &args.color_right {
        Some(color_right) => (
            super::render::file_input(args, color, args.depth.as_ref(), None)?,
            super::render::file_input(args, color_right, args.depth_right.as_ref(), None)?,
            format!("{} | {}", color.display(), color_right.display()),
        ),
        None => (
            super::render::file_input(args, color, args.depth.as_ref(), Some("left"))?,
            super::render::file_input(args, color, args.depth.as_ref(), Some("right"))?,
            format!("{} (views left, right)", color.display()),
        ),
    };
    let (l, r) = (&left.frame, &right.frame);
    if (l.width, l.height) != (r.width, r.height) {
        return Err(Error::input(format!(
            "the left frame ({}) is {}×{} and the right ({}) {}×{}: a stereo pair needs one \
             size",
            left.label, l.width, l.height, right.label, r.width, r.height
        )));
    }
    let mut warnings = Vec::new();
    for (side, input) in SIDES.iter().zip([&left, &right]) {
        warnings.extend(input.warnings.iter().map(|w| format!("{side} eye: {w}")));
    }
    Ok(([left.frame, right.frame], label, warnings))
}

/// A vergence in words; a negative one (a hyperopic eye's far point, or its focus when it
/// accommodates too little for infinity) lies beyond infinity.
fn distance(d: f64) -> String {
    if d > 0.0 {
        format!("{:.3} m ({d:.2} D)", 1.0 / d)
    } else if d < -1e-9 {
        format!("beyond infinity ({d:.2} D)")
    } else {
        "infinity".into()
    }
}

fn print(s: &Summary) {
    match (s.ipd_mm, s.vergence_deg) {
        (Some(ipd_mm), Some(vergence_deg)) => println!(
            "wrote {} ({}×{}, scene {}, two eyes {:.1} mm apart converging {:.2}° on {} from {}; \
             pupils {:.2} mm from {})",
            s.outputs.join(", "),
            s.width,
            s.height,
            s.scene,
            ipd_mm,
            vergence_deg,
            s.fixation_m
                .map_or("infinity".into(), |_| distance(s.eyes[0].demand_d)),
            s.fixation_from,
            s.pupil_mm,
            s.pupil_source,
        ),
        _ => println!(
            "wrote {} ({}×{}, stereo pair {}, both eyes fixating {} from {}; pupils {:.2} mm \
             from {})",
            s.outputs.join(", "),
            s.width,
            s.height,
            s.scene,
            distance(s.eyes[0].demand_d),
            s.fixation_from,
            s.pupil_mm,
            s.pupil_source,
        ),
    }
    if let Some(h) = &s.headset {
        println!(
            "  each eye as the {} shows it: {}×{}, {:.1}° × {:.1}° ({:.2} px/° at the centre), \
             both within {:.1} ms at {} Hz",
            h.name,
            h.width_px,
            h.height_px,
            h.fov_x_deg,
            h.fov_y_deg,
            h.preset.spec().centre_px_per_deg(),
            h.frame_budget_ms,
            h.refresh_hz
        );
    }
    println!(
        "  accommodation {:.2} D, driven by the {} eye",
        s.yoke.accommodation_d, s.driver
    );
    for e in &s.eyes {
        println!(
            "  {:<5} eye {}: focused at {}, defocus at the target {:+.2} D (far point {}){}",
            e.side,
            e.eye,
            distance(e.focus_d),
            e.residual_defocus_d,
            distance(e.far_point_d),
            e.correction
                .as_ref()
                .map(|c| format!(", through {c}"))
                .unwrap_or_default()
        );
    }
}

/// The files a pair is written to: one per eye (`separate`), else `-o`.
fn output_paths(args: &RenderArgs, stereo: StereoOutput) -> Vec<PathBuf> {
    match stereo {
        StereoOutput::Separate => SIDES
            .iter()
            .map(|side| eye_output(&args.output, side))
            .collect(),
        _ => vec![args.output.clone()],
    }
}

/// The pair's images as `stereo` lays them out: the two frames (left, right) for
/// `separate`, else one.
pub fn stereo_images(
    stereo: StereoOutput,
    (w, h): (u32, u32),
    frames: &[&Vec<[f32; 4]>; 2],
) -> Vec<ImageRgba> {
    match stereo {
        StereoOutput::Separate => (0..2)
            .map(|e| ImageRgba::new(w, h, frames[e].clone()))
            .collect(),
        StereoOutput::SideBySide => {
            let mut pixels = Vec::with_capacity(2 * frames[0].len());
            for row in 0..h as usize {
                for f in frames.iter() {
                    pixels.extend_from_slice(&f[row * w as usize..(row + 1) * w as usize]);
                }
            }
            vec![ImageRgba::new(2 * w, h, pixels)]
        }
        StereoOutput::Anaglyph => {
            let pixels = frames[0]
                .iter()
                .zip(frames[1].iter())
                .map(|(l, r)| [l[0], r[1], r[2], 1.0])
                .collect();
            vec![ImageRgba::new(w, h, pixels)]
        }
    }
}

/// Writes the pair as asked into the temporaries of `files` (`paths` in order).
fn write(
    args: &RenderArgs,
    stereo: StereoOutput,
    (w, h): (u32, u32),
    frames: &[&Vec<[f32; 4]>; 2],
    exposure_ev: f32,
    (files, paths): (&super::outputs::Outputs, &[PathBuf]),
) -> Result<()> {
    let exr = args
        .output
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("exr"));
    let mode = args.tonemap.mode();
    let save = |path: &Path, image: &ImageRgba| {
        let path = files.temporary(path);
        if exr {
            image_io::write_exr_rgba(path, image)
        } else {
            image_io::write_png(path, image, Tonemap { exposure_ev, mode })
        }
    };
    let images = stereo_images(stereo, (w, h), frames);
    for (path, image) in paths.iter().zip(&images) {
        save(path, image)?;
    }
    Ok(())
}
