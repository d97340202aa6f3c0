//! Exact kernels of a real eye for the ground-truth renderer: the PSF at any object vergence,
//! projected at its natural fractional size (no interpolation over distance or radius). It
//! shares the focused eye, its measurement and β with the grid ([`ColumnOptics`]).

use super::axes::{KernelSettings, Screen};
use super::defocus::ColumnOptics;
use super::project::cropped_psf;
use crate::eye::Eye;
use crate::Result;

/// A square kernel of side 2·radius + 1, row-major, row j ↔ screen offset dy = j − radius
/// (downwards), column i ↔ dx = i − radius; normalised to sum 1.
#[derive(Clone, Debug, PartialEq)]
pub struct Kernel {
    pub radius: u32,
    pub values: Vec<f32>,
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
        let ch = &self.column.channels[channel.min(2)];
        let psf = cropped_psf(ch, dioptre.max(0.0), &self.screen, &self.settings)?;
        let natural = psf.natural_radius_px();
        let r = natural.min(self.max_radius_px as f64);
        let radius = r.ceil() as u32;
        let values = psf
            .resample(radius, r + 0.5)
            .into_iter()
            .map(|v| v as f32)
            .collect();
        Ok((natural, Kernel { radius, values }))
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
            })
    }
}
