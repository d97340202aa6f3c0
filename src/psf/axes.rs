//! The grid's parameter axes and the numerical settings of the kernel precomputation.

use super::kernels::DioptreAxis;
use serde::{Deserialize, Serialize};

/// Default R, G, B wavelengths (nm).
pub const DEFAULT_WAVELENGTHS_NM: [f64; 3] = [612.0, 549.0, 464.0];

/// Where the grid samples (pupil, focus, object distance, wavelength).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct GridAxes {
    /// Object vergences (D, from the corneal vertex): uniform, as the runtime indexes them.
    pub objects: DioptreAxis,
    /// Focus states in dioptres (0 = infinity), strictly increasing.
    pub focus_d: Vec<f64>,
    /// Entrance-pupil diameters (mm), strictly increasing.
    pub pupils_mm: Vec<f64>,
    /// R, G, B.
    pub wavelengths_nm: [f64; 3],
}

impl Default for GridAxes {
    /// 161 objects over 0–10 D in steps of 1/16 D (a sample at infinity, 0 D), 5 focus states
    /// over 0.125–10.125 D, 4 pupils linear in 2–7 mm, 612 / 549 / 464 nm. (The seed paper
    /// sampled objects every 0.25 D from 0.125 D: near each channel's focus the PSF's shape
    /// changes faster than that, and the runtime's linear blend between two object samples left
    /// small blur up to 30 dB from the wave-optics truth; see docs/validation-common-cases.md,
    /// case 7.)
    fn default() -> Self {
        GridAxes {
            objects: DioptreAxis::spanning(0.0, 10.0, 161),
            focus_d: linspace(0.125, 10.125, 5),
            pupils_mm: linspace(2.0, 7.0, 4),
            wavelengths_nm: DEFAULT_WAVELENGTHS_NM,
        }
    }
}

/// `count` values from `lo` to `hi` inclusive.
pub fn linspace(lo: f64, hi: f64, count: usize) -> Vec<f64> {
    match count {
        0 => Vec::new(),
        1 => vec![lo],
        _ => (0..count)
            .map(|i| lo + (hi - lo) * i as f64 / (count - 1) as f64)
            .collect(),
    }
}

impl GridAxes {
    pub fn psf_count(&self) -> usize {
        self.objects.count * self.focus_d.len() * self.pupils_mm.len() * 3
    }

    /// The (pupil mm, focus D) of every column of the grid, pupil-major.
    pub fn column_states(&self) -> Vec<(f64, f64)> {
        self.pupils_mm
            .iter()
            .flat_map(|&p| self.focus_d.iter().map(move |&f| (p, f)))
            .collect()
    }

    /// Checks ranges; the message names the axis and what is allowed.
    pub fn validate(&self) -> Result<(), String> {
        let o = &self.objects;
        if o.count == 0 || o.count > 1024 {
            return Err(format!("objects: {} samples; allowed 1 to 1024", o.count));
        }
        if !(o.min_d.is_finite() && o.step_d.is_finite() && o.step_d > 0.0) {
            return Err("objects: minimum and step must be finite, step > 0".into());
        }
        if o.min_d < 0.0 || o.max_d() > 50.0 {
            return Err(format!(
                "objects: {}..{} D is outside 0 to 50 D (nearer than 2 cm)",
                o.min_d,
                o.max_d()
            ));
        }
        check_axis("focus-d", &self.focus_d, 0.0, 50.0, "0 to 50 D")?;
        let pupils = crate::limits::PUPIL_MM;
        check_axis(
            "pupils-mm",
            &self.pupils_mm,
            pupils.min,
            pupils.max,
            &pupils.allowed(),
        )?;
        for w in self.wavelengths_nm {
            crate::limits::WAVELENGTH_NM.check("wavelengths-nm:", w)?;
        }
        Ok(())
    }
}

fn check_axis(name: &str, v: &[f64], lo: f64, hi: f64, allowed: &str) -> Result<(), String> {
    if v.is_empty() || v.len() > 64 {
        return Err(format!("{name}: 1 to 64 values are required"));
    }
    if let Some(bad) = v
        .iter()
        .find(|x| !(x.is_finite() && **x >= lo && **x <= hi))
    {
        return Err(format!("{name}: {bad} is outside {allowed}"));
    }
    if v.windows(2).any(|w| w[1] <= w[0]) {
        return Err(format!("{name}: values must be strictly increasing"));
    }
    Ok(())
}

/// The output the kernels are projected for.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Screen {
    pub fov_y_deg: f64,
    pub height_px: u32,
}

impl Default for Screen {
    fn default() -> Self {
        Screen {
            fov_y_deg: 60.0,
            height_px: 720,
        }
    }
}

impl Screen {
    /// Pixels per radian of visual angle at the image centre of a pinhole projection:
    /// (H/2)/tan(fov_y/2). (The seed paper's linear H/fov_y is 10 % larger at 60°; the centre
    /// is where the viewer looks, so its scale is the one that must be right.)
    pub fn px_per_radian(&self) -> f64 {
        0.5 * self.height_px as f64 / (0.5 * self.fov_y_deg.to_radians()).tan()
    }

    pub fn validate(&self) -> Result<(), String> {
        crate::limits::FOV_Y_DEG.check("fov-y:", self.fov_y_deg)?;
        if !(16..=16384).contains(&self.height_px) {
            return Err(format!(
                "height: {} px is outside 16 to 16384",
                self.height_px
            ));
        }
        Ok(())
    }
}

/// Which method computes the PSFs of the kernels.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum MethodChoice {
    /// Per PSF, the cheaper of the two where the β expansion meets its tolerance, else FFT.
    #[default]
    Auto,
    /// Always the ENZ series (whatever the β truncation; for tests and comparisons).
    Enz,
    /// Always the transform of the sampled pupil function.
    Fft,
}

