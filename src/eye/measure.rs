//! Aberration measurement of an eye for one wavelength, entrance pupil and object distance.
//!
//! Rays leave the on-axis object point (or a plane wave for an object at infinity), aimed at a
//! fixed pattern of points on the paraxial entrance pupil (the iris imaged back through the
//! cornea), and are traced exactly to the vitreous. Their optical paths are completed to a
//! reference sphere centred on the chief ray's retinal point and passing through the exit-pupil
//! centre. The wavefront error W = L_chief − L (positive where the wave leads the reference)
//! is fitted with orthonormal OSA Zernikes over the entrance pupil, in µm. With this sign an
//! eye that focuses in front of the retina (myopia) has positive c(2,0), as OSA prescribes.
//!
//! The analysis pupil is the circular disc of the requested diameter in the entrance-pupil
//! plane, as an aberrometer defines it; a toric cornea makes the image of a round iris
//! slightly elliptical, which is reported (per-meridian magnification and the iris diameter the
//! disc needs) rather than folded into the fit.

use super::error::EyeError;
use super::fit::PupilPattern;
use super::paraxial::{paraxial, Paraxial};
use super::surface::{dot, V3};
use super::system::{OpticalSystem, MAX_SURFACES};
use super::trace::{trace_range, Ray};
use crate::optics::zernike::{num_terms, osa_index};
use serde::Serialize;
use std::sync::OnceLock;

/// Refraction in power-vector form (D), referred to the entrance-pupil plane.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Refraction {
    pub m: f64,
    pub j0: f64,
    pub j45: f64,
}

/// Everything a measurement reports.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Measurement {
    pub wavelength_nm: f64,
    pub pupil_mm: f64,
    /// `None` = object at infinity.
    pub object_distance_m: Option<f64>,
    pub max_order: u32,
    /// OSA-ordered coefficients (µm) over the entrance pupil of diameter `pupil_mm`.
    pub coefficients_um: Vec<f64>,
    /// Equivalent power of the eye (D), mean of the two principal meridians x and y.
    pub power_d: f64,
    /// Minimum-RMS refraction from the second-order terms.
    pub refraction: Refraction,
    /// Sphere from the wavefront curvature at the pupil centre (includes c(4,0), c(6,0), …), D.
    pub paraxial_sphere_d: f64,
    /// RMS wavefront error without piston and tilt (µm).
    pub rms_um: f64,
    pub entrance_pupil_z_mm: f64,
    /// Entrance-pupil size per iris size in the x and y meridians (their ratio is the
    /// ellipticity of the pupil as seen from outside).
    pub entrance_pupil_magnification: [f64; 2],
    /// Iris diameter that lets the whole analysis pupil through (mm).
    pub iris_diameter_mm: f64,
    pub exit_pupil_z_mm: f64,
    pub exit_pupil_diameter_mm: f64,
    /// Exit pupil to retina along the axis (mm).
    pub pupil_retina_mm: f64,
    /// Iris plane to retina (mm).
    pub iris_retina_mm: f64,
    /// Image-side focal length n'/P (mm).
    pub focal_length_image_mm: f64,
    /// Sine of the image-side cone half-angle, and n'·sin.
    pub image_sin_angle: f64,
    pub image_numerical_aperture: f64,
    pub image_index: f64,
    /// Chief-ray intersection with the retina (mm).
    pub image_point_mm: [f64; 3],
    pub rays: usize,
    pub vignetted_rays: usize,
}

/// One coefficient with its indices, for reports (`{"n":4,"m":0,"um":0.239}`).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Coefficient {
    pub n: u32,
    pub m: i32,
    pub um: f64,
}

impl Measurement {
    /// Coefficients as (n, m, µm) records in OSA order.
    pub fn coefficient_list(&self) -> Vec<Coefficient> {
        self.coefficients_um
            .iter()
            .enumerate()
            .map(|(j, &um)| {
                let (n, m) = crate::optics::zernike::osa_nm(j);
                Coefficient { n, m, um }
            })
            .collect()
    }

    /// Coefficient (µm) of term (n, m); 0 outside the fitted orders.
    pub fn coefficient_um(&self, n: u32, m: i32) -> f64 {
        let j = osa_index(n, m);
        self.coefficients_um.get(j).copied().unwrap_or(0.0)
    }
}

