//! The ENZ amplitude (the complex optical field U, whose squared modulus is the PSF) of one
//! pupil at one defocus, organised for fast synthesis on grids.
//!
//! U(r, φ) = 2 Σ_m i^m e^{imφ} Σ_n β_nm √(n+1) V_nm(r, f). For each azimuthal order m the
//! inner sum is one Bessel–Bessel series G_m(r) = Σ_l D_ml J_{|m|+2l+1}(2πr)/(2πr) whose
//! coefficients D are computed once (they do not depend on r). A radius then costs one Bessel
//! sequence shared by every m plus one short dot product per m.

use super::enz::{bb_coefficients_batch, bessel_over_v, defocus_weights};
use super::zernike::osa_index;
use num_complex::Complex64;
use rayon::prelude::*;
use std::f64::consts::PI;

struct Combo {
    /// offset into the parity-split Bessel array (see [`Scratch`])
    offset: usize,
    odd: bool,
    dre: Vec<f64>,
    dim: Vec<f64>,
}

/// Reusable buffers for [`RadialAmplitude::eval_radii`].
#[derive(Default)]
pub struct Block8 {
    radii: [Scratch; 8],
    odd: Vec<f64>,
    even: Vec<f64>,
}

/// Reusable buffers for [`RadialAmplitude::eval_radius`].
#[derive(Default)]
pub struct Scratch {
    jbuf: Vec<f64>,
    b: Vec<f64>,
    b_odd: Vec<f64>,
    b_even: Vec<f64>,
}

/// Per-m Bessel–Bessel coefficients of one pupil at one f.
pub struct RadialAmplitude {
    pub f: f64,
    pub degree: u32,
    combos: Vec<Combo>,
    nu_max: usize,
}

#[inline]
fn dot2(a: &[f64], b: &[f64], c: &[f64]) -> (f64, f64) {
    // Eight independent partial sums so the loop vectorises.
    let n = a.len().min(b.len()).min(c.len());
    let (a, b, c) = (&a[..n], &b[..n], &c[..n]);
    let mut sa = [0.0f64; 4];
    let mut sb = [0.0f64; 4];
    let chunks = n / 4;
    for i in 0..chunks {
        for k in 0..4 {
            let x = c[4 * i + k];
            sa[k] += a[4 * i + k] * x;
            sb[k] += b[4 * i + k] * x;
        }
    }
    let (mut ra, mut rb) = (
        (sa[0] + sa[1]) + (sa[2] + sa[3]),
        (sb[0] + sb[1]) + (sb[2] + sb[3]),
    );
    for i in 4 * chunks..n {
        ra += a[i] * c[i];
        rb += b[i] * c[i];
    }
    (ra, rb)
}

