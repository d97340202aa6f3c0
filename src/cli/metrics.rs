//! `ocular metrics`: PSNR, SSIM and FLIP between two images of the same size, with FLIP's
//! quartiles and a colour-mapped error map. EXR pairs get HDR-FLIP on linear light; PNG and
//! JPEG pairs get LDR-FLIP on their sRGB-decoded values.

use std::path::{Path, PathBuf};

use clap::Args;

use super::outputs::{check_extension, check_folder};
use crate::image_io;
use crate::metrics::flip::{self, FlipStats, HdrSettings, ToneMapper};
use crate::metrics::{psnr, ssim, ImageView};
use crate::{Error, Result};

#[derive(Debug, Args)]
#[command(after_help = "Examples:\n  \
    ocular metrics truth.png splat.png\n  \
    ocular metrics truth.exr splat.exr --monitor 0.6,2560,0.5 --map flip.png --json\n\n\
PSNR and SSIM are computed on what the files store: sRGB-encoded values in [0, 1] for PNG and \
JPEG (a peak of 1), linear values for EXR (the peak is the reference's largest channel value). \
FLIP (Andersson et al. 2020; HDR-FLIP 2021) judges the pair as a viewer alternating between them \
sees it at the given pixels per degree; 0 is no visible difference, 1 the largest. Quartiles are \
plain percentiles of the per-pixel map.")]
pub struct MetricsArgs {
    /// The reference image: EXR (HDR) or PNG / JPEG (LDR, sRGB).
    #[arg(value_name = "REFERENCE")]
    pub reference: PathBuf,
    /// The image judged against it: the same kind and size.
    #[arg(value_name = "TEST")]
    pub test: PathBuf,
    /// Viewing condition in pixels per degree (default: FLIP's, 67.02: 0.7 m from a 0.7 m
    /// wide monitor 3840 pixels across).
    #[arg(
        long,
        value_name = "N",
        conflicts_with = "monitor",
        allow_hyphen_values = true
    )]
    pub ppd: Option<f64>,
    /// Viewing condition as a monitor's width (m), its horizontal resolution (px) and the
    /// viewer's distance (m).
    #[arg(long, value_name = "WIDTH_M,RES_X,DIST_M", value_parser = parse_monitor)]
    pub monitor: Option<(f64, u32, f64)>,
    /// Tone mapper of HDR-FLIP's exposures (EXR only).
    #[arg(long, value_enum, default_value = "aces")]
    pub tone_mapper: ToneMapperArg,
    /// First exposure (stops) of HDR-FLIP (default: where the reference's brightest pixel
    /// tone maps to 0.85).
    #[arg(long, value_name = "STOPS", allow_hyphen_values = true)]
    pub start_exposure: Option<f64>,
    /// Last exposure (stops) of HDR-FLIP (default: where the reference's median pixel tone
    /// maps to 0.85).
    #[arg(long, value_name = "STOPS", allow_hyphen_values = true)]
    pub stop_exposure: Option<f64>,
    /// Number of exposures of HDR-FLIP (default: one per stop of the range, at least 2).
    #[arg(long, value_name = "N")]
    pub exposures: Option<usize>,
    /// Print the results as JSON instead of a table.
    #[arg(long)]
    pub json: bool,
    /// Write the FLIP map, colour-mapped (magma: black = no error, pale yellow = 1), as PNG.
    #[arg(long, value_name = "FILE.png")]
    pub map: Option<PathBuf>,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum ToneMapperArg {
    Aces,
    Hable,
    Reinhard,
}

impl From<ToneMapperArg> for ToneMapper {
    fn from(t: ToneMapperArg) -> ToneMapper {
        match t {
            ToneMapperArg::Aces => ToneMapper::Aces,
            ToneMapperArg::Hable => ToneMapper::Hable,
            ToneMapperArg::Reinhard => ToneMapper::Reinhard,
        }
    }
}

