//! Aberrations off axis: the eye traced for a field direction (h, v).
//!
//! Field angles are object-space directions in degrees: a point at field (h, v) lies along
//! (tan h, tan v, 1) from the entrance pupil, +x and +y being the eye's axes (so a pinhole
//! camera's pixel at (x, y) from the centre, at focal length f, has tan h = x/f, tan v = y/f).
//!
//! Rays are labelled by where they cross the *pupil plane*: the plane through the on-axis
//! entrance-pupil centre perpendicular to the field direction, with the basis e₂ = the
//! eye's +y made perpendicular to the direction and e₁ = e₂ × direction (on axis these are
//! +x and +y, and everything below reduces to the on-axis measurement).
//!
//! Normalisation ("stretched ellipse"): the pupil `pupil_mm` names the on-axis entrance
//! pupil, i.e. a fixed iris. Off axis that iris is seen foreshortened: rays through its rim
//! in the tangential meridian (the plane of axis and field direction) span less of the
//! pupil plane than on axis, those in the sagittal meridian about as much. The analysis
//! pupil is the on-axis disc stretched along the tangential and sagittal axes by those two
//! ratios and moved with the midpoint of the rim rays: an ellipse with semi-axes
//! (R·s_t, R·s_s), aspect ratio ≈ cos θ. Zernike coefficients are fitted over the unit disc
//! this ellipse is stretched onto (normalised coordinate u maps linearly to the pupil
//! plane), so they are in µm like the on-axis ones but describe the elliptical pupil.
//!
//! The refraction is that of the fitted second-order wavefront in physical pupil-plane
//! coordinates (the quadratic form mapped back through the stretch), so M, J0 and J45 are
//! the sphero-cylinder that best flattens the wavefront over the real elliptical pupil, in
//! dioptres, with J0 along e₁/e₂. Using the circular formula on stretched coefficients
//! would add a spurious astigmatism of order M·(1 − cos²θ).
//!
//! The wavefront is referred to a sphere centred on the chief ray's (the ray through the
//! iris centre) intersection with the retina, whatever its shape, so defocus is relative to
//! the retina at that eccentricity: peripheral refraction.

use super::error::EyeError;
use super::measure::{
    check_inputs, dist, measure, path_to_sphere, rho2_coefficient, truncate, Measurement, Measurer,
    Refraction,
};
use super::paraxial::paraxial;
use super::surface::{dot, V3};
use super::system::{OpticalSystem, MAX_SURFACES};
use super::trace::{trace_range, Ray};
use crate::optics::zernike::{num_terms, osa_index};
use serde::Serialize;

/// Largest eccentricity (degrees from the axis) the tracer accepts.
pub const MAX_FIELD_DEG: f64 = 60.0;

/// Where the off-axis pupil lies and how it was normalised.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct FieldPupil {
    /// Field angles (h, v), degrees.
    pub field_deg: [f64; 2],
    /// Angle between the field direction and the axis, degrees.
    pub eccentricity_deg: f64,
    /// Object-space direction of the field (unit vector).
    pub direction: [f64; 3],
    /// Iris diameter whose on-axis image is the requested pupil (mm).
    pub iris_diameter_mm: f64,
    /// Semi-axes of the analysis ellipse, tangential then sagittal (mm).
    pub semi_axes_mm: [f64; 2],
    /// Tangential axis of the ellipse, degrees from e₁ towards e₂.
    pub tangential_axis_deg: f64,
    /// Ellipse centre and chief-ray crossing in the pupil plane (mm, basis e₁, e₂).
    pub centre_mm: [f64; 2],
    pub chief_mm: [f64; 2],
}

/// A measurement off axis: the on-axis record (coefficients over the stretched ellipse,
/// refraction of the physical wavefront) and the pupil it was made over.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct FieldMeasurement {
    #[serde(flatten)]
    pub measurement: Measurement,
    pub field: FieldPupil,
}