/// A reusable measuring instrument: the pupil pattern and its fit operator.
#[derive(Debug, Clone)]
pub struct Measurer {
    pattern: PupilPattern,
    rim: Vec<[f64; 2]>,
}

/// Order of the default fit.
pub const DEFAULT_ORDER: u32 = 6;

impl Measurer {
    /// `rings` × `spokes` rays, fit to `max_order` (≤ 10 is sensible).
    pub fn new(max_order: u32, rings: usize, spokes: usize) -> Measurer {
        let rim = (0..8)
            .map(|k| {
                let th = k as f64 * std::f64::consts::FRAC_PI_4;
                [th.cos(), th.sin()]
            })
            .collect();
        Measurer {
            pattern: PupilPattern::new(max_order, rings, spokes),
            rim,
        }
    }

    /// 16 rings × 64 spokes = 1024 rays, order 6.
    pub fn standard() -> &'static Measurer {
        static M: OnceLock<Measurer> = OnceLock::new();
        M.get_or_init(|| Measurer::new(DEFAULT_ORDER, 16, 64))
    }

    /// Pattern sized for a fit of `max_order` (standard one for ≤ 6; cached up to 10).
    pub fn for_order(max_order: u32) -> &'static Measurer {
        static M: OnceLock<Vec<Measurer>> = OnceLock::new();
        if max_order <= DEFAULT_ORDER {
            return Measurer::standard();
        }
        let all = M.get_or_init(|| (7..=10).map(|o| Measurer::new(o, 24, 96)).collect());
        &all[(max_order.min(10) - 7) as usize]
    }

    pub(super) fn pattern(&self) -> &PupilPattern {
        &self.pattern
    }

    pub fn max_order(&self) -> u32 {
        self.pattern.order
    }

    pub fn rays(&self) -> usize {
        self.pattern.points.len()
    }

    /// Measures `sys` at `wavelength_nm` over an entrance pupil of `pupil_mm` for an on-axis
    /// object at `object_distance_m` metres from the corneal vertex (`None` = infinity).
    pub fn measure(
        &self,
        sys: &OpticalSystem,
        wavelength_nm: f64,
        pupil_mm: f64,
        object_distance_m: Option<f64>,
    ) -> Result<Measurement, EyeError> {
        let a = chief_ray(
            sys,
            wavelength_nm,
            pupil_mm,
            object_distance_m,
            "; the eye cannot image the axis",
        )?;

        let np = self.pattern.points.len();
        let mut w = vec![0.0; np];
        let mut valid = vec![true; np];
        let mut vignetted = 0;
        for (i, p) in self.pattern.points.iter().enumerate() {
            match a.wavefront_um(sys, p) {
                Some(v) => w[i] = v,
                None => {
                    valid[i] = false;
                    vignetted += 1;
                }
            }
        }
        let nt = num_terms(self.pattern.order);
        let mut c = vec![0.0; nt];
        if vignetted == 0 {
            self.pattern.fit(&w, &mut c);
        } else if vignetted * 4 > np || !self.pattern.fit_subset(&w, &valid, &mut c) {
            return Err(EyeError::Invalid(format!(
                "{vignetted} of {np} rays vignetted at a {pupil_mm} mm pupil; the eye cannot be measured there"
            )));
        }

        // Rim rays for the pupil sizes and the image-side aperture.
        let (mut iris_r, mut xp_r, mut sin_sum, mut rim_n) = (0.0f64, 0.0, 0.0, 0usize);
        for r in &self.rim {
            let mut ray = (a.launch)(r[0], r[1]);
            if trace_range(sys, &a.n, &mut ray, 0..sys.stop_index).is_err() {
                continue;
            }
            let at_stop = ray.at(ray.to_plane(sys.stop_z_mm));
            iris_r = iris_r.max(at_stop[0].hypot(at_stop[1]));
            if trace_range(sys, &a.n, &mut ray, sys.stop_index..a.ns).is_err() {
                continue;
            }
            let q = ray.at(ray.to_plane(a.xp_z));
            xp_r += (q[0] - a.xp_centre[0]).hypot(q[1] - a.xp_centre[1]);
            let cosang = dot(ray.d, a.chief.d).clamp(-1.0, 1.0);
            sin_sum += (1.0 - cosang * cosang).sqrt();
            rim_n += 1;
        }
        let rim_n = rim_n.max(1) as f64;
        let sin_angle = sin_sum / rim_n;
        Ok(assemble(
            &c,
            &a.px,
            &a.py,
            Extra {
                wavelength_nm,
                pupil_mm,
                object_distance_m,
                order: self.pattern.order,
                ep_z: a.ep_z,
                xp_z: a.xp_z,
                iris_d: 2.0 * iris_r,
                xp_d: 2.0 * xp_r / rim_n,
                sin_angle,
                nv: a.nv,
                image: a.image,
                retina_z: sys.retina_z_mm,
                stop_z: sys.stop_z_mm,
                rays: np,
                vignetted,
            },
        ))
    }

    /// Only the coefficients (µm) into `out` (length ≥ terms); no rim rays, no allocation
    /// beyond the per-call sample buffer. For inner loops such as accommodation.
    pub fn coefficients_um(
        &self,
        sys: &OpticalSystem,
        wavelength_nm: f64,
        pupil_mm: f64,
        object_distance_m: Option<f64>,
        out: &mut [f64],
    ) -> Result<(), EyeError> {
        let a = chief_ray(sys, wavelength_nm, pupil_mm, object_distance_m, "")?;
        let np = self.pattern.points.len();
        let mut w = vec![0.0; np];
        for (i, p) in self.pattern.points.iter().enumerate() {
            w[i] = a
                .wavefront_um(sys, p)
                .ok_or_else(|| EyeError::Invalid("ray vignetted".into()))?;
        }
        self.pattern.fit(&w, out);
        Ok(())
    }
}

