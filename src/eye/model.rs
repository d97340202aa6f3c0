//! The parametric eye: the seed paper's parameters (its Table 1) on a Navarro-type structure.
//!
//! Geometry in mm, light along +z, anterior corneal vertex at z = 0. Two-valued parameters are
//! (horizontal, vertical). The lens anterior vertex sits `aqueous_depth_mm` behind the
//! posterior cornea and carries the iris.

use super::correction::{Iol, Spectacle};
use super::error::EyeError;
use super::lens::{lens_geometry, LensGeometry};
use super::media::Medium;
use super::surface::Surface;
use super::system::OpticalSystem;
use crate::optics::zernike::{is_valid_nm, num_terms, osa_index};
use serde::{Deserialize, Serialize};

/// One Zernike elevation term of a corneal surface.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ElevationTerm {
    pub n: u32,
    pub m: i32,
    /// Coefficient in mm (orthonormal OSA term over the elevation radius).
    pub mm: f64,
}

/// A corneal surface: biconic with per-meridian radii, one conic constant, axis rotation and
/// an optional Zernike elevation map.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CornealSurface {
    /// Vertex radii (mm) of the meridians along x' and y', where x' is +x rotated by `axis_deg`.
    pub radius_mm: [f64; 2],
    pub conic: f64,
    #[serde(default)]
    pub axis_deg: f64,
    #[serde(default)]
    pub elevation: Vec<ElevationTerm>,
}

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Cornea {
    pub thickness_mm: f64,
    pub anterior: CornealSurface,
    pub posterior: CornealSurface,
    /// Radius (mm) over which the elevation Zernikes are normalised.
    #[serde(default = "default_elevation_radius")]
    pub elevation_radius_mm: f64,
}

fn default_elevation_radius() -> f64 {
    DEFAULT_ELEVATION_RADIUS_MM
}

/// Normalisation radius of corneal elevation maps: covers an 8 mm entrance pupil on the cornea.
pub const DEFAULT_ELEVATION_RADIUS_MM: f64 = 5.0;

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Lens {
    pub diameter_mm: f64,
    pub volume_mm3: f64,
    pub anterior_conic: f64,
    pub posterior_conic: f64,
    /// Shift of the lens (both surfaces, x and y), mm.
    #[serde(default)]
    pub decentration_mm: [f64; 2],
    /// Rotation of the lens about its equator centre: [0] about the vertical axis (the lens
    /// axis leans towards +x), [1] about the horizontal axis (leans towards +y), degrees.
    #[serde(default)]
    pub tilt_deg: [f64; 2],
}

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Eye {
    /// Anterior cornea vertex to retina along the axis.
    pub axial_length_mm: f64,
    pub cornea: Cornea,
    /// Posterior cornea vertex to anterior lens vertex.
    pub aqueous_depth_mm: f64,
    pub lens: Lens,
    /// Amplitude of accommodation (D): how far the lens may accommodate from relaxed (see
    /// `eye::age`). Absent = unlimited unless an age sets it.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub accommodation_max_d: Option<f64>,
    /// A spectacle or contact lens in front of the cornea, traced with the eye.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub correction: Option<Spectacle>,
    /// An intraocular lens in place of the crystalline lens (no accommodation).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub iol: Option<Iol>,
    /// Shape of the image surface. Files without it get the wide-angle retina (a sphere of
    /// radius 12 mm, Escudero-Sanz & Navarro 1999); on axis the shape changes nothing.
    #[serde(default, skip_serializing_if = "Retina::is_default")]
    pub retina: Retina,
}

/// The image surface: its vertex lies on the axis at `axial_length_mm`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(try_from = "RetinaTable", into = "RetinaTable")]
pub enum Retina {
    /// The plane z = axial length (a paraxial schematic eye's image plane).
    Plane,
    /// A sphere concave towards the light, centred on the axis `radius_mm` in front of the
    /// retinal vertex.
    Sphere { radius_mm: f64 },
}

/// Retinal radius of the wide-angle schematic eye (Escudero-Sanz & Navarro 1999), mm.
pub const WIDE_ANGLE_RETINA_RADIUS_MM: f64 = 12.0;
/// Accepted retinal radii (mm): human retinas lie well inside; flatter is `shape = "plane"`.
pub const RETINA_RADIUS_RANGE_MM: (f64, f64) = (8.0, 1000.0);

/// The `[retina]` table as written: `shape = "plane"`, or `shape = "sphere"` with
/// `radius_mm`.
#[derive(Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct RetinaTable {
    shape: String,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    radius_mm: Option<f64>,
}