/// Checks a field direction: finite, eccentricity within [`MAX_FIELD_DEG`].
pub fn check_field_deg(field_deg: [f64; 2]) -> Result<(), EyeError> {
    let [h, v] = field_deg;
    let ok = h.is_finite()
        && v.is_finite()
        && h.abs() <= MAX_FIELD_DEG
        && v.abs() <= MAX_FIELD_DEG
        && eccentricity_deg(field_deg) <= MAX_FIELD_DEG + 1e-9;
    if ok {
        Ok(())
    } else {
        Err(EyeError::Invalid(format!(
            "field ({h}, {v})° is outside the traced field: each angle and the eccentricity \
             within ±{MAX_FIELD_DEG}°"
        )))
    }
}

/// Where the ray from the axis through `field_deg` leaves the traced field: `field_deg` scaled
/// down (both angles alike) until the direction and each angle lie within [`MAX_FIELD_DEG`]
/// (less a micro-degree, so that the result passes [`check_field_deg`]).
pub fn shrink_into_traced_field(field_deg: [f64; 2]) -> [f64; 2] {
    let limit = MAX_FIELD_DEG - 1e-6;
    let inside = |m: f64| {
        let f = [field_deg[0] * m, field_deg[1] * m];
        eccentricity_deg(f) <= limit && f[0].abs() <= limit && f[1].abs() <= limit
    };
    if inside(1.0) {
        return field_deg;
    }
    let (mut lo, mut hi) = (0.0, 1.0);
    for _ in 0..60 {
        let m = 0.5 * (lo + hi);
        if inside(m) {
            lo = m;
        } else {
            hi = m;
        }
    }
    [field_deg[0] * lo, field_deg[1] * lo]
}

/// Object-space unit direction of field (h, v) degrees.
pub fn field_direction(field_deg: [f64; 2]) -> V3 {
    let (x, y) = (
        field_deg[0].to_radians().tan(),
        field_deg[1].to_radians().tan(),
    );
    let l = (x * x + y * y + 1.0).sqrt();
    [x / l, y / l, 1.0 / l]
}

/// Angle of field (h, v) from the axis, degrees.
pub fn eccentricity_deg(field_deg: [f64; 2]) -> f64 {
    let (x, y) = (
        field_deg[0].to_radians().tan(),
        field_deg[1].to_radians().tan(),
    );
    x.hypot(y).atan().to_degrees()
}

fn add(a: V3, b: V3, s: f64) -> V3 {
    [a[0] + s * b[0], a[1] + s * b[1], a[2] + s * b[2]]
}

fn unit(a: V3) -> V3 {
    let l = dot(a, a).sqrt();
    [a[0] / l, a[1] / l, a[2] / l]
}

fn cross(a: V3, b: V3) -> V3 {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

/// Ray bundle geometry for one field direction.
struct Bundle<'a> {
    sys: &'a OpticalSystem,
    n: [f64; MAX_SURFACES + 1],
    d: V3,
    e1: V3,
    e2: V3,
    anchor: V3,
    object: Option<V3>,
}

impl<'a> Bundle<'a> {
    fn new(
        sys: &'a OpticalSystem,
        wavelength_nm: f64,
        field_deg: [f64; 2],
        ep_z: f64,
        object_distance_m: Option<f64>,
    ) -> Self {
        let d = field_direction(field_deg);
        let e2 = unit(add([0.0, 1.0, 0.0], d, -d[1]));
        let e1 = cross(e2, d);
        let anchor = [0.0, 0.0, ep_z];
        // The object keeps the distance from the pupil centre the on-axis object has, so the
        // field (0, 0) is exactly the on-axis measurement.
        // Beyond 100 km an object is infinity to 1e-5 D, and rays launched from it would lose
        // micrometres of path to rounding (see `measure::spherical_wave_ray`).
        let object = object_distance_m
            .filter(|m| *m < 1e5)
            .map(|m| add(anchor, d, -(1000.0 * m + ep_z)));
        Bundle {
            sys,
            n: sys.indices(wavelength_nm),
            d,
            e1,
            e2,
            anchor,
            object,
        }
    }

    fn ray(&self, q: [f64; 2]) -> Ray {
        let p = add(add(self.anchor, self.e1, q[0]), self.e2, q[1]);
        match self.object {
            Some(o) => Ray::towards(o, p),
            // A common start plane perpendicular to the direction: a plane wavefront.
            None => Ray {
                p: add(p, self.d, -30.0),
                d: self.d,
                opl_mm: 0.0,
            },
        }
    }