/// `--monitor WIDTH_M,RES_X,DIST_M`.
fn parse_monitor(text: &str) -> std::result::Result<(f64, u32, f64), String> {
    let parts: Vec<&str> = text.split(',').map(str::trim).collect();
    let [width, res, dist] = parts[..] else {
        return Err(format!(
            "`{text}` is not WIDTH_M,RES_X,DIST_M (e.g. 0.7,3840,0.7)"
        ));
    };
    let metres = |name: &str, v: &str| -> std::result::Result<f64, String> {
        let m: f64 = v
            .parse()
            .map_err(|_| format!("{name} `{v}` is not a number of metres"))?;
        if !(m.is_finite() && m > 0.0 && m <= 1000.0) {
            return Err(format!("{name} {m} is outside (0, 1000] m"));
        }
        Ok(m)
    };
    let res_x: u32 = res
        .parse()
        .ok()
        .filter(|r| (1..=1_000_000).contains(r))
        .ok_or_else(|| format!("RES_X `{res}` is not a pixel count from 1 to 1000000"))?;
    Ok((metres("WIDTH_M", width)?, res_x, metres("DIST_M", dist)?))
}

/// The range a `--ppd` may take: below 1 a pixel spans more than a degree, above 10 000 the
/// filters would span millions of pixels.
use crate::metrics::flip::{ppd_in_range, PPD_RANGE};

#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "lowercase")]
enum DynamicRange {
    Ldr,
    Hdr,
}

/// An image as read: the values the file stores (for PSNR and SSIM) and linear light (for
/// FLIP).
struct Loaded {
    range: DynamicRange,
    width: usize,
    height: usize,
    stored: Vec<[f32; 4]>,
    linear: Vec<[f32; 4]>,
}

fn kind_of(option: &str, path: &Path) -> Result<DynamicRange> {
    let ext = path
        .extension()
        .and_then(|e| e.to_str())
        .unwrap_or("")
        .to_ascii_lowercase();
    match ext.as_str() {
        "exr" => Ok(DynamicRange::Hdr),
        "png" | "jpg" | "jpeg" => Ok(DynamicRange::Ldr),
        _ => Err(Error::input(format!(
            "{option} {}: give an .exr (HDR) or a .png / .jpg / .jpeg (LDR) image",
            path.display()
        ))),
    }
}

fn load(option: &str, path: &Path) -> Result<Loaded> {
    match kind_of(option, path)? {
        DynamicRange::Hdr => {
            let image = image_io::read_exr_rgba(path)?;
            let bad = |p: &[f32; 4]| !(0..3).all(|c| p[c].is_finite() && p[c] >= 0.0);
            if let Some(first) = image.pixels.iter().position(bad) {
                let count = image.pixels.iter().filter(|p| bad(p)).count();
                let w = image.width.max(1) as usize;
                return Err(Error::file(
                    path,
                    format!(
                        "{count} pixels are NaN, infinite or negative (first at x = {}, y = {}); \
                         the metrics need finite, non-negative linear colour",
                        first % w,
                        first / w
                    ),
                ));
            }
            Ok(Loaded {
                range: DynamicRange::Hdr,
                width: image.width as usize,
                height: image.height as usize,
                stored: image.pixels.clone(),
                linear: image.pixels,
            })
        }
        DynamicRange::Ldr => {
            let decoded = image::ImageReader::open(path)
                .map_err(|e| Error::file(path, format!("cannot read: {e}")))?
                .with_guessed_format()
                .map_err(|e| Error::file(path, format!("cannot read: {e}")))?
                .decode()
                .map_err(|e| Error::file(path, format!("cannot decode: {e}")))?
                .into_rgb32f();
            let (width, height) = (decoded.width() as usize, decoded.height() as usize);
            let stored: Vec<[f32; 4]> = decoded.pixels().map(|p| [p[0], p[1], p[2], 1.0]).collect();
            let linear = stored
                .iter()
                .map(|p| {
                    let l = |v: f32| flip::colour::srgb_to_linear(f64::from(v)) as f32;
                    [l(p[0]), l(p[1]), l(p[2]), 1.0]
                })
                .collect();
            Ok(Loaded {
                range: DynamicRange::Ldr,
                width,
                height,
                stored,
                linear,
            })
        }
    }
}

#[derive(serde::Serialize)]
struct FlipReport {
    /// "LDR-FLIP" or "HDR-FLIP".
    metric: &'static str,
    #[serde(flatten)]
    stats: FlipStats,
    tone_mapper: Option<ToneMapper>,
    exposures: Option<flip::ExposureRange>,
}

#[derive(serde::Serialize)]
struct Report {
    reference: String,
    test: String,
    width: usize,
    height: usize,
    dynamic_range: DynamicRange,
    ppd: f64,
    /// PSNR in dB (null for identical images) over the stored values, with this peak.
    psnr_db: f64,
    psnr_peak: f64,
    mssim: f64,
    ssim_window_px: usize,
    flip: FlipReport,
}

