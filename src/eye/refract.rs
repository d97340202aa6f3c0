//! Objective refraction: the spectacle (or contact) lens that best corrects an eye, from its
//! traced wavefront.
//!
//! "Best" is the minimum-RMS criterion the rest of ocular uses: through the lens, the relaxed
//! eye looking at a distant object has no Zernike defocus and no second-order astigmatism over
//! the pupil. The first estimate carries the eye's power vector at its entrance pupil to the
//! spectacle plane meridian by meridian (F = K/(1 + dK), d from the lens to the entrance
//! pupil); then the lens is refined by measuring through it (the lens changes the entrance
//! pupil and how the eye's higher-order aberrations enter the second-order terms) until the
//! residual is below 1e-4 D.
//!
//! The IOL that leaves an eye emmetropic (`emmetropic_iol_power_d`) is the same question for a
//! lens inside the eye, so it lives here too, above the lens types of `correction` and the
//! measurement both.

use super::correction::{normalised_axis_deg, Iol, Spectacle, IOL_RANGE_D};
use super::error::EyeError;
use super::measure::{Measurer, Refraction};
use super::model::Eye;
use serde::Serialize;

/// A prescription at the spectacle plane, and how well it corrects.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct SpectacleRefraction {
    pub sphere_d: f64,
    /// ≤ 0 (minus-cylinder form).
    pub cylinder_d: f64,
    /// 1–180°.
    pub axis_deg: f64,
    pub vertex_mm: f64,
    pub pupil_mm: f64,
    pub wavelength_nm: f64,
    /// The uncorrected eye's refraction at its entrance pupil (power vector, D).
    pub eye_refraction: Refraction,
    pub eye_entrance_pupil_z_mm: f64,
    /// Length of the power vector (M, J0, J45) left through the lens (D).
    pub residual_d: f64,
    pub iterations: usize,
}

impl SpectacleRefraction {
    pub fn spectacle(&self) -> Result<Spectacle, EyeError> {
        Spectacle::new(
            self.sphere_d,
            self.cylinder_d,
            self.axis_deg,
            self.vertex_mm,
        )
    }
}

/// Sphere, minus cylinder and axis (1–180°) of a power vector.
pub fn power_vector_to_rx(m: f64, j0: f64, j45: f64) -> (f64, f64, f64) {
    let r = j0.hypot(j45);
    let cylinder = -2.0 * r;
    let axis = if r < 1e-12 {
        180.0
    } else {
        normalised_axis_deg(0.5 * j45.atan2(j0).to_degrees())
    };
    (m - cylinder / 2.0, cylinder, axis)
}

/// The power vector (M, J0, J45) of sphere, cylinder and axis (Thibos et al. 1997).
pub fn rx_to_power_vector(sphere_d: f64, cylinder_d: f64, axis_deg: f64) -> [f64; 3] {
    let a = 2.0 * axis_deg.to_radians();
    [
        sphere_d + cylinder_d / 2.0,
        -cylinder_d / 2.0 * a.cos(),
        -cylinder_d / 2.0 * a.sin(),
    ]
}

/// The wavelength (nm) a prescription is taken at unless one is given: the one the renderer
/// accommodates at, so that a lens written by `eye refract` and read by `--correct` focuses
/// the rendered image.
pub const REFRACTION_WAVELENGTH_NM: f64 = 549.0;

/// The refraction at the eye's entrance pupil, `pupil_behind_cornea_mm` behind the cornea,
/// that a spectacle prescription `vertex_mm` in front of the cornea corrects: the inverse of
/// [`refract`]'s first estimate. Each principal meridian's power F at the lens moves to
/// K = F/(1 − dF) at the pupil, d from the lens to the pupil. Sphere, minus cylinder, axis.
pub fn spectacle_to_pupil_rx(
    sphere_d: f64,
    cylinder_d: f64,
    axis_deg: f64,
    vertex_mm: f64,
    pupil_behind_cornea_mm: f64,
) -> Result<(f64, f64, f64), String> {
    let d_m = (vertex_mm + pupil_behind_cornea_mm) * 1e-3;
    let carry = |f: f64| -> Result<f64, String> {
        let denominator = 1.0 - d_m * f;
        // A meridian this strong focuses light before it reaches the eye.
        if denominator < 0.1 {
            return Err(format!(
                "a {f:+.2} D meridian {vertex_mm} mm in front of the cornea focuses light in                  front of the eye; no eye has that refraction"
            ));
        }
        Ok(f / denominator)
    };
    let (k1, k2) = (carry(sphere_d)?, carry(sphere_d + cylinder_d)?);
    let pv = rx_to_power_vector(k1, k2 - k1, axis_deg);
    Ok(power_vector_to_rx(pv[0], pv[1], pv[2]))
}