impl TryFrom<RetinaTable> for Retina {
    type Error = String;
    fn try_from(t: RetinaTable) -> Result<Self, String> {
        match (t.shape.as_str(), t.radius_mm) {
            ("plane", None) => Ok(Retina::Plane),
            ("sphere", Some(radius_mm)) => Ok(Retina::Sphere { radius_mm }),
            ("plane", Some(_)) => Err("retina: a plane has no radius_mm".into()),
            ("sphere", None) => Err("retina: a sphere needs radius_mm".into()),
            (other, _) => Err(format!(
                "retina.shape {other:?} is not allowed; use \"sphere\" or \"plane\""
            )),
        }
    }
}

impl From<Retina> for RetinaTable {
    fn from(r: Retina) -> Self {
        match r {
            Retina::Plane => RetinaTable {
                shape: "plane".into(),
                radius_mm: None,
            },
            Retina::Sphere { radius_mm } => RetinaTable {
                shape: "sphere".into(),
                radius_mm: Some(radius_mm),
            },
        }
    }
}

impl Default for Retina {
    fn default() -> Self {
        Retina::Sphere {
            radius_mm: WIDE_ANGLE_RETINA_RADIUS_MM,
        }
    }
}

impl Retina {
    pub fn is_default(&self) -> bool {
        *self == Retina::default()
    }

    /// Radius of curvature (mm); infinite for the plane.
    pub fn radius_mm(&self) -> f64 {
        match *self {
            Retina::Plane => f64::INFINITY,
            Retina::Sphere { radius_mm } => radius_mm,
        }
    }
}

impl Default for Eye {
    fn default() -> Self {
        Eye::navarro()
    }
}

fn finite(name: &'static str, value: f64) -> Result<(), EyeError> {
    if value.is_finite() {
        Ok(())
    } else {
        Err(EyeError::NonFinite { name, value })
    }
}

fn positive(name: &str, value: f64) -> Result<(), EyeError> {
    if value > 0.0 {
        Ok(())
    } else {
        Err(EyeError::Invalid(format!(
            "{name} must be positive, got {value}"
        )))
    }
}

/// Semi-diameter over which the cornea must exist and keep a positive thickness: a 7 mm
/// pupil (the paper's largest). Wider rays that find no surface are reported as vignetted.
const CORNEA_OPTICAL_ZONE_MM: f64 = 3.5;
/// Thinnest vitreous chamber accepted between posterior lens and retina.
const MIN_VITREOUS_MM: f64 = 5.0;

impl Eye {
    fn scalars(&self) -> Vec<(&'static str, f64)> {
        let c = &self.cornea;
        let l = &self.lens;
        vec![
            ("axial_length_mm", self.axial_length_mm),
            ("cornea.thickness_mm", c.thickness_mm),
            ("cornea.anterior.radius_mm[0]", c.anterior.radius_mm[0]),
            ("cornea.anterior.radius_mm[1]", c.anterior.radius_mm[1]),
            ("cornea.anterior.conic", c.anterior.conic),
            ("cornea.anterior.axis_deg", c.anterior.axis_deg),
            ("cornea.posterior.radius_mm[0]", c.posterior.radius_mm[0]),
            ("cornea.posterior.radius_mm[1]", c.posterior.radius_mm[1]),
            ("cornea.posterior.conic", c.posterior.conic),
            ("cornea.posterior.axis_deg", c.posterior.axis_deg),
            ("cornea.elevation_radius_mm", c.elevation_radius_mm),
            ("aqueous_depth_mm", self.aqueous_depth_mm),
            ("lens.diameter_mm", l.diameter_mm),
            ("lens.volume_mm3", l.volume_mm3),
            ("lens.anterior_conic", l.anterior_conic),
            ("lens.posterior_conic", l.posterior_conic),
            ("lens.decentration_mm[0]", l.decentration_mm[0]),
            ("lens.decentration_mm[1]", l.decentration_mm[1]),
            ("lens.tilt_deg[0]", l.tilt_deg[0]),
            ("lens.tilt_deg[1]", l.tilt_deg[1]),
        ]
    }

    /// Lens radii and cap heights derived from the lens parameters.
    pub fn lens_geometry(&self) -> Result<LensGeometry, EyeError> {
        let l = &self.lens;
        positive("lens.diameter_mm", l.diameter_mm)?;
        positive("lens.volume_mm3", l.volume_mm3)?;
        lens_geometry(
            l.diameter_mm,
            l.volume_mm3,
            l.anterior_conic,
            l.posterior_conic,
        )
    }

    /// Axial position of the lens equator plane (mm from the corneal vertex).
    pub fn lens_equator_z_mm(&self) -> Result<f64, EyeError> {
        let g = self.lens_geometry()?;
        Ok(self.cornea.thickness_mm + self.aqueous_depth_mm + g.anterior_thickness_mm)
    }

    /// Checks that the parameters describe a buildable eye.
    pub fn validate(&self) -> Result<(), EyeError> {
        self.system().map(|_| ())
    }

