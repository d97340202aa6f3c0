//! HDR-FLIP (Andersson et al. 2021): an HDR pair is judged as a viewer would see it across the
//! exposures a tone-mapped display could show. Each exposure 2^c scales both images, a tone
//! mapper brings them to [0, 1] and LDR-FLIP compares them; the map keeps each pixel's largest
//! error. The automatic range starts where the reference's brightest pixel and stops where its
//! median pixel reaches 0.85 after tone mapping, one exposure per stop (at least two).

use super::plane::Plane;
use crate::metrics::ImageView;

/// The tone curve of each exposure.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "lowercase")]
pub enum ToneMapper {
    /// Narkowicz's fit of the ACES filmic curve with its 0.6 pre-exposure removed (FLIP's
    /// default).
    Aces,
    /// Hable's filmic curve as a rational fit.
    Hable,
    /// Reinhard's L / (1 + L) on luminance, hue kept.
    Reinhard,
}

impl ToneMapper {
    /// (a, b, c, d, e, f) of the curve (a x² + b x + c) / (d x² + e x + f) per channel; for
    /// Reinhard, the curve its luminance follows.
    fn rational(self) -> [f64; 6] {
        match self {
            ToneMapper::Aces => [
                0.6 * 0.6 * 2.51,
                0.6 * 0.03,
                0.0,
                0.6 * 0.6 * 2.43,
                0.6 * 0.59,
                0.14,
            ],
            ToneMapper::Hable => [0.231683, 0.013791, 0.0, 0.18, 0.3, 0.018],
            ToneMapper::Reinhard => [0.0, 1.0, 0.0, 0.0, 1.0, 1.0],
        }
    }

    pub fn apply(self, rgb: [f64; 3]) -> [f64; 3] {
        match self {
            ToneMapper::Reinhard => {
                let y = relative_luminance(rgb);
                rgb.map(|c| c / (1.0 + y))
            }
            _ => {
                let [a, b, c, d, e, f] = self.rational();
                rgb.map(|x| (a * x * x + b * x + c) / (d * x * x + e * x + f))
            }
        }
    }

    /// The input value the curve maps to `target`: the larger root of
    /// (a − t d) x² + (b − t e) x + (c − t f) = 0.
    pub fn input_for(self, target: f64) -> f64 {
        let [a, b, c, d, e, f] = self.rational();
        let (qa, qb, qc) = (a - target * d, b - target * e, c - target * f);
        if qa == 0.0 {
            return -qc / qb;
        }
        let mid = -0.5 * qb / qa;
        mid + (mid * mid - qc / qa).sqrt()
    }
}

/// Luminance of linear sRGB (Rec. 709 weights).
fn relative_luminance(rgb: [f64; 3]) -> f64 {
    0.2126 * rgb[0] + 0.7152 * rgb[1] + 0.0722 * rgb[2]
}

/// Exposures c (the images are multiplied by 2^c), evenly spaced from start to stop.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct ExposureRange {
    pub start: f64,
    pub stop: f64,
    pub count: usize,
}

impl ExposureRange {
    pub fn exposures(&self) -> Vec<f64> {
        if self.count == 1 {
            return vec![self.start];
        }
        let step = (self.stop - self.start) / (self.count - 1) as f64;
        (0..self.count)
            .map(|i| self.start + i as f64 * step)
            .collect()
    }
}

/// The tone-mapped value the automatic range aims the brightest and the median pixel at.
pub const TARGET: f64 = 0.85;

/// HDR-FLIP's settings: the tone mapper and, where given, the range (else automatic).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct HdrSettings {
    pub tone_mapper: ToneMapper,
    pub start: Option<f64>,
    pub stop: Option<f64>,
    pub count: Option<usize>,
}

impl Default for HdrSettings {
    fn default() -> Self {
        HdrSettings {
            tone_mapper: ToneMapper::Aces,
            start: None,
            stop: None,
            count: None,
        }
    }
}

