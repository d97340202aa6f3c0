//! `ocular eye …`: estimate an eye from a wavefront or a prescription, show, measure and draw
//! eyes, and list the presets.

use clap::{Args, Subcommand};
use std::io::IsTerminal;
use std::path::PathBuf;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;

use super::outputs::Outputs;
use super::write_atomic;
use crate::aberrations::{self, ZernikeSet};
use crate::eye::estimate::prescription::RxTarget;
use crate::eye::estimate::{self, Estimate, Method, Progress, Settings};
use crate::eye::{self, file as eye_file};
use crate::{Error, Result};

#[derive(Debug, Args)]
pub struct EyeArgs {
    #[command(subcommand)]
    pub command: EyeCommand,
}

#[derive(Debug, Subcommand)]
pub enum EyeCommand {
    /// Fit a physical eye to a wavefront (Zernike file or preset) or a prescription.
    Estimate(Box<EstimateArgs>),
    /// Print an eye's structure and derived optics.
    Show(ShowArgs),
    /// Measure an eye's aberrations, power and refraction.
    Measure(MeasureArgs),
    /// The spectacle prescription that best corrects an eye ("S C x A", as --correct takes it).
    Refract(super::refract::RefractArgs),
    /// Draw a cross-section of an eye with ray bundles focused at two distances (SVG).
    Draw(DrawArgs),
    /// List the eye presets and the aberration presets.
    List,
}

#[derive(Debug, Args)]
pub struct EstimateArgs {
    /// Zernike file (.toml, .csv or .abp; OSA coefficients in µm).
    #[arg(long, value_name = "FILE", conflicts_with_all = ["preset", "rx"])]
    pub zernike: Option<PathBuf>,
    /// Aberration preset (see `ocular eye list`).
    #[arg(long, value_name = "NAME", conflicts_with = "rx")]
    pub preset: Option<String>,
    /// Spectacle prescription "S C x A" (dioptres, axis in degrees) at --vertex-mm in front
    /// of the cornea, as --correct and `eye refract` read it; needs --pupil-mm.
    #[arg(long, value_name = "\"S C x A\"", allow_hyphen_values = true)]
    pub rx: Option<String>,
    /// Vertex distance of --rx, lens to cornea, in mm (0 to 16; 0 = contact lens; default 12,
    /// the same as --correct's).
    #[arg(long, value_name = "MM", requires = "rx", value_parser = super::correction::parse_vertex_option, allow_hyphen_values = true)]
    pub vertex_mm: Option<f64>,
    /// Extra higher-order terms for --rx: "n,m,µm" (repeatable).
    #[arg(
        long = "term",
        value_name = "N,M,UM",
        allow_hyphen_values = true,
        requires = "rx"
    )]
    pub terms: Vec<String>,
    /// Pupil diameter of the measurement (mm, 1–9); with a file it replaces the file's value.
    #[arg(long)]
    pub pupil_mm: Option<f64>,
    /// Wavelength of the measurement (nm); default: the file's, or for --rx 549 nm (the
    /// wavelength the renderer accommodates at and `eye refract` measures at).
    #[arg(long)]
    pub wavelength_nm: Option<f64>,
    /// Where to write the eye file (TOML).
    #[arg(short = 'o', long, value_name = "EYE.toml")]
    pub output: PathBuf,
    /// Also write a JSON report.
    #[arg(long, value_name = "REPORT.json")]
    pub json: Option<PathBuf>,
    /// Plot input vs achieved coefficients (SVG or PNG by extension).
    #[arg(long, value_name = "FIT.svg|png")]
    pub plot: Option<PathBuf>,
    /// Stop after this many seconds and write the best eye so far (marked not converged).
    #[arg(long, allow_hyphen_values = true)]
    pub max_time_s: Option<f64>,
    /// Worker threads (default: all cores).
    #[arg(long)]
    pub threads: Option<usize>,
    /// Optimiser: hybrid (least squares + pattern-search polish) or gps (pattern search only).
    #[arg(long, default_value = "hybrid")]
    pub method: Method,
    /// Opportunistic poll in the pattern search (stop polling at the first improvement).
    #[arg(long)]
    pub opportunistic: bool,
    /// Highest Zernike order fitted (terms the input does not give count as zero).
    #[arg(long, default_value_t = 6)]
    pub order: u32,
    /// Print the report as JSON on stdout instead of a summary.
    #[arg(long)]
    pub print_json: bool,
}

