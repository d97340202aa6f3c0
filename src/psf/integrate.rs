//! Integration of a sampled PSF over screen pixels of any size and position.
//!
//! The samples are point values of a smooth (band-limited) intensity. Between them the
//! intensity is taken to be the cubic convolution interpolant (Keys, a = −½), which is exact
//! for quadratics; integrating it over the unit cell of each sample gives cell integrals, and
//! sums of cells give the integral over any run of whole cells exactly. A pixel's edges fall
//! inside cells: there the running integral F (known exactly at every cell boundary) is
//! interpolated by a cubic through the four nearest boundaries, so a pixel costs two cubic
//! evaluations of F plus the whole cells between them. Everything is separable in x and y.
//!
//! For PSFs much larger than the pixels asked for, cells are first merged into bins of up to a
//! quarter of the finest pixel: kernels at every radius then cost about the same whatever the
//! PSF's sample count.

/// ∫_0^s of the Keys kernel (a = −½), s ≥ 0.
fn keys_integral_from_zero(s: f64) -> f64 {
    let s = s.min(2.0);
    if s <= 1.0 {
        0.375 * s.powi(4) - 5.0 / 6.0 * s.powi(3) + s
    } else {
        let g = |t: f64| -0.125 * t.powi(4) + 5.0 / 6.0 * t.powi(3) - 2.0 * t * t + 2.0 * t;
        keys_integral_from_zero(1.0) + g(s) - g(1.0)
    }
}

/// ∫_{−∞}^t of the Keys kernel.
fn keys_cumulative(t: f64) -> f64 {
    0.5 + t.signum() * keys_integral_from_zero(t.abs())
}

/// Integral of the interpolant over the unit cell of sample i, per unit value of sample
/// i + d: taps for d = 0, ±1, ±2.
fn cell_taps() -> [f64; 5] {
    let g = |d: f64| keys_cumulative(d + 0.5) - keys_cumulative(d - 0.5);
    [g(-2.0), g(-1.0), g(0.0), g(1.0), g(2.0)]
}

/// Cell integrals of one PSF (merged into bins), ready for pixel integration.
#[derive(Clone, Debug)]
pub struct BoxIntegrator {
    /// Bin integrals, m × m, row-major in PSF-grid orientation (row 0 at +y).
    bins: Vec<f32>,
    m: usize,
    /// Bin size and the lower edge of bin 0, in samples from the centre sample (columns: +x;
    /// rows: −y, i.e. growing with the row index).
    size: f64,
    origin: f64,
}

impl BoxIntegrator {
    /// From `side`² samples (odd side, centre sample on the axis). `finest` is the smallest
    /// pixel (in samples) the kernels will ask for: bins are at most a quarter of it and at
    /// most `max_bin` samples (the scale on which the PSF itself is smooth), unless that
    /// would keep more than `max_bins` bins per side.
    pub fn new(
        values: &[f32],
        side: usize,
        finest: f64,
        max_bin: usize,
        max_bins: usize,
    ) -> BoxIntegrator {
        let taps = cell_taps();
        // the interpolant reaches two samples beyond the outermost ones
        let w = side + 4;
        let by_pixel = if finest.is_finite() && finest > 8.0 {
            (finest / 4.0).floor() as usize
        } else {
            1
        };
        let bin = by_pixel
            .min(max_bin)
            .max(1)
            .max(w.div_ceil(max_bins.max(8)));
        let m = w.div_ceil(bin);
        let mut bins = vec![0.0f64; m * m];
        // Row by row (one row of cells stays in cache): the row's cell integrals, merged into
        // column bins, then spread over the five rows of cells its taps reach, so the vertical
        // pass costs m per tap, not w.
        let mut cells = vec![0.0f64; w];
        let mut merged = vec![0.0f64; m];
        for (q, src) in values.chunks(side).take(side).enumerate() {
            if src.iter().all(|&v| v == 0.0) {
                continue;
            }
            // sample i sits in padded cell i + 2 and feeds cells i .. i + 4
            cells.fill(0.0);
            for (t, g) in taps.iter().enumerate() {
                for (d, v) in cells[4 - t..4 - t + side].iter_mut().zip(src) {
                    *d += f64::from(*v) * g;
                }
            }
            for (c, chunk) in merged.iter_mut().zip(cells.chunks(bin)) {
                *c = chunk.iter().sum();
            }
            for (t, g) in taps.iter().enumerate() {
                let cq = (q + 4 - t) / bin;
                let dst = &mut bins[cq * m..(cq + 1) * m];
                for (d, v) in dst.iter_mut().zip(&merged) {
                    *d += v * g;
                }
            }
        }
        BoxIntegrator {
            bins: bins.into_iter().map(|v| v as f32).collect(),
            m,
            size: bin as f64,
            origin: -((side / 2) as f64) - 2.5,
        }
    }

