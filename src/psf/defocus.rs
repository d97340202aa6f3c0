//! One (pupil, focus) state of an eye: accommodation, aberrations per wavelength, and the ENZ
//! defocus parameter of every object distance.
//!
//! # The defocus parameter
//! The eye is focused on the focus distance (at the accommodation wavelength) and measured at
//! each channel's wavelength with the object AT the focus distance: the measured c(2,0) is the
//! eye's own residual error at that wavelength (its refractive error where the lens cannot
//! compensate, and the chromatic focal shift), f_focus = 4√3·π·c(2,0)/λ.
//!
//! Moving the object changes only the wave that reaches the entrance pupil: a point at
//! distance L from the entrance-pupil plane sends a wave whose path to pupil radius r exceeds
//! the axial one by √(L² + r²) − L ≈ r²/(2L). Relative to the focus object (distance L_f) the
//! wavefront error W (positive where the wave leads) changes by
//!   ΔW(r) = r²/2 · (1/L_f − 1/L_o) = (R²/2)·ΔD·ρ²,  ΔD = V_f − V_o,  V = 1/L,
//! and the phase 2π·ΔW/λ = π·ΔD·R²/λ·ρ² is exactly the ENZ defocus term f·ρ². So
//!   f(object) = f_focus + π·(V_focus − V_object)·R²/λ
//! (R the entrance-pupil radius, λ in vacuum, vergences at the entrance pupil: an object at d
//! metres from the corneal vertex has V = 1/(d + e), e the entrance pupil's depth behind the
//! vertex). This is the object-space form of the seed paper's image-space focal shifts
//! (its Eq. 4–5); it needs no thin-lens model of the eye. Sign: an object FARTHER than the
//! focus (V_o < V_f) focuses in front of the retina, like a myopic eye, and gets f > 0 (the
//! sign of a positive, myopic c(2,0)); a nearer object gets f < 0. Neglected: the r⁴/(8L³)
//! part of the incoming wave and the change of the eye's higher-order aberrations with object
//! distance (both tiny beyond 10 cm); a test compares f with a direct measurement of the eye
//! at the object distance.

use super::axes::KernelSettings;
use super::field_shape::FieldShape;
use crate::eye::field::measure_field;
use crate::eye::{focus_within_range, Eye, FocusLimit};
use crate::optics::beta::beta_from_alpha;
use crate::optics::psf::{defocus_f_from_c20, Pupil};
use crate::optics::zernike::{order_for_len, wavefront_gradient};
use crate::{Error, Result};
use std::f64::consts::PI;

/// One wavelength of one (pupil, focus) state.
#[derive(Clone, Debug)]
pub struct ChannelOptics {
    pub wavelength_nm: f64,
    pub pupil_mm: f64,
    /// c(2,0) of the eye for an object at the focus distance (µm), and its f.
    pub residual_c20_um: f64,
    pub focus_f: f64,
    /// Vergence of the focus distance at the entrance pupil (1/m).
    pub focus_vergence: f64,
    /// Entrance pupil depth behind the corneal vertex (m).
    pub entrance_pupil_m: f64,
    /// Measured wavefront without piston, tilt and c(2,0) (OSA, µm).
    pub alpha_um: Vec<f64>,
    /// β of the residual wavefront (defocus and tilt excluded; f is added per object).
    pub pupil: Pupil,
    /// Ray displacement of the residual wavefront, ∇W/λ (λ/NA), at pupil points (x, y).
    slopes: Vec<([f64; 2], [f64; 2])>,
    /// Off axis: how the elliptical pupil maps onto the disc the wavefront is fitted over
    /// (see [`super::field_shape`]); `None` on axis.
    pub field: Option<FieldShape>,
}

