//! Spectacle prescriptions (sphere, cylinder, axis) and their second-order Zernike terms.

use std::fmt;

/// A spectacle prescription: sphere and cylinder in dioptres, cylinder axis in degrees
/// (TABO convention, counter-clockwise from the +x axis, the same θ as the Zernike terms).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Prescription {
    pub sphere_d: f64,
    pub cylinder_d: f64,
    pub axis_deg: f64,
}

/// Why a prescription string could not be read.
#[derive(Debug, Clone, PartialEq)]
pub struct PrescriptionError(pub String);

impl fmt::Display for PrescriptionError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}", self.0)
    }
}

impl std::error::Error for PrescriptionError {}

const RX_FORMS: &str = "expected \"S\", \"S DS\", \"S C x A\" or \"S/C x A\" \
                        (dioptres, axis 0-180 degrees), e.g. \"-6 -3 x 102\" or \"+1.5 DS\"";

impl Prescription {
    pub fn new(sphere_d: f64, cylinder_d: f64, axis_deg: f64) -> Self {
        Prescription {
            sphere_d,
            cylinder_d,
            axis_deg,
        }
    }

    /// Parse strings such as "-6 -3 x 102", "-6.00/-3.00x102", "+1.5 DS", "plano",
    /// "-2.00 DS / -0.75 DC x 180" or "-1 -0.5 @ 45".
    pub fn parse(text: &str) -> Result<Prescription, PrescriptionError> {
        let err =
            |what: &str| PrescriptionError(format!("prescription {text:?}: {what}; {RX_FORMS}"));
        let lower = text.trim().to_ascii_lowercase();
        if lower.is_empty() {
            return Err(err("empty"));
        }
        let cleaned = lower
            .replace("plano", "0")
            .replace("pl", "0")
            .replace("ds", " ")
            .replace("dc", " ")
            .replace(['×', '@', '*'], "x");
        let (powers, axis) = match cleaned.split_once('x') {
            Some((p, a)) => (p.to_string(), Some(a.trim().to_string())),
            None => (cleaned.clone(), None),
        };
        // Tokenise the powers: a sign starts a new number, '/' ',' and spaces separate.
        let mut nums: Vec<String> = Vec::new();
        let mut cur = String::new();
        for ch in powers.chars() {
            match ch {
                '+' | '-' => {
                    if !cur.is_empty() {
                        nums.push(std::mem::take(&mut cur));
                    }
                    cur.push(ch);
                }
                '0'..='9' | '.' => cur.push(ch),
                ' ' | '/' | ',' | '\t' | 'd' => {
                    if !cur.is_empty() {
                        nums.push(std::mem::take(&mut cur));
                    }
                }
                _ => return Err(err(&format!("unexpected character {ch:?}"))),
            }
        }
        if !cur.is_empty() {
            nums.push(cur);
        }
        let parse_num = |s: &str, what: &str| -> Result<f64, PrescriptionError> {
            let v: f64 = s
                .parse()
                .map_err(|_| err(&format!("{what} {s:?} is not a number")))?;
            if !v.is_finite() {
                return Err(err(&format!("{what} must be finite")));
            }
            Ok(v)
        };
        let (sphere, cyl) = match nums.len() {
            1 => (parse_num(&nums[0], "sphere")?, 0.0),
            2 => (
                parse_num(&nums[0], "sphere")?,
                parse_num(&nums[1], "cylinder")?,
            ),
            0 => return Err(err("no sphere power")),
            _ => return Err(err("more than two powers")),
        };
        let axis_v = match axis {
            Some(a) => {
                if a.is_empty() {
                    return Err(err("axis missing after 'x'"));
                }
                let a = a.trim_end_matches(['°', ' ']);
                let v = parse_num(a, "axis")?;
                if !(0.0..=180.0).contains(&v) {
                    return Err(err(&format!("axis {v} outside 0-180 degrees")));
                }
                v
            }
            None => {
                if cyl != 0.0 {
                    return Err(err("cylinder given without an axis"));
                }
                0.0
            }
        };
        if sphere.abs() > 40.0 || cyl.abs() > 20.0 {
            return Err(err("power beyond ±40 D sphere / ±20 D cylinder"));
        }
        Ok(Prescription::new(sphere, cyl, axis_v))
    }

