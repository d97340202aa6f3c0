//! The classic previous method (after Barsky 2011): split the frame into N slices of equal
//! width in dioptres, convolve each slice (colour premultiplied by its coverage, and the
//! coverage itself) with the PSF at the slice's centre, and composite the blurred slices back to
//! front with the over operator. Occlusion is only handled at slice boundaries — which is the
//! point of comparing against it. Same kernels as the ground truth (`ExactKernels`).

use rayon::prelude::*;

use super::reference::{ExactKernels, Kernel};
use super::splat::FrameInput;

/// The seed paper's slice count.
pub const DEFAULT_SLICES: usize = 41;

/// Renders the frame with `slices` depth slices spanning the frame's own dioptre range.
pub fn render(input: &FrameInput<'_>, kernels: &dyn ExactKernels, slices: usize) -> Vec<[f32; 4]> {
    let (w, h) = (input.width as usize, input.height as usize);
    let slices = slices.max(1);
    // Vergence along each pixel's ray (slices share one kernel each, so the local scale of a
    // wide frame does not apply to them).
    let dioptres: Vec<f64> = input.projection().dioptres(input.depth_m);
    let lo = dioptres.iter().copied().fold(f64::INFINITY, f64::min);
    let hi = dioptres.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    let width_d = ((hi - lo) / slices as f64).max(1e-9);
    let slice_of = |d: f64| (((d - lo) / width_d) as usize).min(slices - 1);
    let members: Vec<usize> = dioptres.iter().map(|&d| slice_of(d)).collect();

    // Accumulated premultiplied colour and coverage per channel, composited far to near.
    let mut color = vec![[0.0f32; 3]; w * h];
    let mut alpha = vec![[0.0f32; 3]; w * h];
    for s in 0..slices {
        if !members.contains(&s) {
            continue;
        }
        let centre = lo + (s as f64 + 0.5) * width_d;
        let k: [Kernel; 3] = [0, 1, 2].map(|c| kernels.kernel(c, centre));
        let (layer_color, layer_alpha) = blur_slice(input, &members, s, &k);
        for i in 0..w * h {
            for c in 0..3 {
                let a = layer_alpha[i][c].min(1.0);
                color[i][c] = layer_color[i][c] + (1.0 - a) * color[i][c];
                alpha[i][c] = a + (1.0 - a) * alpha[i][c];
            }
        }
    }
    (0..w * h)
        .map(|i| {
            let v = [0, 1, 2].map(|c| {
                if alpha[i][c] > 0.0 {
                    color[i][c] / alpha[i][c]
                } else {
                    0.0
                }
            });
            [v[0], v[1], v[2], 1.0]
        })
        .collect()
}

type Planes = (Vec<[f32; 3]>, Vec<[f32; 3]>);

/// Scatters every pixel of slice `s` through its channel's kernel: (colour·coverage, coverage).
/// Bands of source rows scatter in parallel into their own buffers, which are then added in
/// band order: identical inputs give identical bits (a shared parallel reduction would add
/// the same terms in an order that depends on scheduling).
fn blur_slice(
    input: &FrameInput<'_>,
    members: &[usize],
    s: usize,
    kernels: &[Kernel; 3],
) -> Planes {
    const BAND_ROWS: usize = 16;
    let (w, h) = (input.width as usize, input.height as usize);
    let reach = kernels.iter().map(|k| k.radius as usize).max().unwrap_or(0);
    // Per band: the first output row it touches and its (colour, coverage) rows from there.
    let bands: Vec<(usize, Planes)> = (0..h.div_ceil(BAND_ROWS))
        .into_par_iter()
        .map(|band| {
            let (y0, y1) = (band * BAND_ROWS, ((band + 1) * BAND_ROWS).min(h));
            let top = y0.saturating_sub(reach);
            let rows = (y1 + reach).min(h) - top;
            let mut col = vec![[0.0f32; 3]; rows * w];
            let mut alp = vec![[0.0f32; 3]; rows * w];
            for y in y0..y1 {
                for x in 0..w {
                    let i = y * w + x;
                    if members[i] != s {
                        continue;
                    }
                    for (c, k) in kernels.iter().enumerate() {
                        let r = k.radius as i64;
                        for dy in -r..=r {
                            let ty = y as i64 + dy;
                            if ty < 0 || ty >= h as i64 {
                                continue;
                            }
                            for dx in -r..=r {
                                let tx = x as i64 + dx;
                                if tx < 0 || tx >= w as i64 {
                                    continue;
                                }
                                let weight = k.at(dx, dy);
                                let t = (ty as usize - top) * w + tx as usize;
                                col[t][c] += weight * input.color[i][c];
                                alp[t][c] += weight;
                            }
                        }
                    }
                }
            }
            (top, (col, alp))
        })
        .collect();
    let mut col = vec![[0.0f32; 3]; w * h];
    let mut alp = vec![[0.0f32; 3]; w * h];
    for (top, (bc, ba)) in bands {
        let start = top * w;
        for (t, (c, a)) in bc.iter().zip(&ba).enumerate() {
            for k in 0..3 {
                col[start + t][k] += c[k];
                alp[start + t][k] += a[k];
            }
        }
    }
    (col, alp)
}