/// The spectacle prescription `vertex_mm` in front of the cornea whose principal meridians,
/// carried to the entrance pupil `pupil_behind_cornea_mm` behind the cornea, give the power
/// vector (M, J0, J45): each meridian's power K at the pupil is F = K/(1 + dK) at the lens, d
/// from the lens to the pupil (the inverse of [`spectacle_to_pupil_rx`]). Sphere, minus
/// cylinder, axis. Paraxial: [`refract`] refines it by tracing through the lens.
pub fn pupil_to_spectacle_rx(
    pupil_power_vector: [f64; 3],
    vertex_mm: f64,
    pupil_behind_cornea_mm: f64,
) -> (f64, f64, f64) {
    let d_m = (vertex_mm + pupil_behind_cornea_mm) * 1e-3;
    let [m, j0, j45] = pupil_power_vector;
    let (s, c, a) = power_vector_to_rx(m, j0, j45);
    let carry = |k: f64| k / (1.0 + d_m * k);
    let (s1, s2) = (carry(s), carry(s + c));
    let pv = rx_to_power_vector(s1, s2 - s1, a);
    power_vector_to_rx(pv[0], pv[1], pv[2])
}

fn measure_far(
    eye: &Eye,
    pupil_mm: f64,
    wavelength_nm: f64,
) -> Result<(Refraction, f64), EyeError> {
    let m = Measurer::standard().measure(&eye.system()?, wavelength_nm, pupil_mm, None)?;
    Ok((m.refraction, m.entrance_pupil_z_mm))
}

/// The lens at `vertex_mm` in front of the cornea that corrects `eye` (its own spectacle
/// removed; an IOL kept) for a distant object over a `pupil_mm` entrance pupil at
/// `wavelength_nm`.
pub fn refract(
    eye: &Eye,
    pupil_mm: f64,
    vertex_mm: f64,
    wavelength_nm: f64,
) -> Result<SpectacleRefraction, EyeError> {
    let mut bare = eye.clone();
    bare.correction = None;
    let (r0, ep_z) = measure_far(&bare, pupil_mm, wavelength_nm)?;
    let d_m = (vertex_mm + ep_z) * 1e-3;
    let (s1, c1, a1) = pupil_to_spectacle_rx([r0.m, r0.j0, r0.j45], vertex_mm, ep_z);
    let mut pv = rx_to_power_vector(s1, c1, a1);
    let mut corrected = bare.clone();
    let mut residual = f64::INFINITY;
    let mut iterations = 0;
    while iterations < 12 {
        let (s, c, a) = power_vector_to_rx(pv[0], pv[1], pv[2]);
        corrected.correction = Some(Spectacle::new(s, c, a, vertex_mm)?);
        let (r, _) = measure_far(&corrected, pupil_mm, wavelength_nm)?;
        iterations += 1;
        residual = (r.m * r.m + r.j0 * r.j0 + r.j45 * r.j45).sqrt();
        if residual < 1e-4 {
            break;
        }
        // A lens change dF moves the vergence at the pupil by dF/(1 − dF)².
        let gain = (1.0 - d_m * pv[0]).powi(2);
        pv[0] += r.m * gain;
        pv[1] += r.j0 * gain;
        pv[2] += r.j45 * gain;
    }
    let (sphere_d, cylinder_d, axis_deg) = power_vector_to_rx(pv[0], pv[1], pv[2]);
    Ok(SpectacleRefraction {
        sphere_d,
        cylinder_d,
        axis_deg,
        vertex_mm,
        pupil_mm,
        wavelength_nm,
        eye_refraction: r0,
        eye_entrance_pupil_z_mm: ep_z,
        residual_d: residual,
        iterations,
    })
}

