//! `ocular psf`: one point-spread function from a Zernike set, for people and for checks by
//! other tools. Writes the intensity as a single-channel 32-bit float EXR (normalised to sum 1,
//! optical axis at pixel (N/2, N/2), row 0 at the top, +x right, +y up), a JSON sidecar with
//! every input and accuracy figure, and optionally a log-scaled PNG preview.

use std::path::{Path, PathBuf};

use clap::Args;

use super::outputs::Outputs;
use crate::aberrations::{self, ZernikeSet};
use crate::image_io::{self, ImageGray, ImageRgba, Tonemap, TonemapMode};
use crate::optics::beta::StilesCrawford;
use crate::optics::psf::{
    arcmin_from_pitch, compute_psf, defocus_f_from_dioptres, pitch_from_arcmin, PsfRequest,
};
use crate::{Error, Result};

#[derive(Debug, Args)]
#[command(
    after_help = "Orientation: the EXR's row 0 is the top; +x points right and +y up, parallel to the \
pupil axes of the Zernike set. A positive c(3,1) coma puts the sharp core at +x with its flare towards −x.\n\n\
Examples:\n  ocular psf --preset keratoconus -o kc.exr --png kc.png\n  \
ocular psf --zernike eye.abp --pupil-mm 4 --wavelength-nm 550 --defocus-d 1.5 --size 512 -o psf.exr"
)]
pub struct PsfArgs {
    /// Zernike file: our TOML format, CSV (`j,coefficient_um` with `# pupil_diameter_mm = …`
    /// and `# wavelength_nm = …` header lines) or an `.abp` file.
    #[arg(
        long,
        value_name = "FILE",
        conflicts_with = "preset",
        required_unless_present = "preset"
    )]
    pub zernike: Option<PathBuf>,
    /// A built-in aberration set: healthy, myopia, myopia3, astigmatism, keratoconus.
    #[arg(long, value_name = "NAME")]
    pub preset: Option<String>,
    /// Pupil diameter (mm) for the PSF; at most the set's own pupil (the coefficients are
    /// rescaled exactly to a smaller concentric pupil). Default: the set's pupil.
    #[arg(long, value_name = "MM", allow_negative_numbers = true)]
    pub pupil_mm: Option<f64>,
    /// Wavelength (nm, 380–1000). The wavefront in µm is taken as given at this wavelength
    /// (no chromatic aberration: use an eye model for that). Default: the set's wavelength.
    #[arg(long, value_name = "NM", allow_negative_numbers = true)]
    pub wavelength_nm: Option<f64>,
    /// Extra defocus in dioptres (positive = the eye focuses too strongly, like myopia).
    #[arg(
        long,
        value_name = "D",
        default_value_t = 0.0,
        allow_negative_numbers = true
    )]
    pub defocus_d: f64,
    /// Angular size of one output pixel in arcminutes (object space).
    #[arg(
        long,
        value_name = "ARCMIN",
        default_value_t = 0.25,
        allow_negative_numbers = true
    )]
    pub pitch_arcmin: f64,
    /// Output side in pixels.
    #[arg(long, value_name = "N", default_value_t = 256)]
    pub size: usize,
    /// Pupil energy the β expansion may miss (its degree grows until it misses less).
    #[arg(long, default_value_t = 1e-8)]
    pub beta_tolerance: f64,
    /// Highest β expansion degree.
    #[arg(long, default_value_t = 160)]
    pub max_degree: u32,
    /// Stiles–Crawford apodisation: intensity sensitivity 10^(−ρ·r²) over the pupil radius r in
    /// mm, given as ρ in 1/mm² (the usual foveal value: 0.05). Off by default.
    #[arg(long, value_name = "PER_MM2")]
    pub stiles_crawford: Option<f64>,
    /// Output EXR (single channel "Y", 32-bit float).
    #[arg(short, long, value_name = "FILE")]
    pub output: PathBuf,
    /// Also write a log-scaled preview PNG (4 decades below the peak).
    #[arg(long, value_name = "FILE")]
    pub png: Option<PathBuf>,
    /// Print the sidecar JSON to standard output as well.
    #[arg(long)]
    pub json: bool,
}

#[derive(serde::Serialize)]
struct Sidecar<'a> {
    source: &'a str,
    pupil_mm: f64,
    wavelength_nm: f64,
    coefficients: Vec<Coefficient>,
    defocus_d: f64,
    defocus_f: f64,
    pitch_arcmin: f64,
    pitch_lambda_over_na: f64,
    size: usize,
    optical_axis_pixel: [usize; 2],
    orientation: &'static str,
    beta_degree: u32,
    beta_truncation_error: f64,
    beta_tolerance: f64,
    strehl: f64,
    energy_in_grid: f64,
    stiles_crawford_per_mm2: Option<f64>,
    seconds: f64,
    exr: String,
}

