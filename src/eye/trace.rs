//! Exact real-ray tracing through an [`OpticalSystem`].

use super::surface::{dot, refract, V3};
use super::system::OpticalSystem;

/// A ray: position (mm), unit direction and optical path accumulated so far (mm).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Ray {
    pub p: V3,
    pub d: V3,
    pub opl_mm: f64,
}

impl Ray {
    /// Ray from `p` towards `target`, optical path zero.
    pub fn towards(p: V3, target: V3) -> Ray {
        let d = [target[0] - p[0], target[1] - p[1], target[2] - p[2]];
        let l = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt();
        Ray {
            p,
            d: [d[0] / l, d[1] / l, d[2] / l],
            opl_mm: 0.0,
        }
    }

    /// Point at parameter `s` (mm) along the ray.
    #[inline]
    pub fn at(&self, s: f64) -> V3 {
        [
            self.p[0] + s * self.d[0],
            self.p[1] + s * self.d[1],
            self.p[2] + s * self.d[2],
        ]
    }

    /// Parameter where the ray crosses the plane z = `z_mm` (may be negative).
    #[inline]
    pub fn to_plane(&self, z_mm: f64) -> f64 {
        (z_mm - self.p[2]) / self.d[2]
    }
}

// Here rather than in `system`: a system is what rays cross, the ray belongs to the tracer.
impl OpticalSystem {
    /// Where a ray (already in the vitreous, travelling towards +z) meets the retina; `None`
    /// when it misses a spherical retina.
    pub fn retina_hit(&self, ray: &Ray) -> Option<V3> {
        let r = self.retina_radius_mm;
        if !r.is_finite() {
            return Some(ray.at(ray.to_plane(self.retina_z_mm)));
        }
        let q = [ray.p[0], ray.p[1], ray.p[2] - (self.retina_z_mm - r)];
        let b = dot(ray.d, q);
        let disc = b * b - (dot(q, q) - r * r);
        if disc < 0.0 {
            return None;
        }
        // The far intersection: the back wall of the globe, which the light reaches.
        Some(ray.at(-b + disc.sqrt()))
    }
}

/// Why a ray stopped.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Vignetting {
    /// The ray misses surface `0` (outside its extent, or no intersection).
    Missed(usize),
    /// Total internal reflection at surface `0`.
    TotalInternalReflection(usize),
}

/// Traces `ray` through surfaces `range` (indices `n` from [`OpticalSystem::indices`]), leaving
/// it on the last surface, refracted, with its optical path updated. On failure the ray is left
/// where it stopped and never holds NaN.
pub fn trace_range(
    sys: &OpticalSystem,
    n: &[f64],
    ray: &mut Ray,
    range: std::ops::Range<usize>,
) -> Result<(), Vignetting> {
    for i in range {
        let s = &sys.surfaces[i];
        let (pl, dl) = s.to_local(ray.p, ray.d);
        let (t, normal) = s.intersect_local(pl, dl).ok_or(Vignetting::Missed(i))?;
        if !t.is_finite() || t < -1e-6 {
            return Err(Vignetting::Missed(i));
        }
        let hit = [pl[0] + t * dl[0], pl[1] + t * dl[1], pl[2] + t * dl[2]];
        let (dn, phase_mm) = if s.has_phase() {
            let d = s
                .phase_refract(dl, hit[0], hit[1], n[i], n[i + 1])
                .ok_or(Vignetting::TotalInternalReflection(i))?;
            (d, s.phase_mm(hit[0], hit[1]).0)
        } else {
            let d = refract(dl, normal, n[i], n[i + 1])
                .ok_or(Vignetting::TotalInternalReflection(i))?;
            (d, 0.0)
        };
        let (pg, dg) = s.to_global(hit, dn);
        ray.opl_mm += n[i] * t + phase_mm;
        ray.p = pg;
        ray.d = dg;
    }
    Ok(())
}

/// Traces through every surface.
#[inline]
pub fn trace(sys: &OpticalSystem, n: &[f64], ray: &mut Ray) -> Result<(), Vignetting> {
    trace_range(sys, n, ray, 0..sys.surfaces.len())
}

/// Traces to the retina plane and returns the points visited (start, each surface, retina).
/// For drawing; allocates.
pub fn trace_path(
    sys: &OpticalSystem,
    wavelength_nm: f64,
    start: Ray,
) -> (Vec<V3>, Option<Vignetting>) {
    let n = sys.indices(wavelength_nm);
    let mut ray = start;
    let mut pts = vec![ray.p];
    for i in 0..sys.surfaces.len() {
        if let Err(v) = trace_range(sys, &n, &mut ray, i..i + 1) {
            return (pts, Some(v));
        }
        pts.push(ray.p);
    }
    let s = ray.to_plane(sys.retina_z_mm);
    pts.push(ray.at(s));
    (pts, None)
}
