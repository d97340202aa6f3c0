//! The optimisation parameters of the eye: which fields of [`Eye`] move, their prior (mean,
//! deviation, weight) and their bounds, and the map between an eye and a vector normalised to
//! [0, 1] per parameter (so one mesh size means the same fraction of every range).
//!
//! The numbers follow the seed paper's Table 1 except where this eye model cannot use them
//! (see [`prior_centre`] and the lens rows of [`ParamSpec::table`]):
//! - Lens centre: Navarro's relaxed lens in this model (diameter 11.257 mm, 196.3 mm³, conics
//!   −3.1316 / −1.0) instead of Table 1's 11.1 mm, 160.1 mm³, −4.4 / −4.0. With every lens
//!   surface one conic cap reaching the equator, Table 1's mean lens has a posterior radius of
//!   −1.88 mm (an 84 D eye) and a 160 mm³ lens of normal shape is several dioptres too weak,
//!   so Table 1's volume only makes sense for the framework's own lens parametrisation.
//!   Table 1's deviations and half-widths of the bounds are kept around the new centre.
//!   Navarro's posterior conic (−1.0) sits on Table 1's upper bound, which is kept.

use crate::eye::model::{ElevationTerm, Eye, DEFAULT_ELEVATION_RADIUS_MM};
use serde::Serialize;

/// One field of the eye the optimiser may move.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
pub enum Field {
    AxialLength,
    CorneaThickness,
    AnteriorRadius(usize),
    PosteriorRadius(usize),
    AnteriorConic,
    PosteriorConic,
    AnteriorAxis,
    PosteriorAxis,
    AqueousDepth,
    LensDiameter,
    LensVolume,
    LensAnteriorConic,
    LensPosteriorConic,
    LensDecentration(usize),
    LensTilt(usize),
    /// Corneal elevation term: surface (0 anterior, 1 posterior), n, m.
    Elevation(usize, u32, i32),
}

/// Prior and bounds of one parameter.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ParamSpec {
    pub name: String,
    pub field: Field,
    pub mean: f64,
    pub sigma: f64,
    pub lower: f64,
    pub upper: f64,
    /// Table 1's a_l.
    pub weight: f64,
}

/// Which parameter groups are free.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
pub struct Groups {
    /// Lens decentration and tilt.
    pub lens_pose: bool,
    /// Anterior corneal elevation up to this order (0 = none; Table 1 allows 1–6).
    pub anterior_elevation_order: u32,
    /// Posterior corneal elevation of orders 5–6 (Table 1's only posterior terms).
    pub posterior_elevation: bool,
}

impl Groups {
    /// Groups a wavefront needs: structure alone for orders ≤ 2 (the eye's own spherical
    /// aberration is then matched by the conics), corneal elevation and lens pose once the
    /// input holds tilt or irregular higher-order terms, and the order-5/6 terms (both
    /// surfaces, as Table 1 has them) only when the input reaches those orders.
    pub fn for_target(coefficients: &[(u32, i32, f64)]) -> Groups {
        let nonzero = |c: &&(u32, i32, f64)| c.2 != 0.0;
        let irregular = coefficients
            .iter()
            .filter(nonzero)
            .any(|&(n, m, _)| n == 1 || (n >= 3 && m != 0) || n >= 5);
        let max_order = coefficients
            .iter()
            .filter(nonzero)
            .map(|c| c.0)
            .max()
            .unwrap_or(0);
        Groups {
            lens_pose: irregular,
            anterior_elevation_order: if irregular { max_order.clamp(4, 6) } else { 0 },
            posterior_elevation: irregular && max_order >= 5,
        }
    }
}

/// The prior centre: Table 1's means for the cornea, anterior chamber and axial length, and
/// Navarro's relaxed lens expressed in this lens model (see the module notes).
pub fn prior_centre() -> Eye {
    let mut eye = Eye::population_mean();
    let nav = Eye::navarro();
    eye.lens = nav.lens.clone();
    eye
}

