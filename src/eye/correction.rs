//! Corrections that become part of the traced optical system: a spectacle or contact lens
//! in front of the cornea, and a monofocal intraocular lens (IOL) in place of the crystalline
//! lens.
//!
//! Both are ideal thin lenses (see [`Surface::ideal_lens`]): a spectacle prescription is a
//! back-vertex power at a vertex distance, which a thin lens at that distance reproduces
//! exactly, and an IOL's labelled power is its power in the eye. Being part of the system,
//! they change the vergence, the entrance pupil (so magnification) and the aberrations that
//! every measurement and every kernel sees.
//!
//! Conventions are clinical optometry's: sphere S and cylinder C in dioptres in
//! minus-cylinder form (a plus-cylinder entry is transposed), axis A in degrees 1–180,
//! counter-clockwise from the eye's +x axis, the same axis the Zernike prescription formulas
//! of docs/design.md ("Conventions and units") use. The lens has power S along its axis
//! meridian and S + C across it. The vertex distance is from the lens to the corneal vertex;
//! 0 is a contact lens. The lens's own chromatic aberration is left out (P/V: 0.09 D for a
//! 5 D CR-39 lens).
//!
//! The model holds these lenses, so this module stays below it: what needs an eye (where an
//! IOL sits, the IOL power or spectacle an eye needs) is in `model` and `refract`.

use super::error::EyeError;
use super::surface::Surface;
use crate::optics::zernike::Prescription;
use serde::{Deserialize, Serialize};

/// Allowed ranges, checked where the values enter (parser and eye file).
pub const SPHERE_RANGE_D: (f64, f64) = (-25.0, 25.0);
pub const CYLINDER_RANGE_D: (f64, f64) = (-10.0, 10.0);
/// Up to 16 mm, so that the nearest depth ocular renders (2 cm) stays in front of the lens.
pub const VERTEX_RANGE_MM: (f64, f64) = (0.0, 16.0);
pub const IOL_RANGE_D: (f64, f64) = (-10.0, 40.0);
/// The spectacle vertex distance clinics assume when none is given.
pub const DEFAULT_VERTEX_MM: f64 = 12.0;

/// A sphero-cylindrical lens in front of the eye.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Spectacle {
    pub sphere_d: f64,
    /// ≤ 0 (minus-cylinder form).
    #[serde(default)]
    pub cylinder_d: f64,
    /// 0–180° (typed: 1–180°).
    #[serde(default = "default_axis")]
    pub axis_deg: f64,
    /// Lens to corneal vertex (mm); 0 = contact lens.
    #[serde(default = "default_vertex")]
    pub vertex_mm: f64,
}

impl Spectacle {
    /// Power matrix (D) in the lens plane, x right and y up as the wearer sees: the sphere
    /// along the axis, sphere + cylinder across it (minus-cylinder form, axis counter-clockwise
    /// from +x).
    pub fn power_matrix_d(&self) -> [[f64; 2]; 2] {
        let a = self.axis_deg.to_radians();
        // The cylinder's power acts across its axis.
        let (nx, ny) = (-a.sin(), a.cos());
        let (s, c) = (self.sphere_d, self.cylinder_d);
        [
            [s + c * nx * nx, c * nx * ny],
            [c * nx * ny, s + c * ny * ny],
        ]
    }

    /// Angular magnification for distant objects of this lens `vertex_mm` in front of the
    /// cornea, seen from an entrance pupil `pupil_behind_cornea_mm` behind it: a chief ray
    /// that leaves the lens at tangent t crossed it at height −h·t (h = vertex + pupil depth)
    /// and was bent by −P·(−h·t), so t = t₀ + h·P·t and t = (I − h·P)⁻¹·t₀ (the spectacle
    /// magnification's power factor; a thin lens has no shape factor).
    pub fn angular_magnification(&self, pupil_behind_cornea_mm: f64) -> [[f64; 2]; 2] {
        let h_m = 1e-3 * (self.vertex_mm + pupil_behind_cornea_mm);
        let p = self.power_matrix_d();
        let a = [
            [1.0 - h_m * p[0][0], -h_m * p[0][1]],
            [-h_m * p[1][0], 1.0 - h_m * p[1][1]],
        ];
        let det = a[0][0] * a[1][1] - a[0][1] * a[1][0];
        [
            [a[1][1] / det, -a[0][1] / det],
            [-a[1][0] / det, a[0][0] / det],
        ]
    }
}

fn default_axis() -> f64 {
    180.0
}

fn default_vertex() -> f64 {
    DEFAULT_VERTEX_MM
}

/// A monofocal intraocular lens replacing the crystalline lens.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Iol {
    /// Power in the eye (D), as labelled.
    pub power_d: f64,
}

fn in_range(name: &str, v: f64, (lo, hi): (f64, f64), unit: &str) -> Result<(), EyeError> {
    if v.is_finite() && v >= lo && v <= hi {
        Ok(())
    } else {
        Err(EyeError::Invalid(format!(
            "{name} {v} is outside {lo} to {hi} {unit}"
        )))
    }
}

