//! Measures of a spot in a rendered image, written for the tests (independent of the renderer).

/// RMS width (px) of the green channel around pixel column `x` of row `cy`, horizontally and
/// vertically, over a square window of half-side `window` (columns outside the frame skipped).
pub fn rms_widths(
    image: &[[f32; 4]],
    w: usize,
    (x, cy): (usize, usize),
    window: i64,
) -> (f64, f64) {
    let (mut e, mut mx, mut my) = (0.0f64, 0.0, 0.0);
    let mut samples = Vec::new();
    for dy in -window..=window {
        for dx in -window..=window {
            let (px, py) = (x as i64 + dx, cy as i64 + dy);
            if px < 0 || px >= w as i64 {
                continue;
            }
            let v = f64::from(image[py as usize * w + px as usize][1]);
            samples.push((dx as f64, dy as f64, v));
            e += v;
            mx += v * dx as f64;
            my += v * dy as f64;
        }
    }
    let (mx, my) = (mx / e, my / e);
    let (mut vx, mut vy) = (0.0, 0.0);
    for (dx, dy, v) in samples {
        vx += v * (dx - mx).powi(2);
        vy += v * (dy - my).powi(2);
    }
    ((vx / e).sqrt(), (vy / e).sqrt())
}
