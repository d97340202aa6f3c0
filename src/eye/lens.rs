//! Crystalline-lens geometry in closed form from equatorial diameter, volume and conics.
//!
//! The lens is two conic caps meeting at the equator. With the cap heights in a fixed ratio
//! ρ = t_A / t_P, the volume π(a²t/2 + (1+k)t³/6) of each cap makes the total volume a cubic
//! in t_P; its smallest positive root gives both heights, and each radius then follows from the
//! conic passing through the equator point: a² = 2Rt − (1+k)t².

use super::error::EyeError;
use std::f64::consts::PI;

/// Anterior / posterior cap-height ratio. Chosen so that Navarro's relaxed surfaces
/// (R_A = 10.2 mm, Q_A = −3.1316, R_P = −6.0 mm, Q_P = −1, thickness 4.0 mm) are reproduced
/// exactly: those surfaces meet at a 11.2574 mm equator with caps of 1.35983 and 2.64017 mm.
/// Hermans et al. (2009) found the ratio stays nearly constant during accommodation.
pub const LENS_THICKNESS_RATIO: f64 = 0.515_052_245_667_148_6;

/// Derived geometry of the lens.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LensGeometry {
    /// Anterior vertex radius (mm, positive: convex towards the cornea).
    pub anterior_radius_mm: f64,
    /// Posterior vertex radius (mm, negative: convex towards the retina).
    pub posterior_radius_mm: f64,
    pub anterior_thickness_mm: f64,
    pub posterior_thickness_mm: f64,
    pub semi_diameter_mm: f64,
}

impl LensGeometry {
    pub fn thickness_mm(&self) -> f64 {
        self.anterior_thickness_mm + self.posterior_thickness_mm
    }
}

/// Volume (mm³) of a conic cap of height `t_mm` over semi-diameter `a_mm`.
pub fn cap_volume_mm3(a_mm: f64, t_mm: f64, conic: f64) -> f64 {
    PI * (a_mm * a_mm * t_mm / 2.0 + (1.0 + conic) * t_mm.powi(3) / 6.0)
}

/// Vertex radius of the conic through the vertex and the equator point (a, t).
pub fn cap_radius_mm(a_mm: f64, t_mm: f64, conic: f64) -> f64 {
    (a_mm * a_mm + (1.0 + conic) * t_mm * t_mm) / (2.0 * t_mm)
}

/// Lens geometry from equatorial diameter, volume and the two conic constants.
pub fn lens_geometry(
    diameter_mm: f64,
    volume_mm3: f64,
    anterior_conic: f64,
    posterior_conic: f64,
) -> Result<LensGeometry, EyeError> {
    let a = diameter_mm / 2.0;
    let rho = LENS_THICKNESS_RATIO;
    let c1 = PI * a * a * (rho + 1.0) / 2.0;
    let c3 = PI * ((1.0 + anterior_conic) * rho.powi(3) + (1.0 + posterior_conic)) / 6.0;
    let f = |t: f64| c3 * t * t * t + c1 * t - volume_mm3;
    let t_max = max_posterior_height_mm(a, anterior_conic, posterior_conic);
    if t_max.is_finite() {
        let v_max = f(t_max) + volume_mm3;
        if volume_mm3 >= v_max {
            return Err(EyeError::LensCannotClose {
                volume_mm3,
                diameter_mm,
                max_volume_mm3: v_max,
            });
        }
    }
    // f is monotone on [0, t_max] and keeps one curvature sign there, so Newton from the
    // linear estimate (c3 ≥ 0) or from zero (c3 < 0) converges monotonically.
    let mut t = if c3 < 0.0 { 0.0 } else { volume_mm3 / c1 };
    for _ in 0..100 {
        let step = f(t) / (3.0 * c3 * t * t + c1);
        t -= step;
        if step.abs() < 1e-15 * t.abs().max(1e-3) {
            break;
        }
    }
    let tp = t;
    let ta = rho * tp;
    let ra = cap_radius_mm(a, ta, anterior_conic);
    let rp = cap_radius_mm(a, tp, posterior_conic);
    for (name, r, k, tt) in [
        ("anterior", ra, anterior_conic, ta),
        ("posterior", rp, posterior_conic, tp),
    ] {
        // An ellipsoidal cap may not run past its own semi-axis, and the radius must be real.
        let reach = 1.0 - (1.0 + k) * a * a / (r * r);
        if !(r > 0.0 && tt > 0.0 && reach >= -1e-12 && (k <= -1.0 || tt <= r / (1.0 + k) + 1e-12)) {
            return Err(EyeError::Invalid(format!(
                "lens cannot close: the {name} cap (conic {k}, height {tt:.3} mm) cannot reach \
                 an equator of diameter {diameter_mm} mm"
            )));
        }
    }
    Ok(LensGeometry {
        anterior_radius_mm: ra,
        posterior_radius_mm: -rp,
        anterior_thickness_mm: ta,
        posterior_thickness_mm: tp,
        semi_diameter_mm: a,
    })
}

