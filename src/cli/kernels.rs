//! `ocular kernels`: precompute an eye's kernel grid, write it, and optionally draw a contact
//! sheet and the projected-size plot.

use clap::Args;
use indicatif::{ProgressBar, ProgressStyle};
use std::io::IsTerminal;
use std::path::PathBuf;
use std::sync::Mutex;
use std::time::Instant;

use crate::eye::Eye;
use crate::psf::axes::{GridAxes, KernelSettings, Screen};
use crate::psf::cache::{cached, grid_key, write_grid, CacheOutcome};
use crate::psf::field::FieldAxes;
use crate::psf::grid::{compute_grid, GridReport, Stage};
use crate::psf::kernels::DioptreAxis;
use crate::psf::preview;
use crate::psf::request::{grid_settings, scene_grid};
use crate::{Error, Result};

#[derive(Debug, Args)]
pub struct KernelsArgs {
    /// The eye: a TOML eye file or a preset name.
    #[arg(long, value_name = "FILE|NAME")]
    pub eye: String,
    #[command(flatten)]
    pub correction: super::correction::CorrectionArgs,
    /// Object distances in dioptres: MIN..MAX:COUNT, uniform [default: 0..10:161].
    #[arg(long, value_name = "MIN..MAX:N")]
    pub objects: Option<String>,
    /// Focus states in dioptres, comma-separated, increasing; 0 = infinity
    /// [default: 5 values over 0.125..10.125].
    #[arg(long, value_name = "LIST")]
    pub focus_d: Option<String>,
    /// Pupil diameters in mm, comma-separated, increasing [default: 4 values over 2..7].
    #[arg(long, value_name = "LIST")]
    pub pupils_mm: Option<String>,
    /// R, G, B wavelengths in nm [default: 612,549,464].
    #[arg(long, value_name = "R,G,B")]
    pub wavelengths_nm: Option<String>,
    /// Vertical field of view of the output (degrees).
    #[arg(long, default_value_t = 60.0)]
    pub fov_y: f64,
    /// Output image height (pixels).
    #[arg(long, default_value_t = 720)]
    pub height: u32,
    /// Output image width (pixels, 16–16384) for --field-deg auto [default: 16:9 of --height].
    #[arg(long)]
    pub width: Option<u32>,
    /// Largest kernel radius (px); larger natural radii are clamped.
    #[arg(long, default_value_t = 64)]
    pub rmax_cap: u32,
    /// Fraction of each PSF's energy the cropped kernel keeps.
    #[arg(long, default_value_t = 0.999)]
    pub energy: f64,
    /// Object samples get a PSF of their own only where the blend of the computed ones
    /// around them would misplace more than this fraction of a kernel's energy (L1, 0 to 0.5;
    /// 0 computes every sample). Dense near each colour's focus, sparse far from it.
    #[arg(
        long,
        value_name = "L1",
        allow_hyphen_values = true,
        default_value_t = crate::psf::DEFAULT_OBJECT_TOLERANCE
    )]
    pub object_tolerance: f64,
    /// Only what a scene needs: its depth range in dioptres (MIN..MAX); with one --focus-d and
    /// one --pupils-mm value this is a single column of the grid.
    #[arg(long, value_name = "MIN..MAX")]
    pub scene_d: Option<String>,
    #[command(flatten)]
    pub cache: super::CacheArgs,
    /// Output grid file.
    #[arg(short = 'o', long, value_name = "FILE")]
    pub output: PathBuf,
    /// Contact sheet PNG: kernels per object distance and channel.
    #[arg(long, value_name = "PNG")]
    pub preview: Option<PathBuf>,
    /// Plot PNG: projected PSF size against object dioptres per channel for two focus states.
    #[arg(long, value_name = "PNG")]
    pub plot: Option<PathBuf>,
    /// Grids over the visual field: H0..H1:N,V0..V1:M (degrees, N and M 1–31, each angle
    /// within ±60° and every direction at most 60° off axis), or "auto": the range the frame
    /// shows (--fov-y, --width × --height) with the coarsest steps that keep the measured
    /// interpolation error of the wavefront within 0.04 µm RMS. Writes an index (TOML) to -o
    /// and one grid per direction next to it (STEM.hI.vJ.bin, I and J the angles' indices);
    /// each is cached on its own.
    #[arg(long, value_name = "H0..H1:N,V0..V1:M", allow_hyphen_values = true)]
    pub field_deg: Option<String>,
    /// Print the report as JSON.
    #[arg(long)]
    pub json: bool,
}

