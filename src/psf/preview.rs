//! Pictures of a kernel grid: a contact sheet of kernels per object distance and channel, and
//! the projected PSF size against object dioptres per channel for two focus states (the seed
//! paper's Figure 7). Drawn into plain RGB buffers with a built-in 5×7 font.

use super::kernels::level_of_radius;
use super::kernels::KernelGrid;
use crate::{Error, Result};
use image::{Rgb, RgbImage};
use std::path::Path;

/// 5×7 glyphs, one byte per row (bit 4 = leftmost column).
fn glyph(c: char) -> [u8; 7] {
    match c.to_ascii_uppercase() {
        'A' => [14, 17, 17, 31, 17, 17, 17],
        'B' => [30, 17, 17, 30, 17, 17, 30],
        'C' => [14, 17, 16, 16, 16, 17, 14],
        'D' => [30, 17, 17, 17, 17, 17, 30],
        'E' => [31, 16, 16, 30, 16, 16, 31],
        'F' => [31, 16, 16, 30, 16, 16, 16],
        'G' => [14, 17, 16, 23, 17, 17, 15],
        'H' => [17, 17, 17, 31, 17, 17, 17],
        'I' => [14, 4, 4, 4, 4, 4, 14],
        'J' => [7, 2, 2, 2, 2, 18, 12],
        'K' => [17, 18, 20, 24, 20, 18, 17],
        'L' => [16, 16, 16, 16, 16, 16, 31],
        'M' => [17, 27, 21, 21, 17, 17, 17],
        'N' => [17, 17, 25, 21, 19, 17, 17],
        'O' => [14, 17, 17, 17, 17, 17, 14],
        'P' => [30, 17, 17, 30, 16, 16, 16],
        'Q' => [14, 17, 17, 17, 21, 18, 13],
        'R' => [30, 17, 17, 30, 20, 18, 17],
        'S' => [15, 16, 16, 14, 1, 1, 30],
        'T' => [31, 4, 4, 4, 4, 4, 4],
        'U' => [17, 17, 17, 17, 17, 17, 14],
        'V' => [17, 17, 17, 17, 17, 10, 4],
        'W' => [17, 17, 17, 21, 21, 21, 10],
        'X' => [17, 17, 10, 4, 10, 17, 17],
        'Y' => [17, 17, 10, 4, 4, 4, 4],
        'Z' => [31, 1, 2, 4, 8, 16, 31],
        '0' => [14, 17, 19, 21, 25, 17, 14],
        '1' => [4, 12, 4, 4, 4, 4, 14],
        '2' => [14, 17, 1, 2, 4, 8, 31],
        '3' => [31, 2, 4, 2, 1, 17, 14],
        '4' => [2, 6, 10, 18, 31, 2, 2],
        '5' => [31, 16, 30, 1, 1, 17, 14],
        '6' => [6, 8, 16, 30, 17, 17, 14],
        '7' => [31, 1, 2, 4, 8, 8, 8],
        '8' => [14, 17, 17, 14, 17, 17, 14],
        '9' => [14, 17, 17, 15, 1, 2, 12],
        '.' => [0, 0, 0, 0, 0, 12, 12],
        '-' => [0, 0, 0, 31, 0, 0, 0],
        '+' => [0, 4, 4, 31, 4, 4, 0],
        ':' => [0, 12, 12, 0, 12, 12, 0],
        '/' => [1, 2, 2, 4, 8, 8, 16],
        '(' => [2, 4, 8, 8, 8, 4, 2],
        ')' => [8, 4, 2, 2, 2, 4, 8],
        '=' => [0, 0, 31, 0, 31, 0, 0],
        ',' => [0, 0, 0, 0, 12, 4, 8],
        _ => [0; 7],
    }
}

const WHITE: Rgb<u8> = Rgb([255, 255, 255]);
const GREY: Rgb<u8> = Rgb([110, 110, 110]);
const CHANNEL: [Rgb<u8>; 3] = [Rgb([230, 60, 50]), Rgb([60, 200, 70]), Rgb([70, 110, 240])];

/// Draws `text` with its top-left corner at (x, y), each font pixel `scale`² screen pixels.
pub fn text(img: &mut RgbImage, x: i64, y: i64, scale: i64, color: Rgb<u8>, s: &str) {
    for (k, c) in s.chars().enumerate() {
        let g = glyph(c);
        for (row, bits) in g.iter().enumerate() {
            for col in 0..5 {
                if bits & (16 >> col) != 0 {
                    for dy in 0..scale {
                        for dx in 0..scale {
                            put(
                                img,
                                x + (k as i64 * 6 + col) * scale + dx,
                                y + row as i64 * scale + dy,
                                color,
                            );
                        }
                    }
                }
            }
        }
    }
}

