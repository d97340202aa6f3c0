//! Ground truth: every pixel splats the exact kernel of its own dioptre (rounded to bins of
//! 0.001 D) for each channel — no interpolation over distance or radius, no merging — with the
//! same front-to-back blending as the splat runtime. It is the oracle of the tests and of the
//! quality figures, so it is written independently of the GPU passes (CPU, rayon, per tile).

use std::collections::HashMap;
use std::sync::Arc;

use rayon::prelude::*;

use super::splat::FrameInput;

/// Bin width of the ground truth's dioptre quantisation (the seed paper's 3 decimals).
pub const DIOPTRE_BIN_D: f64 = 0.001;

/// A square kernel of side 2·radius + 1, row-major, row j ↔ screen offset dy = j − radius
/// (downwards), column i ↔ dx = i − radius; normalised to sum 1.
#[derive(Clone, Debug, PartialEq)]
pub struct Kernel {
    pub radius: u32,
    pub values: Vec<f32>,
}

impl Kernel {
    pub fn side(&self) -> usize {
        2 * self.radius as usize + 1
    }

    /// Weight at offset (dx, dy) from the centre; zero outside.
    pub fn at(&self, dx: i64, dy: i64) -> f32 {
        let r = self.radius as i64;
        if dx.abs() > r || dy.abs() > r {
            return 0.0;
        }
        self.values[((dy + r) * (2 * r + 1) + dx + r) as usize]
    }
}

/// The exact kernel for a channel (0 = R, 1 = G, 2 = B) at an object vergence in dioptres, for
/// the frame's pupil, focus, resolution and field of view.
pub trait ExactKernels: Sync {
    fn kernel(&self, channel: usize, dioptre: f64) -> Kernel;
}

/// Vergence of a depth in metres; 0, negative, NaN or infinite depth is optical infinity.
pub fn dioptre_of_depth(depth_m: f32) -> f64 {
    if depth_m > 0.0 && depth_m.is_finite() {
        1.0 / f64::from(depth_m)
    } else {
        0.0
    }
}

/// The sort key the runtime uses: depth bits (infinity as a huge finite depth), then index.
pub fn sort_depth(depth_m: f32) -> f32 {
    if depth_m > 0.0 && !depth_m.is_nan() {
        if depth_m.is_finite() {
            depth_m
        } else {
            3.0e38
        }
    } else {
        3.0e38
    }
}

fn bin_of(dioptre: f64) -> i64 {
    (dioptre / DIOPTRE_BIN_D).round() as i64
}

/// Renders the ground truth. `tile` only sets the work granularity (results do not depend on
/// it). Returns linear RGBA (alpha 1), row-major.
pub fn render(input: &FrameInput<'_>, kernels: &dyn ExactKernels) -> Vec<[f32; 4]> {
    let (w, h) = (input.width as usize, input.height as usize);
    let bins: Vec<i64> = input
        .depth_m
        .iter()
        .map(|&d| bin_of(dioptre_of_depth(d)))
        .collect();
    let kernel_table = exact_kernels_for(&bins, kernels);
    let lookup = |channel: usize, bin: i64| -> &Kernel { &kernel_table[&(channel, bin)] };

    // Reach of each pixel's fragment: the largest kernel radius over its channels.
    let reach: Vec<i64> = bins
        .iter()
        .map(|&b| {
            (0..3)
                .map(|c| lookup(c, b).radius as i64)
                .max()
                .unwrap_or(0)
        })
        .collect();
    let max_reach = reach.iter().copied().max().unwrap_or(0);
    const TILE: usize = 16;
    let tiles_x = w.div_ceil(TILE);
    let tiles_y = h.div_ceil(TILE);
    let keys: Vec<(u32, u32)> = input
        .depth_m
        .iter()
        .enumerate()
        .map(|(i, &d)| (sort_depth(d).to_bits(), i as u32))
        .collect();

    let tiles: Vec<Vec<(usize, [f32; 4])>> = (0..tiles_x * tiles_y)
        .into_par_iter()
        .map(|t| {
            let (tx, ty) = (t % tiles_x, t / tiles_x);
            let (x0, y0) = ((tx * TILE) as i64, (ty * TILE) as i64);
            let (x1, y1) = (
                ((tx + 1) * TILE).min(w) as i64 - 1,
                ((ty + 1) * TILE).min(h) as i64 - 1,
            );
            // Fragments whose square support reaches this tile.
            let mut list: Vec<u32> = Vec::new();
            let (sy0, sy1) = ((y0 - max_reach).max(0), (y1 + max_reach).min(h as i64 - 1));
            let (sx0, sx1) = ((x0 - max_reach).max(0), (x1 + max_reach).min(w as i64 - 1));
            for sy in sy0..=sy1 {
                for sx in sx0..=sx1 {
                    let i = sy as usize * w + sx as usize;
                    let r = reach[i];
                    if sx + r >= x0 && sx - r <= x1 && sy + r >= y0 && sy - r <= y1 {
                        list.push(i as u32);
                    }
                }
            }
            list.sort_unstable_by_key(|&i| keys[i as usize]);
            let mut out = Vec::with_capacity(TILE * TILE);
            for py in y0..=y1 {
                for px in x0..=x1 {
                    let mut c = [0.0f32; 3];
                    let mut a = [0.0f32; 3];
                    for &i in &list {
                        let i = i as usize;
                        let (fx, fy) = ((i % w) as i64, (i / w) as i64);
                        if (px - fx).abs() > reach[i] || (py - fy).abs() > reach[i] {
                            continue;
                        }
                        for ch in 0..3 {
                            let weight = lookup(ch, bins[i]).at(px - fx, py - fy);
                            c[ch] += (1.0 - a[ch]) * weight * input.color[i][ch];
                            a[ch] += (1.0 - a[ch]) * weight;
                        }
                    }
                    let value = [0, 1, 2].map(|ch| if a[ch] > 0.0 { c[ch] / a[ch] } else { 0.0 });
                    out.push((
                        py as usize * w + px as usize,
                        [value[0], value[1], value[2], 1.0],
                    ));
                }
            }
            out
        })
        .collect();
    let mut image = vec![[0.0f32; 4]; w * h];
    for (index, value) in tiles.into_iter().flatten() {
        image[index] = value;
    }
    image
}

/// Computes each distinct (channel, bin) kernel once, in parallel.
fn exact_kernels_for(
    bins: &[i64],
    kernels: &dyn ExactKernels,
) -> HashMap<(usize, i64), Arc<Kernel>> {
    let mut distinct: Vec<i64> = bins.to_vec();
    distinct.sort_unstable();
    distinct.dedup();
    let jobs: Vec<(usize, i64)> = distinct
        .iter()
        .flat_map(|&b| (0..3).map(move |c| (c, b)))
        .collect();
    jobs.into_par_iter()
        .map(|(c, b)| {
            (
                (c, b),
                Arc::new(kernels.kernel(c, b as f64 * DIOPTRE_BIN_D)),
            )
        })
        .collect()
}

/// Number of distinct dioptre bins in a depth buffer (what the ground truth must compute).
pub fn distinct_bins(depth_m: &[f32]) -> usize {
    let mut bins: Vec<i64> = depth_m
        .iter()
        .map(|&d| bin_of(dioptre_of_depth(d)))
        .collect();
    bins.sort_unstable();
    bins.dedup();
    bins.len()
}