#[derive(Debug, Args)]
pub struct ShowArgs {
    /// Eye file or preset name.
    pub eye: String,
    /// Wavelength of the derived optics (nm).
    #[arg(long, default_value_t = 555.0)]
    pub wavelength_nm: f64,
    /// Pupil diameter of the derived optics (mm, 1–9).
    #[arg(long, default_value_t = 5.0)]
    pub pupil_mm: f64,
}

#[derive(Debug, Args)]
pub struct MeasureArgs {
    /// Eye file or preset name.
    pub eye: String,
    /// Pupil diameter the wavefront is measured over (mm, 1–9).
    #[arg(long)]
    pub pupil_mm: f64,
    /// Wavelength of the measurement (nm).
    #[arg(long)]
    pub wavelength_nm: f64,
    /// Distance the eye focuses on, and where the measured object point sits (m or "inf").
    #[arg(long, default_value = "inf", allow_hyphen_values = true)]
    pub focus_m: String,
    /// Highest Zernike order (1–10).
    #[arg(long, default_value_t = 6)]
    pub order: u32,
    /// Field direction "H,V" in degrees (object space; H towards +x, V towards +y), each
    /// within ±60° and at most 60° from the axis. Off axis the coefficients are fitted over
    /// the elliptical pupil stretched to the unit disc (see docs/off-axis.md).
    #[arg(long, value_name = "H,V", allow_hyphen_values = true)]
    pub field_deg: Option<String>,
    /// Print the measurement as JSON.
    #[arg(long)]
    pub json: bool,
    #[command(flatten)]
    pub correction: super::correction::CorrectionArgs,
}

#[derive(Debug, Args)]
pub struct DrawArgs {
    /// Eye file or preset name.
    pub eye: String,
    /// Where to write the drawing (SVG).
    #[arg(short = 'o', long, value_name = "EYE.svg")]
    pub output: PathBuf,
    /// Pupil diameter of the ray bundles (mm, 1–9).
    #[arg(long, default_value_t = 4.0)]
    pub pupil_mm: f64,
    /// Wavelength the rays are traced at (nm).
    #[arg(long, default_value_t = 555.0)]
    pub wavelength_nm: f64,
    /// Focus distances of the two panels (m or "inf").
    #[arg(long, num_args = 1.., default_values = ["inf", "0.2"], allow_hyphen_values = true)]
    pub focus_m: Vec<String>,
}

pub fn run(args: &EyeArgs) -> Result<()> {
    match &args.command {
        EyeCommand::Estimate(a) => run_estimate(a),
        EyeCommand::Show(a) => run_show(a),
        EyeCommand::Measure(a) => run_measure(a),
        EyeCommand::Draw(a) => run_draw(a),
        EyeCommand::Refract(a) => super::refract::run(a),
        EyeCommand::List => run_list(),
    }
}

fn finite_option(name: &str, v: Option<f64>) -> Result<()> {
    match v {
        Some(x) if !x.is_finite() => Err(Error::input(format!(
            "--{name} must be a finite number, got {x}"
        ))),
        _ => Ok(()),
    }
}

fn check_pupil(p: f64) -> Result<()> {
    crate::limits::PUPIL_MM
        .check("--pupil-mm", p)
        .map(|_| ())
        .map_err(Error::input)
}

/// The eye `spec` names (a preset or a file), with the pupil and wavelength it is shown,
/// measured or drawn at checked first (show, measure, draw).
fn resolve_at(spec: &str, pupil_mm: f64, wavelength_nm: f64) -> Result<eye_file::EyeFile> {
    let f = eye_file::resolve(spec)?;
    check_pupil(pupil_mm)?;
    crate::limits::WAVELENGTH_NM
        .check("--wavelength-nm", wavelength_nm)
        .map_err(Error::input)?;
    Ok(f)
}

/// What `eye estimate` fits: a wavefront as given, or a prescription, whose wavefront depends
/// on the fitted eye (see [`RxTarget`]).
enum Target {
    Wavefront(ZernikeSet),
    Prescription(RxTarget),
}

fn estimate_error(e: estimate::EstimateError) -> Error {
    match e {
        estimate::EstimateError::Input(m) => Error::Input(m),
        estimate::EstimateError::Eye(e) => Error::Eye(e),
    }
}

