//! A cross-section of the eye with traced ray bundles, as SVG text (the seed paper's
//! Figure 4 is the model): one panel per focus distance, the eye accommodated to it.

use super::accommodate::accommodate;
use super::error::EyeError;
use super::model::Eye;
use super::paraxial::paraxial;
use super::system::OpticalSystem;
use super::trace::{trace_path, Ray};
use std::fmt::Write;

/// Settings of the drawing.
#[derive(Debug, Clone)]
pub struct DrawSettings {
    /// Focus distances (m, `None` = infinity); one panel each.
    pub focus_m: Vec<Option<f64>>,
    pub pupil_mm: f64,
    pub wavelength_nm: f64,
    /// Rays per bundle across the vertical meridian.
    pub rays: usize,
    /// Pixels per millimetre.
    pub scale: f64,
}

impl Default for DrawSettings {
    fn default() -> Self {
        DrawSettings {
            focus_m: vec![None, Some(0.2)],
            pupil_mm: 4.0,
            wavelength_nm: 555.0,
            rays: 9,
            scale: 24.0,
        }
    }
}

const HALF_HEIGHT_MM: f64 = 7.0;
const MARGIN_MM: f64 = 3.0;

/// Draws `eye` in the y–z plane for every focus distance of `settings`.
pub fn cross_section_svg(eye: &Eye, settings: &DrawSettings) -> Result<String, EyeError> {
    let s = settings.scale;
    let length = eye.axial_length_mm + 2.0 * MARGIN_MM;
    let panel_h = 2.0 * HALF_HEIGHT_MM + 2.0;
    let w = length * s;
    let h = panel_h * s * settings.focus_m.len() as f64;
    let mut out = String::new();
    let _ = writeln!(
        out,
        r#"<svg xmlns="http://www.w3.org/2000/svg" width="{w:.0}" height="{h:.0}" viewBox="0 0 {w:.0} {h:.0}" font-family="sans-serif" font-size="13">"#
    );
    let _ = writeln!(out, r#"<rect width="100%" height="100%" fill="white"/>"#);
    for (k, focus) in settings.focus_m.iter().enumerate() {
        let acc = accommodate(eye, *focus, settings.pupil_mm, settings.wavelength_nm)?;
        let sys = acc.eye.system()?;
        let y0 = (k as f64 * panel_h + 1.0 + HALF_HEIGHT_MM) * s;
        let map = |z: f64, y: f64| ((z + MARGIN_MM) * s, y0 - y * s);
        panel(&mut out, &sys, settings, *focus, &map);
        let label = match focus {
            Some(d) => format!("focused at {d} m"),
            None => "focused at infinity".to_string(),
        };
        let _ = writeln!(
            out,
            r#"<text x="8" y="{:.1}">{label}; lens diameter {:.3} mm; {} mm pupil, {} nm</text>"#,
            y0 - (HALF_HEIGHT_MM - 0.6) * s,
            acc.diameter_mm,
            settings.pupil_mm,
            settings.wavelength_nm
        );
    }
    out.push_str("</svg>\n");
    Ok(out)
}

fn polyline(out: &mut String, pts: &[(f64, f64)], style: &str) {
    let mut d = String::new();
    for (x, y) in pts {
        let _ = write!(d, "{x:.2},{y:.2} ");
    }
    let _ = writeln!(
        out,
        r#"<polyline points="{}" fill="none" {style}/>"#,
        d.trim_end()
    );
}

fn panel(
    out: &mut String,
    sys: &OpticalSystem,
    settings: &DrawSettings,
    focus: Option<f64>,
    map: &dyn Fn(f64, f64) -> (f64, f64),
) {
    // Surface profiles in the vertical meridian (x = 0), in the global frame.
    for (i, surf) in sys.surfaces.iter().enumerate() {
        let half = surf.semi_diameter_mm.min(6.0);
        let mut pts = Vec::new();
        for k in 0..=120 {
            let y = -half + 2.0 * half * k as f64 / 120.0;
            if let Some(sg) = surf.sag(0.0, y) {
                let (p, _) = surf.to_global([0.0, y, sg.z], [0.0, 0.0, 1.0]);
                pts.push(map(p[2], p[1]));
            }
        }
        let colour = if i < 2 { "#3a6ea5" } else { "#b5651d" };
        polyline(out, &pts, &format!(r#"stroke="{colour}" stroke-width="2""#));
    }
    // Retina and optical axis.
    let (rx, ry0) = map(sys.retina_z_mm, -HALF_HEIGHT_MM);
    let (_, ry1) = map(sys.retina_z_mm, HALF_HEIGHT_MM);
    let _ = writeln!(
        out,
        r##"<line x1="{rx:.1}" y1="{ry0:.1}" x2="{rx:.1}" y2="{ry1:.1}" stroke="#a33" stroke-width="3"/>"##
    );
    let (ax0, ay) = map(-MARGIN_MM, 0.0);
    let (ax1, _) = map(sys.retina_z_mm + MARGIN_MM * 0.5, 0.0);
    let _ = writeln!(
        out,
        r##"<line x1="{ax0:.1}" y1="{ay:.1}" x2="{ax1:.1}" y2="{ay:.1}" stroke="#999" stroke-dasharray="4 4"/>"##
    );
    // Rays aimed at the entrance pupil; the iris drawn where the marginal rays pass it.
    let p = paraxial(sys, settings.wavelength_nm, 90.0);
    let r = settings.pupil_mm / 2.0;
    let n = settings.rays.max(2);
    let mut iris = 0.0f64;
    for k in 0..n {
        let v = -1.0 + 2.0 * k as f64 / (n - 1) as f64;
        let target = [0.0, r * v, p.entrance_pupil_z_mm];
        let start = match focus {
            Some(d) => {
                let ray = Ray::towards([0.0, 0.0, -1000.0 * d], target);
                let s = ray.to_plane(-MARGIN_MM);
                Ray {
                    p: ray.at(s),
                    ..ray
                }
            }
            None => Ray {
                p: [0.0, r * v, -MARGIN_MM],
                d: [0.0, 0.0, 1.0],
                opl_mm: 0.0,
            },
        };
        let (pts, _) = trace_path(sys, settings.wavelength_nm, start);
        if pts.len() > sys.stop_index {
            let (a, b) = (pts[sys.stop_index - 1], pts[sys.stop_index]);
            let f = (sys.stop_z_mm - a[2]) / (b[2] - a[2]);
            iris = iris.max((a[1] + f * (b[1] - a[1])).abs());
        }
        let mapped: Vec<_> = pts.iter().map(|q| map(q[2], q[1])).collect();
        polyline(
            out,
            &mapped,
            r##"stroke="#e8a000" stroke-width="1" stroke-opacity="0.8""##,
        );
    }
    for sign in [-1.0, 1.0] {
        let (x, y0) = map(sys.stop_z_mm, sign * iris);
        let (_, y1) = map(sys.stop_z_mm, sign * 6.0);
        let _ = writeln!(
            out,
            r##"<line x1="{x:.1}" y1="{y0:.1}" x2="{x:.1}" y2="{y1:.1}" stroke="#333" stroke-width="4"/>"##
        );
    }
}
