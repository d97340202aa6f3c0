//! One refracting surface of the eye: a biconic (toric conicoid) base with an optional
//! Zernike elevation map, placed with a decentration and a tilt about a pivot on the axis.
//!
//! The Zernike elevation is converted once into plain monomials in x and y, because the ray
//! intersection evaluates sag and gradient several times per ray and the monomial form costs a
//! few dozen multiply-adds without any recursion or allocation.

use crate::optics::zernike::osa_nm;

/// Minimal 3-vector; the tracer needs only a handful of operations.
pub type V3 = [f64; 3];

#[inline]
pub fn dot(a: V3, b: V3) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

#[inline]
fn mat_vec(m: &[[f64; 3]; 3], v: V3) -> V3 {
    [dot(m[0], v), dot(m[1], v), dot(m[2], v)]
}

#[inline]
fn mat_t_vec(m: &[[f64; 3]; 3], v: V3) -> V3 {
    [
        m[0][0] * v[0] + m[1][0] * v[1] + m[2][0] * v[2],
        m[0][1] * v[0] + m[1][1] * v[1] + m[2][1] * v[2],
        m[0][2] * v[0] + m[1][2] * v[1] + m[2][2] * v[2],
    ]
}

/// Highest elevation order the monomial table holds.
pub const MAX_ELEVATION_ORDER: u32 = 10;
const DEG: usize = MAX_ELEVATION_ORDER as usize + 1;

fn binomial(n: u64, k: u64) -> f64 {
    (0..k).fold(1.0, |acc, i| acc * (n - i) as f64 / (i + 1) as f64)
}

fn factorial(n: u64) -> f64 {
    (1..=n).fold(1.0, |acc, i| acc * i as f64)
}

/// Monomial coefficients a[p][q] (of x^p y^q) of the orthonormal OSA Zernike term (n, m).
pub fn zernike_monomials(n: u32, m: i32) -> [[f64; DEG]; DEG] {
    let mut out = [[0.0; DEG]; DEG];
    let am = m.unsigned_abs() as u64;
    let n64 = n as u64;
    let norm = if m == 0 {
        ((n + 1) as f64).sqrt()
    } else {
        (2.0 * (n + 1) as f64).sqrt()
    };
    // Angular part: Re or Im of (x + i y)^|m| as (power of x, power of y, coefficient).
    let mut angular: Vec<(u64, u64, f64)> = Vec::new();
    for k in 0..=am {
        let c = binomial(am, k);
        let (keep, sign) = match (m >= 0, k % 2) {
            (true, 0) => (true, if (k / 2).is_multiple_of(2) { 1.0 } else { -1.0 }),
            (false, 1) => (
                true,
                if ((k - 1) / 2).is_multiple_of(2) {
                    1.0
                } else {
                    -1.0
                },
            ),
            _ => (false, 0.0),
        };
        if keep {
            angular.push((am - k, k, sign * c));
        }
    }
    // Radial part divided by ρ^|m|: Σ_k r_k (x² + y²)^((n−|m|)/2 − k).
    let half = (n64 - am) / 2;
    for k in 0..=half {
        let rk = if k.is_multiple_of(2) { 1.0 } else { -1.0 } * factorial(n64 - k)
            / (factorial(k) * factorial((n64 + am) / 2 - k) * factorial(half - k));
        let s = half - k;
        for l in 0..=s {
            let c = rk * binomial(s, l);
            for &(px, py, ca) in &angular {
                let p = (px + 2 * l) as usize;
                let q = (py + 2 * (s - l)) as usize;
                out[p][q] += norm * c * ca;
            }
        }
    }
    out
}

/// Monomials of every OSA term up to [`MAX_ELEVATION_ORDER`], built once.
fn monomial_table() -> &'static [[[f64; DEG]; DEG]] {
    static T: std::sync::OnceLock<Vec<[[f64; DEG]; DEG]>> = std::sync::OnceLock::new();
    T.get_or_init(|| {
        (0..crate::optics::zernike::num_terms(MAX_ELEVATION_ORDER))
            .map(|j| {
                let (n, m) = osa_nm(j);
                zernike_monomials(n, m)
            })
            .collect()
    })
}