/// What both measurements start from: the media, the paraxial pupils, the launcher over the
/// entrance pupil, and the chief ray traced to the retina with the reference sphere it gives.
struct Chief<L> {
    n: [f64; MAX_SURFACES + 1],
    ns: usize,
    /// The index of the medium before the retina.
    nv: f64,
    px: Paraxial,
    py: Paraxial,
    ep_z: f64,
    xp_z: f64,
    launch: L,
    chief: Ray,
    image: V3,
    xp_centre: V3,
    /// The reference sphere's radius (image to exit-pupil centre) and the chief ray's optical
    /// path to it.
    rs: f64,
    l_ref: f64,
}

impl<L: Fn(f64, f64) -> Ray> Chief<L> {
    /// The wavefront (µm, against the reference sphere) of the ray through pupil point `p`;
    /// none where it is vignetted.
    fn wavefront_um(&self, sys: &OpticalSystem, p: &[f64; 2]) -> Option<f64> {
        let mut ray = (self.launch)(p[0], p[1]);
        trace_range(sys, &self.n, &mut ray, 0..self.ns).ok()?;
        let s = path_to_sphere(&ray, self.image, self.rs)?;
        Some(1000.0 * (self.l_ref - ray.opl_mm - self.nv * s))
    }
}

/// The inputs checked and the chief ray traced; `vignetted` ends the error where it is
/// vignetted.
fn chief_ray(
    sys: &OpticalSystem,
    wavelength_nm: f64,
    pupil_mm: f64,
    object_distance_m: Option<f64>,
    vignetted: &str,
) -> Result<Chief<impl Fn(f64, f64) -> Ray>, EyeError> {
    check_inputs(wavelength_nm, pupil_mm, object_distance_m)?;
    let n = sys.indices(wavelength_nm);
    let ns = sys.surfaces.len();
    let nv = n[ns];
    let px = paraxial(sys, wavelength_nm, 0.0);
    let py = paraxial(sys, wavelength_nm, 90.0);
    let ep_z = 0.5 * (px.entrance_pupil_z_mm + py.entrance_pupil_z_mm);
    let xp_z = 0.5 * (px.exit_pupil_z_mm + py.exit_pupil_z_mm);
    let launch = launcher(object_distance_m, pupil_mm / 2.0, ep_z, first_z(sys))?;
    let mut chief = launch(0.0, 0.0);
    trace_range(sys, &n, &mut chief, 0..ns)
        .map_err(|v| EyeError::Invalid(format!("chief ray vignetted ({v:?}){vignetted}")))?;
    let image = chief.at(chief.to_plane(sys.retina_z_mm));
    let s_xp = chief.to_plane(xp_z);
    let xp_centre = chief.at(s_xp);
    let rs = dist(image, xp_centre);
    let l_ref = chief.opl_mm + nv * s_xp;
    Ok(Chief {
        n,
        ns,
        nv,
        px,
        py,
        ep_z,
        xp_z,
        launch,
        chief,
        image,
        xp_centre,
        rs,
        l_ref,
    })
}