    /// Builds the traceable optical system (validates on the way).
    pub fn system(&self) -> Result<OpticalSystem, EyeError> {
        for (name, v) in self.scalars() {
            finite(name, v)?;
        }
        let c = &self.cornea;
        positive("cornea.thickness_mm", c.thickness_mm)?;
        positive("aqueous_depth_mm", self.aqueous_depth_mm)?;
        positive("axial_length_mm", self.axial_length_mm)?;
        positive("cornea.elevation_radius_mm", c.elevation_radius_mm)?;
        for (name, s) in [("anterior", &c.anterior), ("posterior", &c.posterior)] {
            for r in s.radius_mm {
                if r.is_nan() || r <= 0.0 {
                    return Err(EyeError::Invalid(format!(
                        "cornea.{name}.radius_mm must be positive (convex towards the object), got {r}"
                    )));
                }
            }
        }
        if let Retina::Sphere { radius_mm } = self.retina {
            let (lo, hi) = RETINA_RADIUS_RANGE_MM;
            if !(radius_mm.is_finite() && (lo..=hi).contains(&radius_mm)) {
                return Err(EyeError::Invalid(format!(
                    "retina.radius_mm must lie in {lo}–{hi} mm (shape = \"plane\" for a flat \
                     retina), got {radius_mm}"
                )));
            }
        }
        if self.lens.tilt_deg.iter().any(|t| t.abs() >= 45.0) {
            return Err(EyeError::Invalid(format!(
                "lens.tilt_deg must stay within ±45°, got {:?}",
                self.lens.tilt_deg
            )));
        }
        let g = self.lens_geometry()?;
        let ant = corneal_surface(&c.anterior, 0.0, c.elevation_radius_mm, "anterior")?;
        let post = corneal_surface(
            &c.posterior,
            c.thickness_mm,
            c.elevation_radius_mm,
            "posterior",
        )?;
        // The cornea must keep a positive thickness over the optical zone.
        for k in 0..=36 {
            let phi = k as f64 * std::f64::consts::PI / 18.0;
            for r in [0.0, 1.5, 3.0, CORNEA_OPTICAL_ZONE_MM] {
                let (x, y) = (r * phi.cos(), r * phi.sin());
                let (sa, sp) = match (ant.sag(x, y), post.sag(x, y)) {
                    (Some(a), Some(p)) => (a.z, p.z),
                    _ => {
                        return Err(EyeError::Invalid(format!(
                        "cornea does not extend over its {CORNEA_OPTICAL_ZONE_MM} mm optical zone \
                             (conic too large for its radius)"
                    )))
                    }
                };
                if c.thickness_mm + sp - sa <= 0.0 {
                    return Err(EyeError::Invalid(format!(
                        "cornea surfaces cross {r} mm off axis (thickness {:.3} mm there)",
                        c.thickness_mm + sp - sa
                    )));
                }
            }
        }
        let z_lens = c.thickness_mm + self.aqueous_depth_mm;
        let z_eq = z_lens + g.anterior_thickness_mm;
        let z_back = z_eq + g.posterior_thickness_mm;
        let vitreous = self.axial_length_mm - z_back;
        if vitreous < MIN_VITREOUS_MM {
            return Err(EyeError::Invalid(format!(
                "vitreous depth {vitreous:.3} mm is too short (axial length {} mm, lens ends at {z_back:.3} mm)",
                self.axial_length_mm
            )));
        }
        let l = &self.lens;
        let tilt = [l.tilt_deg[0].to_radians(), l.tilt_deg[1].to_radians()];
        // Both lens surfaces share the lens's semi-diameter and placement.
        let lens_surface = |z: f64, radius_mm: f64, conic: f64| {
            Surface::conic(z, radius_mm, conic, g.semi_diameter_mm).with_placement(
                l.decentration_mm,
                tilt,
                z_eq,
            )
        };
        let lens_a = lens_surface(z_lens, g.anterior_radius_mm, l.anterior_conic);
        let lens_p = lens_surface(z_back, g.posterior_radius_mm, l.posterior_conic);
        if let Some(a) = self.accommodation_max_d {
            if !(a.is_finite() && (0.0..=super::age::MAX_AMPLITUDE_D).contains(&a)) {
                return Err(EyeError::Invalid(format!(
                    "accommodation_max_d {a} is outside 0 to {} D",
                    super::age::MAX_AMPLITUDE_D
                )));
            }
        }
        let (mut surfaces, mut media) = match &self.iol {
            None => (
                vec![ant, post, lens_a, lens_p],
                vec![
                    Medium::Cornea,
                    Medium::Aqueous,
                    Medium::Lens,
                    Medium::Vitreous,
                ],
            ),
            Some(iol) => {
                iol.validate()?;
                (
                    vec![ant, post, iol.surface(z_eq)],
                    vec![Medium::Cornea, Medium::Aqueous, Medium::Vitreous],
                )
            }
        };
        let mut stop_index = 2;
        if let Some(spec) = &self.correction {
            spec.validate()?;
            surfaces.insert(0, spec.surface());
            media.insert(0, Medium::Air);
            stop_index += 1;
        }
        Ok(OpticalSystem {
            surfaces,
            media,
            stop_index,
            stop_z_mm: z_lens,
            retina_z_mm: self.axial_length_mm,
            retina_radius_mm: self.retina.radius_mm(),
            lens_index_offset: 0.0,
        })
    }