/// A surface in its own frame: vertex at the origin, sag z = f(x, y) towards +z.
#[derive(Debug, Clone)]
pub struct Surface {
    /// Axial position of the vertex before decentration and tilt (mm).
    pub vertex_z_mm: f64,
    /// Curvatures (1/mm) along the rotated x' and y' meridians.
    pub curvature: [f64; 2],
    pub conic: f64,
    /// Rotation of the x' meridian counter-clockwise from +x (rad).
    pub axis_rad: f64,
    /// Elevation monomials (mm) already scaled to millimetre coordinates; empty when none.
    elevation: Vec<(usize, usize, f64)>,
    /// The same polynomial differentiated in x and in y, kept as separate lists so the hot
    /// loop has no branches.
    elevation_dx: Vec<(usize, usize, f64)>,
    elevation_dy: Vec<(usize, usize, f64)>,
    elevation_degree: usize,
    /// Largest radial distance from the surface axis where the surface exists (mm).
    pub semi_diameter_mm: f64,
    pub decenter_mm: [f64; 2],
    /// Rotations about the y axis (horizontal tilt) and the x axis (vertical tilt), rad.
    pub tilt_rad: [f64; 2],
    pub pivot_z_mm: f64,
    rot: [[f64; 3]; 3],
    tilted: bool,
    axis_cs: (f64, f64),
    /// Powers (1/mm) of an ideal thin lens in this surface's plane along x' and y': a phase
    /// −½(P₁x'² + P₂y'²) added to the optical path, its gradient to the ray's transverse
    /// momentum. Zero for refracting surfaces.
    pub phase_power_per_mm: [f64; 2],
}

/// Result of evaluating the sag: value and partial derivatives, or `None` outside the domain.
#[derive(Debug, Clone, Copy)]
pub struct Sag {
    pub z: f64,
    pub dzdx: f64,
    pub dzdy: f64,
}

impl Surface {
    /// A rotationally symmetric conicoid; radius ∞ (or 0 curvature) is a plane.
    pub fn conic(vertex_z_mm: f64, radius_mm: f64, conic: f64, semi_diameter_mm: f64) -> Self {
        Self::toric(
            vertex_z_mm,
            [radius_mm, radius_mm],
            conic,
            0.0,
            semi_diameter_mm,
        )
    }