/// Measures with the standard (order 6) or a higher-order pattern.
pub fn measure(
    sys: &OpticalSystem,
    wavelength_nm: f64,
    pupil_mm: f64,
    object_distance_m: Option<f64>,
    max_order: u32,
) -> Result<Measurement, EyeError> {
    let m =
        Measurer::for_order(max_order).measure(sys, wavelength_nm, pupil_mm, object_distance_m)?;
    Ok(truncate(m, max_order))
}

pub(super) fn truncate(mut m: Measurement, max_order: u32) -> Measurement {
    if max_order < m.max_order {
        m.coefficients_um.truncate(num_terms(max_order));
        m.max_order = max_order;
    }
    m
}

pub(super) fn check_inputs(
    wavelength_nm: f64,
    pupil_mm: f64,
    object_distance_m: Option<f64>,
) -> Result<(), EyeError> {
    // The optics' own domain (the commands and files accept the narrower ranges of
    // `crate::limits`; tests trace a 0.5 mm pupil to compare with paraxial optics).
    if !(wavelength_nm.is_finite() && (300.0..=1100.0).contains(&wavelength_nm)) {
        return Err(EyeError::Invalid(format!(
            "wavelength {wavelength_nm} nm is outside 300–1100 nm"
        )));
    }
    if !(pupil_mm.is_finite() && pupil_mm > 0.0 && pupil_mm <= 10.0) {
        return Err(EyeError::Invalid(format!(
            "pupil diameter {pupil_mm} mm is outside (0, 10] mm"
        )));
    }
    if let Some(d) = object_distance_m {
        if !(d.is_finite() && d > 0.02) {
            return Err(EyeError::Invalid(format!(
                "object distance {d} m must be finite and beyond 0.02 m (use None for infinity)"
            )));
        }
    }
    Ok(())
}

/// The frontmost vertex of the system (a spectacle lens lies before the cornea).
fn first_z(sys: &OpticalSystem) -> f64 {
    sys.surfaces
        .iter()
        .map(|s| s.vertex_z_mm)
        .fold(0.0, f64::min)
}

/// Ray factory for normalised pupil coordinates (u, v) on the entrance pupil; a plane wave
/// starts 5 mm before the first surface, and a point object must lie before it.
fn launcher(
    object_distance_m: Option<f64>,
    radius_mm: f64,
    ep_z: f64,
    first_z_mm: f64,
) -> Result<impl Fn(f64, f64) -> Ray, EyeError> {
    if let Some(d) = object_distance_m {
        if -1000.0 * d >= first_z_mm {
            return Err(EyeError::Invalid(format!(
                "an object {d} m from the cornea lies behind the lens {:.1} mm in front of it",
                -first_z_mm
            )));
        }
    }
    let start_z = first_z_mm - 5.0;
    // A point object nearer than 5 mm before the first surface: start halfway to it.
    let point_start_z =
        move |object_mm: f64| start_z.max(0.5 * (first_z_mm - object_mm)).min(first_z_mm);
    Ok(move |u: f64, v: f64| match object_distance_m {
        Some(d) => spherical_wave_ray(
            1000.0 * d,
            [radius_mm * u, radius_mm * v],
            ep_z,
            point_start_z(1000.0 * d),
        ),
        None => Ray {
            p: [radius_mm * u, radius_mm * v, start_z],
            d: [0.0, 0.0, 1.0],
            opl_mm: 0.0,
        },
    })
}

/// The ray from an on-axis point `object_mm` before the corneal vertex, aimed at `aim` on the
/// entrance-pupil plane `ep_z`, started where it crosses the object's spherical wavefront
/// through (0, 0, `start_z`), with optical path zero there (every start point is equally far
/// from the object). Starting at the object itself would carry paths of ~10¹³ mm for a focus
/// of 10⁻¹⁰ D, whose differences lose micrometres to rounding; the sag is written so that no
/// large numbers cancel.
fn spherical_wave_ray(object_mm: f64, aim: [f64; 2], ep_z: f64, start_z: f64) -> Ray {
    let axial = ep_z + object_mm;
    let h2 = aim[0] * aim[0] + aim[1] * aim[1];
    let s = (h2 + axial * axial).sqrt();
    let radius = object_mm + start_z;
    let sag = radius * h2 / (s * (s + axial));
    Ray {
        p: [radius * aim[0] / s, radius * aim[1] / s, start_z - sag],
        d: [aim[0] / s, aim[1] / s, axial / s],
        opl_mm: 0.0,
    }
}