/// The target from the options, checked, and a one-line description of its source.
fn target(a: &EstimateArgs) -> Result<(Target, String)> {
    if !a.terms.is_empty() && a.rx.is_none() {
        return Err(Error::input(
            "--term adds higher-order terms to --rx \"S C x A\"; a --zernike file or --preset \
             gives all its own terms",
        ));
    }
    finite_option("pupil-mm", a.pupil_mm)?;
    finite_option("wavelength-nm", a.wavelength_nm)?;
    if let Some(p) = a.pupil_mm {
        check_pupil(p)?;
    }
    let set = if let Some(path) = &a.zernike {
        let s = ZernikeSet::load(path, a.pupil_mm, a.wavelength_nm)?;
        (
            s,
            format!("ocular eye estimate --zernike {}", path.display()),
        )
    } else if let Some(name) = &a.preset {
        let mut s = aberrations::preset(name)?;
        if let Some(p) = a.pupil_mm {
            s = s.with_pupil(p).map_err(|_| {
                Error::input(format!(
                    "--pupil-mm {p} is larger than the preset's {} mm pupil; a wavefront can \
                     only be rescaled to a smaller pupil",
                    s.pupil_diameter_mm
                ))
            })?;
        }
        if let Some(w) = a.wavelength_nm {
            s.wavelength_nm = w;
        }
        (s, format!("ocular eye estimate --preset {name}"))
    } else if let Some(rx) = &a.rx {
        let pupil = a.pupil_mm.ok_or_else(|| {
            Error::input("--rx needs --pupil-mm (the pupil the prescription's wavefront covers)")
        })?;
        let mut t =
            RxTarget::new(rx, pupil, a.wavelength_nm, a.vertex_mm).map_err(estimate_error)?;
        for term in &a.terms {
            t.extra_terms.push(parse_term(term)?);
        }
        t.start_target().map_err(estimate_error)?;
        let command = format!(
            "ocular eye estimate --rx \"{rx}\" --vertex-mm {} --pupil-mm {pupil}",
            t.vertex_mm
        );
        return Ok((Target::Prescription(t), command));
    } else {
        return Err(Error::input(
            "give the wavefront: --zernike FILE, --preset NAME, or --rx \"S C x A\" with --pupil-mm",
        ));
    };
    estimate::check_target(&set.0).map_err(|e| Error::input(e.to_string()))?;
    Ok((Target::Wavefront(set.0), set.1))
}

fn parse_term(t: &str) -> Result<(u32, i32, f64)> {
    let bad = || {
        Error::input(format!(
            "--term {t:?}: expected \"n,m,µm\" for an existing Zernike term, e.g. \"4,0,0.1\""
        ))
    };
    let parts: Vec<&str> = t.split(',').map(str::trim).collect();
    if parts.len() != 3 {
        return Err(bad());
    }
    let n: u32 = parts[0].parse().map_err(|_| bad())?;
    let m: i32 = parts[1].parse().map_err(|_| bad())?;
    let v: f64 = parts[2].parse().map_err(|_| bad())?;
    if !crate::optics::zernike::is_valid_nm(n, m) || n > 10 || !v.is_finite() {
        return Err(bad());
    }
    Ok((n, m, v))
}