    /// The eye alone: no spectacle or contact lens, no IOL (the natural lens back).
    pub fn without_corrections(&self) -> Eye {
        Eye {
            correction: None,
            iol: None,
            ..self.clone()
        }
    }

    /// Parses and validates an eye from TOML text: either the bare structure, or an eye file
    /// whose `[eye]` table holds it next to an `[estimate]` record (see `eye::file`).
    pub fn from_toml_str(text: &str) -> Result<Eye, EyeError> {
        let bad = |e: toml::de::Error| EyeError::Invalid(format!("eye file: {}", e.message()));
        let table: toml::Table = toml::from_str(text).map_err(bad)?;
        let eye: Eye = if let Some(inner) = table.get("eye") {
            if let Some(k) = table.keys().find(|k| *k != "eye" && *k != "estimate") {
                return Err(EyeError::Invalid(format!(
                    "eye file: unknown table {k:?} next to [eye]; allowed: [eye], [estimate]"
                )));
            }
            let toml::Value::Table(t) = inner else {
                return Err(EyeError::Invalid("eye file: 'eye' must be a table".into()));
            };
            t.clone().try_into().map_err(bad)?
        } else {
            toml::from_str(text).map_err(bad)?
        };
        eye.validate()?;
        Ok(eye)
    }

    pub fn to_toml_string(&self) -> String {
        toml::to_string_pretty(self).expect("an Eye always serialises")
    }

    /// A copy with a new lens diameter at the same volume, keeping the lens equator plane
    /// fixed (the zonules hold the equator; the lens thickens both ways, as in Navarro's
    /// accommodation where the anterior chamber shallows).
    pub fn with_lens_diameter(&self, diameter_mm: f64) -> Result<Eye, EyeError> {
        let g0 = self.lens_geometry()?;
        let mut e = self.clone();
        e.lens.diameter_mm = diameter_mm;
        let g1 = e.lens_geometry()?;
        e.aqueous_depth_mm += g0.anterior_thickness_mm - g1.anterior_thickness_mm;
        if e.aqueous_depth_mm.is_nan() || e.aqueous_depth_mm <= 0.0 {
            return Err(EyeError::Invalid(format!(
                "a lens diameter of {diameter_mm:.3} mm closes the anterior chamber"
            )));
        }
        Ok(e)
    }
}

// With the model rather than with the lens: where an IOL sits is a fact of the eye it is put in.
impl Iol {
    /// Where the IOL sits: the crystalline lens's equator plane (the capsular bag holds the
    /// optic there), in mm from the corneal vertex; the iris stays where it was.
    pub fn plane_z_mm(eye: &Eye) -> Result<f64, EyeError> {
        eye.lens_equator_z_mm()
    }
}

fn corneal_surface(
    s: &CornealSurface,
    z_mm: f64,
    elevation_radius_mm: f64,
    name: &str,
) -> Result<Surface, EyeError> {
    let mut surf = Surface::toric(
        z_mm,
        s.radius_mm,
        s.conic,
        s.axis_deg.to_radians(),
        f64::INFINITY,
    );
    if !s.elevation.is_empty() {
        let max_n = s.elevation.iter().map(|t| t.n).max().unwrap_or(0);
        if max_n > super::surface::MAX_ELEVATION_ORDER {
            return Err(EyeError::Invalid(format!(
                "cornea.{name}.elevation: order {max_n} above {}",
                super::surface::MAX_ELEVATION_ORDER
            )));
        }
        let mut coeffs = vec![0.0; num_terms(max_n)];
        for t in &s.elevation {
            if !is_valid_nm(t.n, t.m) {
                return Err(EyeError::Invalid(format!(
                    "cornea.{name}.elevation: ({}, {}) is not a Zernike term",
                    t.n, t.m
                )));
            }
            if !t.mm.is_finite() {
                return Err(EyeError::NonFinite {
                    name: "cornea elevation coefficient",
                    value: t.mm,
                });
            }
            coeffs[osa_index(t.n, t.m)] += t.mm;
        }
        surf = surf.with_elevation(&coeffs, elevation_radius_mm);
    }
    Ok(surf)
}