impl RadialAmplitude {
    /// Coefficients for β (OSA order, orders ≤ `degree`) at defocus f. Combination index c:
    /// 0 → m = 0; 2μ−1 → m = +μ; 2μ → m = −μ. The factor 2·i^m and the parity of V for
    /// negative m are folded in, so U = Σ_c G_c(r) e^{i m_c φ}.
    pub fn new(beta: &[Complex64], degree: u32, f: f64) -> RadialAmplitude {
        let w = defocus_weights(f);
        let c_count = 2 * degree as usize + 1;
        let mut combos = Vec::with_capacity(c_count);
        let mut nu_max = 1usize;
        let ipow = [
            Complex64::new(2.0, 0.0),
            Complex64::new(0.0, 2.0),
            Complex64::new(-2.0, 0.0),
            Complex64::new(0.0, -2.0),
        ];
        let h_of = |mu: u32, m: i32| -> Vec<Complex64> {
            let p = ((degree - mu) / 2) as usize;
            (0..=p)
                .map(|l| {
                    let n = mu + 2 * l as u32;
                    beta.get(osa_index(n, m)).copied().unwrap_or_default() * ((n + 1) as f64).sqrt()
                })
                .collect()
        };
        let empty = |h: &[Complex64]| h.iter().all(|v| v.norm_sqr() == 0.0);
        let mut ds: Vec<Vec<Complex64>> = vec![Vec::new(); c_count];
        for mu in 0..=degree {
            let signs: &[i32] = if mu == 0 { &[1] } else { &[1, -1] };
            let hs: Vec<(usize, Vec<Complex64>)> = signs
                .iter()
                .map(|&sg| {
                    let c = if mu == 0 {
                        0
                    } else if sg > 0 {
                        2 * mu as usize - 1
                    } else {
                        2 * mu as usize
                    };
                    (c, h_of(mu, sg * mu as i32))
                })
                .filter(|(_, h)| !empty(h))
                .collect();
            if hs.is_empty() {
                continue;
            }
            let refs: Vec<&[Complex64]> = hs.iter().map(|(_, h)| h.as_slice()).collect();
            // V_{n,−μ} = (−1)^μ V_{n,μ} and i^{−μ}(−1)^μ = i^μ: both signs carry 2·i^μ.
            let k = ipow[(mu % 4) as usize];
            for ((c, _), d) in hs.iter().zip(bb_coefficients_batch(mu, &refs, &w, f)) {
                ds[*c] = d.into_iter().map(|v| v * k).collect();
            }
        }
        for (c, d) in ds.into_iter().enumerate() {
            let mu = c.div_ceil(2) as u32;
            nu_max = nu_max.max(mu as usize + 2 * d.len() + 1);
            // ν = μ + 2l + 1: odd ν for even μ, even ν for odd μ.
            let odd = mu.is_multiple_of(2);
            let offset = if odd {
                mu as usize / 2
            } else {
                (mu as usize).div_ceil(2)
            };
            combos.push(Combo {
                offset,
                odd,
                dre: d.iter().map(|v| v.re).collect(),
                dim: d.iter().map(|v| v.im).collect(),
            });
        }
        RadialAmplitude {
            f,
            degree,
            combos,
            nu_max,
        }
    }

    /// Floating-point work of one [`RadialAmplitude::eval_radius`] beyond the Bessel sequence
    /// (for choosing between tabulation strategies).
    pub fn work_per_radius(&self) -> usize {
        self.combos.iter().map(|c| 4 * c.dre.len()).sum::<usize>() + 3 * self.nu_max
    }

    /// Number of azimuthal combinations, 2·degree + 1.
    pub fn combos(&self) -> usize {
        self.combos.len()
    }

    /// G_c(r) for every combination c at one radius (r ≥ 0), into `out[..combos()]`.
    pub fn eval_radius(&self, r: f64, s: &mut Scratch, out: &mut [Complex64]) {
        let v = 2.0 * PI * r.abs();
        bessel_over_v(v, self.nu_max, &mut s.jbuf, &mut s.b);
        s.b_odd.clear();
        s.b_even.clear();
        s.b_odd.extend(s.b.iter().skip(1).step_by(2));
        s.b_even.extend(s.b.iter().step_by(2));
        for (c, cb) in self.combos.iter().enumerate() {
            let src = if cb.odd { &s.b_odd } else { &s.b_even };
            let (re, im) = if cb.offset < src.len() {
                dot2(&cb.dre, &cb.dim, &src[cb.offset..])
            } else {
                (0.0, 0.0)
            };
            out[c] = Complex64::new(re, im);
        }
    }