    /// Where the ray labelled `q` crosses the iris plane (x, y), mm.
    fn iris(&self, q: [f64; 2]) -> Option<[f64; 2]> {
        let mut ray = self.ray(q);
        trace_range(self.sys, &self.n, &mut ray, 0..self.sys.stop_index).ok()?;
        let p = ray.at(ray.to_plane(self.sys.stop_z_mm));
        Some([p[0], p[1]])
    }

    /// The pupil-plane label of the ray through iris point `target`, by Newton's method with a
    /// finite-difference Jacobian (the map is smooth and nearly linear).
    fn through_iris(&self, target: [f64; 2], guess: [f64; 2]) -> Option<[f64; 2]> {
        let mut q = guess;
        let h = 1e-5;
        for _ in 0..40 {
            let f = self.iris(q)?;
            let r = [f[0] - target[0], f[1] - target[1]];
            if r[0].hypot(r[1]) < 1e-11 {
                return Some(q);
            }
            let fx = self.iris([q[0] + h, q[1]])?;
            let fy = self.iris([q[0], q[1] + h])?;
            let j = [
                [(fx[0] - f[0]) / h, (fy[0] - f[0]) / h],
                [(fx[1] - f[1]) / h, (fy[1] - f[1]) / h],
            ];
            let det = j[0][0] * j[1][1] - j[0][1] * j[1][0];
            if det.abs() < 1e-12 {
                return None;
            }
            q[0] -= (j[1][1] * r[0] - j[0][1] * r[1]) / det;
            q[1] -= (-j[1][0] * r[0] + j[0][0] * r[1]) / det;
        }
        None
    }

    /// Direction of `v` (a vector in space) in the pupil-plane basis, normalised.
    fn in_plane(&self, v: V3) -> [f64; 2] {
        let a = [dot(v, self.e1), dot(v, self.e2)];
        let l = a[0].hypot(a[1]);
        [a[0] / l, a[1] / l]
    }
}

/// Rim rays of the iris in the tangential and sagittal meridians.
struct Rim {
    /// Tangential and sagittal unit axes in the pupil-plane basis.
    t: [f64; 2],
    s: [f64; 2],
    /// Half extents along t and s (mm) and the midpoint (pupil-plane basis).
    half: [f64; 2],
    mid: [f64; 2],
    /// The four labels: +t, −t, +s, −s.
    labels: [[f64; 2]; 4],
}

fn rim(b: &Bundle, radial: [f64; 2], iris_r: f64, chief: [f64; 2], scale: f64) -> Option<Rim> {
    let rho = [radial[0], radial[1], 0.0];
    let t = b.in_plane(add(rho, b.d, -dot(rho, b.d)));
    let s = [-t[1], t[0]];
    let sig = [-radial[1], radial[0]];
    let mut labels = [[0.0; 2]; 4];
    let targets = [
        [iris_r * radial[0], iris_r * radial[1]],
        [-iris_r * radial[0], -iris_r * radial[1]],
        [iris_r * sig[0], iris_r * sig[1]],
        [-iris_r * sig[0], -iris_r * sig[1]],
    ];
    let axes = [t, [-t[0], -t[1]], s, [-s[0], -s[1]]];
    for k in 0..4 {
        let guess = [chief[0] + scale * axes[k][0], chief[1] + scale * axes[k][1]];
        labels[k] = b.through_iris(targets[k], guess)?;
    }
    let pdot = |a: [f64; 2], v: [f64; 2]| a[0] * v[0] + a[1] * v[1];
    let diff = |a: [f64; 2], c: [f64; 2]| [a[0] - c[0], a[1] - c[1]];
    let half = [
        0.5 * pdot(diff(labels[0], labels[1]), t),
        0.5 * pdot(diff(labels[2], labels[3]), s),
    ];
    let mt = 0.5 * (pdot(labels[0], t) + pdot(labels[1], t));
    let ms = 0.5 * (pdot(labels[2], s) + pdot(labels[3], s));
    Some(Rim {
        t,
        s,
        half,
        mid: [mt * t[0] + ms * s[0], mt * t[1] + ms * s[1]],
        labels,
    })
}