impl ParamSpec {
    fn new(name: &str, field: Field, mean: f64, sigma: f64, bounds: [f64; 2], weight: f64) -> Self {
        ParamSpec {
            name: name.to_string(),
            field,
            mean,
            sigma,
            lower: bounds[0],
            upper: bounds[1],
            weight,
        }
    }

    /// Every parameter of the groups, in a fixed order.
    pub fn table(groups: Groups) -> Vec<ParamSpec> {
        let centre = prior_centre();
        let lens = &centre.lens;
        let p = ParamSpec::new;
        let mut v = vec![
            p(
                "axial_length_mm",
                Field::AxialLength,
                23.82,
                0.81,
                [21.82, 25.82],
                2.0,
            ),
            p(
                "cornea.thickness_mm",
                Field::CorneaThickness,
                0.55,
                0.03,
                [0.4, 0.7],
                32.0,
            ),
            p(
                "cornea.anterior.radius_mm[0]",
                Field::AnteriorRadius(0),
                7.81,
                0.25,
                [6.5, 9.81],
                1.0,
            ),
            p(
                "cornea.anterior.radius_mm[1]",
                Field::AnteriorRadius(1),
                7.81,
                0.25,
                [6.5, 9.81],
                1.0,
            ),
            p(
                "cornea.posterior.radius_mm[0]",
                Field::PosteriorRadius(0),
                6.44,
                0.23,
                [5.5, 8.44],
                1.0,
            ),
            p(
                "cornea.posterior.radius_mm[1]",
                Field::PosteriorRadius(1),
                6.44,
                0.23,
                [5.5, 8.44],
                1.0,
            ),
            p(
                "cornea.anterior.conic",
                Field::AnteriorConic,
                -0.29,
                0.09,
                [-2.29, 1.71],
                1.0,
            ),
            p(
                "cornea.posterior.conic",
                Field::PosteriorConic,
                -0.34,
                0.24,
                [-2.34, 1.66],
                1.0,
            ),
            p(
                "cornea.anterior.axis_deg",
                Field::AnteriorAxis,
                0.0,
                0.0,
                [-45.0, 45.0],
                0.1,
            ),
            p(
                "cornea.posterior.axis_deg",
                Field::PosteriorAxis,
                0.0,
                0.0,
                [-45.0, 45.0],
                0.1,
            ),
            p(
                "aqueous_depth_mm",
                Field::AqueousDepth,
                2.90,
                0.39,
                [2.2, 3.5],
                1.0,
            ),
            // Table 1 half-widths (0.5 mm, 7 mm³) around Navarro's lens.
            p(
                "lens.diameter_mm",
                Field::LensDiameter,
                lens.diameter_mm,
                0.3,
                [lens.diameter_mm - 0.5, lens.diameter_mm + 0.5],
                1.0,
            ),
            p(
                "lens.volume_mm3",
                Field::LensVolume,
                lens.volume_mm3,
                2.5,
                [lens.volume_mm3 - 7.0, lens.volume_mm3 + 7.0],
                0.1,
            ),
            p(
                "lens.anterior_conic",
                Field::LensAnteriorConic,
                lens.anterior_conic,
                1.6,
                [-10.4, -1.0],
                2.0,
            ),
            p(
                "lens.posterior_conic",
                Field::LensPosteriorConic,
                lens.posterior_conic,
                2.0,
                [-10.0, -1.0],
                2.0,
            ),
        ];
        if groups.lens_pose {
            for (i, axis) in ["x", "y"].iter().enumerate() {
                v.push(p(
                    &format!("lens.decentration_mm[{i}] ({axis})"),
                    Field::LensDecentration(i),
                    0.0,
                    0.0,
                    [-0.8, 0.8],
                    8.0,
                ));
            }
            for (i, axis) in ["x", "y"].iter().enumerate() {
                v.push(p(
                    &format!("lens.tilt_deg[{i}] ({axis})"),
                    Field::LensTilt(i),
                    0.0,
                    0.0,
                    [-7.0, 7.0],
                    1.0,
                ));
            }
        }
        // The elevation terms (n, m), m = −n, −n + 2, …, n, of one corneal surface (0 anterior,
        // 1 posterior), each within ±bound mm.
        let elevation = |v: &mut Vec<ParamSpec>, surface: usize, n: u32, bound: f64| {
            let side = ["anterior", "posterior"][surface];
            for k in 0..=n {
                let m = 2 * k as i32 - n as i32;
                v.push(p(
                    &format!("cornea.{side}.elevation({n},{m})_mm"),
                    Field::Elevation(surface, n, m),
                    0.0,
                    0.0,
                    [-bound, bound],
                    1.0,
                ));
            }
        };
        for n in 1..=groups.anterior_elevation_order.min(6) {
            elevation(&mut v, 0, n, if n <= 4 { 0.10 } else { 0.05 });
        }
        if groups.posterior_elevation {
            for n in 5..=6u32 {
                elevation(&mut v, 1, n, 0.05);
            }
        }
        v
    }