fn run_estimate(a: &EstimateArgs) -> Result<()> {
    let (target, command) = target(a)?;
    let mut outputs = Outputs::new();
    outputs.add("-o", &a.output, &["toml"])?;
    if let Some(p) = &a.json {
        outputs.add("--json", p, &["json"])?;
    }
    if let Some(p) = &a.plot {
        outputs.add("--plot", p, &["svg", "png"])?;
    }
    outputs.probe()?;
    if !(1..=10).contains(&a.order) {
        return Err(Error::input(format!(
            "--order {} is not allowed; need 1 to 10",
            a.order
        )));
    }
    let settings = Settings {
        method: a.method,
        max_time_s: a.max_time_s,
        threads: a.threads,
        opportunistic: a.opportunistic,
        order: a.order,
        ..Settings::default()
    };
    let cancel = Arc::new(AtomicBool::new(false));
    // A first SIGINT or SIGTERM stops the search (the best eye is still written, and the exit
    // status says which signal cancelled it); a second one exits at once.
    let interrupted = Arc::new(AtomicBool::new(false));
    let terminated = Arc::new(AtomicBool::new(false));
    for (signal, code, flag) in [
        (signal_hook::consts::SIGINT, 130, &interrupted),
        (signal_hook::consts::SIGTERM, 143, &terminated),
    ] {
        let _ = signal_hook::flag::register_conditional_shutdown(signal, code, Arc::clone(&cancel));
        let _ = signal_hook::flag::register(signal, Arc::clone(&cancel));
        let _ = signal_hook::flag::register(signal, Arc::clone(flag));
    }
    let bar = std::io::stderr().is_terminal().then(|| {
        let b = indicatif::ProgressBar::new_spinner();
        b.enable_steady_tick(std::time::Duration::from_millis(200));
        b
    });
    let mut progress = |p: &Progress| {
        if let Some(b) = &bar {
            b.set_message(format!(
                "{}: loss {:.4e}, {} evaluations, {:.1} s",
                p.stage, p.loss, p.evaluations, p.elapsed_s
            ));
        }
    };
    let est = match &target {
        Target::Wavefront(set) => estimate::estimate(set, &settings, &cancel, &mut progress),
        Target::Prescription(rx) => rx.estimate(&settings, &cancel, &mut progress),
    }
    .map_err(estimate_error)?;
    if let Some(b) = bar {
        b.finish_and_clear();
    }
    write_outputs(a, &est, &command, &outputs)?;
    outputs.commit()?;
    let r = &est.report;
    if a.print_json {
        println!("{}", json(r)?);
    } else {
        println!(
            "{}: loss {:.4e} (coefficients {:.4e}, prior {:.4e}); RMS error {:.4} µm over orders 1–{} \
             ({:.4} µm over the given terms); {} evaluations in {:.2} s on {} threads; \
             parameters {}in bounds; {}",
            a.output.display(),
            r.loss,
            r.coefficient_loss,
            r.prior_loss,
            r.rms_error_um,
            r.order,
            r.rms_error_given_um,
            r.evaluations,
            r.time_s,
            r.threads,
            if r.all_in_bounds { "" } else { "NOT " },
            if r.converged {
                "converged".to_string()
            } else {
                format!("NOT converged (stopped: {})", r.stop)
            }
        );
    }
    // A cancelled fit is not a converged one: the status says so (128 + the signal number).
    let signalled = if interrupted.load(Ordering::SeqCst) {
        Some(("SIGINT", 130))
    } else if terminated.load(Ordering::SeqCst) {
        Some(("SIGTERM", 143))
    } else {
        None
    };
    if let Some((name, code)) = signalled {
        eprintln!(
            "cancelled by {name}: wrote the best eye so far, marked not converged, to {}",
            a.output.display()
        );
        std::process::exit(code);
    }
    Ok(())
}

pub(super) fn json<T: serde::Serialize>(v: &T) -> Result<String> {
    serde_json::to_string_pretty(v).map_err(|e| Error::input(format!("cannot encode JSON: {e}")))
}

fn write_outputs(a: &EstimateArgs, est: &Estimate, command: &str, outputs: &Outputs) -> Result<()> {
    let r = &est.report;
    let header = format!(
        "Eye estimated by ocular {} from a {} mm, {} nm wavefront.\n\
         Reproduce: {command} -o {}\n{}",
        env!("CARGO_PKG_VERSION"),
        r.pupil_mm,
        r.wavelength_nm,
        a.output.display(),
        if r.converged {
            String::new()
        } else {
            format!(
                "NOT CONVERGED (stopped: {}): the best eye found so far.",
                r.stop
            )
        }
    );
    let text = eye_file::to_toml(&est.eye, Some(r), header.trim_end());
    if let Some(p) = &a.plot {
        let is_png = p.extension().is_some_and(|e| e.eq_ignore_ascii_case("png"));
        let bytes = if is_png {
            super::eye_plot::png(&r.terms)?
        } else {
            super::eye_plot::svg(&r.terms, r).into_bytes()
        };
        write_atomic(outputs.temporary(p), &bytes)?;
    }
    if let Some(p) = &a.json {
        #[derive(serde::Serialize)]
        struct Full<'a> {
            eye: &'a eye::Eye,
            estimate: &'a estimate::Report,
        }
        let t = json(&Full {
            eye: &est.eye,
            estimate: r,
        })?;
        write_atomic(outputs.temporary(p), t.as_bytes())?;
    }
    write_atomic(outputs.temporary(&a.output), text.as_bytes())
}