/// Measures `sys` for field direction `field_deg` (degrees) with the standard or a
/// higher-order pattern; the field (0, 0) is exactly [`measure`].
pub fn measure_field(
    sys: &OpticalSystem,
    wavelength_nm: f64,
    pupil_mm: f64,
    object_distance_m: Option<f64>,
    field_deg: [f64; 2],
    max_order: u32,
) -> Result<FieldMeasurement, EyeError> {
    check_inputs(wavelength_nm, pupil_mm, object_distance_m)?;
    check_field_deg(field_deg)?;
    let meas = Measurer::for_order(max_order);
    let m = if field_deg == [0.0, 0.0] {
        let m = measure(sys, wavelength_nm, pupil_mm, object_distance_m, max_order)?;
        let pupil = FieldPupil {
            field_deg,
            eccentricity_deg: 0.0,
            direction: [0.0, 0.0, 1.0],
            iris_diameter_mm: m.iris_diameter_mm,
            semi_axes_mm: [pupil_mm / 2.0; 2],
            tangential_axis_deg: 0.0,
            centre_mm: [0.0; 2],
            chief_mm: [0.0; 2],
        };
        return Ok(FieldMeasurement {
            measurement: m,
            field: pupil,
        });
    } else {
        measure_off_axis(
            meas,
            sys,
            wavelength_nm,
            pupil_mm,
            object_distance_m,
            field_deg,
        )?
    };
    Ok(FieldMeasurement {
        measurement: truncate(m.measurement, max_order),
        field: m.field,
    })
}

fn vignetted_chief(field_deg: [f64; 2]) -> EyeError {
    EyeError::Invalid(format!(
        "no ray from field ({}, {})° passes the iris centre; the eye cannot image that direction",
        field_deg[0], field_deg[1]
    ))
}

