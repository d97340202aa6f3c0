//! Named eyes: Navarro's schematic eye in the parametric form, the population mean of the seed
//! paper's Table 1, and Navarro's own accommodating eye (as an optical system).

use super::error::EyeError;
use super::lens::diameter_volume_from_radii;
use super::media::Medium;
use super::model::{
    Cornea, CornealSurface, Eye, Lens, Retina, DEFAULT_ELEVATION_RADIUS_MM,
    WIDE_ANGLE_RETINA_RADIUS_MM,
};
use super::surface::Surface;
use super::system::OpticalSystem;

/// Navarro's relaxed-eye constants (mm).
pub const NAVARRO_CORNEA_THICKNESS_MM: f64 = 0.55;
pub const NAVARRO_AQUEOUS_MM: f64 = 3.05;
pub const NAVARRO_LENS_THICKNESS_MM: f64 = 4.0;
pub const NAVARRO_VITREOUS_MM: f64 = 16.40398;
/// Vitreous depth of the wide-angle eye (Escudero-Sanz & Navarro 1999): paraxially
/// emmetropic at 543 nm, axial length 23.9203 mm.
pub const WIDE_ANGLE_VITREOUS_MM: f64 = 16.3203;

fn cornea(ra: f64, ka: f64, rp: f64, kp: f64, t: f64) -> Cornea {
    Cornea {
        thickness_mm: t,
        anterior: CornealSurface {
            radius_mm: [ra, ra],
            conic: ka,
            axis_deg: 0.0,
            elevation: Vec::new(),
        },
        posterior: CornealSurface {
            radius_mm: [rp, rp],
            conic: kp,
            axis_deg: 0.0,
            elevation: Vec::new(),
        },
        elevation_radius_mm: DEFAULT_ELEVATION_RADIUS_MM,
    }
}

/// A schematic eye: a centred lens of [diameter mm, volume mm³, anterior conic, posterior
/// conic], the default retina, and no correction, IOL or amplitude of its own.
fn schematic(axial_length_mm: f64, cornea: Cornea, aqueous_depth_mm: f64, lens: [f64; 4]) -> Eye {
    let [diameter_mm, volume_mm3, anterior_conic, posterior_conic] = lens;
    Eye {
        axial_length_mm,
        cornea,
        aqueous_depth_mm,
        lens: Lens {
            diameter_mm,
            volume_mm3,
            anterior_conic,
            posterior_conic,
            decentration_mm: [0.0; 2],
            tilt_deg: [0.0; 2],
        },
        accommodation_max_d: None,
        correction: None,
        iol: None,
        retina: Retina::default(),
    }
}

impl Eye {
    /// Navarro's relaxed eye (A = 0) expressed in the parametric form; its lens diameter and
    /// volume are those at which Navarro's two lens surfaces meet.
    pub fn navarro() -> Eye {
        let (d, v, _) =
            diameter_volume_from_radii(10.2, -6.0, -3.1316, -1.0, NAVARRO_LENS_THICKNESS_MM)
                .expect("Navarro's lens surfaces meet");
        schematic(
            NAVARRO_CORNEA_THICKNESS_MM
                + NAVARRO_AQUEOUS_MM
                + NAVARRO_LENS_THICKNESS_MM
                + NAVARRO_VITREOUS_MM,
            cornea(7.72, -0.26, 6.5, 0.0, NAVARRO_CORNEA_THICKNESS_MM),
            NAVARRO_AQUEOUS_MM,
            [d, v, -3.1316, -1.0],
        )
    }

    /// The wide-angle schematic eye of Escudero-Sanz & Navarro (1999): Navarro's relaxed
    /// surfaces and dispersion, a vitreous of 16.3203 mm and a spherical retina of radius
    /// 12 mm, built to reproduce off-axis aberrations up to 60°.
    pub fn navarro_wide() -> Eye {
        let mut e = Eye::navarro();
        e.axial_length_mm = NAVARRO_CORNEA_THICKNESS_MM
            + NAVARRO_AQUEOUS_MM
            + NAVARRO_LENS_THICKNESS_MM
            + WIDE_ANGLE_VITREOUS_MM;
        e.retina = Retina::Sphere {
            radius_mm: WIDE_ANGLE_RETINA_RADIUS_MM,
        };
        e
    }

    /// The population means of the seed paper's Table 1, taken literally. Under the lens model
    /// (each conic cap reaching the equator) the mean lens (11.1 mm, 160.1 mm³, conics −4.4 and
    /// −4.0) has a posterior vertex radius of only −1.88 mm, so this eye is about 84 D and
    /// strongly myopic (≈ −11.6 D at 4 mm): a test of extremes, not a typical eye.
    pub fn population_mean() -> Eye {
        schematic(
            23.82,
            cornea(7.81, -0.29, 6.44, -0.34, 0.55),
            2.90,
            [11.1, 160.1, -4.4, -4.0],
        )
    }
}

/// The presets defined in code (no estimate record).
pub(crate) fn builtin_preset(name: &str) -> Option<Eye> {
    match name {
        "navarro" => Some(Eye::navarro()),
        "navarro-wide" => Some(Eye::navarro_wide()),
        "mean" | "population" => Some(Eye::population_mean()),
        _ => None,
    }
}

/// Names accepted by [`Eye::preset`].
pub const PRESET_NAMES: [&str; 7] = [
    "navarro",
    "navarro-wide",
    "mean",
    "healthy",
    "myopia",
    "astigmatism",
    "keratoconus",
];

/// Navarro's (1985) accommodating eye for accommodation `accommodation_d` (his parameter A):
/// lens radii, conics, thickness, anterior-chamber depth and lens index all follow his
/// logarithmic laws; the retina stays where the relaxed eye has it.
pub fn navarro_accommodated(accommodation_d: f64) -> Result<OpticalSystem, EyeError> {
    let a = accommodation_d;
    if !(a.is_finite() && (0.0..=12.0).contains(&a)) {
        return Err(EyeError::Invalid(format!(
            "Navarro accommodation must lie in 0–12 D, got {a}"
        )));
    }
    let l = (a + 1.0).ln();
    let aqueous = NAVARRO_AQUEOUS_MM - 0.05 * l;
    let lens_t = NAVARRO_LENS_THICKNESS_MM + 0.1 * l;
    let z1 = NAVARRO_CORNEA_THICKNESS_MM;
    let z2 = z1 + aqueous;
    let z3 = z2 + lens_t;
    let retina = NAVARRO_CORNEA_THICKNESS_MM
        + NAVARRO_AQUEOUS_MM
        + NAVARRO_LENS_THICKNESS_MM
        + NAVARRO_VITREOUS_MM;
    let big = f64::INFINITY;
    Ok(OpticalSystem {
        surfaces: vec![
            Surface::conic(0.0, 7.72, -0.26, big),
            Surface::conic(z1, 6.5, 0.0, big),
            Surface::conic(z2, 10.2 - 1.75 * l, -3.1316 - 0.34 * l, 5.5),
            Surface::conic(z3, -6.0 + 0.2294 * l, -1.0 - 0.125 * l, 5.5),
        ],
        media: vec![
            Medium::Cornea,
            Medium::Aqueous,
            Medium::Lens,
            Medium::Vitreous,
        ],
        stop_index: 2,
        stop_z_mm: z2,
        retina_z_mm: retina,
        retina_radius_mm: f64::INFINITY,
        lens_index_offset: 9e-5 * (10.0 * a + a * a),
    })
}