#[derive(serde::Serialize)]
struct Coefficient {
    n: u32,
    m: i32,
    um: f64,
}

fn load_set(args: &PsfArgs) -> Result<(ZernikeSet, String)> {
    match (&args.zernike, &args.preset) {
        (Some(path), _) => Ok((
            ZernikeSet::load(path, None, None)?,
            path.display().to_string(),
        )),
        (None, Some(name)) => Ok((aberrations::preset(name)?, format!("preset:{name}"))),
        (None, None) => Err(Error::input("give --zernike FILE or --preset NAME")),
    }
}

fn positive(name: &str, value: f64) -> Result<f64> {
    if value.is_finite() && value > 0.0 {
        Ok(value)
    } else {
        Err(Error::input(format!(
            "{name} must be a positive number (got {value})"
        )))
    }
}

pub fn run(args: &PsfArgs) -> Result<()> {
    let mut outputs = Outputs::new();
    outputs.add("-o", &args.output, &["exr"])?;
    let sidecar_file = sidecar_path(&args.output);
    outputs.add("-o (its JSON sidecar)", &sidecar_file, &["json"])?;
    if let Some(png) = &args.png {
        outputs.add("--png", png, &["png"])?;
    }
    outputs.probe()?;
    let (set, source) = load_set(args)?;
    let (set, pupil_mm) = over_pupil(set, args.pupil_mm)?;
    let wavelength_nm = args.wavelength_nm.unwrap_or(set.wavelength_nm);
    crate::limits::WAVELENGTH_NM
        .check("--wavelength-nm", wavelength_nm)
        .map_err(Error::input)?;
    if !args.defocus_d.is_finite() {
        return Err(Error::input(
            "--defocus-d must be a finite number of dioptres",
        ));
    }
    let pitch_arcmin = positive("--pitch-arcmin", args.pitch_arcmin)?;
    if !(8..=8192).contains(&args.size) {
        return Err(Error::input(format!(
            "--size {} is outside 8–8192 pixels",
            args.size
        )));
    }
    let pitch = pitch_from_arcmin(pitch_arcmin, pupil_mm, wavelength_nm);
    let mut request = PsfRequest::new(
        set.coefficients.clone(),
        pupil_mm,
        wavelength_nm,
        pitch,
        args.size,
    );
    request.defocus_f = defocus_f_from_dioptres(args.defocus_d, pupil_mm, wavelength_nm);
    request.beta_tolerance = positive("--beta-tolerance", args.beta_tolerance)?;
    request.max_degree = args.max_degree;
    request.parallel = true;
    if let Some(rho) = args.stiles_crawford {
        request.stiles_crawford = Some(StilesCrawford {
            rho_per_mm2: positive("--stiles-crawford", rho)?,
        });
    }
    let started = std::time::Instant::now();
    let psf = compute_psf(&request).map_err(|e| option_error(e, args, pupil_mm, wavelength_nm))?;
    let seconds = started.elapsed().as_secs_f64();
    let total: f64 = psf.intensity.iter().sum();
    if !(total.is_finite() && total > 0.0) {
        return Err(Error::input(
            "the PSF has no energy on this grid: enlarge --size or --pitch-arcmin",
        ));
    }
    if psf.energy_in_grid < 0.99 {
        eprintln!(
            "warning: only {:.1}% of the light falls on the {}×{} grid; enlarge --size or --pitch-arcmin",
            100.0 * psf.energy_in_grid.max(0.0),
            args.size,
            args.size
        );
    }
    let normalised: Vec<f32> = psf.intensity.iter().map(|v| (v / total) as f32).collect();
    let n = args.size as u32;
    image_io::write_exr_gray(
        outputs.temporary(&args.output),
        &ImageGray::new(n, n, normalised.clone()),
        "Y",
    )?;
    if let Some(png) = &args.png {
        write_log_preview(outputs.temporary(png), n, &normalised)?;
    }
    let sidecar = Sidecar {
        source: &source,
        pupil_mm,
        wavelength_nm,
        coefficients: set
            .coefficients
            .iter()
            .map(|&(n, m, um)| Coefficient { n, m, um })
            .collect(),
        defocus_d: args.defocus_d,
        defocus_f: psf.defocus_f,
        pitch_arcmin: arcmin_from_pitch(pitch, pupil_mm, wavelength_nm),
        pitch_lambda_over_na: pitch,
        size: args.size,
        optical_axis_pixel: [args.size / 2, args.size / 2],
        orientation: "row 0 at the top; +x right, +y up, parallel to the pupil axes",
        beta_degree: psf.beta_degree,
        beta_truncation_error: psf.beta_truncation_error,
        beta_tolerance: request.beta_tolerance,
        strehl: psf.strehl,
        energy_in_grid: psf.energy_in_grid,
        stiles_crawford_per_mm2: args.stiles_crawford,
        seconds,
        exr: args.output.display().to_string(),
    };
    let text = serde_json::to_string_pretty(&sidecar)
        .map_err(|e| Error::input(format!("cannot encode JSON: {e}")))?;
    image_io::write_text_atomic(outputs.temporary(&sidecar_file), &text)?;
    outputs.commit()?;
    if args.json {
        println!("{text}");
    } else {
        print_written(args, &sidecar);
    }
    Ok(())
}