fn measure_off_axis(
    meas: &Measurer,
    sys: &OpticalSystem,
    wavelength_nm: f64,
    pupil_mm: f64,
    object_distance_m: Option<f64>,
    field_deg: [f64; 2],
) -> Result<FieldMeasurement, EyeError> {
    let px = paraxial(sys, wavelength_nm, 0.0);
    let py = paraxial(sys, wavelength_nm, 90.0);
    let ep_z = 0.5 * (px.entrance_pupil_z_mm + py.entrance_pupil_z_mm);
    let xp_z = 0.5 * (px.exit_pupil_z_mm + py.exit_pupil_z_mm);
    let radius = pupil_mm / 2.0;
    let ns = sys.surfaces.len();
    let axis = Bundle::new(sys, wavelength_nm, [0.0, 0.0], ep_z, object_distance_m);
    let b = Bundle::new(sys, wavelength_nm, field_deg, ep_z, object_distance_m);
    let nv = b.n[ns];

    // The iris: mean radius reached by the on-axis pupil's rim.
    let mut iris_r = 0.0;
    for k in 0..4 {
        let a = k as f64 * std::f64::consts::FRAC_PI_2;
        let p = axis
            .iris([radius * a.cos(), radius * a.sin()])
            .ok_or_else(|| EyeError::Invalid("the on-axis pupil rim is vignetted".into()))?;
        iris_r += 0.25 * p[0].hypot(p[1]);
    }
    let radial = {
        let l = b.d[0].hypot(b.d[1]);
        if l > 1e-12 {
            [b.d[0] / l, b.d[1] / l]
        } else {
            [1.0, 0.0]
        }
    };
    let chief_q = b
        .through_iris([0.0, 0.0], [0.0, 0.0])
        .ok_or_else(|| vignetted_chief(field_deg))?;
    let rim_err = || {
        EyeError::Invalid(format!(
            "the iris rim is not reachable from field ({}, {})° at a {pupil_mm} mm pupil",
            field_deg[0], field_deg[1]
        ))
    };
    let on_axis = rim(&axis, radial, iris_r, [0.0, 0.0], radius).ok_or_else(rim_err)?;
    let off = rim(&b, radial, iris_r, chief_q, radius).ok_or_else(rim_err)?;
    let stretch = [off.half[0] / on_axis.half[0], off.half[1] / on_axis.half[1]];
    let centre = [off.mid[0] - on_axis.mid[0], off.mid[1] - on_axis.mid[1]];
    // Linear map from the unit disc to the pupil plane: R·(s_t t tᵀ + s_s s sᵀ).
    let (t, s) = (off.t, off.s);
    let map = [
        [
            radius * (stretch[0] * t[0] * t[0] + stretch[1] * s[0] * s[0]),
            radius * (stretch[0] * t[0] * t[1] + stretch[1] * s[0] * s[1]),
        ],
        [
            radius * (stretch[0] * t[1] * t[0] + stretch[1] * s[1] * s[0]),
            radius * (stretch[0] * t[1] * t[1] + stretch[1] * s[1] * s[1]),
        ],
    ];
    let label = |u: f64, v: f64| {
        [
            centre[0] + map[0][0] * u + map[0][1] * v,
            centre[1] + map[1][0] * u + map[1][1] * v,
        ]
    };

    let mut chief = b.ray(chief_q);
    trace_range(sys, &b.n, &mut chief, 0..ns).map_err(|_| vignetted_chief(field_deg))?;
    let image = sys
        .retina_hit(&chief)
        .ok_or_else(|| vignetted_chief(field_deg))?;
    let s_xp = chief.to_plane(xp_z);
    let xp_centre = chief.at(s_xp);
    let rs = dist(image, xp_centre);
    let l_ref = chief.opl_mm + nv * s_xp;

    let pattern = meas.pattern();
    let np = pattern.points.len();
    let mut w = vec![0.0; np];
    let mut valid = vec![true; np];
    let mut vignetted = 0;
    for (i, p) in pattern.points.iter().enumerate() {
        let mut ray = b.ray(label(p[0], p[1]));
        let ok = trace_range(sys, &b.n, &mut ray, 0..ns).is_ok();
        match (ok, path_to_sphere(&ray, image, rs)) {
            (true, Some(sd)) => w[i] = 1000.0 * (l_ref - ray.opl_mm - nv * sd),
            _ => {
                valid[i] = false;
                vignetted += 1;
            }
        }
    }
    let mut c = vec![0.0; num_terms(pattern.order)];
    if vignetted == 0 {
        pattern.fit(&w, &mut c);
    } else if vignetted * 4 > np || !pattern.fit_subset(&w, &valid, &mut c) {
        return Err(EyeError::Invalid(format!(
            "{vignetted} of {np} rays vignetted at a {pupil_mm} mm pupil from field ({}, {})°",
            field_deg[0], field_deg[1]
        )));
    }

    // Exit pupil and image-side aperture from the four rim rays.
    let (mut xp_r, mut sin_sum, mut rim_n) = (0.0, 0.0, 0usize);
    for q in off.labels {
        let mut ray = b.ray(q);
        if trace_range(sys, &b.n, &mut ray, 0..ns).is_err() {
            continue;
        }
        xp_r += dist(ray.at(ray.to_plane(xp_z)), xp_centre);
        let cosang = dot(ray.d, chief.d).clamp(-1.0, 1.0);
        sin_sum += (1.0 - cosang * cosang).sqrt();
        rim_n += 1;
    }
    let rim_n = rim_n.max(1) as f64;
    let (refraction, sphere_d) = physical_refraction(&c, map, pattern.order);
    let power_d = 0.5 * (px.power_d + py.power_d);
    let measurement = Measurement {
        wavelength_nm,
        pupil_mm,
        object_distance_m,
        max_order: pattern.order,
        rms_um: c.iter().skip(3).map(|v| v * v).sum::<f64>().sqrt(),
        coefficients_um: c,
        power_d,
        refraction,
        paraxial_sphere_d: sphere_d,
        entrance_pupil_z_mm: ep_z,
        entrance_pupil_magnification: [
            px.entrance_pupil_magnification,
            py.entrance_pupil_magnification,
        ],
        iris_diameter_mm: 2.0 * iris_r,
        exit_pupil_z_mm: xp_z,
        exit_pupil_diameter_mm: 2.0 * xp_r / rim_n,
        pupil_retina_mm: rs,
        iris_retina_mm: dist(image, [0.0, 0.0, sys.stop_z_mm]),
        focal_length_image_mm: nv * 1000.0 / power_d,
        image_sin_angle: sin_sum / rim_n,
        image_numerical_aperture: nv * sin_sum / rim_n,
        image_index: nv,
        image_point_mm: image,
        rays: np,
        vignetted_rays: vignetted,
    };
    let field = FieldPupil {
        field_deg,
        eccentricity_deg: eccentricity_deg(field_deg),
        direction: b.d,
        iris_diameter_mm: 2.0 * iris_r,
        semi_axes_mm: [radius * stretch[0], radius * stretch[1]],
        tangential_axis_deg: t[1].atan2(t[0]).to_degrees(),
        centre_mm: centre,
        chief_mm: chief_q,
    };
    Ok(FieldMeasurement { measurement, field })
}