fn run_show(a: &ShowArgs) -> Result<()> {
    let f = resolve_at(&a.eye, a.pupil_mm, a.wavelength_nm)?;
    let text = eye::show::describe(&f.eye, a.wavelength_nm, a.pupil_mm)?;
    print!("{text}");
    if let Some(r) = &f.estimate {
        println!(
            "estimated from a {} mm, {} nm wavefront: loss {:.4e}, RMS error {:.4} µm, {}",
            r.pupil_mm,
            r.wavelength_nm,
            r.loss,
            r.rms_error_um,
            if r.converged {
                "converged"
            } else {
                "NOT converged"
            }
        );
    }
    Ok(())
}

fn parse_focus(s: &str) -> Result<Option<f64>> {
    let t = s.trim().to_ascii_lowercase();
    if t == "inf" || t == "infinity" {
        return Ok(None);
    }
    match t.parse::<f64>() {
        Ok(v) if v.is_finite() && v > 0.02 => Ok(Some(v)),
        _ => Err(Error::input(format!(
            "--focus-m {s:?} is not allowed; need a distance beyond 0.02 m or \"inf\""
        ))),
    }
}

/// Parses "H,V" degrees for `--field-deg`, range-checked.
pub fn parse_field_deg(s: &str) -> Result<[f64; 2]> {
    let bad = || {
        Error::input(format!(
            "--field-deg {s:?} is not allowed; need \"H,V\" in degrees, each within ±{m}° and \
             at most {m}° from the axis",
            m = eye::field::MAX_FIELD_DEG
        ))
    };
    let parts: Vec<&str> = s.split(',').collect();
    if parts.len() != 2 {
        return Err(bad());
    }
    let h: f64 = parts[0].trim().parse().map_err(|_| bad())?;
    let v: f64 = parts[1].trim().parse().map_err(|_| bad())?;
    eye::field::check_field_deg([h, v]).map_err(|_| bad())?;
    Ok([h, v])
}

fn run_measure(a: &MeasureArgs) -> Result<()> {
    let field = a.field_deg.as_deref().map(parse_field_deg).transpose()?;
    let f = resolve_at(&a.eye, a.pupil_mm, a.wavelength_nm)?;
    if !(1..=10).contains(&a.order) {
        return Err(Error::input(format!(
            "--order {} is not allowed; need 1 to 10",
            a.order
        )));
    }
    let focus = parse_focus(&a.focus_m)?;
    let (eye, physiology) = a.correction.apply(&f.eye, None)?;
    // A plain eye is measured as given at infinity and accommodates to any nearer focus, as
    // before; with an amplitude or an IOL it stays within its range.
    let limited = eye.accommodation_max_d.is_some() || eye.iol.is_some();
    let (focused, focus_limit) = match focus {
        None => (eye.clone(), eye::FocusLimit::Reached),
        Some(_) => {
            let f = eye::focus_within_range(&eye, focus, a.pupil_mm, a.wavelength_nm, limited)?;
            (f.eye, f.limit)
        }
    };
    let sys = focused.system()?;
    let (m, pupil) = match field {
        None => (
            eye::measure(&sys, a.wavelength_nm, a.pupil_mm, focus, a.order)?,
            None,
        ),
        Some(fd) => {
            let r =
                eye::field::measure_field(&sys, a.wavelength_nm, a.pupil_mm, focus, fd, a.order)?;
            (r.measurement, Some(r.field))
        }
    };
    if a.json {
        #[derive(serde::Serialize)]
        struct Out<'a> {
            coefficients: Vec<eye::measure::Coefficient>,
            power_d: f64,
            refraction: eye::Refraction,
            focus_limit: eye::FocusLimit,
            #[serde(flatten)]
            physiology: &'a super::correction::Physiology,
            #[serde(flatten)]
            rest: &'a eye::Measurement,
            #[serde(skip_serializing_if = "Option::is_none")]
            field: Option<&'a eye::field::FieldPupil>,
        }
        println!(
            "{}",
            json(&Out {
                coefficients: m.coefficient_list(),
                power_d: m.power_d,
                refraction: m.refraction,
                focus_limit,
                physiology: &physiology,
                rest: &m,
                field: pupil.as_ref(),
            })?
        );
        return Ok(());
    }
    let at = match &pupil {
        Some(p) => format!(
            ", field ({}, {})° (ellipse {:.3} × {:.3} mm)",
            p.field_deg[0],
            p.field_deg[1],
            2.0 * p.semi_axes_mm[0],
            2.0 * p.semi_axes_mm[1]
        ),
        None => String::new(),
    };
    println!(
        "{} mm pupil, {} nm, focused at {}{at}: power {:.3} D; M {:+.3} D, J0 {:+.3} D, \
         J45 {:+.3} D; HO RMS {:.4} µm",
        a.pupil_mm,
        a.wavelength_nm,
        focus.map_or("infinity".to_string(), |d| format!("{d} m")),
        m.power_d,
        m.refraction.m,
        m.refraction.j0,
        m.refraction.j45,
        m.coefficients_um
            .iter()
            .skip(6)
            .map(|c| c * c)
            .sum::<f64>()
            .sqrt()
    );
    if let Some(c) = &physiology.correction {
        println!("through {c}");
    }
    if let Some(p) = physiology.iol_d {
        println!("with a {p:.2} D IOL");
    }
    if focus_limit != eye::FocusLimit::Reached {
        let at = if focus_limit == eye::FocusLimit::FarPoint {
            "far"
        } else {
            "near"
        };
        println!("focus clamped at the {at} point (the eye cannot focus there)");
    }
    println!("{:>3} {:>4} {:>12}", "n", "m", "µm");
    for c in m.coefficient_list().iter().skip(1) {
        println!("{:>3} {:>4} {:>12.5}", c.n, c.m, c.um);
    }
    Ok(())
}