impl ChannelOptics {
    /// From a measured wavefront (OSA, µm) over `pupil_mm`.
    pub fn from_wavefront(
        coefficients_um: &[f64],
        wavelength_nm: f64,
        pupil_mm: f64,
        focus_vergence: f64,
        entrance_pupil_m: f64,
        settings: &KernelSettings,
    ) -> ChannelOptics {
        let mut alpha_um = coefficients_um.to_vec();
        alpha_um.resize(alpha_um.len().max(15), 0.0);
        let residual_c20_um = alpha_um[4];
        for j in [0, 1, 2, 4] {
            alpha_um[j] = 0.0;
        }
        let t0 = std::time::Instant::now();
        let beta = beta_from_alpha(
            &alpha_um,
            wavelength_nm,
            pupil_mm,
            None,
            settings.beta_tolerance,
            settings.max_beta_degree,
        );
        let lam_um = wavelength_nm * 1e-3;
        let order = order_for_len(alpha_um.len());
        let slopes = ring_gradients(&alpha_um, 12 + 2 * order as usize)
            .map(|(p, (gx, gy))| (p, [gx / lam_um, gy / lam_um]))
            .collect();
        ChannelOptics {
            wavelength_nm,
            pupil_mm,
            residual_c20_um,
            focus_f: defocus_f_from_c20(residual_c20_um, wavelength_nm),
            focus_vergence,
            entrance_pupil_m,
            alpha_um,
            pupil: Pupil {
                beta,
                base_f: 0.0,
                tilt_shift: (0.0, 0.0),
                pupil_diameter_mm: pupil_mm,
                wavelength_nm,
                stiles_crawford: None,
                seconds: t0.elapsed().as_secs_f64(),
            },
            slopes,
            field: None,
        }
    }

    /// Vergence (1/m) at the entrance pupil of an object at `object_d` dioptres from the
    /// corneal vertex (0 = infinity).
    pub fn vergence_at_pupil(&self, object_d: f64) -> f64 {
        vergence_at_pupil(object_d, self.entrance_pupil_m)
    }

    /// ENZ defocus parameter for an object at `object_d` dioptres (see the module docs).
    /// Off axis this is the isotropic part over the stretched disc (the astigmatic part is
    /// added to each PSF's wavefront, see [`super::field_psf`]).
    pub fn defocus_f(&self, object_d: f64) -> f64 {
        let r = 0.5e-3 * self.pupil_mm;
        let delta = self.focus_vergence - self.vergence_at_pupil(object_d);
        let scale = self.field.as_ref().map_or(1.0, |s| s.mean_square());
        self.focus_f + PI * delta * r * r * scale / (self.wavelength_nm * 1e-9)
    }

    /// Geometric (ray) half-extent of the PSF at defocus f, in λ/NA: a pupil point ρ lands at
    /// −(∇W/λ + f·ρ/π), the stationary point of the ENZ integral.
    pub fn ray_extent(&self, f: f64) -> f64 {
        let k = f / PI;
        self.slopes
            .iter()
            .map(|(p, g)| {
                let x = g[0] + k * p[0];
                let y = g[1] + k * p[1];
                x.abs().max(y.abs())
            })
            .fold(0.0, f64::max)
    }

    /// Object-space angle (radians) of one λ/NA: 2λ/D.
    pub fn radians_per_lambda_na(&self) -> f64 {
        2.0 * self.wavelength_nm * 1e-9 / (self.pupil_mm * 1e-3)
    }
}

/// 1/(d + e) for an object d = 1/D metres in front of the vertex; 0 at infinity.
pub fn vergence_at_pupil(object_d: f64, entrance_pupil_m: f64) -> f64 {
    if object_d <= 0.0 {
        0.0
    } else {
        1.0 / (1.0 / object_d + entrance_pupil_m)
    }
}

/// An eye focused for one (pupil, focus) state, measured at the three wavelengths.
#[derive(Clone, Debug)]
pub struct ColumnOptics {
    /// The focused eye (the relaxed one where the focus lies beyond the far point).
    pub eye: Eye,
    pub pupil_mm: f64,
    pub focus_d: f64,
    pub lens_diameter_mm: f64,
    /// The focus lies beyond the eye's far point: the relaxed lens was kept.
    pub beyond_far_point: bool,
    /// Whether the focus was reached, or clamped at the far or the near point.
    pub focus_limit: FocusLimit,
    pub channels: [ChannelOptics; 3],
}

/// Distance in metres of a vergence in dioptres (`None` = infinity).
pub fn distance_of(focus_d: f64) -> Option<f64> {
    (focus_d > 0.0).then(|| 1.0 / focus_d)
}

impl ColumnOptics {
    /// Accommodates `eye` to `focus_d` at the accommodation wavelength for this pupil, then
    /// measures it at each wavelength with the object at the focus distance.
    pub fn new(
        eye: &Eye,
        pupil_mm: f64,
        focus_d: f64,
        wavelengths_nm: [f64; 3],
        settings: &KernelSettings,
    ) -> Result<ColumnOptics> {
        Self::new_in_field(eye, pupil_mm, focus_d, wavelengths_nm, settings, [0.0, 0.0])
    }