/// Refraction of the second-order wavefront over the physical pupil. In normalised
/// coordinates the second-order Zernikes are uᵀQu with
/// Q = [[2√3 c₂⁰ + √6 c₂², √6 c₂⁻²], [√6 c₂⁻², 2√3 c₂⁰ − √6 c₂²]] (plus piston); in the
/// pupil plane q = A·u, so Q_phys = A⁻ᵀ Q A⁻¹, and W = −½[(M+J0)q₁² + (M−J0)q₂² + 2·J45·q₁q₂]
/// (µm, mm, D). The paraxial sphere takes every c(n,0)'s ρ² term the same way.
fn physical_refraction(c: &[f64], a: [[f64; 2]; 2], order: u32) -> (Refraction, f64) {
    let get = |n: u32, m: i32| c.get(osa_index(n, m)).copied().unwrap_or(0.0);
    let (s3, s6) = (3f64.sqrt(), 6f64.sqrt());
    let q = [
        [2.0 * s3 * get(2, 0) + s6 * get(2, 2), s6 * get(2, -2)],
        [s6 * get(2, -2), 2.0 * s3 * get(2, 0) - s6 * get(2, 2)],
    ];
    let det = a[0][0] * a[1][1] - a[0][1] * a[1][0];
    let inv = [
        [a[1][1] / det, -a[0][1] / det],
        [-a[1][0] / det, a[0][0] / det],
    ];
    let congruent = |q: [[f64; 2]; 2]| {
        let mut out = [[0.0; 2]; 2];
        for (i, row) in out.iter_mut().enumerate() {
            for (j, v) in row.iter_mut().enumerate() {
                for k in 0..2 {
                    for l in 0..2 {
                        *v += inv[k][i] * q[k][l] * inv[l][j];
                    }
                }
            }
        }
        out
    };
    let p = congruent(q);
    let refraction = Refraction {
        m: -(p[0][0] + p[1][1]),
        j0: -(p[0][0] - p[1][1]),
        j45: -2.0 * p[0][1],
    };
    let mut a2 = 0.0;
    let mut n = 2;
    while n <= order {
        a2 += rho2_coefficient(n) * get(n, 0);
        n += 2;
    }
    let r = congruent([[a2, 0.0], [0.0, a2]]);
    (refraction, -(r[0][0] + r[1][1]))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::eye::Eye;

    #[test]
    fn physical_refraction_reduces_to_the_circular_formula() {
        let c = [0.0, 0.0, 0.0, 0.3, -1.2, 0.5, 0.0, 0.0, 0.0, 0.0];
        let r = 2.0;
        let (got, _) = physical_refraction(&c, [[r, 0.0], [0.0, r]], 3);
        let r2 = r * r;
        assert!((got.m - (-4.0 * 3f64.sqrt() * -1.2 / r2)).abs() < 1e-12);
        assert!((got.j0 - (-2.0 * 6f64.sqrt() * 0.5 / r2)).abs() < 1e-12);
        assert!((got.j45 - (-2.0 * 6f64.sqrt() * 0.3 / r2)).abs() < 1e-12);
    }

    #[test]
    fn a_tiny_field_matches_the_on_axis_measurement() {
        let sys = Eye::navarro_wide().system().unwrap();
        let on = measure(&sys, 550.0, 4.0, None, 6).unwrap();
        let off = measure_field(&sys, 550.0, 4.0, None, [1e-4, 0.0], 6).unwrap();
        for (j, (a, b)) in on
            .coefficients_um
            .iter()
            .zip(&off.measurement.coefficients_um)
            .enumerate()
            .skip(3)
        {
            assert!((a - b).abs() < 1e-5, "term {j}: {a} vs {b}");
        }
        assert!((on.refraction.m - off.measurement.refraction.m).abs() < 1e-5);
    }
}
