//! Exact kernels of a real eye for the ground-truth renderer: the PSF at any object vergence,
//! projected at its natural fractional size (no interpolation over distance or radius). It
//! shares the focused eye, its measurement and β with the grid ([`ColumnOptics`]).

use super::axes::{KernelSettings, Screen};
use super::defocus::ColumnOptics;
use super::field_psf::cropped_psf;
use crate::eye::Eye;
use crate::Result;
use std::collections::HashMap;
use std::sync::{Arc, Mutex};

/// A square kernel of side 2·radius + 1, row-major, row j ↔ screen offset dy = j − radius
/// (downwards), column i ↔ dx = i − radius; normalised to sum 1.
#[derive(Clone, Debug, PartialEq)]
pub struct Kernel {
    pub radius: u32,
    pub values: Vec<f32>,
    /// The blur radius (px, clamped like the runtime's) the block was drawn for: what decides
    /// how much of the pinhole's local scale applies ([`crate::render::projection::LocalScale`]).
    pub radius_px: f64,
}

impl Kernel {
    pub fn side(&self) -> usize {
        2 * self.radius as usize + 1
    }

    /// Weight at offset (dx, dy) from the centre; zero outside.
    pub fn at(&self, dx: i64, dy: i64) -> f32 {
        let r = self.radius as i64;
        if dx.abs() > r || dy.abs() > r {
            return 0.0;
        }
        self.values[((dy + r) * (2 * r + 1) + dx + r) as usize]
    }

    /// Bilinear interpolation between texels at a fractional offset (zero outside), as a
    /// texture with linear filtering and a zero border samples it.
    pub fn sample(&self, dx: f64, dy: f64) -> f32 {
        let (x0, y0) = (dx.floor(), dy.floor());
        let (tx, ty) = ((dx - x0) as f32, (dy - y0) as f32);
        let (x0, y0) = (x0 as i64, y0 as i64);
        (1.0 - ty) * ((1.0 - tx) * self.at(x0, y0) + tx * self.at(x0 + 1, y0))
            + ty * ((1.0 - tx) * self.at(x0, y0 + 1) + tx * self.at(x0 + 1, y0 + 1))
    }
}

/// The exact kernel for a channel (0 = R, 1 = G, 2 = B) at an object vergence in dioptres, for
/// the frame's pupil, focus, resolution and field of view.
pub trait ExactKernels: Sync {
    fn kernel(&self, channel: usize, dioptre: f64) -> Kernel;

    /// The kernel for the field direction `field_deg` (degrees); on-axis sources ignore it.
    fn kernel_in_field(&self, channel: usize, dioptre: f64, _field_deg: [f64; 2]) -> Kernel {
        self.kernel(channel, dioptre)
    }

    /// The field step (degrees) of this source's directions; None: one PSF for every direction.
    fn field_step_deg(&self) -> Option<f64> {
        None
    }

    /// Readies the directions of these field bins (multiples of the field step) before their
    /// kernels are asked for, in parallel, each once.
    fn prepare_field_bins(&self, _bins: &[(i64, i64)]) {}
}

/// One (pupil, focus) state of an eye, projected for one screen.
#[derive(Clone, Debug)]
pub struct ExactEye {
    pub column: ColumnOptics,
    pub screen: Screen,
    pub settings: KernelSettings,
    /// Radii are clamped here, like the grid's (pass the grid's `max_radius_px`).
    pub max_radius_px: u32,
}

impl ExactEye {
    /// Focuses and measures `eye` (the same steps as the grid).
    pub fn new(
        eye: &Eye,
        pupil_mm: f64,
        focus_d: f64,
        wavelengths_nm: [f64; 3],
        screen: Screen,
        settings: KernelSettings,
        max_radius_px: u32,
    ) -> Result<ExactEye> {
        settings.validate().map_err(crate::Error::input)?;
        screen.validate().map_err(crate::Error::input)?;
        let column = ColumnOptics::new(eye, pupil_mm, focus_d, wavelengths_nm, &settings)?;
        Ok(ExactEye {
            column,
            screen,
            settings,
            max_radius_px,
        })
    }

    /// Natural radius (px, unclamped) and kernel for a channel at an object vergence.
    pub fn kernel_checked(&self, channel: usize, dioptre: f64) -> Result<(f64, Kernel)> {
        self.kernel_of(&self.column, channel, dioptre)
    }