/// An eye from a TOML file or a preset / test-eye name.
pub fn load_eye(spec: &str) -> Result<Eye> {
    super::render::load_eye(spec)
}

fn parse_list(option: &str, text: &str) -> Result<Vec<f64>> {
    text.split(',')
        .map(|t| {
            t.trim().parse::<f64>().map_err(|_| {
                Error::input(format!(
                    "--{option}: {t:?} is not a number (expected a comma-separated list)"
                ))
            })
        })
        .collect()
}

fn parse_range(option: &str, text: &str) -> Result<(f64, f64)> {
    let bad = || Error::input(format!("--{option}: expected MIN..MAX, got {text:?}"));
    let (a, b) = text.split_once("..").ok_or_else(bad)?;
    let a = a.trim().parse::<f64>().map_err(|_| bad())?;
    let b = b.trim().parse::<f64>().map_err(|_| bad())?;
    if !(a.is_finite() && b.is_finite() && a <= b) {
        return Err(bad());
    }
    Ok((a, b))
}

/// `MIN..MAX:N` → an object axis.
pub fn parse_objects(text: &str) -> Result<DioptreAxis> {
    let bad = || {
        Error::input(format!(
            "--objects: expected MIN..MAX:N (dioptres, N >= 1), got {text:?}"
        ))
    };
    let (range, count) = text.rsplit_once(':').ok_or_else(bad)?;
    let (lo, hi) = parse_range("objects", range)?;
    let count: usize = count.trim().parse().map_err(|_| bad())?;
    if count == 0 || (count == 1 && hi != lo) {
        return Err(bad());
    }
    Ok(DioptreAxis::spanning(lo, hi, count))
}

struct Bars {
    bar: Option<ProgressBar>,
    stage: Mutex<Option<Stage>>,
}

impl Bars {
    fn new() -> Bars {
        Bars {
            bar: std::io::stderr().is_terminal().then(ProgressBar::hidden),
            stage: Mutex::new(None),
        }
    }

    fn update(&self, stage: Stage, done: usize, total: usize) {
        let Some(bar) = &self.bar else { return };
        let mut current = self.stage.lock().unwrap_or_else(|e| e.into_inner());
        if *current != Some(stage) {
            *current = Some(stage);
            let label = match stage {
                Stage::Optics => "focusing and measuring",
                Stage::Psfs => "PSFs",
                Stage::Kernels => "kernels",
            };
            bar.reset();
            bar.set_length(total as u64);
            bar.set_style(
                ProgressStyle::with_template(&format!(
                    "{label:>24} [{{bar:40}}] {{pos}}/{{len}} ETA {{eta}}"
                ))
                .unwrap_or_else(|_| ProgressStyle::default_bar()),
            );
            bar.set_draw_target(indicatif::ProgressDrawTarget::stderr());
        }
        // The PSF total grows round by round as intervals are split (psf::object_knots).
        bar.set_length(total as u64);
        bar.set_position(done as u64);
    }

    fn finish(&self) {
        if let Some(bar) = &self.bar {
            bar.finish_and_clear();
        }
    }
}

#[derive(serde::Serialize)]
struct Summary<'a> {
    output: String,
    key: String,
    cache: &'a CacheOutcome,
    seconds: f64,
    psfs: usize,
    psfs_skipped: usize,
    sets: usize,
    objects: DioptreAxis,
    max_radius_px: u32,
    bytes_per_set: u64,
    report: Option<&'a GridReport>,
    plan_notes: &'a [String],
}

