//! Paraxial (first-order) matrix trace in one meridian.
//!
//! Each surface enters with the normal curvature of its full sag (base, toricity and
//! elevation) along the meridian at its vertex; decentration and tilt are first-order
//! invisible on axis and are ignored here. Ray state is (height y, reduced angle w = n·u).

use super::system::OpticalSystem;

type M2 = [[f64; 2]; 2];

fn mul(a: M2, b: M2) -> M2 {
    [
        [
            a[0][0] * b[0][0] + a[0][1] * b[1][0],
            a[0][0] * b[0][1] + a[0][1] * b[1][1],
        ],
        [
            a[1][0] * b[0][0] + a[1][1] * b[1][0],
            a[1][0] * b[0][1] + a[1][1] * b[1][1],
        ],
    ]
}

fn transfer(t_mm: f64, n: f64) -> M2 {
    [[1.0, t_mm / n], [0.0, 1.0]]
}

fn refraction(power_per_mm: f64) -> M2 {
    [[1.0, 0.0], [-power_per_mm, 1.0]]
}

/// First-order properties of a system in one meridian at one wavelength.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Paraxial {
    pub wavelength_nm: f64,
    pub meridian_deg: f64,
    /// Equivalent power (D).
    pub power_d: f64,
    /// Image-side focal length n'/P (mm).
    pub focal_length_image_mm: f64,
    /// Last vertex to the paraxial focus (mm).
    pub back_focal_distance_mm: f64,
    /// Object vergence at the corneal vertex that is focused on the retina (D); negative for
    /// a myopic eye (its far point is real).
    pub refraction_d: f64,
    /// Entrance pupil: axial position (mm) and size per unit iris size.
    pub entrance_pupil_z_mm: f64,
    pub entrance_pupil_magnification: f64,
    /// Exit pupil: axial position (mm) and size per unit iris size.
    pub exit_pupil_z_mm: f64,
    pub exit_pupil_magnification: f64,
    pub image_index: f64,
}

/// Vertex curvature (1/mm) of surface `i` along the meridian at angle `phi` (rad), and the
/// sag offset at the vertex (elevation piston).
fn meridian_curvature(sys: &OpticalSystem, i: usize, phi: f64) -> (f64, f64) {
    let s = &sys.surfaces[i];
    let h = 1e-3;
    let (c, sn) = (phi.cos(), phi.sin());
    let z = |r: f64| s.sag(r * c, r * sn).map(|v| v.z).unwrap_or(0.0);
    let z0 = z(0.0);
    ((z(h) - 2.0 * z0 + z(-h)) / (h * h), z0)
}

/// Paraxial trace in the meridian at `meridian_deg` (0 = horizontal).
pub fn paraxial(sys: &OpticalSystem, wavelength_nm: f64, meridian_deg: f64) -> Paraxial {
    let n = sys.indices(wavelength_nm);
    let ns = sys.surfaces.len();
    let phi = meridian_deg.to_radians();
    let mut z = Vec::with_capacity(ns);
    let mut r = Vec::with_capacity(ns);
    for i in 0..ns {
        let (c, z0) = meridian_curvature(sys, i, phi);
        z.push(sys.surfaces[i].vertex_z_mm + z0);
        let ideal = sys.surfaces[i].phase_power_along(phi);
        r.push(refraction((n[i + 1] - n[i]) * c + ideal));
    }
    // Matrix from the reference plane just before surface `from` to just after surface `to`.
    let span = |from: usize, to: usize| -> M2 {
        let mut m = [[1.0, 0.0], [0.0, 1.0]];
        for i in from..=to {
            if i > from {
                m = mul(transfer(z[i] - z[i - 1], n[i]), m);
            }
            m = mul(r[i], m);
        }
        m
    };
    let sys_m = span(0, ns - 1);
    let nv = n[ns];
    let power = -sys_m[1][0];
    let bfd = -nv * sys_m[0][0] / sys_m[1][0];
    let to_retina = mul(transfer(sys.retina_z_mm - z[ns - 1], nv), sys_m);
    let refraction_d = 1000.0 * to_retina[0][0] / to_retina[0][1];
    // Entrance pupil: stop plane imaged back through the surfaces before it.
    let k = sys.stop_index;
    let mut front = span(0, k - 1);
    front = mul(transfer(sys.stop_z_mm - z[k - 1], n[k]), front);
    let ep_z = front[0][1] / front[0][0];
    let ep_mag = 1.0 / front[0][0];
    // Exit pupil: stop plane imaged forward through the rest.
    let mut back = span(k, ns - 1);
    back = mul(back, transfer(z[k] - sys.stop_z_mm, n[k]));
    let xp_z = z[ns - 1] - nv * back[0][1] / back[1][1];
    let xp_mag = 1.0 / back[1][1];
    Paraxial {
        wavelength_nm,
        meridian_deg,
        power_d: 1000.0 * power,
        focal_length_image_mm: nv / power,
        back_focal_distance_mm: bfd,
        refraction_d,
        entrance_pupil_z_mm: ep_z,
        entrance_pupil_magnification: ep_mag,
        exit_pupil_z_mm: xp_z,
        exit_pupil_magnification: xp_mag,
        image_index: nv,
    }
}