    /// The same refraction in minus-cylinder form with the axis in [0, 180).
    pub fn to_minus_cylinder(self) -> Prescription {
        let (s, c, a) = if self.cylinder_d > 0.0 {
            (
                self.sphere_d + self.cylinder_d,
                -self.cylinder_d,
                self.axis_deg + 90.0,
            )
        } else {
            (self.sphere_d, self.cylinder_d, self.axis_deg)
        };
        let mut a = a.rem_euclid(180.0);
        if a >= 180.0 - 1e-12 {
            a = 0.0;
        }
        Prescription::new(s, c, a)
    }

    /// Zernike (c(2,−2), c(2,0), c(2,2)) in µm for a pupil of the given diameter (mm):
    /// c(2,0) = −R²(S + C/2)/(4√3), c(2,−2) = R²C sin2A/(4√6), c(2,2) = R²C cos2A/(4√6),
    /// R = pupil radius in mm.
    pub fn to_zernike(self, pupil_diameter_mm: f64) -> [f64; 3] {
        let r2 = 0.25 * pupil_diameter_mm * pupil_diameter_mm;
        let a = 2.0 * self.axis_deg.to_radians();
        let c20 = -r2 * (self.sphere_d + 0.5 * self.cylinder_d) / (4.0 * 3f64.sqrt());
        let k = r2 * self.cylinder_d / (4.0 * 6f64.sqrt());
        [k * a.sin(), c20, k * a.cos()]
    }

    /// OSA coefficient vector (orders 0..=2) holding only this prescription.
    pub fn to_osa_coefficients(self, pupil_diameter_mm: f64) -> Vec<f64> {
        let [cm, c0, cp] = self.to_zernike(pupil_diameter_mm);
        let mut v = vec![0.0; 6];
        v[3] = cm;
        v[4] = c0;
        v[5] = cp;
        v
    }

    /// Prescription (minus-cylinder form, axis in [0, 180)) correcting second-order
    /// coefficients c(2,−2), c(2,0), c(2,2) in µm over a pupil of the given diameter (mm).
    pub fn from_zernike(c2m2: f64, c20: f64, c22: f64, pupil_diameter_mm: f64) -> Prescription {
        let r2 = 0.25 * pupil_diameter_mm * pupil_diameter_mm;
        let ks = 4.0 * 6f64.sqrt() / r2;
        let cs = ks * c2m2; // C sin 2A
        let cc = ks * c22; // C cos 2A
        let mag = cs.hypot(cc);
        let (cyl, axis) = if mag < 1e-12 {
            (0.0, 0.0)
        } else {
            // minus cylinder: C = −|C|, so sin2A = −cs/|C|, cos2A = −cc/|C|
            let two_a = (-cs).atan2(-cc);
            (-mag, (0.5 * two_a.to_degrees()).rem_euclid(180.0))
        };
        let sphere = -4.0 * 3f64.sqrt() * c20 / r2 - 0.5 * cyl;
        let axis = if axis >= 180.0 - 1e-9 { 0.0 } else { axis };
        Prescription::new(sphere, cyl, axis)
    }

    /// Same as [`Prescription::from_zernike`] from an OSA vector (needs at least 6 entries).
    pub fn from_osa_coefficients(coeffs: &[f64], pupil_diameter_mm: f64) -> Option<Prescription> {
        if coeffs.len() < 6 {
            return None;
        }
        Some(Self::from_zernike(
            coeffs[3],
            coeffs[4],
            coeffs[5],
            pupil_diameter_mm,
        ))
    }

    /// Spherical equivalent S + C/2.
    pub fn spherical_equivalent_d(self) -> f64 {
        self.sphere_d + 0.5 * self.cylinder_d
    }
}

impl fmt::Display for Prescription {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        if self.cylinder_d == 0.0 {
            write!(f, "{:+.2} DS", self.sphere_d)
        } else {
            write!(
                f,
                "{:+.2} {:+.2} x {:.0}",
                self.sphere_d, self.cylinder_d, self.axis_deg
            )
        }
    }
}