impl Spectacle {
    /// A lens from clinical values, transposing plus-cylinder to minus-cylinder form.
    pub fn new(
        sphere_d: f64,
        cylinder_d: f64,
        axis_deg: f64,
        vertex_mm: f64,
    ) -> Result<Spectacle, EyeError> {
        let s = if cylinder_d > 0.0 {
            Spectacle {
                sphere_d: sphere_d + cylinder_d,
                cylinder_d: -cylinder_d,
                axis_deg: normalised_axis_deg(axis_deg + 90.0),
                vertex_mm,
            }
        } else {
            Spectacle {
                sphere_d,
                cylinder_d,
                axis_deg,
                vertex_mm,
            }
        };
        s.validate()?;
        Ok(s)
    }

    pub fn validate(&self) -> Result<(), EyeError> {
        in_range("correction.sphere_d", self.sphere_d, SPHERE_RANGE_D, "D")?;
        in_range(
            "correction.cylinder_d",
            self.cylinder_d,
            (-10.0, 0.0),
            "D (minus cylinder)",
        )?;
        // Typed prescriptions keep the clinical 1–180 (parse_rx); a computed lens may have
        // any orientation, and 0–1° is as real as 1–180° (eye refract's lens for an eye
        // with a tiny cylinder landed at 0.45°).
        in_range(
            "correction.axis_deg",
            self.axis_deg,
            (0.0, 180.0),
            "degrees",
        )?;
        in_range(
            "correction.vertex_mm",
            self.vertex_mm,
            VERTEX_RANGE_MM,
            "mm",
        )
    }

    /// The thin lens in the system: powers along the axis meridian and across it.
    pub fn surface(&self) -> Surface {
        Surface::ideal_lens(
            -self.vertex_mm,
            [self.sphere_d, self.sphere_d + self.cylinder_d],
            self.axis_deg.to_radians(),
        )
    }

    /// The clinical form `--correct` takes: `S C x A`.
    pub fn notation(&self) -> String {
        format_rx(self.sphere_d, self.cylinder_d, self.axis_deg)
    }
}

/// `S C x A` with signs and two decimals, the axis as a whole degree 1–180 (a cylinder that
/// rounds to zero is written 0.00).
pub fn format_rx(sphere_d: f64, cylinder_d: f64, axis_deg: f64) -> String {
    let (cyl, axis) = if cylinder_d.abs() < 0.005 {
        ("0.00".to_string(), 180.0)
    } else {
        (
            format!("{cylinder_d:+.2}"),
            normalised_axis_deg(axis_deg.round()),
        )
    };
    format!("{sphere_d:+.2} {cyl} x {axis:.0}")
}

/// An axis in degrees folded into (0, 180].
pub fn normalised_axis_deg(axis_deg: f64) -> f64 {
    let a = axis_deg.rem_euclid(180.0);
    if a <= 0.0 {
        180.0
    } else {
        a
    }
}

/// Parses a prescription in any spelling [`Prescription::parse`] reads (`S`, `S DS`,
/// `S C x A`, `S/C x A`, …) and checks the clinical ranges. The error says what is allowed;
/// the caller names the option.
pub fn parse_rx(text: &str, vertex_mm: f64) -> Result<Spectacle, String> {
    let rx = Prescription::parse(text).map_err(|e| e.to_string())?;
    let axis_given = text.contains(['x', 'X', '×', '@', '*']);
    let check = |name: &str, v: f64, (lo, hi): (f64, f64), unit: &str| {
        if v >= lo && v <= hi {
            Ok(())
        } else {
            Err(format!("{name} {v} is outside {lo} to {hi} {unit}"))
        }
    };
    check("sphere", rx.sphere_d, SPHERE_RANGE_D, "D")?;
    check("cylinder", rx.cylinder_d, CYLINDER_RANGE_D, "D")?;
    let axis = if axis_given {
        check("axis", rx.axis_deg, (1.0, 180.0), "degrees")?;
        rx.axis_deg
    } else {
        180.0
    };
    Spectacle::new(rx.sphere_d, rx.cylinder_d, axis, vertex_mm).map_err(|e| e.to_string())
}

impl Iol {
    pub fn validate(&self) -> Result<(), EyeError> {
        in_range("iol.power_d", self.power_d, IOL_RANGE_D, "D")
    }

    pub fn surface(&self, z_mm: f64) -> Surface {
        Surface::ideal_lens(z_mm, [self.power_d; 2], 0.0)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn prescriptions_parse_in_every_clinical_spelling() {
        let a = parse_rx("-2.50 -1.00 x 090", 12.0).unwrap();
        assert_eq!((a.sphere_d, a.cylinder_d, a.axis_deg), (-2.5, -1.0, 90.0));
        for t in [
            "-2.5 -1x90",
            "-2.5/-1.0×90",
            "-2.50 DS / -1.00 DC x 90",
            "-3.5 +1 x 180",
        ] {
            let b = parse_rx(t, 12.0).unwrap();
            assert_eq!(
                (b.sphere_d, b.cylinder_d, b.axis_deg),
                (-2.5, -1.0, 90.0),
                "{t}"
            );
        }
        assert_eq!(parse_rx("+2", 12.0).unwrap().sphere_d, 2.0);
        for bad in [
            "",
            "-2 -1 x 0",
            "-2 -1 x 181",
            "-30",
            "a b x c",
            "-2 -11 x 90",
            "-2 -1",
        ] {
            assert!(parse_rx(bad, 12.0).is_err(), "{bad}");
        }
        assert_eq!(a.notation(), "-2.50 -1.00 x 90");
    }
}