    pub fn range(&self) -> f64 {
        self.upper - self.lower
    }

    pub fn normalise(&self, value: f64) -> f64 {
        (value - self.lower) / self.range()
    }

    /// Exact at the ends, so that a parameter on a bound never reads as past it.
    pub fn denormalise(&self, unit: f64) -> f64 {
        if unit <= 0.0 {
            self.lower
        } else if unit >= 1.0 {
            self.upper
        } else {
            (self.lower + unit * self.range()).clamp(self.lower, self.upper)
        }
    }

    /// Table 1's prior residual w_a·a_l·max(|x̄ − x| − σ, 0), in normalised units.
    pub fn prior_residual(&self, value: f64, w_a: f64) -> f64 {
        let excess = ((value - self.mean).abs() - self.sigma).max(0.0) / self.range();
        w_a * self.weight * excess
    }
}

/// A parameter vector bound to a template eye: the template holds every field that does not
/// move, and slots for the elevation terms that do.
#[derive(Debug, Clone)]
pub struct ParamMap {
    pub specs: Vec<ParamSpec>,
    template: Eye,
    /// For each spec, the index of its elevation term in the template's surface list.
    elevation_slot: Vec<usize>,
}

impl ParamMap {
    /// `template` provides the fixed fields (and the start values of the free ones).
    pub fn new(specs: Vec<ParamSpec>, template: &Eye) -> ParamMap {
        let mut template = template.clone();
        template.cornea.elevation_radius_mm = DEFAULT_ELEVATION_RADIUS_MM;
        let mut elevation_slot = vec![usize::MAX; specs.len()];
        for (i, s) in specs.iter().enumerate() {
            if let Field::Elevation(surface, n, m) = s.field {
                let list = if surface == 0 {
                    &mut template.cornea.anterior.elevation
                } else {
                    &mut template.cornea.posterior.elevation
                };
                let slot = match list.iter().position(|t| t.n == n && t.m == m) {
                    Some(k) => k,
                    None => {
                        list.push(ElevationTerm { n, m, mm: 0.0 });
                        list.len() - 1
                    }
                };
                elevation_slot[i] = slot;
            }
        }
        ParamMap {
            specs,
            template,
            elevation_slot,
        }
    }

    pub fn len(&self) -> usize {
        self.specs.len()
    }

    pub fn is_empty(&self) -> bool {
        self.specs.is_empty()
    }

    /// Physical values of the template's free fields.
    pub fn values_of(&self, eye: &Eye) -> Vec<f64> {
        self.specs
            .iter()
            .enumerate()
            .map(|(i, s)| get(eye, s.field, self.elevation_slot[i]))
            .collect()
    }