    /// [`RadialAmplitude::eval_radius`] for eight radii at once. The Bessel values of the eight
    /// radii are interleaved so that each coefficient D_l is loaded once and multiplies a
    /// contiguous group of eight: the inner loop vectorises and the coefficients stream from
    /// memory once per eight radii. `out` holds 8·combos() values, radius-major.
    pub fn eval_radii8(&self, r: &[f64; 8], s: &mut Block8, out: &mut [Complex64]) {
        let c_count = self.combos();
        let mut len = 0;
        for (q, sq) in s.radii.iter_mut().enumerate() {
            bessel_over_v(2.0 * PI * r[q].abs(), self.nu_max, &mut sq.jbuf, &mut sq.b);
            len = len.max(sq.b.len());
        }
        let half = len / 2 + 1;
        s.odd.clear();
        s.odd.resize(half * 8, 0.0);
        s.even.clear();
        s.even.resize(half * 8, 0.0);
        for (q, sq) in s.radii.iter().enumerate() {
            for (nu, &v) in sq.b.iter().enumerate() {
                let dst = if nu % 2 == 1 { &mut s.odd } else { &mut s.even };
                dst[(nu / 2) * 8 + q] = v;
            }
        }
        for (c, cb) in self.combos.iter().enumerate() {
            let src = if cb.odd { &s.odd } else { &s.even };
            let avail = (src.len() / 8).saturating_sub(cb.offset);
            let n = cb.dre.len().min(avail);
            let mut acc_re = [0.0f64; 8];
            let mut acc_im = [0.0f64; 8];
            let start = (cb.offset * 8).min(src.len());
            let rows = &src[start..start + n * 8];
            for ((row, &dr), &di) in rows.chunks_exact(8).zip(&cb.dre).zip(&cb.dim) {
                for q in 0..8 {
                    acc_re[q] += dr * row[q];
                    acc_im[q] += di * row[q];
                }
            }
            for q in 0..8 {
                out[q * c_count + c] = Complex64::new(acc_re[q], acc_im[q]);
            }
        }
    }

    /// G for a list of radii into `out` (radius-major, combos() values each), eight at a time.
    pub fn eval_radii(&self, radii: &[f64], s: &mut Block8, out: &mut [Complex64]) {
        let c_count = self.combos();
        let mut chunks = radii.chunks_exact(8);
        let mut o = 0;
        for ch in &mut chunks {
            let r: [f64; 8] = std::array::from_fn(|q| ch[q]);
            self.eval_radii8(&r, s, &mut out[o..o + 8 * c_count]);
            o += 8 * c_count;
        }
        for &r in chunks.remainder() {
            self.eval_radius(r, &mut s.radii[0], &mut out[o..o + c_count]);
            o += c_count;
        }
    }

    /// Σ_c G_c e^{i m_c φ} at (x, y) given the radial values g at r = |(x, y)|.
    #[inline]
    pub fn angular_sum(g: &[Complex64], degree: u32, x: f64, y: f64) -> Complex64 {
        let r = x.hypot(y);
        let e1 = if r > 0.0 {
            Complex64::new(x / r, y / r)
        } else {
            Complex64::new(1.0, 0.0)
        };
        let mut acc = g[0];
        let mut e = e1;
        for mu in 1..=degree as usize {
            let (gp, gm) = (g[2 * mu - 1], g[2 * mu]);
            // gp·e + gm·conj(e), written out to save the conj temporary
            acc.re += gp.re * e.re - gp.im * e.im + gm.re * e.re + gm.im * e.im;
            acc.im += gp.re * e.im + gp.im * e.re + gm.im * e.re - gm.re * e.im;
            e *= e1;
        }
        acc
    }