/// The automatic start and stop exposures of a reference image: log2(x / Y_max) and
/// log2(x / Y_median), x being the value the tone mapper takes to 0.85 and Y the luminance;
/// the median of an even count is the upper middle value. None for a reference whose median
/// luminance is not positive (no finite stop).
pub fn automatic_range(reference: ImageView<'_>, tone_mapper: ToneMapper) -> Option<(f64, f64)> {
    let mut y: Vec<f64> = reference
        .pixels
        .iter()
        .map(|p| relative_luminance([0, 1, 2].map(|c| f64::from(p[c]))))
        .collect();
    if y.is_empty() {
        return None;
    }
    let mid = y.len() / 2;
    let (_, median, _) = y.select_nth_unstable_by(mid, f64::total_cmp);
    let median = *median;
    let max = y.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    if median <= 0.0 || !median.is_finite() || !max.is_finite() {
        return None;
    }
    let x = tone_mapper.input_for(TARGET);
    Some(((x / max).log2(), (x / median).log2()))
}

/// An HDR-FLIP result: the map, the exposures it used and, per pixel, which exposure gave its
/// error (0 for the first to 1 for the last).
#[derive(Clone, Debug)]
pub struct HdrFlip {
    pub map: Vec<f32>,
    pub range: ExposureRange,
    pub exposure_map: Vec<f32>,
}

/// Why HDR-FLIP cannot run on the inputs.
#[derive(Clone, Debug, PartialEq)]
pub enum HdrError {
    /// The reference's median luminance is not positive: the automatic stop is infinite.
    NoAutomaticRange,
    /// start > stop, or a count of 0.
    BadRange(String),
}

impl std::fmt::Display for HdrError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            HdrError::NoAutomaticRange => write!(
                f,
                "the reference's median luminance is 0, so HDR-FLIP's automatic exposure range \
                 has no stop; give the range"
            ),
            HdrError::BadRange(m) => write!(f, "{m}"),
        }
    }
}

/// The range `settings` asks for, completed automatically from the reference.
pub fn exposure_range(
    reference: ImageView<'_>,
    settings: &HdrSettings,
) -> Result<ExposureRange, HdrError> {
    let (start, stop) = match (settings.start, settings.stop) {
        (Some(a), Some(b)) => (a, b),
        (a, b) => {
            let (auto_a, auto_b) = automatic_range(reference, settings.tone_mapper)
                .ok_or(HdrError::NoAutomaticRange)?;
            (a.unwrap_or(auto_a), b.unwrap_or(auto_b))
        }
    };
    if !(start.is_finite() && stop.is_finite()) || start > stop {
        return Err(HdrError::BadRange(format!(
            "exposure range {start}..{stop}: the start must be at most the stop"
        )));
    }
    let count = match settings.count {
        Some(0) => {
            return Err(HdrError::BadRange(
                "the number of exposures must be at least 1".into(),
            ))
        }
        Some(n) => n,
        None => ((stop - start).ceil() as usize).max(2),
    };
    Ok(ExposureRange { start, stop, count })
}

/// HDR-FLIP of two linear HDR images (non-negative, finite).
pub fn hdr_flip(
    reference: ImageView<'_>,
    test: ImageView<'_>,
    ppd: f64,
    settings: &HdrSettings,
) -> Result<HdrFlip, HdrError> {
    assert!(
        reference.width == test.width && reference.height == test.height,
        "FLIP of images of different sizes"
    );
    let range = exposure_range(reference, settings)?;
    let n = reference.pixels.len();
    let mut map = vec![0.0f32; n];
    let mut exposure_map = vec![0.0f32; n];
    let exposures = range.exposures();
    for (k, &c) in exposures.iter().enumerate() {
        let scale = c.exp2();
        let mapped = |img: ImageView<'_>| -> [Plane; 3] {
            let rgb: Vec<[f64; 3]> = img
                .pixels
                .iter()
                .map(|p| {
                    let v = [0, 1, 2].map(|i| f64::from(p[i]) * scale);
                    settings.tone_mapper.apply(v).map(|t| t.clamp(0.0, 1.0))
                })
                .collect();
            [0, 1, 2].map(|i| Plane::new(img.width, img.height, rgb.iter().map(|v| v[i]).collect()))
        };
        let errors = super::ldr::flip_planes(&mapped(reference), &mapped(test), ppd);
        let at = if exposures.len() > 1 {
            k as f32 / (exposures.len() - 1) as f32
        } else {
            0.0
        };
        for ((m, e), v) in map.iter_mut().zip(exposure_map.iter_mut()).zip(errors) {
            if v > *m {
                *m = v;
                *e = at;
            }
        }
    }
    Ok(HdrFlip {
        map,
        range,
        exposure_map,
    })
}