    /// A biconic with radii along the x' and y' meridians, x' rotated by `axis_rad`.
    pub fn toric(
        vertex_z_mm: f64,
        radius_mm: [f64; 2],
        conic: f64,
        axis_rad: f64,
        semi_diameter_mm: f64,
    ) -> Self {
        let curv = |r: f64| if r.is_finite() { 1.0 / r } else { 0.0 };
        let mut s = Surface {
            vertex_z_mm,
            curvature: [curv(radius_mm[0]), curv(radius_mm[1])],
            conic,
            axis_rad,
            elevation: Vec::new(),
            elevation_dx: Vec::new(),
            elevation_dy: Vec::new(),
            elevation_degree: 0,
            semi_diameter_mm,
            decenter_mm: [0.0; 2],
            tilt_rad: [0.0; 2],
            pivot_z_mm: vertex_z_mm,
            rot: [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]],
            tilted: false,
            axis_cs: (axis_rad.cos(), axis_rad.sin()),
            phase_power_per_mm: [0.0; 2],
        };
        s.update_placement();
        s
    }

    /// An ideal thin (toric) lens in the plane z = `vertex_z_mm`: powers `power_d` (D) along
    /// the x' and y' meridians, x' rotated by `axis_rad` from +x. It bends every ray by the
    /// gradient of its quadratic phase, so it is free of aberrations of its own only in the
    /// paraxial limit; at spectacle and IOL apertures (≤ 8 mm) the difference is far below
    /// the eye's own aberrations.
    pub fn ideal_lens(vertex_z_mm: f64, power_d: [f64; 2], axis_rad: f64) -> Self {
        let mut s = Self::toric(
            vertex_z_mm,
            [f64::INFINITY; 2],
            0.0,
            axis_rad,
            f64::INFINITY,
        );
        s.phase_power_per_mm = [power_d[0] * 1e-3, power_d[1] * 1e-3];
        s
    }

    pub fn has_phase(&self) -> bool {
        self.phase_power_per_mm != [0.0, 0.0]
    }

    /// The ideal lens's power (1/mm) along the meridian at `phi` rad from +x.
    pub fn phase_power_along(&self, phi: f64) -> f64 {
        let (s, c) = (phi - self.axis_rad).sin_cos();
        self.phase_power_per_mm[0] * c * c + self.phase_power_per_mm[1] * s * s
    }

    /// Optical path (mm) the ideal lens adds at local (x, y), and its gradient.
    #[inline]
    pub fn phase_mm(&self, x: f64, y: f64) -> (f64, [f64; 2]) {
        let (c, s) = self.axis_cs;
        let xr = x * c + y * s;
        let yr = -x * s + y * c;
        let [p1, p2] = self.phase_power_per_mm;
        let phi = -0.5 * (p1 * xr * xr + p2 * yr * yr);
        let gxr = -p1 * xr;
        let gyr = -p2 * yr;
        (phi, [gxr * c - gyr * s, gxr * s + gyr * c])
    }

    /// The direction after the ideal lens at local (x, y): the transverse optical momentum
    /// gains the phase gradient, from index `n1` to `n2`. `None` where the momentum exceeds
    /// `n2` (the ray would be evanescent).
    #[inline]
    pub fn phase_refract(&self, d: V3, x: f64, y: f64, n1: f64, n2: f64) -> Option<V3> {
        let (_, g) = self.phase_mm(x, y);
        let tx = n1 * d[0] + g[0];
        let ty = n1 * d[1] + g[1];
        let tz2 = n2 * n2 - tx * tx - ty * ty;
        if tz2 <= 0.0 || d[2] <= 0.0 {
            return None;
        }
        Some([tx / n2, ty / n2, tz2.sqrt() / n2])
    }

    /// Adds an OSA Zernike elevation (coefficients in mm, OSA order) normalised to `radius_mm`.
    pub fn with_elevation(mut self, coeffs_mm: &[f64], radius_mm: f64) -> Self {
        let mut acc = [[0.0; DEG]; DEG];
        for (j, &c) in coeffs_mm.iter().enumerate() {
            if c == 0.0 {
                continue;
            }
            let (n, _) = osa_nm(j);
            assert!(
                n <= MAX_ELEVATION_ORDER,
                "elevation order {n} above {MAX_ELEVATION_ORDER}"
            );
            let mono = &monomial_table()[j];
            for p in 0..DEG {
                for q in 0..DEG {
                    acc[p][q] += c * mono[p][q] / radius_mm.powi((p + q) as i32);
                }
            }
        }
        self.elevation.clear();
        for (p, row) in acc.iter().enumerate() {
            for (q, &a) in row.iter().enumerate() {
                if a != 0.0 {
                    self.elevation.push((p, q, a));
                }
            }
        }
        self.elevation_degree = self
            .elevation
            .iter()
            .map(|e| e.0.max(e.1))
            .max()
            .unwrap_or(0);
        self.elevation_dx = self
            .elevation
            .iter()
            .filter(|e| e.0 > 0)
            .map(|&(p, q, a)| (p - 1, q, a * p as f64))
            .collect();
        self.elevation_dy = self
            .elevation
            .iter()
            .filter(|e| e.1 > 0)
            .map(|&(p, q, a)| (p, q - 1, a * q as f64))
            .collect();
        self
    }

    /// Places the surface: decentration, tilt about the axial point `pivot_z_mm`.
    pub fn with_placement(
        mut self,
        decenter_mm: [f64; 2],
        tilt_rad: [f64; 2],
        pivot_z_mm: f64,
    ) -> Self {
        self.decenter_mm = decenter_mm;
        self.tilt_rad = tilt_rad;
        self.pivot_z_mm = pivot_z_mm;
        self.update_placement();
        self
    }

    fn update_placement(&mut self) {
        let (sa, ca) = self.tilt_rad[0].sin_cos();
        let (sb, cb) = self.tilt_rad[1].sin_cos();
        // Local → global: rotate about x (local z leans to +y) then about y (leans to +x).
        let ry = [[ca, 0.0, sa], [0.0, 1.0, 0.0], [-sa, 0.0, ca]];
        let rx = [[1.0, 0.0, 0.0], [0.0, cb, sb], [0.0, -sb, cb]];
        let mut r = [[0.0; 3]; 3];
        for (i, row) in r.iter_mut().enumerate() {
            for (j, v) in row.iter_mut().enumerate() {
                *v = (0..3).map(|k| ry[i][k] * rx[k][j]).sum();
            }
        }
        self.rot = r;
        self.tilted = self.tilt_rad != [0.0, 0.0];
        self.axis_cs = (self.axis_rad.cos(), self.axis_rad.sin());
    }

    pub fn has_elevation(&self) -> bool {
        !self.elevation.is_empty()
    }

    fn is_simple(&self) -> bool {
        self.elevation.is_empty() && self.curvature[0] == self.curvature[1]
    }

    /// Global point/direction → local frame.
    #[inline]
    pub fn to_local(&self, p: V3, d: V3) -> (V3, V3) {
        let q = [
            p[0] - self.decenter_mm[0],
            p[1] - self.decenter_mm[1],
            p[2] - self.pivot_z_mm,
        ];
        let (mut ql, dl) = if self.tilted {
            (mat_t_vec(&self.rot, q), mat_t_vec(&self.rot, d))
        } else {
            (q, d)
        };
        ql[2] -= self.vertex_z_mm - self.pivot_z_mm;
        (ql, dl)
    }

    /// Local point/direction → global frame.
    #[inline]
    pub fn to_global(&self, p: V3, d: V3) -> (V3, V3) {
        let q = [p[0], p[1], p[2] + self.vertex_z_mm - self.pivot_z_mm];
        let (qg, dg) = if self.tilted {
            (mat_vec(&self.rot, q), mat_vec(&self.rot, d))
        } else {
            (q, d)
        };
        (
            [
                qg[0] + self.decenter_mm[0],
                qg[1] + self.decenter_mm[1],
                qg[2] + self.pivot_z_mm,
            ],
            dg,
        )
    }

    /// Sag and gradient in the local frame; `None` where the conicoid does not exist.
    #[inline]
    pub fn sag(&self, x: f64, y: f64) -> Option<Sag> {
        let (c, s) = self.axis_cs;
        let xr = x * c + y * s;
        let yr = -x * s + y * c;
        let [cx, cy] = self.curvature;
        let k1 = 1.0 + self.conic;
        let u = cx * xr * xr + cy * yr * yr;
        let q = 1.0 - k1 * (cx * cx * xr * xr + cy * cy * yr * yr);
        if q < 0.0 {
            return None;
        }
        let rq = q.sqrt();
        let inv_den = 1.0 / (1.0 + rq);
        let mut z = u * inv_den;
        // d√q/dx' = −k1 cx² x'/√q; guard the rim where √q → 0 (gradient is vertical there).
        let inv_rq = 1.0 / rq.max(1e-300);
        let zk = k1 * z * inv_rq;
        // ∂z/∂x' = (2cx x' − z·∂√q/∂x')/(1+√q)
        let gxr = (2.0 * cx * xr + zk * cx * cx * xr) * inv_den;
        let gyr = (2.0 * cy * yr + zk * cy * cy * yr) * inv_den;
        let mut gx = gxr * c - gyr * s;
        let mut gy = gxr * s + gyr * c;
        if !self.elevation.is_empty() {
            let mut px = [1.0; DEG];
            let mut py = [1.0; DEG];
            for i in 1..=self.elevation_degree {
                px[i] = px[i - 1] * x;
                py[i] = py[i - 1] * y;
            }
            for &(p, qd, a) in &self.elevation {
                z += a * px[p] * py[qd];
            }
            for &(p, qd, a) in &self.elevation_dx {
                gx += a * px[p] * py[qd];
            }
            for &(p, qd, a) in &self.elevation_dy {
                gy += a * px[p] * py[qd];
            }
        }
        Some(Sag {
            z,
            dzdx: gx,
            dzdy: gy,
        })
    }

    /// Parameter t ≥ −(small) where p + t·d meets the surface (local frame), and the local
    /// outward (+z-ish) unit normal there. `None` when the ray misses.
    pub fn intersect_local(&self, p0: V3, d: V3) -> Option<(f64, V3)> {
        // Move a distant start point to the vertex plane first so the quadratic below is not
        // solved with millimetre-scale answers buried under metre-scale terms.
        let t0 = if d[2].abs() > 1e-9 {
            -p0[2] / d[2]
        } else {
            0.0
        };
        let p = [p0[0] + t0 * d[0], p0[1] + t0 * d[1], p0[2] + t0 * d[2]];
        // Start from the rotationally symmetric conicoid with the mean curvature: exact for
        // the common case and a close first guess for torics and elevation maps.
        let c = 0.5 * (self.curvature[0] + self.curvature[1]);
        let k1 = 1.0 + self.conic;
        let a = c * (d[0] * d[0] + d[1] * d[1] + k1 * d[2] * d[2]);
        let b = 2.0 * (c * (p[0] * d[0] + p[1] * d[1] + k1 * p[2] * d[2]) - d[2]);
        let cc = c * (p[0] * p[0] + p[1] * p[1] + k1 * p[2] * p[2]) - 2.0 * p[2];
        let disc = b * b - 4.0 * a * cc;
        let mut t = if disc >= 0.0 {
            // Root continuous with the vertex-plane crossing (a → 0 gives −cc/b).
            let sq = disc.sqrt();
            let den = b + if b >= 0.0 { sq } else { -sq };
            if den == 0.0 {
                return None;
            }
            -2.0 * cc / den
        } else if d[2].abs() > 1e-12 {
            -p[2] / d[2]
        } else {
            return None;
        };
        if !t.is_finite() {
            return None;
        }
        let n = if self.is_simple() {
            // Gradient of the implicit conicoid c(x² + y²) − 2z + (1+k)c z² = 0.
            let z = p[2] + t * d[2];
            if c * k1 * z > 1.0 {
                // Past the far side of a closed ellipsoid.
                return None;
            }
            [
                -c * (p[0] + t * d[0]),
                -c * (p[1] + t * d[1]),
                1.0 - k1 * c * z,
            ]
        } else {
            let mut last = None;
            for _ in 0..60 {
                let x = p[0] + t * d[0];
                let y = p[1] + t * d[1];
                let s = self.sag(x, y)?;
                let f = p[2] + t * d[2] - s.z;
                let fp = d[2] - s.dzdx * d[0] - s.dzdy * d[1];
                if fp.abs() < 1e-14 {
                    return None;
                }
                let step = f / fp;
                t -= step;
                // Newton is quadratic here: after a step below 1e-6 mm the position error is
                // ~κ·step² ≈ 1e-13 mm, and the normal taken at the previous iterate is off by
                // ~1e-7 rad, which moves optical paths only at second order (< 1e-10 mm).
                if step.abs() < 1e-6 {
                    last = Some(s);
                    break;
                }
            }
            let s = last?;
            [-s.dzdx, -s.dzdy, 1.0]
        };
        let x = p[0] + t * d[0];
        let y = p[1] + t * d[1];
        if x * x + y * y > self.semi_diameter_mm * self.semi_diameter_mm {
            return None;
        }
        let inv = 1.0 / dot(n, n).sqrt();
        Some((t0 + t, [n[0] * inv, n[1] * inv, n[2] * inv]))
    }
}