    /// The amplitude at the four mirror images (x, y), (−x, −y), (x, −y), (−x, y) of one point,
    /// from the radial values g they share. With E_μ = e^{iμφ}: a half turn multiplies E_μ by
    /// (−1)^μ and a mirror in x conjugates it, so four partial sums (even/odd μ, E or Ē on
    /// the m > 0 part) give all four amplitudes for about half the work of two angular sums.
    #[inline]
    pub fn quad_sums(g: &[Complex64], degree: u32, x: f64, y: f64) -> [Complex64; 4] {
        let r = x.hypot(y);
        let e1 = if r > 0.0 {
            Complex64::new(x / r, y / r)
        } else {
            Complex64::new(1.0, 0.0)
        };
        // p: G+ E + G− Ē,  q: G+ Ē + G− E; index 0 even μ, 1 odd μ
        let mut p = [g[0], Complex64::default()];
        let mut q = [g[0], Complex64::default()];
        let mut e = e1;
        for mu in 1..=degree as usize {
            let (gp, gm) = (g[2 * mu - 1], g[2 * mu]);
            let k = mu & 1;
            // G+E = (a + ib)(c + id), G−Ē = (a' + ib')(c − id)
            let (ac, ad, bc, bd) = (gp.re * e.re, gp.re * e.im, gp.im * e.re, gp.im * e.im);
            let (mc, md, nc, nd) = (gm.re * e.re, gm.re * e.im, gm.im * e.re, gm.im * e.im);
            p[k].re += ac - bd + mc + nd;
            p[k].im += ad + bc + nc - md;
            q[k].re += ac + bd + mc - nd;
            q[k].im += bc - ad + md + nc;
            e *= e1;
        }
        [p[0] + p[1], p[0] - p[1], q[0] + q[1], q[0] - q[1]]
    }

    /// Exact amplitude at one point (x, y) in λ/NA.
    pub fn at(&self, x: f64, y: f64) -> Complex64 {
        let mut s = Scratch::default();
        let mut g = vec![Complex64::default(); self.combos()];
        self.eval_radius(x.hypot(y), &mut s, &mut g);
        Self::angular_sum(&g, self.degree, x, y)
    }
}

/// Lagrange interpolation on equally spaced nodes with an even number of taps: the taps sit at
/// offsets −(T/2−1)..=T/2 around the interval [0, 1) that holds the point.
#[derive(Debug, Clone)]
pub struct LagrangeRule {
    pub taps: usize,
    offsets: Vec<f64>,
    denominators: Vec<f64>,
    /// max over t ∈ [0,1] of Π|t − o_j| / T!: error ≈ this · (2πh)^T for an amplitude
    /// band-limited to one cycle per unit r (every ENZ amplitude is).
    pub error_constant: f64,
}

impl LagrangeRule {
    pub fn new(taps: usize) -> LagrangeRule {
        let taps = taps.clamp(2, 24) & !1;
        let offsets: Vec<f64> = (0..taps)
            .map(|k| k as f64 - (taps / 2 - 1) as f64)
            .collect();
        let denominators = (0..taps)
            .map(|k| {
                (0..taps)
                    .filter(|&j| j != k)
                    .map(|j| offsets[k] - offsets[j])
                    .product()
            })
            .collect();
        let fact: f64 = (1..=taps).map(|v| v as f64).product();
        let mut worst: f64 = 0.0;
        for i in 0..=200 {
            let t = i as f64 / 200.0;
            worst = worst.max(offsets.iter().map(|o| (t - o).abs()).product::<f64>());
        }
        LagrangeRule {
            taps,
            offsets,
            denominators,
            error_constant: worst / fact,
        }
    }

    /// Node spacing that keeps the interpolation error below `tol` (relative to the amplitude's
    /// maximum), never above 0.45 (the Nyquist spacing is 0.5).
    pub fn step_for(&self, tol: f64) -> f64 {
        let x = (tol.clamp(1e-15, 1e-1) / self.error_constant).powf(1.0 / self.taps as f64);
        (x / (2.0 * PI)).min(0.45)
    }

    /// Number of ghost nodes needed below r = 0.
    pub fn ghosts(&self) -> usize {
        self.taps / 2 - 1
    }

    /// Weights for position t ∈ [0, 1) into `w[..taps]`.
    #[inline]
    pub fn weights(&self, t: f64, w: &mut [f64]) {
        let d: [f64; 24] = std::array::from_fn(|j| {
            if j < self.taps {
                t - self.offsets[j]
            } else {
                1.0
            }
        });
        // Exactly on a node the product form below would divide by zero.
        if let Some(k) = (0..self.taps).find(|&k| d[k] == 0.0) {
            w[..self.taps].iter_mut().for_each(|v| *v = 0.0);
            w[k] = 1.0;
            return;
        }
        let all: f64 = d[..self.taps].iter().product();
        for k in 0..self.taps {
            w[k] = all / (d[k] * self.denominators[k]);
        }
    }
}