    fn kernel_of(
        &self,
        column: &ColumnOptics,
        channel: usize,
        dioptre: f64,
    ) -> Result<(f64, Kernel)> {
        let ch = &column.channels[channel.min(2)];
        let psf = cropped_psf(ch, dioptre.max(0.0), &self.screen, &self.settings)?;
        let natural = psf.natural_radius_px();
        let r = natural.min(self.max_radius_px as f64);
        let radius = r.ceil() as u32;
        let values = psf
            .resample(radius, r + 0.5)
            .into_iter()
            .map(|v| v as f32)
            .collect();
        Ok((
            natural,
            Kernel {
                radius,
                values,
                radius_px: r,
            },
        ))
    }
}

/// Off axis: the exact kernel of the eye traced for the direction of each field bin of
/// `step_deg` (no interpolation over the field, no lattice): the ground truth of the
/// off-axis runtime. Directions beyond the traced field take its edge along the same ray
/// from the centre, as the runtime's lattice does.
pub struct ExactFieldEye {
    pub on_axis: ExactEye,
    pub step_deg: f64,
    wavelengths_nm: [f64; 3],
    columns: Mutex<HashMap<(i64, i64), Arc<ColumnOptics>>>,
}

impl ExactFieldEye {
    pub fn new(on_axis: ExactEye, wavelengths_nm: [f64; 3], step_deg: f64) -> Result<Self> {
        if !(step_deg.is_finite() && step_deg > 0.0) {
            return Err(crate::Error::input(format!(
                "field step {step_deg}° must be positive"
            )));
        }
        Ok(ExactFieldEye {
            on_axis,
            step_deg,
            wavelengths_nm,
            columns: Mutex::new(HashMap::new()),
        })
    }

    fn column(&self, bin: (i64, i64)) -> Result<Arc<ColumnOptics>> {
        if let Some(c) = self.columns.lock().expect("not poisoned").get(&bin) {
            return Ok(c.clone());
        }
        let field =
            within_traced_field([bin.0 as f64 * self.step_deg, bin.1 as f64 * self.step_deg]);
        let c = Arc::new(self.on_axis.column.at_field(
            self.wavelengths_nm,
            &self.on_axis.settings,
            field,
        )?);
        self.columns
            .lock()
            .expect("not poisoned")
            .insert(bin, c.clone());
        Ok(c)
    }

    fn bin(&self, field_deg: [f64; 2]) -> (i64, i64) {
        (
            (field_deg[0] / self.step_deg).round() as i64,
            (field_deg[1] / self.step_deg).round() as i64,
        )
    }
}

/// `field_deg`, or where the ray from the axis through it leaves the traced field (as the
/// runtime's lattice stops there).
pub fn within_traced_field(field_deg: [f64; 2]) -> [f64; 2] {
    if crate::eye::field::check_field_deg(field_deg).is_ok() {
        return field_deg;
    }
    crate::eye::field::shrink_into_traced_field(field_deg)
}

impl ExactKernels for ExactFieldEye {
    fn kernel(&self, channel: usize, dioptre: f64) -> Kernel {
        self.kernel_in_field(channel, dioptre, [0.0, 0.0])
    }

    fn kernel_in_field(&self, channel: usize, dioptre: f64, field_deg: [f64; 2]) -> Kernel {
        self.column(self.bin(field_deg))
            .and_then(|c| self.on_axis.kernel_of(&c, channel, dioptre))
            .map(|(_, k)| k)
            .unwrap_or_else(|_| Kernel {
                radius: 0,
                values: vec![1.0],
                radius_px: 0.0,
            })
    }

    fn field_step_deg(&self) -> Option<f64> {
        Some(self.step_deg)
    }

    fn prepare_field_bins(&self, bins: &[(i64, i64)]) {
        use rayon::prelude::*;
        // a failure shows up again, and is handled, when the bin's kernel is asked for
        bins.par_iter().for_each(|&b| {
            let _ = self.column(b);
        });
    }
}

impl ExactKernels for ExactEye {
    fn kernel(&self, channel: usize, dioptre: f64) -> Kernel {
        // The inputs were validated when the eye was built; a failure here (a defocus beyond
        // the ENZ engine's range) can only come from an absurd vergence: show it as a point.
        self.kernel_checked(channel, dioptre)
            .map(|(_, k)| k)
            .unwrap_or_else(|_| Kernel {
                radius: 0,
                values: vec![1.0],
                radius_px: 0.0,
            })
    }
}