/// Vector Snell refraction of unit `d` at unit normal `n` from index `n1` to `n2`;
/// `None` on total internal reflection.
#[inline]
pub fn refract(d: V3, n: V3, n1: f64, n2: f64) -> Option<V3> {
    let mut cosi = dot(d, n);
    let mut nn = n;
    if cosi < 0.0 {
        nn = [-n[0], -n[1], -n[2]];
        cosi = -cosi;
    }
    let mu = n1 / n2;
    let k = 1.0 - mu * mu * (1.0 - cosi * cosi);
    if k < 0.0 {
        return None;
    }
    let g = k.sqrt() - mu * cosi;
    Some([
        mu * d[0] + g * nn[0],
        mu * d[1] + g * nn[1],
        mu * d[2] + g * nn[2],
    ])
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::optics::zernike::{basis_values, num_terms};

    #[test]
    fn monomials_match_the_zernike_basis() {
        let order = MAX_ELEVATION_ORDER;
        let mut z = vec![0.0; num_terms(order)];
        for &(x, y) in &[(0.3, -0.2), (-0.7, 0.5), (0.05, 0.9), (1.2, 0.4)] {
            basis_values(order, x, y, &mut z);
            for (j, want) in z.iter().enumerate() {
                let (n, m) = osa_nm(j);
                let a = zernike_monomials(n, m);
                let mut v = 0.0;
                for (p, row) in a.iter().enumerate() {
                    for (q, c) in row.iter().enumerate() {
                        v += c * x.powi(p as i32) * y.powi(q as i32);
                    }
                }
                assert!(
                    (v - want).abs() < 1e-9 * (1.0 + want.abs()),
                    "({n},{m}) at ({x},{y}): {v} vs {want}"
                );
            }
        }
    }

    #[test]
    fn sag_gradient_matches_finite_differences() {
        let s = Surface::toric(0.0, [7.6, 8.1], -0.3, 0.4, f64::INFINITY).with_elevation(
            &[
                0.0, 0.001, -0.002, 0.0, 0.003, 0.001, 0.0, 0.002, 0.0, -0.001,
            ],
            5.0,
        );
        let h = 1e-6;
        for &(x, y) in &[(0.0, 0.0), (1.0, -2.0), (-3.0, 2.5)] {
            let g = s.sag(x, y).unwrap();
            let dx = (s.sag(x + h, y).unwrap().z - s.sag(x - h, y).unwrap().z) / (2.0 * h);
            let dy = (s.sag(x, y + h).unwrap().z - s.sag(x, y - h).unwrap().z) / (2.0 * h);
            assert!((g.dzdx - dx).abs() < 1e-7 && (g.dzdy - dy).abs() < 1e-7);
        }
    }

    #[test]
    fn intersection_lands_on_the_surface_and_misses_cleanly() {
        let s = Surface::toric(0.0, [7.6, 8.1], -0.3, 0.4, 6.0)
            .with_elevation(&[0.0, 0.001, -0.002, 0.0, 0.003, 0.001], 5.0)
            .with_placement([0.2, -0.1], [0.05, -0.03], 1.0);
        let d = [0.05, -0.02, 1.0];
        let l = dot(d, d).sqrt();
        let d = [d[0] / l, d[1] / l, d[2] / l];
        let (pl, dl) = s.to_local([1.5, 2.0, -4.0], d);
        let (t, n) = s.intersect_local(pl, dl).unwrap();
        let hit = [pl[0] + t * dl[0], pl[1] + t * dl[1], pl[2] + t * dl[2]];
        assert!((hit[2] - s.sag(hit[0], hit[1]).unwrap().z).abs() < 1e-12);
        assert!((dot(n, n) - 1.0).abs() < 1e-12);
        // A ray far outside the surface's extent misses instead of producing NaN.
        let (pl, dl) = s.to_local([20.0, 0.0, -4.0], [0.0, 0.0, 1.0]);
        assert!(s.intersect_local(pl, dl).is_none());
        // Total internal reflection is reported, not NaN.
        assert!(refract(
            [0.9f64.sqrt(), 0.0, 0.1f64.sqrt()],
            [0.0, 0.0, 1.0],
            1.5,
            1.0
        )
        .is_none());
    }
}