/// G_c(r) tabulated at r_k = (k − g)·step, g ghost nodes below 0 filled by the parity
/// G(−r) = (−1)^μ G(r), read by Lagrange interpolation.
pub struct AmplitudeTable {
    pub step: f64,
    pub degree: u32,
    pub rule: LagrangeRule,
    nodes: usize,
    c_count: usize,
    table: Vec<Complex64>,
}

impl AmplitudeTable {
    pub fn new(
        rf: &RadialAmplitude,
        r_max: f64,
        rule: LagrangeRule,
        step: f64,
        parallel: bool,
    ) -> AmplitudeTable {
        let c_count = rf.combos();
        let ghosts = rule.ghosts();
        let nodes = (r_max / step).ceil() as usize + rule.taps + ghosts + 1;
        let mut table = vec![Complex64::default(); nodes * c_count];
        // Rows in blocks of eight nodes; ghost nodes (r < 0) take the parity (−1)^μ.
        let block = 8 * c_count;
        let fill = |blk: usize, rows: &mut [Complex64], s: &mut Block8| {
            let k0 = blk * 8;
            let count = rows.len() / c_count;
            let radii: Vec<f64> = (0..count)
                .map(|q| ((k0 + q) as f64 - ghosts as f64) * step)
                .collect();
            let abs: Vec<f64> = radii.iter().map(|r| r.abs()).collect();
            rf.eval_radii(&abs, s, rows);
            for (q, r) in radii.iter().enumerate() {
                if *r < 0.0 {
                    for (c, v) in rows[q * c_count..(q + 1) * c_count].iter_mut().enumerate() {
                        if c.div_ceil(2) % 2 == 1 {
                            *v = -*v;
                        }
                    }
                }
            }
        };
        if parallel {
            table
                .par_chunks_mut(block)
                .enumerate()
                .for_each_init(Block8::default, |s, (k, rows)| fill(k, rows, s));
        } else {
            let mut s = Block8::default();
            for (k, rows) in table.chunks_mut(block).enumerate() {
                fill(k, rows, &mut s);
            }
        }
        AmplitudeTable {
            step,
            degree: rf.degree,
            rule,
            nodes,
            c_count,
            table,
        }
    }

    /// Radial nodes in the table.
    pub fn nodes(&self) -> usize {
        self.nodes
    }

    /// Interpolated radial values G_c(r) into `g[..2·degree+1]`; false (and g untouched)
    /// beyond the table.
    #[inline]
    pub fn radial(&self, r: f64, g: &mut [Complex64]) -> bool {
        let u = r / self.step;
        let i = u.floor() as usize; // interval [i, i+1); first tap at node index i (ghost shift)
        let taps = self.rule.taps;
        if i + taps > self.nodes {
            return false;
        }
        let mut w = [0.0; 24];
        self.rule.weights(u - i as f64, &mut w);
        let g = &mut g[..self.c_count];
        let rows = &self.table[i * self.c_count..(i + taps) * self.c_count];
        g.iter_mut().for_each(|v| *v = Complex64::default());
        for (t, &wt) in w[..taps].iter().enumerate() {
            let row = &rows[t * self.c_count..(t + 1) * self.c_count];
            for (gv, tv) in g.iter_mut().zip(row) {
                gv.re += tv.re * wt;
                gv.im += tv.im * wt;
            }
        }
        true
    }

    /// Interpolated amplitude at (x, y); 0 beyond the table. `g` is scratch of length ≥ 2·degree+1.
    #[inline]
    pub fn at(&self, x: f64, y: f64, g: &mut [Complex64]) -> Complex64 {
        if !self.radial(x.hypot(y), g) {
            return Complex64::default();
        }
        RadialAmplitude::angular_sum(g, self.degree, x, y)
    }
}
