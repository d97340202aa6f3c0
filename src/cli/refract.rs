//! `ocular eye refract`: the spectacle prescription that best corrects an eye, printed in the
//! form `--correct` takes, so that prescription → eye → prescription is a scriptable loop.

use clap::Args;

use super::correction::number;
use crate::eye::correction::{format_rx, DEFAULT_VERTEX_MM};
use crate::eye::file as eye_file;
use crate::eye::refract::refract;
use crate::{Error, Result};

#[derive(Debug, Args)]
pub struct RefractArgs {
    /// Eye file or preset name (a correction in the file is removed first; an IOL is kept).
    pub eye: String,
    /// Entrance-pupil diameter the wavefront is measured over, in mm (1 to 9).
    #[arg(long, default_value_t = 4.0, value_parser = parse_pupil_mm, allow_hyphen_values = true)]
    pub pupil_mm: f64,
    /// Vertex distance of the spectacle plane, lens to cornea, in mm (0 to 16; 0 = contact lens).
    #[arg(long, default_value_t = DEFAULT_VERTEX_MM, value_parser = super::correction::parse_vertex_option, allow_hyphen_values = true)]
    pub vertex_mm: f64,
    /// Wavelength of the refraction in nm (380 to 1000; default: the wavelength the renderer
    /// accommodates at).
    #[arg(long, default_value_t = crate::eye::refract::REFRACTION_WAVELENGTH_NM, value_parser = parse_wavelength_nm, allow_hyphen_values = true)]
    pub wavelength_nm: f64,
    /// Print JSON (sphere_d, cylinder_d, axis_deg, rx, and the measurement behind them).
    #[arg(long)]
    pub json: bool,
}

fn parse_pupil_mm(text: &str) -> std::result::Result<f64, String> {
    let v = number(text)?;
    within(crate::limits::PUPIL_MM, v)
}

fn parse_wavelength_nm(text: &str) -> std::result::Result<f64, String> {
    let v = number(text)?;
    within(crate::limits::WAVELENGTH_NM, v)
}

fn within(limit: crate::limits::Limit, v: f64) -> std::result::Result<f64, String> {
    if limit.contains(v) {
        Ok(v)
    } else {
        Err(format!("{v} is outside {}", limit.allowed()))
    }
}

pub fn run(a: &RefractArgs) -> Result<()> {
    let f = eye_file::resolve(&a.eye)?;
    let r = refract(&f.eye, a.pupil_mm, a.vertex_mm, a.wavelength_nm)
        .map_err(|e| Error::input(format!("{}: cannot refract the eye: {e}", a.eye)))?;
    let rx = format_rx(r.sphere_d, r.cylinder_d, r.axis_deg);
    if a.json {
        #[derive(serde::Serialize)]
        struct Out<'a> {
            rx: &'a str,
            #[serde(flatten)]
            refraction: &'a crate::eye::refract::SpectacleRefraction,
        }
        let text = serde_json::to_string_pretty(&Out {
            rx: &rx,
            refraction: &r,
        })
        .map_err(|e| Error::input(format!("cannot encode JSON: {e}")))?;
        return print_out(&format!("{text}\n"));
    }
    print_out(&format!("{rx}\n{}\n", details(a, &r)))
}

/// Writes to stdout; a closed pipe (`| head -1`) ends the command quietly.
fn print_out(text: &str) -> Result<()> {
    use std::io::Write;
    let mut out = std::io::stdout().lock();
    match out.write_all(text.as_bytes()).and_then(|_| out.flush()) {
        Err(e) if e.kind() != std::io::ErrorKind::BrokenPipe => Err(Error::input(format!(
            "cannot write to standard output: {e}"
        ))),
        _ => Ok(()),
    }
}

fn details(a: &RefractArgs, r: &crate::eye::refract::SpectacleRefraction) -> String {
    format!(
        "at {} over a {} mm pupil, {} nm; the eye's own refraction at its entrance pupil \
         ({:.2} mm behind the cornea): M {:+.3} D, J0 {:+.3} D, J45 {:+.3} D; residual through \
         the lens {:.1e} D",
        if a.vertex_mm == 0.0 {
            "the cornea (contact lens)".to_string()
        } else {
            format!("a {} mm vertex distance", a.vertex_mm)
        },
        a.pupil_mm,
        a.wavelength_nm,
        r.eye_entrance_pupil_z_mm,
        r.eye_refraction.m,
        r.eye_refraction.j0,
        r.eye_refraction.j45,
        r.residual_d
    )
}