pub fn run(args: &MetricsArgs) -> Result<()> {
    let ppd = viewing_ppd(args)?;
    if let Some(path) = &args.map {
        check_extension("--map", path, &["png"])?;
        check_folder("--map", path)?;
    }
    let hdr = check_kinds(args)?;
    let reference = load("REFERENCE", &args.reference)?;
    let test = load("TEST", &args.test)?;
    if (reference.width, reference.height) != (test.width, test.height) {
        return Err(Error::input(format!(
            "{} is {}×{} and {} is {}×{}: the images must have the same size",
            args.reference.display(),
            reference.width,
            reference.height,
            args.test.display(),
            test.width,
            test.height
        )));
    }
    let (w, h) = (reference.width, reference.height);
    let peak = if hdr {
        hdr_peak(&reference.stored)
    } else {
        1.0
    };
    let (stored_ref, stored_test) = (view(&reference.stored, (w, h)), view(&test.stored, (w, h)));
    let psnr_db = psnr(stored_ref, stored_test, peak);
    let quality = ssim(stored_ref, stored_test, peak);
    let settings = HdrSettings {
        tone_mapper: args.tone_mapper.into(),
        start: args.start_exposure,
        stop: args.stop_exposure,
        count: args.exposures,
    };
    let (linear_ref, linear_test) = (view(&reference.linear, (w, h)), view(&test.linear, (w, h)));
    let (map, exposures) = if hdr {
        let result = flip::hdr_flip(linear_ref, linear_test, ppd, &settings)
            .map_err(|e| hdr_error(args, e))?;
        (result.map, Some(result.range))
    } else {
        (flip::ldr_flip(linear_ref, linear_test, ppd), None)
    };
    let stats = FlipStats::of(&map);
    let report = Report {
        reference: args.reference.display().to_string(),
        test: args.test.display().to_string(),
        width: w,
        height: h,
        dynamic_range: reference.range,
        ppd,
        psnr_db,
        psnr_peak: peak,
        mssim: quality.mean,
        ssim_window_px: quality.window_px,
        flip: FlipReport {
            metric: if hdr { "HDR-FLIP" } else { "LDR-FLIP" },
            stats,
            tone_mapper: hdr.then_some(settings.tone_mapper),
            exposures,
        },
    };
    if let Some(path) = &args.map {
        write_map(path, &map, w, h)?;
    }
    if args.json {
        let text = serde_json::to_string_pretty(&report)
            .map_err(|e| Error::input(format!("cannot encode JSON: {e}")))?;
        println!("{text}");
    } else {
        print_table(&report);
        if let Some(path) = &args.map {
            println!("wrote {}", path.display());
        }
    }
    Ok(())
}

/// The viewing condition in pixels per degree: --ppd, else from --monitor, else FLIP's.
fn viewing_ppd(args: &MetricsArgs) -> Result<f64> {
    match (args.ppd, args.monitor) {
        (Some(p), _) => {
            if !ppd_in_range(p) {
                return Err(Error::input(format!(
                    "--ppd {p} is outside {} to {} pixels per degree",
                    PPD_RANGE.0, PPD_RANGE.1
                )));
            }
            Ok(p)
        }
        (None, Some((width_m, res_x, dist_m))) => {
            let p = flip::pixels_per_degree(width_m, f64::from(res_x), dist_m);
            if !ppd_in_range(p) {
                return Err(Error::input(format!(
                    "--monitor {width_m},{res_x},{dist_m} gives {p:.3} pixels per degree, outside \
                     {} to {}",
                    PPD_RANGE.0, PPD_RANGE.1
                )));
            }
            Ok(p)
        }
        (None, None) => Ok(flip::DEFAULT_PPD),
    }
}