    /// As [`ColumnOptics::new`], measured for the field direction `field_deg` (degrees; the
    /// eye still accommodates on axis). Field (0, 0) is the on-axis column.
    pub fn new_in_field(
        eye: &Eye,
        pupil_mm: f64,
        focus_d: f64,
        wavelengths_nm: [f64; 3],
        settings: &KernelSettings,
        field_deg: [f64; 2],
    ) -> Result<ColumnOptics> {
        let distance = distance_of(focus_d);
        let f = focus_within_range(
            eye,
            distance,
            pupil_mm,
            settings.accommodation_nm,
            settings.far_point_limit,
        )
        .map_err(|e| {
            Error::input(format!(
                "cannot focus the eye at focus-d {focus_d} D with pupils-mm {pupil_mm}: {e}"
            ))
        })?;
        let (focused, focus_limit) = (f.eye, f.limit);
        let channels = measure_channels(
            &focused,
            pupil_mm,
            focus_d,
            wavelengths_nm,
            settings,
            field_deg,
        )?;
        Ok(ColumnOptics {
            eye: focused.clone(),
            pupil_mm,
            focus_d,
            lens_diameter_mm: focused.lens.diameter_mm,
            beyond_far_point: focus_limit == FocusLimit::FarPoint,
            focus_limit,
            channels,
        })
    }

    /// This column's focused eye measured for another field direction (no new accommodation:
    /// the eye focuses on axis whatever direction is measured).
    pub fn at_field(
        &self,
        wavelengths_nm: [f64; 3],
        settings: &KernelSettings,
        field_deg: [f64; 2],
    ) -> Result<ColumnOptics> {
        let channels = measure_channels(
            &self.eye,
            self.pupil_mm,
            self.focus_d,
            wavelengths_nm,
            settings,
            field_deg,
        )?;
        Ok(ColumnOptics {
            channels,
            ..self.clone()
        })
    }
}

/// The focused eye measured at each wavelength for `field_deg`, the object at the focus.
fn measure_channels(
    focused: &Eye,
    pupil_mm: f64,
    focus_d: f64,
    wavelengths_nm: [f64; 3],
    settings: &KernelSettings,
    field_deg: [f64; 2],
) -> Result<[ChannelOptics; 3]> {
    let distance = distance_of(focus_d);
    let sys = focused.system()?;
    let mut channels = Vec::with_capacity(3);
    for wavelength_nm in wavelengths_nm {
        let fm = measure_field(
            &sys,
            wavelength_nm,
            pupil_mm,
            distance,
            field_deg,
            settings.zernike_order,
        )
        .map_err(|e| {
            Error::input(format!(
                "cannot measure the eye at pupils-mm {pupil_mm}, {wavelength_nm} nm, \
                 focus-d {focus_d} D, field {field_deg:?}°: {e}"
            ))
        })?;
        let m = &fm.measurement;
        let e = m.entrance_pupil_z_mm * 1e-3;
        let mut ch = ChannelOptics::from_wavefront(
            &m.coefficients_um,
            wavelength_nm,
            pupil_mm,
            vergence_at_pupil(focus_d, e),
            e,
            settings,
        );
        if field_deg != [0.0, 0.0] {
            ch.field = Some(FieldShape::from_pupil(&fm.field, pupil_mm));
        }
        channels.push(ch);
    }
    Ok(channels.try_into().expect("three channels"))
}

/// The wavefront's gradient at points of the unit pupil on `rings` evenly spaced rings of
/// 8 + 4·ring spokes each (ring by ring, spoke by spoke): where slopes and ray extents are
/// sampled.
pub(super) fn ring_gradients(
    alpha_um: &[f64],
    rings: usize,
) -> impl Iterator<Item = ([f64; 2], (f64, f64))> + '_ {
    (1..=rings).flat_map(move |ring| {
        let rho = ring as f64 / rings as f64;
        let spokes = 8 + 4 * ring;
        (0..spokes).map(move |k| {
            let th = 2.0 * PI * k as f64 / spokes as f64;
            let (x, y) = (rho * th.cos(), rho * th.sin());
            ([x, y], wavefront_gradient(alpha_um, x, y))
        })
    })
}