pub fn run(args: &KernelsArgs) -> Result<()> {
    let (auto, field) = field_option(args)?;
    let mut outputs = super::outputs::Outputs::new();
    match &field {
        Some(f) => super::kernels_field::register(&mut outputs, &args.output, f)?,
        None if auto => outputs.add("-o", &args.output, &["toml"])?,
        None => outputs.add("-o", &args.output, &[])?,
    }
    if let Some(p) = &args.preview {
        outputs.add("--preview", p, &["png"])?;
    }
    if let Some(p) = &args.plot {
        outputs.add("--plot", p, &["png"])?;
    }
    outputs.probe()?;
    let eye = args.correction.apply(&load_eye(&args.eye)?, None)?.0;
    let Planned {
        axes,
        screen,
        settings,
        skipped,
        notes,
    } = planned_grid(args)?;
    let dir = args.cache.dir();
    let mut field = field;
    if auto {
        let (fresh, axes) = auto_field(args, &eye, &axes, &screen)?;
        drop(outputs);
        outputs = fresh;
        field = Some(axes);
    }
    if let Some(f) = &field {
        return super::kernels_field::run(
            outputs,
            &args.output,
            &args.eye,
            &eye,
            &axes,
            &screen,
            &settings,
            f,
            dir.as_deref(),
            args.json,
        );
    }
    let key = grid_key(&eye, &axes, &screen, &settings);
    let bars = Bars::new();
    let t = Instant::now();
    let progress = |s: Stage, d: usize, n: usize| bars.update(s, d, n);
    let (grid, report, outcome) = cached(dir.as_deref(), &key, || {
        compute_grid(&eye, &axes, &screen, &settings, &progress)
    })?;
    bars.finish();
    print_warnings(report.as_ref(), &outcome);
    write_grid(outputs.temporary(&args.output), &grid, &key)?;
    if let Some(p) = &args.preview {
        preview::write_png(outputs.temporary(p), &preview::contact_sheet(&grid))?;
    }
    if let Some(p) = &args.plot {
        preview::write_png(outputs.temporary(p), &preview::size_plot(&grid))?;
    }
    outputs.commit()?;
    let summary = Summary {
        output: args.output.display().to_string(),
        key,
        cache: &outcome,
        seconds: t.elapsed().as_secs_f64(),
        psfs: axes.psf_count(),
        psfs_skipped: skipped,
        sets: grid.sets.len(),
        objects: grid.objects,
        max_radius_px: grid.max_radius_px,
        bytes_per_set: grid.sets[0].size_bytes(),
        report: report.as_ref(),
        plan_notes: &notes,
    };
    if args.json {
        let text = serde_json::to_string_pretty(&summary)
            .map_err(|e| Error::input(format!("cannot encode JSON: {e}")))?;
        println!("{text}");
    } else {
        print_summary(&summary, &grid);
    }
    Ok(())
}

/// `--field-deg`: whether it is `auto`, and the lattice it gives otherwise; with the options
/// that only make sense with (or without) it.
fn field_option(args: &KernelsArgs) -> Result<(bool, Option<FieldAxes>)> {
    if let Some(w) = args.width {
        if !(16..=16384).contains(&w) {
            return Err(Error::input(format!(
                "--width {w} is not allowed; need 16 to 16384 pixels"
            )));
        }
    }
    let auto = args.field_deg.as_deref().map(str::trim) == Some("auto");
    let field = match &args.field_deg {
        Some(_) if auto => None,
        Some(text) => Some(FieldAxes::parse(text).map_err(Error::input)?),
        None => None,
    };
    if args.width.is_some() && !auto {
        return Err(Error::input("--width is only used by --field-deg auto"));
    }
    if (auto || field.is_some()) && (args.preview.is_some() || args.plot.is_some()) {
        return Err(Error::input(
            "--field-deg writes one grid per direction; --preview and --plot draw a single grid",
        ));
    }
    Ok((auto, field))
}

/// The grid the options ask for, checked and (with --scene-d) narrowed.
struct Planned {
    axes: GridAxes,
    screen: Screen,
    settings: KernelSettings,
    skipped: usize,
    notes: Vec<String>,
}

