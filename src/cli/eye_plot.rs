//! Input vs achieved Zernike coefficients per (n, m), as bars side by side (the seed paper's
//! Figure 14): SVG with labels, or a PNG of the same bars for viewers without SVG.

use crate::eye::estimate::{Report, TermFit};
use crate::{Error, Result};
use std::fmt::Write;

const W_BAR: f64 = 9.0;
const GAP: f64 = 8.0;
const LEFT: f64 = 70.0;
const TOP: f64 = 50.0;
const PLOT_H: f64 = 300.0;
const BOTTOM: f64 = 60.0;

/// Symmetric value range covering every bar, rounded up to a readable step.
fn range(terms: &[TermFit]) -> (f64, f64) {
    let max = terms
        .iter()
        .flat_map(|t| [t.input_um.abs(), t.achieved_um.abs()])
        .fold(0.0f64, f64::max)
        .max(0.05);
    let step = nice_step(max / 4.0);
    ((max / step).ceil() * step, step)
}

fn nice_step(raw: f64) -> f64 {
    let p = 10f64.powf(raw.log10().floor());
    [1.0, 2.0, 5.0, 10.0]
        .iter()
        .map(|k| k * p)
        .find(|s| *s >= raw)
        .unwrap_or(10.0 * p)
}

fn width(terms: &[TermFit]) -> f64 {
    LEFT + terms.len() as f64 * (2.0 * W_BAR + GAP) + 20.0
}

pub fn svg(terms: &[TermFit], r: &Report) -> String {
    let (vmax, step) = range(terms);
    let w = width(terms);
    let h = TOP + PLOT_H + BOTTOM;
    let y = |v: f64| TOP + PLOT_H / 2.0 - v / vmax * PLOT_H / 2.0;
    let mut s = String::new();
    let _ = writeln!(
        s,
        r#"<svg xmlns="http://www.w3.org/2000/svg" width="{w:.0}" height="{h:.0}" viewBox="0 0 {w:.0} {h:.0}" font-family="sans-serif" font-size="11">"#
    );
    let _ = writeln!(s, r#"<rect width="100%" height="100%" fill="white"/>"#);
    let _ = writeln!(
        s,
        r#"<text x="10" y="18" font-size="14">Zernike coefficients (µm), {} mm pupil, {} nm: input (grey) vs achieved (blue); RMS error {:.4} µm</text>"#,
        r.pupil_mm, r.wavelength_nm, r.rms_error_um
    );
    let mut v = -vmax;
    while v <= vmax + 1e-9 {
        let yy = y(v);
        let _ = writeln!(
            s,
            r##"<line x1="{LEFT}" x2="{:.1}" y1="{yy:.1}" y2="{yy:.1}" stroke="{}" stroke-width="1"/><text x="{:.1}" y="{:.1}" text-anchor="end">{}</text>"##,
            w - 20.0,
            if v.abs() < 1e-12 { "#444" } else { "#ddd" },
            LEFT - 6.0,
            yy + 4.0,
            fmt_tick(v, step)
        );
        v += step;
    }
    for (i, t) in terms.iter().enumerate() {
        let x0 = LEFT + GAP / 2.0 + i as f64 * (2.0 * W_BAR + GAP);
        for (k, (val, colour)) in [(t.input_um, "#999"), (t.achieved_um, "#2a6fdb")]
            .iter()
            .enumerate()
        {
            let (a, b) = (y(*val), y(0.0));
            let _ = writeln!(
                s,
                r#"<rect x="{:.1}" y="{:.1}" width="{W_BAR}" height="{:.1}" fill="{colour}"/>"#,
                x0 + k as f64 * W_BAR,
                a.min(b),
                (a - b).abs().max(0.5)
            );
        }
        let lx = x0 + W_BAR;
        let ly = TOP + PLOT_H + 12.0;
        let _ = writeln!(
            s,
            r#"<text x="{lx:.1}" y="{ly:.1}" text-anchor="end" transform="rotate(-60 {lx:.1} {ly:.1})"{}>({},{})</text>"#,
            if t.given {
                r#" font-weight="bold""#
            } else {
                ""
            },
            t.n,
            t.m
        );
    }
    s.push_str("</svg>\n");
    s
}

fn fmt_tick(v: f64, step: f64) -> String {
    let decimals = (-step.log10().floor()).max(0.0) as usize;
    format!("{v:.decimals$}")
}

/// The same bars as a PNG (no text: axis lines at every tick, order separators in light grey).
pub fn png(terms: &[TermFit]) -> Result<Vec<u8>> {
    let (vmax, step) = range(terms);
    let w = width(terms).ceil() as u32;
    let h = (TOP + PLOT_H + 20.0) as u32;
    let mut img = image::RgbImage::from_pixel(w, h, image::Rgb([255, 255, 255]));
    let y = |v: f64| TOP + PLOT_H / 2.0 - v / vmax * PLOT_H / 2.0;
    let mut fill = |x0: f64, x1: f64, y0: f64, y1: f64, c: [u8; 3]| {
        let (xa, xb) = (x0.max(0.0) as u32, (x1.ceil() as u32).min(w));
        let (ya, yb) = (
            y0.min(y1).max(0.0) as u32,
            (y0.max(y1).ceil() as u32).min(h),
        );
        for yy in ya..yb.max(ya + 1).min(h) {
            for xx in xa..xb {
                img.put_pixel(xx, yy, image::Rgb(c));
            }
        }
    };
    let mut v = -vmax;
    while v <= vmax + 1e-9 {
        let c = if v.abs() < 1e-12 { [60; 3] } else { [221; 3] };
        fill(LEFT, w as f64 - 20.0, y(v), y(v) + 1.0, c);
        v += step;
    }
    let mut last_n = None;
    for (i, t) in terms.iter().enumerate() {
        let x0 = LEFT + GAP / 2.0 + i as f64 * (2.0 * W_BAR + GAP);
        if last_n != Some(t.n) {
            fill(
                x0 - GAP / 2.0,
                x0 - GAP / 2.0 + 1.0,
                TOP,
                TOP + PLOT_H,
                [200; 3],
            );
            last_n = Some(t.n);
        }
        fill(x0, x0 + W_BAR, y(t.input_um), y(0.0), [153; 3]);
        fill(
            x0 + W_BAR,
            x0 + 2.0 * W_BAR,
            y(t.achieved_um),
            y(0.0),
            [42, 111, 219],
        );
    }
    let mut out = std::io::Cursor::new(Vec::new());
    img.write_to(&mut out, image::ImageFormat::Png)
        .map_err(|e| Error::input(format!("cannot encode PNG: {e}")))?;
    Ok(out.into_inner())
}
