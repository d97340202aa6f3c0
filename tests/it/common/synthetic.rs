//! A synthetic, analytic "eye" for testing the runtime independently of the optics: per
//! channel, the blur radius grows linearly with the dioptre distance from that channel's
//! focus, and the kernel shape is a soft disc whose asymmetry varies smoothly with dioptres
//! (so that orientation mistakes and interpolation over distance both show).

use ocular::psf::{
    level_block_radius, level_count, level_radius_px, DioptreAxis, KernelGrid, KernelSet,
};
use ocular::render::reference::{ExactKernels, Kernel};
use ocular::render::splat::MergeSettings;

/// No merge levels: every pixel is splatted at full resolution, as the exact reference sums.
pub const NO_MERGE: MergeSettings = MergeSettings {
    levels: 0,
    blur_per_block: 0.0,
    min_radius_px: 5.0,
    color_error: MergeSettings::DEFAULT_COLOR_ERROR,
    white: 1.0,
    dioptre_tolerance: 0.01,
    scale_error_px: MergeSettings::DEFAULT_SCALE_ERROR_PX,
};

#[derive(Clone, Debug)]
pub struct SyntheticEye {
    /// Dioptres at which each channel is sharpest (a chromatic focus shift).
    pub focus_d: [f64; 3],
    /// Blur radius growth in pixels per dioptre.
    pub px_per_d: f64,
    /// Radius at best focus (0 = a perfect point).
    pub floor_px: f64,
    /// Extra scale per grid pupil (pupil_mm / 4): bigger pupils blur more.
    pub pupil_scale: bool,
}

impl SyntheticEye {
    pub fn new(focus_d: f64, px_per_d: f64) -> Self {
        SyntheticEye {
            focus_d: [focus_d - 0.15, focus_d, focus_d + 0.25],
            px_per_d,
            floor_px: 0.0,
            pupil_scale: false,
        }
    }

    pub fn radius_px(&self, channel: usize, dioptre: f64, pupil_mm: f64) -> f64 {
        let scale = if self.pupil_scale {
            pupil_mm / 4.0
        } else {
            1.0
        };
        self.floor_px + scale * self.px_per_d * (dioptre - self.focus_d[channel]).abs()
    }

    /// Unnormalised profile at normalised offset (x, y) ∈ [−1, 1]², support half-width 1.
    fn profile(&self, channel: usize, dioptre: f64, x: f64, y: f64) -> f64 {
        let rho2 = x * x + y * y;
        if rho2 >= 1.0 {
            return 0.0;
        }
        let s = (1.7 * dioptre + channel as f64).sin();
        (1.0 - rho2).powf(0.6) * (1.0 + 0.35 * s * x + 0.2 * s * y)
    }

    /// Area-weighted kernel of the given integer radius whose profile support has half-width
    /// `half_width_px` (the kernel's own half side is radius + 0.5).
    pub fn kernel_values(
        &self,
        channel: usize,
        dioptre: f64,
        half_width_px: f64,
        radius: u32,
    ) -> Vec<f32> {
        let side = 2 * radius as usize + 1;
        if radius == 0 || half_width_px <= 0.5 {
            let mut v = vec![0.0; side * side];
            v[side * side / 2] = 1.0;
            return v;
        }
        const SUB: usize = 6;
        let mut values = vec![0.0f64; side * side];
        for j in 0..side {
            for i in 0..side {
                let mut sum = 0.0;
                for sj in 0..SUB {
                    for si in 0..SUB {
                        let dx = i as f64 - radius as f64 - 0.5 + (si as f64 + 0.5) / SUB as f64;
                        let dy = j as f64 - radius as f64 - 0.5 + (sj as f64 + 0.5) / SUB as f64;
                        sum +=
                            self.profile(channel, dioptre, dx / half_width_px, dy / half_width_px);
                    }
                }
                values[j * side + i] = sum;
            }
        }
        let total: f64 = values.iter().sum();
        values.iter().map(|v| (v / total) as f32).collect()
    }

    /// One kernel set for a (pupil, focus) state: every object distance at every radius.
    pub fn kernel_set(&self, objects: DioptreAxis, max_radius: u32, pupil_mm: f64) -> KernelSet {
        let mut set = KernelSet::zeroed(pupil_mm, self.focus_d[1], objects, max_radius);
        for o in 0..objects.count {
            let d = objects.value_d(o);
            for c in 0..3 {
                set.radius_px[o][c] = self.radius_px(c, d, pupil_mm).min(max_radius as f64) as f32;
            }
            for level in 0..level_count(max_radius) {
                let (half_width, r) = (level_radius_px(level) + 0.5, level_block_radius(level));
                let per_channel: Vec<Vec<f32>> = (0..3)
                    .map(|c| self.kernel_values(c, d, half_width, r))
                    .collect();
                for (t, texel) in set.kernel_mut(level, o).iter_mut().enumerate() {
                    *texel = [per_channel[0][t], per_channel[1][t], per_channel[2][t]];
                }
            }
        }
        set
    }

    /// A grid with one set per pupil (single focus state).
    pub fn grid(
        &self,
        objects: DioptreAxis,
        max_radius: u32,
        pupils_mm: &[f64],
        height_px: u32,
    ) -> KernelGrid {
        KernelGrid {
            pupils_mm: pupils_mm.to_vec(),
            focus_d: vec![self.focus_d[1]],
            wavelengths_nm: [612.0, 549.0, 464.0],
            objects,
            max_radius_px: max_radius,
            fov_y_deg: 60.0,
            height_px,
            sets: pupils_mm
                .iter()
                .map(|&p| self.kernel_set(objects, max_radius, p))
                .collect(),
        }
    }
}

/// Exact kernels at the true (fractional) radius, for the ground truth.
pub struct ExactSynthetic {
    pub eye: SyntheticEye,
    pub pupil_mm: f64,
    pub max_radius: u32,
}

impl ExactKernels for ExactSynthetic {
    fn kernel(&self, channel: usize, dioptre: f64) -> Kernel {
        let r = self
            .eye
            .radius_px(channel, dioptre, self.pupil_mm)
            .min(self.max_radius as f64);
        let radius = r.ceil() as u32;
        Kernel {
            radius,
            values: self.eye.kernel_values(channel, dioptre, r + 0.5, radius),
            radius_px: r,
        }
    }
}