/// Draws a white label on a dark box into a linear float image (for labelled video panels).
pub fn draw_label(image: &mut crate::image_io::ImageRgba, x: u32, y: u32, label: &str) {
    const SCALE: u32 = 2;
    let (w, h) = (image.width, image.height);
    let box_w = (label.chars().count() as u32 * 6 + 2) * SCALE;
    let box_h = 9 * SCALE;
    for py in y..(y + box_h).min(h) {
        for px in x..(x + box_w).min(w) {
            image.pixels[(py * w + px) as usize] = [0.02, 0.02, 0.02, 1.0];
        }
    }
    for (k, c) in label.chars().enumerate() {
        for (row, bits) in glyph(c).iter().enumerate() {
            for col in 0..5u32 {
                if bits & (16 >> col) == 0 {
                    continue;
                }
                for dy in 0..SCALE {
                    for dx in 0..SCALE {
                        let px = x + SCALE + (k as u32 * 6 + col) * SCALE + dx;
                        let py = y + SCALE + row as u32 * SCALE + dy;
                        if px < w && py < h {
                            image.pixels[(py * w + px) as usize] = [1.0, 1.0, 1.0, 1.0];
                        }
                    }
                }
            }
        }
    }
}

fn put(img: &mut RgbImage, x: i64, y: i64, c: Rgb<u8>) {
    if x >= 0 && y >= 0 && (x as u32) < img.width() && (y as u32) < img.height() {
        img.put_pixel(x as u32, y as u32, c);
    }
}

fn line(img: &mut RgbImage, (x0, y0): (f64, f64), (x1, y1): (f64, f64), c: Rgb<u8>, w: i64) {
    let steps = ((x1 - x0).abs().max((y1 - y0).abs()).ceil() as i64).max(1);
    for i in 0..=steps {
        let t = i as f64 / steps as f64;
        let (x, y) = (x0 + t * (x1 - x0), y0 + t * (y1 - y0));
        for dy in -(w / 2)..=(w / 2) {
            for dx in -(w / 2)..=(w / 2) {
                put(img, x.round() as i64 + dx, y.round() as i64 + dy, c);
            }
        }
    }
}

/// The set shown: the largest pupil at the nearest-to-far focus (the most blur).
fn shown_set(grid: &KernelGrid) -> usize {
    (grid.pupils_mm.len() - 1) * grid.focus_d.len()
}

/// Kernels of one set at their natural (rounded-up) radius: one row per object distance,
/// columns R, G, B and the three together; each kernel scaled to its own peak (square-root
/// tone curve so faint flare stays visible).
pub fn contact_sheet(grid: &KernelGrid) -> RgbImage {
    let set = &grid.sets[shown_set(grid)];
    let cell = (2 * grid.max_radius_px as i64 + 1).max(15);
    let zoom = (96 / cell).max(1);
    let cs = cell * zoom + 6;
    let label_w = 6 * 9 * 2 + 10;
    let header = 60;
    let (w, h) = (
        (label_w + 4 * cs + 10).max(560),
        header + set.objects.count as i64 * cs + 10,
    );
    let mut img = RgbImage::from_pixel(w as u32, h as u32, Rgb([0, 0, 0]));
    text(
        &mut img,
        8,
        8,
        2,
        WHITE,
        &format!(
            "PUPIL {:.2} MM  FOCUS {:.3} D  RMAX {} PX",
            set.pupil_mm, set.focus_d, grid.max_radius_px
        ),
    );
    for (i, name) in ["R", "G", "B", "RGB"].iter().enumerate() {
        text(
            &mut img,
            label_w + i as i64 * cs + cs / 2 - 8,
            36,
            2,
            if i < 3 { CHANNEL[i] } else { WHITE },
            name,
        );
    }
    for o in 0..set.objects.count {
        let y0 = header + o as i64 * cs;
        text(
            &mut img,
            6,
            y0 + cs / 2 - 7,
            2,
            GREY,
            &format!("{:.3} D", set.objects.value_d(o)),
        );
        let mut kernels = Vec::new();
        for c in 0..3 {
            let r = (set.radius_px[o][c].ceil() as u32).min(grid.max_radius_px);
            // A whole radius is always a level; below 2 px its ceiling may lie above the
            // levels the distance holds (src/psf/level_band.rs), and the highest held is drawn.
            let level = (level_of_radius(f64::from(r)) as u32).min(set.top_level[o]);
            let k = set.kernel(level, o);
            let peak = k.iter().map(|t| t[c]).fold(0.0f32, f32::max).max(1e-12);
            kernels.push((
                r,
                k.iter().map(|t| (t[c] / peak).sqrt()).collect::<Vec<_>>(),
            ));
        }
        for col in 0..4 {
            let x0 = label_w + col as i64 * cs + 3;
            for (c, (r, vals)) in kernels.iter().enumerate() {
                if col < 3 && col != c {
                    continue;
                }
                let side = 2 * *r as i64 + 1;
                let off = (cell - side) / 2;
                for (t, v) in vals.iter().enumerate() {
                    let (i, j) = (t as i64 % side, t as i64 / side);
                    for dy in 0..zoom {
                        for dx in 0..zoom {
                            let (px, py) =
                                (x0 + (off + i) * zoom + dx, y0 + 3 + (off + j) * zoom + dy);
                            if px >= 0
                                && py >= 0
                                && (px as u32) < img.width()
                                && (py as u32) < img.height()
                            {
                                let mut p = *img.get_pixel(px as u32, py as u32);
                                let level = (v.clamp(0.0, 1.0) * 255.0) as u8;
                                if col == 3 {
                                    p.0[c] = level;
                                } else {
                                    p = Rgb([level; 3]);
                                }
                                img.put_pixel(px as u32, py as u32, p);
                            }
                        }
                    }
                }
            }
        }
    }
    img
}