    /// Normalised vector of `eye` (clamped into the box).
    pub fn unit_of(&self, eye: &Eye) -> Vec<f64> {
        let mut e = eye.clone();
        // Elevation slots refer to the template's layout.
        e.cornea.anterior.elevation = self.template.cornea.anterior.elevation.clone();
        e.cornea.posterior.elevation = self.template.cornea.posterior.elevation.clone();
        for (i, s) in self.specs.iter().enumerate() {
            if let Field::Elevation(surface, n, m) = s.field {
                let src = if surface == 0 {
                    &eye.cornea.anterior.elevation
                } else {
                    &eye.cornea.posterior.elevation
                };
                let v: f64 = src
                    .iter()
                    .filter(|t| t.n == n && t.m == m)
                    .map(|t| t.mm)
                    .sum();
                set(&mut e, s.field, self.elevation_slot[i], v);
            }
        }
        self.values_of(&e)
            .iter()
            .zip(&self.specs)
            .map(|(&v, s)| s.normalise(v).clamp(0.0, 1.0))
            .collect()
    }

    /// Writes the eye for normalised vector `unit` into `out` (reusing its allocations).
    pub fn write_eye(&self, unit: &[f64], out: &mut Eye) {
        out.clone_from(&self.template);
        for (i, s) in self.specs.iter().enumerate() {
            set(out, s.field, self.elevation_slot[i], s.denormalise(unit[i]));
        }
    }

    pub fn eye(&self, unit: &[f64]) -> Eye {
        let mut e = self.template.clone();
        self.write_eye(unit, &mut e);
        e
    }

    /// Sum of squared prior residuals at `unit`.
    pub fn prior_loss(&self, unit: &[f64], w_a: f64) -> f64 {
        self.specs
            .iter()
            .zip(unit)
            .map(|(s, &u)| s.prior_residual(s.denormalise(u), w_a).powi(2))
            .sum()
    }
}

fn get(eye: &Eye, field: Field, slot: usize) -> f64 {
    let c = &eye.cornea;
    match field {
        Field::AxialLength => eye.axial_length_mm,
        Field::CorneaThickness => c.thickness_mm,
        Field::AnteriorRadius(i) => c.anterior.radius_mm[i],
        Field::PosteriorRadius(i) => c.posterior.radius_mm[i],
        Field::AnteriorConic => c.anterior.conic,
        Field::PosteriorConic => c.posterior.conic,
        Field::AnteriorAxis => c.anterior.axis_deg,
        Field::PosteriorAxis => c.posterior.axis_deg,
        Field::AqueousDepth => eye.aqueous_depth_mm,
        Field::LensDiameter => eye.lens.diameter_mm,
        Field::LensVolume => eye.lens.volume_mm3,
        Field::LensAnteriorConic => eye.lens.anterior_conic,
        Field::LensPosteriorConic => eye.lens.posterior_conic,
        Field::LensDecentration(i) => eye.lens.decentration_mm[i],
        Field::LensTilt(i) => eye.lens.tilt_deg[i],
        Field::Elevation(0, ..) => c.anterior.elevation[slot].mm,
        Field::Elevation(..) => c.posterior.elevation[slot].mm,
    }
}

fn set(eye: &mut Eye, field: Field, slot: usize, v: f64) {
    let c = &mut eye.cornea;
    match field {
        Field::AxialLength => eye.axial_length_mm = v,
        Field::CorneaThickness => c.thickness_mm = v,
        Field::AnteriorRadius(i) => c.anterior.radius_mm[i] = v,
        Field::PosteriorRadius(i) => c.posterior.radius_mm[i] = v,
        Field::AnteriorConic => c.anterior.conic = v,
        Field::PosteriorConic => c.posterior.conic = v,
        Field::AnteriorAxis => c.anterior.axis_deg = v,
        Field::PosteriorAxis => c.posterior.axis_deg = v,
        Field::AqueousDepth => eye.aqueous_depth_mm = v,
        Field::LensDiameter => eye.lens.diameter_mm = v,
        Field::LensVolume => eye.lens.volume_mm3 = v,
        Field::LensAnteriorConic => eye.lens.anterior_conic = v,
        Field::LensPosteriorConic => eye.lens.posterior_conic = v,
        Field::LensDecentration(i) => eye.lens.decentration_mm[i] = v,
        Field::LensTilt(i) => eye.lens.tilt_deg[i] = v,
        Field::Elevation(0, ..) => c.anterior.elevation[slot].mm = v,
        Field::Elevation(..) => c.posterior.elevation[slot].mm = v,
    }
}