/// Numerical settings of the precomputation.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct KernelSettings {
    /// PSF sample size on the retina (µm) and retinal scale (µm per degree): together an
    /// angular pitch of sample_um / um_per_deg degrees (the seed paper's 4 µm, 288 µm/deg).
    pub sample_um: f64,
    pub um_per_deg: f64,
    /// Samples per 2π of defocus: the pitch is at most 4/N λ/NA, so a PSF whose defocus is
    /// f spans at least N·|f|/2π samples across. (The seed paper sizes its grid as
    /// ⌈|f|/2π⌉·N samples of µ_s with N = 4; here the grid size follows the PSF's ray extent
    /// instead, and N only caps the pitch: with the default 2 the µ_s pitch is always finer.)
    pub samples_per_2pi: f64,
    /// At least this many PSF samples per output pixel (kernels are never upsampled from a
    /// grid coarser than the screen).
    pub samples_per_pixel: f64,
    /// At least this many PSF samples per λ/NA while the grid stays within
    /// [`super::project::MAX_PSF_SIDE`] and a pixel holds at most
    /// [`super::project::MAX_SAMPLES_PER_PIXEL`] samples: the intensity holds spatial
    /// frequencies up to 2 per λ/NA, and the cubic interpolant integrated over each pixel needs
    /// about four samples per period of the highest one.
    pub samples_per_lambda_na: f64,
    /// How each PSF is computed (see [`MethodChoice`]).
    pub method: MethodChoice,
    /// Fraction of the computed PSF's energy the cropped square keeps.
    pub energy: f64,
    /// Room around the geometric (ray) extent of the PSF for diffraction, in λ/NA.
    pub diffraction_margin: f64,
    /// Largest kernel radius (px); natural radii beyond it are clamped.
    pub max_radius_cap: u32,
    /// Wavelength at which the eye accommodates: the luminance-weighted middle of the
    /// spectrum, where the accommodation system puts its best focus.
    pub accommodation_nm: f64,
    /// The eye as given is fully relaxed: focusing farther than its far point is impossible,
    /// so such a focus keeps the relaxed lens (a myopic eye stays blurred at distance).
    pub far_point_limit: bool,
    /// Zernike order of the aberration measurement.
    pub zernike_order: u32,
    /// Pupil energy the β expansion may miss, and its degree cap: a channel whose expansion
    /// does not meet the tolerance below the cap has its PSFs computed by FFT instead.
    pub beta_tolerance: f64,
    pub max_beta_degree: u32,
    /// Relative accuracy of the ENZ radial tables.
    pub radial_tolerance: f64,
    /// Largest L1 distance (fraction of a kernel's energy misplaced) between a kernel and the
    /// one interpolated from the computed object samples around it: PSFs are computed where
    /// the object axis needs them (dense near each channel's focus, sparse far from it) and
    /// the samples between are filled by the runtime's own linear blend
    /// ([`super::object_knots`]). 0 computes every sample.
    #[serde(default = "default_object_tolerance")]
    pub object_tolerance: f64,
}

fn default_object_tolerance() -> f64 {
    super::object_knots::DEFAULT_OBJECT_TOLERANCE
}

impl Default for KernelSettings {
    fn default() -> Self {
        KernelSettings {
            sample_um: 4.0,
            um_per_deg: 288.0,
            samples_per_2pi: 2.0,
            samples_per_pixel: 4.0,
            samples_per_lambda_na: 8.0,
            method: MethodChoice::Auto,
            energy: 0.999,
            diffraction_margin: 4.0,
            max_radius_cap: 64,
            accommodation_nm: 549.0,
            far_point_limit: true,
            zernike_order: 6,
            beta_tolerance: 1e-4,
            max_beta_degree: 120,
            radial_tolerance: 1e-5,
            object_tolerance: default_object_tolerance(),
        }
    }
}

impl KernelSettings {
    pub fn validate(&self) -> Result<(), String> {
        let checks: [(&str, f64, f64, f64); 12] = [
            ("sample_um", self.sample_um, 0.05, 100.0),
            ("um_per_deg", self.um_per_deg, 100.0, 500.0),
            ("samples_per_2pi", self.samples_per_2pi, 1.0, 64.0),
            ("samples_per_pixel", self.samples_per_pixel, 1.0, 16.0),
            (
                "samples_per_lambda_na",
                self.samples_per_lambda_na,
                0.5,
                64.0,
            ),
            ("energy", self.energy, 0.5, 0.999999),
            ("diffraction_margin", self.diffraction_margin, 0.0, 100.0),
            ("accommodation_nm", self.accommodation_nm, 380.0, 800.0),
            ("beta_tolerance", self.beta_tolerance, 1e-12, 0.1),
            ("radial_tolerance", self.radial_tolerance, 1e-12, 1e-2),
            ("max_radius_cap", self.max_radius_cap as f64, 0.0, 512.0),
            ("object_tolerance", self.object_tolerance, 0.0, 0.5),
        ];
        for (name, v, lo, hi) in checks {
            if !(v.is_finite() && v >= lo && v <= hi) {
                return Err(format!("{name}: {v} is outside {lo} to {hi}"));
            }
        }
        if !(2..=10).contains(&self.zernike_order) {
            return Err(format!(
                "zernike_order: {} is outside 2 to 10",
                self.zernike_order
            ));
        }
        if !(4..=160).contains(&self.max_beta_degree) {
            return Err(format!(
                "max_beta_degree: {} is outside 4 to 160",
                self.max_beta_degree
            ));
        }
        Ok(())
    }
}