/// Whether the images are HDR (both EXR) or LDR (neither); the HDR options are refused for
/// LDR images and checked for range.
fn check_kinds(args: &MetricsArgs) -> Result<bool> {
    let (ref_kind, test_kind) = (
        kind_of("REFERENCE", &args.reference)?,
        kind_of("TEST", &args.test)?,
    );
    if ref_kind != test_kind {
        return Err(Error::input(format!(
            "{} and {}: one is HDR (EXR) and the other LDR (PNG/JPEG); compare images of one kind",
            args.reference.display(),
            args.test.display()
        )));
    }
    let hdr = ref_kind == DynamicRange::Hdr;
    let hdr_options_given =
        args.start_exposure.is_some() || args.stop_exposure.is_some() || args.exposures.is_some();
    if !hdr && (hdr_options_given || args.tone_mapper != ToneMapperArg::Aces) {
        return Err(Error::input(
            "--tone-mapper / --start-exposure / --stop-exposure / --exposures apply to EXR \
             (HDR) images",
        ));
    }
    if let Some(n) = args.exposures {
        if !(1..=64).contains(&n) {
            return Err(Error::input(format!("--exposures {n} is outside 1 to 64")));
        }
    }
    for (name, v) in [
        ("--start-exposure", args.start_exposure),
        ("--stop-exposure", args.stop_exposure),
    ] {
        if let Some(v) = v.filter(|v| !(v.is_finite() && v.abs() <= 64.0)) {
            return Err(Error::input(format!(
                "{name} {v} is outside -64 to 64 stops"
            )));
        }
    }
    Ok(hdr)
}

/// The PSNR peak of an HDR reference: its largest channel value (1 where it is black).
fn hdr_peak(stored: &[[f32; 4]]) -> f64 {
    let max = stored
        .iter()
        .flat_map(|p| [p[0], p[1], p[2]])
        .fold(0.0f32, f32::max);
    if max > 0.0 {
        f64::from(max)
    } else {
        1.0
    }
}

/// An HDR-FLIP error with the options that fix it named.
fn hdr_error(args: &MetricsArgs, e: flip::hdr::HdrError) -> Error {
    Error::input(match e {
        flip::hdr::HdrError::NoAutomaticRange => format!(
            "{}: {e} (--start-exposure and --stop-exposure)",
            args.reference.display()
        ),
        flip::hdr::HdrError::BadRange(_) => {
            format!("--start-exposure / --stop-exposure / --exposures: {e}")
        }
    })
}

fn view(pixels: &[[f32; 4]], (w, h): (usize, usize)) -> ImageView<'_> {
    ImageView::new(w, h, pixels)
}

fn print_table(r: &Report) {
    let kind = match r.dynamic_range {
        DynamicRange::Ldr => "LDR",
        DynamicRange::Hdr => "HDR",
    };
    println!(
        "{} against {} ({kind}, {}×{}), {:.2} pixels per degree",
        r.test, r.reference, r.width, r.height, r.ppd
    );
    let db = if r.psnr_db.is_infinite() {
        "∞".to_string()
    } else {
        format!("{:.2}", r.psnr_db)
    };
    println!("  PSNR      {db:>9} dB (peak {:.4})", r.psnr_peak);
    let window = if r.ssim_window_px == 11 {
        String::new()
    } else {
        format!(
            " ({0}×{0} window: the image is under 11 pixels)",
            r.ssim_window_px
        )
    };
    println!("  MSSIM     {:>9.4}{window}", r.mssim);
    let s = &r.flip.stats;
    println!(
        "  {:<9} {:>9.4} mean   quartiles {:.4} / {:.4} / {:.4}   min {:.4}   max {:.4}",
        r.flip.metric, s.mean, s.q1, s.median, s.q3, s.min, s.max
    );
    if let (Some(tm), Some(e)) = (r.flip.tone_mapper, r.flip.exposures) {
        println!(
            "  HDR-FLIP exposures {:+.3} to {:+.3} stops, {} of them, tone mapper {}",
            e.start,
            e.stop,
            e.count,
            match tm {
                ToneMapper::Aces => "ACES",
                ToneMapper::Hable => "Hable",
                ToneMapper::Reinhard => "Reinhard",
            }
        );
    }
}

/// The map through the magma colour map as an 8-bit PNG, written atomically.
fn write_map(path: &Path, map: &[f32], w: usize, h: usize) -> Result<()> {
    use image::ImageEncoder;
    let rgb: Vec<u8> = map
        .iter()
        .flat_map(|&e| flip::magma(f64::from(e)))
        .collect();
    let mut bytes = Vec::new();
    image::codecs::png::PngEncoder::new(&mut bytes)
        .write_image(&rgb, w as u32, h as u32, image::ExtendedColorType::Rgb8)
        .map_err(|e| Error::file(path, format!("cannot encode PNG: {e}")))?;
    super::write_atomic(path, &bytes)
}