fn run_draw(a: &DrawArgs) -> Result<()> {
    let f = resolve_at(&a.eye, a.pupil_mm, a.wavelength_nm)?;
    let ext = a
        .output
        .extension()
        .and_then(|e| e.to_str())
        .unwrap_or("")
        .to_ascii_lowercase();
    if ext != "svg" {
        return Err(Error::input(format!(
            "{}: extension {ext:?} is not allowed; need .svg",
            a.output.display()
        )));
    }
    let focus_m = a
        .focus_m
        .iter()
        .map(|s| parse_focus(s))
        .collect::<Result<Vec<_>>>()?;
    let settings = eye::draw::DrawSettings {
        focus_m,
        pupil_mm: a.pupil_mm,
        wavelength_nm: a.wavelength_nm,
        ..Default::default()
    };
    let svg = eye::draw::cross_section_svg(&f.eye, &settings)?;
    write_atomic(&a.output, svg.as_bytes())
}

fn run_list() -> Result<()> {
    println!("eye presets (ocular eye show|measure|draw NAME):");
    for name in eye_file::preset_names() {
        let f = eye_file::preset(name).expect("listed presets exist");
        let what = match &f.estimate {
            Some(r) => format!(
                "estimated from a {} mm, {} nm wavefront (RMS error {:.4} µm)",
                r.pupil_mm, r.wavelength_nm, r.rms_error_um
            ),
            None => match name {
                "navarro" => "Navarro's relaxed schematic eye".to_string(),
                "navarro-wide" => {
                    "Escudero-Sanz & Navarro's wide-angle eye (12 mm retina)".to_string()
                }
                _ => "the seed paper's Table 1 means, taken literally".to_string(),
            },
        };
        println!("  {name:<12} {what}");
    }
    println!("aberration presets (ocular eye estimate --preset NAME):");
    for name in aberrations::preset_names() {
        let s = aberrations::preset(name)?;
        println!(
            "  {name:<12} {} mm pupil, {} nm, {}",
            s.pupil_diameter_mm,
            s.wavelength_nm,
            describe_terms(&s)
        );
    }
    Ok(())
}

/// "aberration-free", "1 term of order 2", "27 terms up to order 6": piston changes no image,
/// so a set of piston alone is described as free of aberration.
fn describe_terms(set: &ZernikeSet) -> String {
    let terms: Vec<_> = set
        .coefficients
        .iter()
        .filter(|&&(n, _, um)| n > 0 && um != 0.0)
        .collect();
    let order = terms.iter().map(|t| t.0).max().unwrap_or(0);
    match terms.len() {
        0 => "aberration-free (piston only)".to_string(),
        1 => format!("1 term, of order {order}"),
        k => format!("{k} terms up to order {order}"),
    }
}