    /// Bytes held.
    pub fn size_bytes(&self) -> usize {
        self.bins.len() * 4
    }

    /// Kernel of integer `radius` whose pixels are `scale` samples wide, in screen orientation
    /// (rows reversed: screen y is down, the PSF grid's +y up), normalised to sum 1.
    pub fn kernel(&self, radius: u32, scale: f64) -> Vec<f64> {
        self.kernel_with(&self.summed_area(), radius, scale)
    }

    /// The summed-area table of the bins, which kernels at every radius share: build once per
    /// PSF, then ask [`Self::kernel_with`] for each radius.
    pub fn summed_area(&self) -> SummedArea {
        let m = self.m;
        // sat[j][i] = Σ_{q<j} Σ_{p<i} bins[q][p]: row j is the running sum along x of every
        // bin row above it, i.e. the vertical running sum of the rows' running sums
        let mut sat = vec![0.0f64; (m + 1) * (m + 1)];
        for (q, row) in self.bins.chunks(m).enumerate() {
            let (above, rest) = sat.split_at_mut((q + 1) * (m + 1));
            let prev = &above[q * (m + 1)..];
            let dst = &mut rest[..m + 1];
            let mut acc = 0.0;
            for i in 0..m {
                acc += f64::from(row[i]);
                dst[i + 1] = prev[i + 1] + acc;
            }
        }
        SummedArea { sat }
    }

    /// As [`Self::kernel`], from the integrator's [`Self::summed_area`]. A pixel's integral is
    /// F(hi) − F(lo), F the running integral interpolated by a cubic through the four nearest
    /// bin boundaries: read from the summed-area table, each costs eight reads whatever the
    /// pixel's width, first along x on the table rows the pixel rows' stencils touch, then
    /// along y over those results.
    pub fn kernel_with(&self, summed_area: &SummedArea, radius: u32, scale: f64) -> Vec<f64> {
        let side = 2 * radius as usize + 1;
        let delta = || {
            let mut v = vec![0.0; side * side];
            v[side * side / 2] = 1.0;
            v
        };
        if radius == 0 || !(scale > 0.0 && scale.is_finite()) {
            return delta();
        }
        let offsets = (0..side).map(|i| i as f64 - radius as f64);
        let sx: Vec<_> = offsets
            .clone()
            .map(|u| {
                (
                    self.stencil((u - 0.5) * scale),
                    self.stencil((u + 0.5) * scale),
                )
            })
            .collect();
        // screen row offset u (down) shows PSF y = u·scale, i.e. row coordinate −u·scale
        let sy: Vec<_> = offsets
            .map(|u| {
                (
                    self.stencil(-(u + 0.5) * scale),
                    self.stencil(-(u - 0.5) * scale),
                )
            })
            .collect();
        let m = self.m;
        // G_j(u) = Σ_{q<j} ∫ row q over pixel column u: the summed-area table's row j read
        // through pixel column u's stencils, needed only at the bin boundaries the rows'
        // stencils touch (at most four per row edge), not at all m + 1
        let clamp = |j: i64| j.clamp(0, m as i64) as usize;
        let mut slot = vec![usize::MAX; m + 1];
        let mut needed = Vec::new();
        for ((ja, _), (jb, _)) in &sy {
            for j in (0..4).flat_map(|k| [clamp(ja + k), clamp(jb + k)]) {
                if slot[j] == usize::MAX {
                    slot[j] = needed.len();
                    needed.push(j);
                }
            }
        }
        let mut g = vec![0.0f64; needed.len() * side];
        for (row, &j) in g.chunks_mut(side).zip(&needed) {
            let h = &summed_area.sat[j * (m + 1)..(j + 1) * (m + 1)];
            for (v, (lo, hi)) in row.iter_mut().zip(&sx) {
                *v = between(h, lo, hi);
            }
        }
        let mut out = vec![0.0f64; side * side];
        let at = |j: i64| slot[clamp(j)] * side;
        for (dst, ((ja, la), (jb, lb))) in out.chunks_mut(side).zip(&sy) {
            for k in 0..4 {
                let (hi, lo) = (at(jb + k as i64), at(ja + k as i64));
                for (o, (gh, gl)) in dst
                    .iter_mut()
                    .zip(g[hi..hi + side].iter().zip(&g[lo..lo + side]))
                {
                    *o += lb[k] * gh - la[k] * gl;
                }
            }
        }
        // the interpolant may ring slightly below zero next to a sharp core
        out.iter_mut().for_each(|v| *v = v.max(0.0));
        let total: f64 = out.iter().sum();
        if total > 0.0 && total.is_finite() {
            out.iter_mut().for_each(|v| *v /= total);
            out
        } else {
            delta()
        }
    }

