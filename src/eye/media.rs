//! Refractive indices of the ocular media after Navarro's dispersion model.
//!
//! Each medium is described by its index at four reference wavelengths (n**, n_F, n_C, n*);
//! a common set of wavelength weights a_i(λ) of Herzberger form interpolates between them.
//! The coefficient values are the corrected ones quoted in shared/reference/README.md.

use serde::{Deserialize, Serialize};

/// A medium an eye ray can travel in.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Medium {
    Air,
    Cornea,
    Aqueous,
    Lens,
    Vitreous,
}

const COEFFS: [[f64; 4]; 4] = [
    [0.661_471_96, -0.403_527_96, -0.280_467_90, 0.033_859_79],
    [-4.201_463_83, 2.735_089_56, 1.505_437_84, -0.115_932_35],
    [6.298_342_37, -4.694_099_35, -1.575_086_50, 0.102_930_38],
    [-1.758_350_59, 2.362_537_94, 0.350_116_57, -0.020_857_82],
];

/// Indices (n**, n_F, n_C, n*) of the four media.
const REFERENCE: [[f64; 4]; 4] = [
    [1.3975, 1.3807, 1.37405, 1.3668],
    [1.3593, 1.3422, 1.3354, 1.3278],
    [1.4492, 1.42625, 1.4175, 1.4097],
    [1.3565, 1.3407, 1.3341, 1.3273],
];

fn weights(wavelength_nm: f64) -> [f64; 4] {
    let l = wavelength_nm * 1e-3;
    let l2 = l * l;
    let q = 1.0 / (l2 - 0.028);
    let mut a = [0.0; 4];
    for (ai, c) in a.iter_mut().zip(COEFFS.iter()) {
        *ai = c[0] + c[1] * l2 + c[2] * q + c[3] * q * q;
    }
    a
}

impl Medium {
    /// The medium's row in the index tables; none for air (index 1).
    fn row(self) -> Option<usize> {
        match self {
            Medium::Air => None,
            Medium::Cornea => Some(0),
            Medium::Aqueous => Some(1),
            Medium::Lens => Some(2),
            Medium::Vitreous => Some(3),
        }
    }
}

/// Refractive index of `medium` at `wavelength_nm` (Navarro's relaxed lens index for the lens).
pub fn refractive_index(medium: Medium, wavelength_nm: f64) -> f64 {
    let Some(row) = medium.row() else {
        return 1.0;
    };
    let a = weights(wavelength_nm);
    a.iter()
        .zip(REFERENCE[row].iter())
        .map(|(a, n)| a * n)
        .sum()
}

/// Indices at 589.3 nm that define Navarro's schematic eye (Escudero-Sanz & Navarro 1999).
const ANCHOR_589: [f64; 4] = [1.376, 1.3374, 1.42, 1.336];

/// Index used by the eye model: the dispersion curve shifted (by at most 8e-5) so that it
/// passes exactly through the schematic eye's defining index at 589.3 nm. Without the shift the
/// relaxed eye's power is 0.02 D short of Navarro's 60.416 D, because the lens index the
/// formula yields at 589.3 nm is 1.41992 rather than 1.42.
pub fn eye_index(medium: Medium, wavelength_nm: f64) -> f64 {
    let Some(row) = medium.row() else {
        return 1.0;
    };
    refractive_index(medium, wavelength_nm) - refractive_index(medium, 589.3) + ANCHOR_589[row]
}

/// Indices of air, cornea, aqueous, lens and vitreous at one wavelength; `lens_offset` is added
/// to the lens (Navarro's accommodation raises the lens index uniformly).
pub fn indices(wavelength_nm: f64, lens_offset: f64) -> [f64; 5] {
    [
        1.0,
        eye_index(Medium::Cornea, wavelength_nm),
        eye_index(Medium::Aqueous, wavelength_nm),
        eye_index(Medium::Lens, wavelength_nm) + lens_offset,
        eye_index(Medium::Vitreous, wavelength_nm),
    ]
}