#[inline]
pub(super) fn dist(a: V3, b: V3) -> f64 {
    ((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2) + (a[2] - b[2]).powi(2)).sqrt()
}

/// Signed distance along the ray to the near side of the reference sphere.
#[inline]
pub(super) fn path_to_sphere(ray: &Ray, centre: V3, radius: f64) -> Option<f64> {
    let q = [
        ray.p[0] - centre[0],
        ray.p[1] - centre[1],
        ray.p[2] - centre[2],
    ];
    let b = dot(ray.d, q);
    let c = dot(q, q) - radius * radius;
    let disc = b * b - c;
    if disc < 0.0 {
        return None;
    }
    Some(-b - disc.sqrt())
}

struct Extra {
    wavelength_nm: f64,
    pupil_mm: f64,
    object_distance_m: Option<f64>,
    order: u32,
    ep_z: f64,
    xp_z: f64,
    iris_d: f64,
    xp_d: f64,
    sin_angle: f64,
    nv: f64,
    image: V3,
    retina_z: f64,
    stop_z: f64,
    rays: usize,
    vignetted: usize,
}

/// ρ² coefficient of the radial polynomial R_n^0 times its normalisation √(n+1).
pub(super) fn rho2_coefficient(n: u32) -> f64 {
    let h = (n / 2) as i64;
    // R_n^0(ρ) = Σ_k (−1)^k (n−k)! / (k! ((n/2−k)!)²) ρ^(n−2k); ρ² is k = n/2 − 1.
    let k = h - 1;
    let f = |x: i64| (1..=x).fold(1.0, |a, i| a * i as f64);
    let sign = if k % 2 == 0 { 1.0 } else { -1.0 };
    sign * f(n as i64 - k) / (f(k) * f(h - k) * f(h - k)) * ((n + 1) as f64).sqrt()
}

fn assemble(c: &[f64], px: &Paraxial, py: &Paraxial, e: Extra) -> Measurement {
    let r2 = (e.pupil_mm / 2.0).powi(2);
    let get = |n: u32, m: i32| c.get(osa_index(n, m)).copied().unwrap_or(0.0);
    let s6 = 6f64.sqrt();
    let refraction = Refraction {
        m: -4.0 * 3f64.sqrt() * get(2, 0) / r2,
        j0: -2.0 * s6 * get(2, 2) / r2,
        j45: -2.0 * s6 * get(2, -2) / r2,
    };
    // W ≈ a₂ρ² near the centre; W[µm] = −M·r²/2 with r in mm.
    let mut a2 = 0.0;
    let mut n = 2;
    while n <= e.order {
        a2 += rho2_coefficient(n) * get(n, 0);
        n += 2;
    }
    let rms = c.iter().skip(3).map(|v| v * v).sum::<f64>().sqrt();
    let power_d = 0.5 * (px.power_d + py.power_d);
    Measurement {
        wavelength_nm: e.wavelength_nm,
        pupil_mm: e.pupil_mm,
        object_distance_m: e.object_distance_m,
        max_order: e.order,
        coefficients_um: c.to_vec(),
        power_d,
        refraction,
        paraxial_sphere_d: -2.0 * a2 / r2,
        rms_um: rms,
        entrance_pupil_z_mm: e.ep_z,
        entrance_pupil_magnification: [
            px.entrance_pupil_magnification,
            py.entrance_pupil_magnification,
        ],
        iris_diameter_mm: e.iris_d,
        exit_pupil_z_mm: e.xp_z,
        exit_pupil_diameter_mm: e.xp_d,
        pupil_retina_mm: e.retina_z - e.xp_z,
        iris_retina_mm: e.retina_z - e.stop_z,
        focal_length_image_mm: e.nv * 1000.0 / power_d,
        image_sin_angle: e.sin_angle,
        image_numerical_aperture: e.nv * e.sin_angle,
        image_index: e.nv,
        image_point_mm: e.image,
        rays: e.rays,
        vignetted_rays: e.vignetted,
    }
}