fn planned_grid(args: &KernelsArgs) -> Result<Planned> {
    let mut axes = GridAxes::default();
    if let Some(text) = &args.wavelengths_nm {
        let wl = parse_list("wavelengths-nm", text)?;
        axes.wavelengths_nm = wl.try_into().map_err(|_| {
            Error::input("--wavelengths-nm: exactly three values (R,G,B) are required")
        })?;
    }
    if let Some(text) = &args.objects {
        axes.objects = parse_objects(text)?;
    }
    if let Some(text) = &args.focus_d {
        axes.focus_d = parse_list("focus-d", text)?;
    }
    if let Some(text) = &args.pupils_mm {
        axes.pupils_mm = parse_list("pupils-mm", text)?;
    }
    let screen = Screen {
        fov_y_deg: args.fov_y,
        height_px: args.height,
    };
    let settings = grid_settings(
        &axes,
        &screen,
        args.rmax_cap,
        args.energy,
        args.object_tolerance,
    )?;
    let (mut skipped, mut notes) = (0, Vec::new());
    if let Some(range) = &args.scene_d {
        let narrowed = scene_grid(&axes, screen, parse_range("scene-d", range)?)?;
        (axes, skipped, notes) = (narrowed.axes, narrowed.skipped_psfs, narrowed.notes);
    }
    Ok(Planned {
        axes,
        screen,
        settings,
        skipped,
        notes,
    })
}

/// `--field-deg auto`: the lattice the frame needs, and the outputs it writes (checked).
fn auto_field(
    args: &KernelsArgs,
    eye: &Eye,
    axes: &GridAxes,
    screen: &Screen,
) -> Result<(super::outputs::Outputs, FieldAxes)> {
    let width = args
        .width
        .unwrap_or(((args.height as f64) * 16.0 / 9.0).round() as u32);
    let plan = super::kernels_field::plan(eye, axes, screen, width)?;
    for n in &plan.notes {
        eprintln!("note: {n}");
    }
    eprintln!(
        "field plan: {} × {} directions over ±{:.1}° × ±{:.1}°, interpolation error {:.4} µm \
         (tolerance {} µm)",
        plan.axes.h_deg.len(),
        plan.axes.v_deg.len(),
        plan.axes.h_deg.last().copied().unwrap_or(0.0),
        plan.axes.v_deg.last().copied().unwrap_or(0.0),
        plan.worst_error_um,
        plan.tolerance_um
    );
    let mut fresh = super::outputs::Outputs::new();
    super::kernels_field::register(&mut fresh, &args.output, &plan.axes)?;
    fresh.probe()?;
    Ok((fresh, plan.axes))
}

fn print_warnings(report: Option<&GridReport>, outcome: &CacheOutcome) {
    if let Some(r) = report {
        for w in &r.warnings {
            eprintln!("warning: {w}");
        }
    }
    match outcome {
        CacheOutcome::Stored {
            warning: Some(w), ..
        } => eprintln!("warning: {w}"),
        CacheOutcome::WriteFailed(w) => eprintln!("warning: {w}"),
        _ => {}
    }
}

fn print_summary(summary: &Summary<'_>, grid: &crate::psf::kernels::KernelGrid) {
    let source = match summary.cache {
        CacheOutcome::Hit(p) => format!("loaded from cache {}", p.display()),
        _ => format!("computed in {:.1} s", summary.seconds),
    };
    println!(
        "{}: {} sets (pupils {:?} mm × focus {:?} D), {} objects {:.3}..{:.3} D, Rmax {} px, \
         {:.1} MiB per set; {} PSFs ({} skipped{}), {source}",
        summary.output,
        summary.sets,
        grid.pupils_mm,
        grid.focus_d,
        grid.objects.count,
        grid.objects.min_d,
        grid.objects.max_d(),
        grid.max_radius_px,
        summary.bytes_per_set as f64 / (1 << 20) as f64,
        summary.psfs,
        summary.psfs_skipped,
        summary.report.map_or(String::new(), |r| format!(
            ", {} computed, {} blended between them",
            r.psfs_computed, r.psfs_filled
        )),
    );
    for n in summary.plan_notes {
        println!("  plan: {n}");
    }
    let Some(r) = summary.report else { return };
    for c in &r.columns {
        println!(
            "  pupil {:.2} mm, focus {:.3} D: lens {:.3} mm{}, residual R/G/B {:+.3} {:+.3} {:+.3} D, beta degree {:?}, PSFs by FFT {:?}, missed pupil energy {:.1e} {:.1e} {:.1e}",
            c.pupil_mm,
            c.focus_d,
            c.lens_diameter_mm,
            if c.beyond_far_point { " (beyond far point: relaxed)" } else { "" },
            c.residual_d[0],
            c.residual_d[1],
            c.residual_d[2],
            c.beta_degree,
            c.fft_psfs,
            c.missed_energy[0],
            c.missed_energy[1],
            c.missed_energy[2],
        );
    }
}