/// Projected PSF radius (px) against object dioptres, per channel, for the first and last
/// focus state at the largest pupil: solid for the first focus, dashed for the last.
pub fn size_plot(grid: &KernelGrid) -> RgbImage {
    let (w, h) = (900i64, 600i64);
    let (left, right, top, bottom) = (90.0, 30.0, 60.0, 70.0);
    let mut img = RgbImage::from_pixel(w as u32, h as u32, Rgb([0, 0, 0]));
    let p = grid.pupils_mm.len() - 1;
    let focus = [0, grid.focus_d.len() - 1];
    let o = grid.objects;
    let ymax = focus
        .iter()
        .flat_map(|&f| grid.set(p, f).radius_px.iter().flatten().copied())
        .fold(1.0f32, f32::max) as f64;
    let ymax = (ymax * 1.1 / 5.0).ceil() * 5.0;
    let (x0, x1) = (o.min_d, o.max_d().max(o.min_d + 1e-9));
    let px = |d: f64| left + (d - x0) / (x1 - x0) * (w as f64 - left - right);
    let py = |r: f64| h as f64 - bottom - r / ymax * (h as f64 - top - bottom);
    // axes, ticks and labels
    line(
        &mut img,
        (left, py(0.0)),
        (w as f64 - right, py(0.0)),
        GREY,
        1,
    );
    line(&mut img, (left, top), (left, py(0.0)), GREY, 1);
    for k in 0..=5 {
        let d = x0 + (x1 - x0) * k as f64 / 5.0;
        line(&mut img, (px(d), py(0.0)), (px(d), py(0.0) + 6.0), GREY, 1);
        text(
            &mut img,
            px(d) as i64 - 15,
            h - bottom as i64 + 12,
            2,
            WHITE,
            &format!("{d:.1}"),
        );
        let r = ymax * k as f64 / 5.0;
        line(&mut img, (left - 6.0, py(r)), (left, py(r)), GREY, 1);
        text(&mut img, 8, py(r) as i64 - 7, 2, WHITE, &format!("{r:.0}"));
    }
    text(
        &mut img,
        w / 2 - 140,
        h - 28,
        2,
        WHITE,
        "OBJECT VERGENCE (D)",
    );
    text(&mut img, 8, 36, 2, WHITE, "RADIUS (PX)");
    text(
        &mut img,
        left as i64 + 120,
        10,
        2,
        WHITE,
        &format!(
            "PUPIL {:.1} MM  FOCUS {:.2} D (SOLID), {:.2} D (DASHED)",
            grid.pupils_mm[p], grid.focus_d[focus[0]], grid.focus_d[focus[1]]
        ),
    );
    for (fi, &f) in focus.iter().enumerate() {
        let set = grid.set(p, f);
        for (c, &color) in CHANNEL.iter().enumerate() {
            for k in 1..o.count {
                let a = (px(o.value_d(k - 1)), py(set.radius_px[k - 1][c] as f64));
                let b = (px(o.value_d(k)), py(set.radius_px[k][c] as f64));
                // the second focus state dashed: every other segment
                if fi == 0 || k % 2 == 1 {
                    line(&mut img, a, b, color, 2);
                }
            }
        }
    }
    for (c, name) in ["612", "549", "464"].iter().enumerate() {
        let y = top as i64 + 10 + 22 * c as i64;
        line(
            &mut img,
            (w as f64 - 200.0, y as f64 + 7.0),
            (w as f64 - 160.0, y as f64 + 7.0),
            CHANNEL[c],
            2,
        );
        let nm = grid.wavelengths_nm[c];
        let label = if (nm - name.parse::<f64>().unwrap_or(0.0)).abs() < 0.5 {
            format!("{name} NM")
        } else {
            format!("{nm:.0} NM")
        };
        text(&mut img, w - 150, y, 2, CHANNEL[c], &label);
    }
    img
}

/// Writes a PNG atomically.
pub fn write_png(path: &Path, img: &RgbImage) -> Result<()> {
    let dir = path
        .parent()
        .filter(|p| !p.as_os_str().is_empty())
        .unwrap_or(Path::new("."));
    let tmp = dir.join(format!(
        ".{}.tmp{}",
        path.file_name()
            .map(|n| n.to_string_lossy().to_string())
            .unwrap_or_default(),
        std::process::id()
    ));
    let result = img
        .save_with_format(&tmp, image::ImageFormat::Png)
        .map_err(|e| Error::file(path, e))
        .and_then(|_| std::fs::rename(&tmp, path).map_err(|e| Error::file(path, e)));
    if result.is_err() {
        let _ = std::fs::remove_file(&tmp);
    }
    result
}