/// Largest posterior cap height (mm) for which both caps still exist: a hyperboloidal cap
/// (k < −1) needs t < a/√(−(1+k)) for a positive vertex radius, an ellipsoidal one (k > −1)
/// may not pass its own semi-axis, and the volume must still grow with t.
fn max_posterior_height_mm(a: f64, anterior_conic: f64, posterior_conic: f64) -> f64 {
    let rho = LENS_THICKNESS_RATIO;
    let limit = |k: f64| {
        if k < -1.0 {
            a / (-(1.0 + k)).sqrt()
        } else if k > -1.0 {
            // Cap through (a, t) stays on the near half of the ellipse while t ≤ a/√(1+k).
            a / (1.0 + k).sqrt()
        } else {
            f64::INFINITY
        }
    };
    let c1 = PI * a * a * (rho + 1.0) / 2.0;
    let c3 = PI * ((1.0 + anterior_conic) * rho.powi(3) + (1.0 + posterior_conic)) / 6.0;
    let peak = if c3 < 0.0 {
        (c1 / (-3.0 * c3)).sqrt()
    } else {
        f64::INFINITY
    };
    (limit(anterior_conic) / rho)
        .min(limit(posterior_conic))
        .min(peak)
}

/// Largest lens volume (mm³) that caps with these conics can hold at this diameter; the
/// parameter box of the seed paper holds lenses beyond it, which the model must refuse.
pub fn max_volume_mm3(diameter_mm: f64, anterior_conic: f64, posterior_conic: f64) -> f64 {
    let a = diameter_mm / 2.0;
    let tp = max_posterior_height_mm(a, anterior_conic, posterior_conic);
    if !tp.is_finite() {
        return f64::INFINITY;
    }
    cap_volume_mm3(a, LENS_THICKNESS_RATIO * tp, anterior_conic)
        + cap_volume_mm3(a, tp, posterior_conic)
}

/// Inverse problem: the equatorial diameter and volume (mm, mm³) at which two conic caps with
/// the given vertex radii (posterior negative) and total thickness meet, with their own height
/// ratio. Used to express Navarro's lens in the parametric form.
pub fn diameter_volume_from_radii(
    anterior_radius_mm: f64,
    posterior_radius_mm: f64,
    anterior_conic: f64,
    posterior_conic: f64,
    thickness_mm: f64,
) -> Option<(f64, f64, f64)> {
    let rp = -posterior_radius_mm;
    // a² from each cap must agree: g(t_A) = 0 with t_P = T − t_A.
    let a2 = |t: f64, r: f64, k: f64| 2.0 * r * t - (1.0 + k) * t * t;
    let g = |ta: f64| {
        a2(ta, anterior_radius_mm, anterior_conic) - a2(thickness_mm - ta, rp, posterior_conic)
    };
    let (mut lo, mut hi) = (1e-9, thickness_mm - 1e-9);
    if g(lo) * g(hi) > 0.0 {
        return None;
    }
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if g(lo) * g(mid) <= 0.0 {
            hi = mid;
        } else {
            lo = mid;
        }
    }
    let ta = 0.5 * (lo + hi);
    let tp = thickness_mm - ta;
    let a2v = a2(ta, anterior_radius_mm, anterior_conic);
    if a2v <= 0.0 {
        return None;
    }
    let a = a2v.sqrt();
    let v = cap_volume_mm3(a, ta, anterior_conic) + cap_volume_mm3(a, tp, posterior_conic);
    Some((2.0 * a, v, ta / tp))
}