/// The coefficients over `--pupil-mm` (default: their own pupil; never a larger one).
fn over_pupil(set: ZernikeSet, pupil_mm: Option<f64>) -> Result<(ZernikeSet, f64)> {
    let pupil_mm = positive("--pupil-mm", pupil_mm.unwrap_or(set.pupil_diameter_mm))?;
    if pupil_mm > set.pupil_diameter_mm + 1e-9 {
        return Err(Error::input(format!(
            "--pupil-mm {pupil_mm} is larger than the {} mm pupil the coefficients were measured over; \
             allowed: up to {} mm",
            set.pupil_diameter_mm, set.pupil_diameter_mm
        )));
    }
    if pupil_mm < set.pupil_diameter_mm {
        return Ok((set.with_pupil(pupil_mm)?, pupil_mm));
    }
    Ok((set, pupil_mm))
}

fn print_written(args: &PsfArgs, sidecar: &Sidecar<'_>) {
    println!(
        "wrote {} ({}×{}, {:.3} arcmin/px, Strehl {:.4}, β degree {}, truncation {:.1e}, {:.2} s) and {}",
        args.output.display(),
        args.size,
        args.size,
        args.pitch_arcmin,
        sidecar.strehl,
        sidecar.beta_degree,
        sidecar.beta_truncation_error,
        sidecar.seconds,
        sidecar_path(&args.output).display()
    );
}

/// The optics core names its own quantities (`defocus_f`, `pitch_lambda_over_na`, the grid
/// extent); the user gave options, so the message names those and their allowed values.
fn option_error(
    e: crate::optics::OpticsError,
    args: &PsfArgs,
    pupil_mm: f64,
    wavelength_nm: f64,
) -> Error {
    use crate::optics::OpticsError;
    let OpticsError::OutOfRange { field, .. } = &e else {
        return e.into();
    };
    let per_dioptre = defocus_f_from_dioptres(1.0, pupil_mm, wavelength_nm).abs();
    let limit_d = 5000.0 / per_dioptre.max(f64::MIN_POSITIVE);
    if field.contains("defocus") {
        Error::input(format!(
            "--defocus-d {}: with the set's own defocus this is more than a {pupil_mm} mm pupil at \
             {wavelength_nm} nm allows (|total defocus| up to about {limit_d:.0} D)",
            args.defocus_d
        ))
    } else if field.contains("grid extent") {
        Error::input(format!(
            "--size {} with --pitch-arcmin {}: the grid reaches too far from the optical axis for \
             this pupil and wavelength; lower --size or --pitch-arcmin",
            args.size, args.pitch_arcmin
        ))
    } else if field.contains("pitch") {
        Error::input(format!(
            "--pitch-arcmin {} is outside what the computation allows for a {pupil_mm} mm pupil \
             at {wavelength_nm} nm ({:.2e} to {:.2e} arcmin)",
            args.pitch_arcmin,
            arcmin_from_pitch(1e-4, pupil_mm, wavelength_nm),
            arcmin_from_pitch(1e3, pupil_mm, wavelength_nm)
        ))
    } else if field == "max_degree" {
        Error::input(format!(
            "--max-degree {} is outside 1 to 300",
            args.max_degree
        ))
    } else if field == "beta_tolerance" {
        Error::input(format!(
            "--beta-tolerance {} is outside 1e-14 to 0.5",
            args.beta_tolerance
        ))
    } else {
        e.into()
    }
}

/// `psf.exr` → `psf.json`.
fn sidecar_path(exr: &Path) -> PathBuf {
    exr.with_extension("json")
}

/// Grey levels log10(I / peak) from −4 (black) to 0 (white).
fn write_log_preview(path: &Path, n: u32, intensity: &[f32]) -> Result<()> {
    let peak = intensity
        .iter()
        .copied()
        .fold(0.0f32, f32::max)
        .max(f32::MIN_POSITIVE);
    let pixels = intensity
        .iter()
        .map(|&v| {
            let g = ((v / peak).max(1e-12).log10() + 4.0) / 4.0;
            let g = g.clamp(0.0, 1.0);
            [g, g, g, 1.0]
        })
        .collect();
    image_io::write_png(
        path,
        &ImageRgba::new(n, n, pixels),
        Tonemap {
            exposure_ev: 0.0,
            mode: TonemapMode::Clamp,
        },
    )
}