/// The IOL power (D) that leaves `eye` (its cornea, axial length and IOL plane; any
/// spectacle removed) without Zernike defocus for a distant object over a `pupil_mm` pupil at
/// `wavelength_nm`: the traced counterpart of the thin-lens vergence formula (Fyodorov,
/// Binkhorst) with this eye's own effective lens position.
pub fn emmetropic_iol_power_d(
    eye: &Eye,
    pupil_mm: f64,
    wavelength_nm: f64,
) -> Result<f64, EyeError> {
    let mut bare = eye.clone();
    bare.correction = None;
    let meas = Measurer::new(4, 6, 16);
    let j20 = crate::optics::zernike::osa_index(2, 0);
    let mut buf = [0.0; 15];
    let mut c20 = |p: f64| -> Result<f64, EyeError> {
        bare.iol = Some(Iol { power_d: p });
        let sys = bare.system()?;
        meas.coefficients_um(&sys, wavelength_nm, pupil_mm, None, &mut buf)?;
        Ok(buf[j20])
    };
    let (mut p0, mut p1) = (20.0, 22.0);
    let (mut g0, mut g1) = (c20(p0)?, c20(p1)?);
    for _ in 0..40 {
        if g1.abs() < 1e-7 || g1 == g0 {
            break;
        }
        let p2 = (p1 - g1 * (p1 - p0) / (g1 - g0)).clamp(IOL_RANGE_D.0, IOL_RANGE_D.1);
        (p0, g0) = (p1, g1);
        p1 = p2;
        g1 = c20(p1)?;
    }
    if g1.abs() > 1e-4 {
        return Err(EyeError::Invalid(format!(
            "no IOL power within {} to {} D makes this eye emmetropic",
            IOL_RANGE_D.0, IOL_RANGE_D.1
        )));
    }
    Ok(p1)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn power_vectors_round_trip_through_minus_cylinder_form() {
        for (s, c, a) in [(-2.0, -1.5, 30.0), (1.0, -0.25, 180.0), (-6.0, 0.0, 180.0)] {
            let pv = rx_to_power_vector(s, c, a);
            let (s2, c2, a2) = power_vector_to_rx(pv[0], pv[1], pv[2]);
            assert!(
                (s - s2).abs() < 1e-12 && (c - c2).abs() < 1e-12,
                "{s} {c} {a}"
            );
            assert!((a - a2).abs() < 1e-9, "{a} vs {a2}");
        }
        // J0 = −(C/2)·cos 2A: a −1 D cylinder at 90° has J0 = −0.5 D.
        let pv = rx_to_power_vector(0.0, -1.0, 90.0);
        assert!((pv[1] + 0.5).abs() < 1e-12);
    }

    /// Power matrix of sphere S along axis A and S + C across it.
    fn power_matrix(s: f64, c: f64, a_deg: f64) -> [[f64; 2]; 2] {
        let (sa, ca) = a_deg.to_radians().sin_cos();
        // across the axis: the unit vector (−sin A, cos A)
        [
            [s + c * sa * sa, -c * sa * ca],
            [-c * sa * ca, s + c * ca * ca],
        ]
    }

    /// Against the far point: a meridian of power F at the lens images infinity 1/F in front
    /// of it, so at a pupil d behind the lens the vergence is 1/(1/F − d). For an oblique
    /// cylinder each principal meridian (an eigenvector of the power matrix) moves on its own,
    /// and the matrix rebuilt from the moved eigenvalues is the result's.
    #[test]
    fn spectacle_meridians_move_to_the_pupil_by_their_far_points() {
        let (vertex_mm, pupil_mm) = (12.0, 3.1);
        let d_m = (vertex_mm + pupil_mm) * 1e-3;
        for (s, c, a) in [
            (-6.0, 0.0, 180.0),
            (4.0, 0.0, 180.0),
            (-2.25, -1.5, 35.0),
            (2.5, -1.75, 135.0),
            (-3.0, -2.0, 60.0),
        ] {
            let (ks, kc, ka) = spectacle_to_pupil_rx(s, c, a, vertex_mm, pupil_mm).unwrap();
            let got = power_matrix(ks, kc, ka);
            let p = power_matrix(s, c, a);
            // eigen-decomposition of the symmetric 2×2 lens matrix
            let mean = 0.5 * (p[0][0] + p[1][1]);
            let half = (0.25 * (p[0][0] - p[1][1]).powi(2) + p[0][1] * p[0][1]).sqrt();
            let theta = 0.5 * (2.0 * p[0][1]).atan2(p[0][0] - p[1][1]);
            let (st, ct) = theta.sin_cos();
            let far = |f: f64| 1.0 / (1.0 / f - d_m);
            let (l1, l2) = (far(mean + half), far(mean - half));
            let want = [
                [l1 * ct * ct + l2 * st * st, (l1 - l2) * st * ct],
                [(l1 - l2) * st * ct, l1 * st * st + l2 * ct * ct],
            ];
            for i in 0..2 {
                for j in 0..2 {
                    assert!(
                        (got[i][j] - want[i][j]).abs() < 1e-9,
                        "{s} {c} x {a}: {got:?} vs {want:?}"
                    );
                }
            }
            // and back: refract's first estimate is the inverse
            let carry = |k: f64| k / (1.0 + d_m * k);
            let (b1, b2) = (carry(ks), carry(ks + kc));
            assert!((b1 - s).abs() < 1e-9 && (b2 - (s + c)).abs() < 1e-9);
        }
        // a 60 D meridian at 20 mm focuses 16.7 mm from the lens, before the pupil
        assert!(spectacle_to_pupil_rx(40.0, 20.0, 90.0, 16.0, 4.0).is_err());
    }
}