    /// The first of the four bin boundaries around `x` (samples from the centre, along a
    /// binned axis) and the cubic Lagrange weights of F at them.
    fn stencil(&self, x: f64) -> (i64, [f64; 4]) {
        let tau = (x - self.origin) / self.size;
        let j0 = tau.floor() as i64 - 1;
        let t = tau - j0 as f64; // nodes at t = 0, 1, 2, 3
        let l = [
            -(t - 1.0) * (t - 2.0) * (t - 3.0) / 6.0,
            t * (t - 2.0) * (t - 3.0) / 2.0,
            -t * (t - 1.0) * (t - 3.0) / 2.0,
            t * (t - 1.0) * (t - 2.0) / 6.0,
        ];
        (j0, l)
    }
}

/// The summed-area table of an integrator's bins ((m + 1)², row j column i: the bins above
/// row j and left of column i).
pub struct SummedArea {
    sat: Vec<f64>,
}

/// F(hi) − F(lo) for a running sum `f` (constant beyond its ends) and two stencils.
fn between(f: &[f64], (ja, la): &(i64, [f64; 4]), (jb, lb): &(i64, [f64; 4])) -> f64 {
    let last = f.len() as i64 - 1;
    let at = |j: i64| f[j.clamp(0, last) as usize];
    (0..4)
        .map(|k| lb[k] * at(jb + k as i64) - la[k] * at(ja + k as i64))
        .sum()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn taps_sum_to_one_and_the_kernel_integrates_to_one() {
        let t = cell_taps();
        assert!((t.iter().sum::<f64>() - 1.0).abs() < 1e-14);
        assert!((keys_cumulative(2.0) - 1.0).abs() < 1e-14);
        assert!((keys_cumulative(0.0) - 0.5).abs() < 1e-14);
    }

    /// A Gaussian sampled finely, integrated over pixels, against its exact pixel integrals
    /// (error functions by quadrature).
    #[test]
    fn gaussian_pixel_integrals() {
        let (side, sigma, x0) = (201usize, 9.0f64, 3.3f64);
        let c = (side / 2) as f64;
        let g = |x: f64, y: f64| (-((x - x0).powi(2) + y * y) / (2.0 * sigma * sigma)).exp();
        let values: Vec<f32> = (0..side * side)
            .map(|i| g((i % side) as f64 - c, c - (i / side) as f64) as f32)
            .collect();
        // 1-D integral of the Gaussian over [a, b] by a fine midpoint rule
        let int = |a: f64, b: f64, mu: f64| {
            let n = 4000;
            let h = (b - a) / n as f64;
            (0..n)
                .map(|k| {
                    let x = a + (k as f64 + 0.5) * h;
                    (-(x - mu).powi(2) / (2.0 * sigma * sigma)).exp() * h
                })
                .sum::<f64>()
        };
        for (radius, scale) in [(3u32, 7.3f64), (10, 2.1), (2, 40.0)] {
            // bins no larger than a quarter σ (the role a quarter λ/NA plays for a PSF)
            let b = BoxIntegrator::new(&values, side, scale, 2, 4096);
            let k = b.kernel(radius, scale);
            let s = 2 * radius as usize + 1;
            let mut exact = vec![0.0; s * s];
            for j in 0..s {
                for i in 0..s {
                    let (u, v) = (i as f64 - radius as f64, j as f64 - radius as f64);
                    // screen row v (down) is PSF y = v·scale; the Gaussian is even in y
                    exact[j * s + i] = int((u - 0.5) * scale, (u + 0.5) * scale, x0)
                        * int((v - 0.5) * scale, (v + 0.5) * scale, 0.0);
                }
            }
            let total: f64 = exact.iter().sum();
            for (a, e) in k.iter().zip(&exact) {
                assert!(
                    (a - e / total).abs() < 2e-4,
                    "r {radius}: {a} vs {}",
                    e / total
                );
            }
        }
    }
}
