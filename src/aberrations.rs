//! Zernike wavefront sets: file formats and built-in presets.
//!
//! All coefficients are OSA/ANSI (n, m) in µm over a pupil of `pupil_diameter_mm` measured at
//! `wavelength_nm`. Three file formats are read:
//!
//! **TOML (ocular's own)**, `*.toml`:
//! ```toml
//! pupil_diameter_mm = 5.0
//! wavelength_nm = 587.56
//!
//! [[term]]
//! n = 2
//! m = 0
//! um = 5.4127
//! ```
//! Repeated (n, m) are summed. Unknown keys are errors.
//!
//! **CSV**, `*.csv`: one `j,coefficient_um` pair per line, j the OSA single index (0 = piston).
//! Blank lines, lines starting with `#` and everything after a `#` later in a line (an inline
//! comment) are ignored, except the header lines `# pupil_mm = 5.0` (alias
//! `# pupil_diameter_mm = 5.0`; both spellings must agree where both appear) and
//! `# wavelength_nm = 550`, which set the pupil diameter and wavelength. A first line
//! `j,coefficient_um` (any case) is skipped. Pupil and wavelength given
//! to [`ZernikeSet::from_csv_str`] / [`ZernikeSet::load`] override the header lines; one of the
//! two sources must provide each.
//!
//! **ABP**, `*.abp` (the seed paper's framework): lines `Ap = <pupil mm>`, `Wa = <nm>` and
//! `Z[n, m] = <µm>`; blank lines and lines starting with `#`, `//` or `%` are ignored, and so
//! is an inline comment after a value (`Z[1, -1] = -1.150  # estimated`, also `//` or `%`), as
//! in the framework's own presets.
//!
//! A UTF-8 byte-order mark at the start of a CSV or ABP file is ignored.

use crate::optics::zernike::{is_valid_nm, num_terms, osa_index, osa_nm, rescale_pupil};
use serde::Deserialize;
use std::path::Path;

/// The line up to the first of `markers` (an inline or whole-line comment), trimmed. No value
/// in these formats contains a comment marker, so the first one always starts the comment.
fn strip_inline_comment<'a>(line: &'a str, markers: &[&str]) -> &'a str {
    let end = markers
        .iter()
        .filter_map(|m| line.find(m))
        .min()
        .unwrap_or(line.len());
    line[..end].trim()
}

fn without_bom(text: &str) -> &str {
    text.strip_prefix('\u{feff}').unwrap_or(text)
}

/// Highest order accepted in files.
pub const MAX_FILE_ORDER: u32 = 30;

/// A wavefront description: (n, m, µm) terms over a pupil at a wavelength.
#[derive(Debug, Clone, PartialEq)]
pub struct ZernikeSet {
    pub pupil_diameter_mm: f64,
    pub wavelength_nm: f64,
    pub coefficients: Vec<(u32, i32, f64)>,
}

/// Why a Zernike set could not be read; messages name the source (file), the line where known,
/// and what is allowed.
#[derive(Debug, thiserror::Error)]
pub enum AberrationError {
    #[error("{file}:{line}: {message}")]
    Parse {
        file: String,
        line: usize,
        message: String,
    },
    #[error("{file}: {message}")]
    Invalid { file: String, message: String },
    #[error("{file}: cannot read: {source}")]
    Io {
        file: String,
        #[source]
        source: std::io::Error,
    },
    #[error("unknown preset {name:?}; available: {available}")]
    UnknownPreset { name: String, available: String },
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct TomlFile {
    pupil_diameter_mm: f64,
    wavelength_nm: f64,
    #[serde(default)]
    term: Vec<toml::Spanned<TomlTerm>>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct TomlTerm {
    n: u32,
    m: i32,
    um: f64,
}

fn line_of(text: &str, byte: usize) -> usize {
    text[..byte.min(text.len())].matches('\n').count() + 1
}

fn check_pupil_wavelength(file: &str, pupil: f64, wl: f64) -> Result<(), AberrationError> {
    let invalid = |message| AberrationError::Invalid {
        file: file.into(),
        message,
    };
    crate::limits::PUPIL_MM
        .check("pupil diameter", pupil)
        .map_err(invalid)?;
    crate::limits::WAVELENGTH_NM
        .check("wavelength", wl)
        .map_err(invalid)?;
    Ok(())
}

/// An error at `file:line` from its message.
fn parse_error(file: &str, line: usize) -> impl Fn(String) -> AberrationError + '_ {
    move |message| AberrationError::Parse {
        file: file.into(),
        line,
        message,
    }
}

fn check_term(
    file: &str,
    line: usize,
    n: i64,
    m: i64,
    v: f64,
) -> Result<(u32, i32), AberrationError> {
    let err = parse_error(file, line);
    if n < 0 || n > MAX_FILE_ORDER as i64 || m.abs() > n || !is_valid_nm(n as u32, m as i32) {
        return Err(err(format!(
            "Zernike term (n, m) = ({n}, {m}) does not exist; need 0 <= n <= {MAX_FILE_ORDER}, |m| <= n, n - |m| even"
        )));
    }
    if !v.is_finite() || v.abs() > 1e3 {
        return Err(err(format!(
            "coefficient of ({n}, {m}) = {v} is not allowed; need a finite value, |c| <= 1000 um"
        )));
    }
    Ok((n as u32, m as i32))
}

impl ZernikeSet {
    /// Parse ocular's TOML format; `file` names the source in error messages.
    pub fn from_toml_str(text: &str, file: &str) -> Result<ZernikeSet, AberrationError> {
        let parsed: TomlFile = toml::from_str(text).map_err(|e| {
            let line = e.span().map(|s| line_of(text, s.start)).unwrap_or(0);
            parse_error(file, line)(format!(
                "{} (expected pupil_diameter_mm, wavelength_nm and [[term]] tables with n, m, um)",
                e.message()
            ))
        })?;
        check_pupil_wavelength(file, parsed.pupil_diameter_mm, parsed.wavelength_nm)?;
        let mut coefficients = Vec::with_capacity(parsed.term.len());
        for t in &parsed.term {
            let line = line_of(text, t.span().start);
            let v = t.get_ref();
            let (n, m) = check_term(file, line, v.n as i64, v.m as i64, v.um)?;
            coefficients.push((n, m, v.um));
        }
        Ok(ZernikeSet {
            pupil_diameter_mm: parsed.pupil_diameter_mm,
            wavelength_nm: parsed.wavelength_nm,
            coefficients,
        })
    }

    /// Parse CSV `j,coefficient_um`; `pupil_diameter_mm` / `wavelength_nm` override the
    /// `# key = value` header lines.
    pub fn from_csv_str(
        text: &str,
        file: &str,
        pupil_diameter_mm: Option<f64>,
        wavelength_nm: Option<f64>,
    ) -> Result<ZernikeSet, AberrationError> {
        let mut pupil = None;
        let mut wl = None;
        let mut coefficients = Vec::new();
        for (i, raw) in without_bom(text).lines().enumerate() {
            let line = i + 1;
            let s = raw.trim();
            if s.is_empty() {
                continue;
            }
            if let Some(c) = s.strip_prefix('#') {
                let c = strip_inline_comment(c, &["#"]);
                if let Some((k, v)) = c.split_once('=') {
                    let key = k.trim().to_ascii_lowercase();
                    let val: Option<f64> = v.trim().parse().ok();
                    let slot = match key.as_str() {
                        "pupil_mm" | "pupil_diameter_mm" => Some(&mut pupil),
                        "wavelength_nm" => Some(&mut wl),
                        _ => None,
                    };
                    if let Some(slot) = slot {
                        let val = val.ok_or_else(|| {
                            parse_error(file, line)(format!(
                                "{key} needs a number, got {:?}",
                                v.trim()
                            ))
                        })?;
                        if slot.is_some_and(|old| old != val) {
                            return Err(parse_error(file, line)(format!(
                                "{key} = {val} contradicts an earlier header line ({})",
                                slot.unwrap_or_default()
                            )));
                        }
                        *slot = Some(val);
                    }
                }
                continue;
            }
            let s = strip_inline_comment(s, &["#"]);
            if coefficients.is_empty()
                && s.to_ascii_lowercase().replace(' ', "") == "j,coefficient_um"
            {
                continue;
            }
            let err = parse_error(file, line);
            let (a, b) = s.split_once(',').ok_or_else(|| {
                err(format!(
                    "expected 'j,coefficient_um' (OSA index, micrometres), got {s:?}"
                ))
            })?;
            let j: usize = a.trim().parse().map_err(|_| {
                err(format!(
                    "OSA index {:?} is not a non-negative integer",
                    a.trim()
                ))
            })?;
            if j >= num_terms(MAX_FILE_ORDER) {
                return Err(err(format!(
                    "OSA index {j} is beyond order {MAX_FILE_ORDER} (need j < {})",
                    num_terms(MAX_FILE_ORDER)
                )));
            }
            let v: f64 = b
                .trim()
                .parse()
                .map_err(|_| err(format!("coefficient {:?} is not a number (um)", b.trim())))?;
            let (n, m) = osa_nm(j);
            check_term(file, line, n as i64, m as i64, v)?;
            coefficients.push((n, m, v));
        }
        let pupil = pupil_diameter_mm
            .or(pupil)
            .ok_or_else(|| AberrationError::Invalid {
                file: file.into(),
                message:
                    "pupil diameter not given: add a line '# pupil_mm = 5.0' (or '# pupil_diameter_mm = 5.0') or pass it"
                        .into(),
            })?;
        let wl = wavelength_nm
            .or(wl)
            .ok_or_else(|| AberrationError::Invalid {
                file: file.into(),
                message: "wavelength not given: add a line '# wavelength_nm = 550' or pass it"
                    .into(),
            })?;
        check_pupil_wavelength(file, pupil, wl)?;
        Ok(ZernikeSet {
            pupil_diameter_mm: pupil,
            wavelength_nm: wl,
            coefficients,
        })
    }

    /// Parse the `.abp` format (`Ap = `, `Wa = `, `Z[n, m] = `).
    pub fn from_abp_str(text: &str, file: &str) -> Result<ZernikeSet, AberrationError> {
        let mut pupil = None;
        let mut wl = None;
        let mut coefficients = Vec::new();
        for (i, raw) in without_bom(text).lines().enumerate() {
            let line = i + 1;
            let s = strip_inline_comment(raw, &["#", "//", "%"]);
            if s.is_empty() {
                continue;
            }
            let err = parse_error(file, line);
            let (k, v) = s.split_once('=').ok_or_else(|| {
                err(format!(
                    "expected 'Ap = mm', 'Wa = nm' or 'Z[n, m] = um', got {s:?}"
                ))
            })?;
            let k = k.trim();
            let val: f64 = v.trim().parse().map_err(|_| {
                err(format!(
                    "value {:?} is not a number (a number may be followed by a # comment)",
                    v.trim()
                ))
            })?;
            if k.eq_ignore_ascii_case("ap") {
                pupil = Some(val);
            } else if k.eq_ignore_ascii_case("wa") {
                wl = Some(val);
            } else if let Some(inner) = k
                .strip_prefix('Z')
                .or_else(|| k.strip_prefix('z'))
                .and_then(|r| r.trim().strip_prefix('['))
                .and_then(|r| r.strip_suffix(']'))
            {
                let (a, b) = inner
                    .split_once(',')
                    .ok_or_else(|| err(format!("expected Z[n, m], got {k:?}")))?;
                let n: i64 = a
                    .trim()
                    .parse()
                    .map_err(|_| err(format!("n {:?} is not an integer", a.trim())))?;
                let m: i64 = b
                    .trim()
                    .parse()
                    .map_err(|_| err(format!("m {:?} is not an integer", b.trim())))?;
                let (n, m) = check_term(file, line, n, m, val)?;
                coefficients.push((n, m, val));
            } else {
                return Err(err(format!(
                    "unknown key {k:?}; allowed: Ap (pupil mm), Wa (wavelength nm), Z[n, m] (um)"
                )));
            }
        }
        let pupil = pupil.ok_or_else(|| AberrationError::Invalid {
            file: file.into(),
            message: "missing 'Ap = <pupil diameter mm>'".into(),
        })?;
        let wl = wl.ok_or_else(|| AberrationError::Invalid {
            file: file.into(),
            message: "missing 'Wa = <wavelength nm>'".into(),
        })?;
        check_pupil_wavelength(file, pupil, wl)?;
        Ok(ZernikeSet {
            pupil_diameter_mm: pupil,
            wavelength_nm: wl,
            coefficients,
        })
    }

    /// Read a file, choosing the format by extension (.toml, .csv, .abp). Pupil and wavelength
    /// overrides apply to CSV (and replace the file's values for the other formats).
    pub fn load(
        path: &Path,
        pupil_diameter_mm: Option<f64>,
        wavelength_nm: Option<f64>,
    ) -> Result<ZernikeSet, AberrationError> {
        let file = path.display().to_string();
        let text = std::fs::read_to_string(path).map_err(|source| AberrationError::Io {
            file: file.clone(),
            source,
        })?;
        // Spreadsheet programs save CSV (and editors sometimes TOML) with a UTF-8 byte-order
        // mark; it is not part of the first field.
        let text = text.strip_prefix('\u{feff}').unwrap_or(&text);
        let ext = path
            .extension()
            .and_then(|e| e.to_str())
            .unwrap_or("")
            .to_ascii_lowercase();
        let mut set = match ext.as_str() {
            "toml" => Self::from_toml_str(text, &file)?,
            "csv" => return Self::from_csv_str(text, &file, pupil_diameter_mm, wavelength_nm),
            "abp" => Self::from_abp_str(text, &file)?,
            _ => {
                return Err(AberrationError::Invalid {
                    file,
                    message: format!("unknown extension {ext:?}; allowed: .toml, .csv, .abp"),
                })
            }
        };
        if let Some(p) = pupil_diameter_mm {
            set.pupil_diameter_mm = p;
        }
        if let Some(w) = wavelength_nm {
            set.wavelength_nm = w;
        }
        check_pupil_wavelength(&file, set.pupil_diameter_mm, set.wavelength_nm)?;
        Ok(set)
    }

    /// Highest order present (0 when empty).
    pub fn max_order(&self) -> u32 {
        self.coefficients.iter().map(|c| c.0).max().unwrap_or(0)
    }

    /// OSA-ordered coefficient vector (repeated terms summed), orders 0..=max(max_order, min_order).
    pub fn osa_vector(&self, min_order: u32) -> Vec<f64> {
        let mut v = vec![0.0; num_terms(self.max_order().max(min_order))];
        for &(n, m, c) in &self.coefficients {
            v[osa_index(n, m)] += c;
        }
        v
    }

    /// The same wavefront described over a smaller concentric pupil (exact rescaling).
    pub fn with_pupil(&self, pupil_diameter_mm: f64) -> Result<ZernikeSet, AberrationError> {
        let c = rescale_pupil(
            &self.osa_vector(0),
            pupil_diameter_mm / self.pupil_diameter_mm,
        )
        .map_err(|e| AberrationError::Invalid {
            file: "<rescale>".into(),
            message: e.to_string(),
        })?;
        let coefficients = c
            .iter()
            .enumerate()
            .filter(|(_, v)| **v != 0.0)
            .map(|(j, v)| {
                let (n, m) = osa_nm(j);
                (n, m, *v)
            })
            .collect();
        Ok(ZernikeSet {
            pupil_diameter_mm,
            wavelength_nm: self.wavelength_nm,
            coefficients,
        })
    }

    /// Write in ocular's TOML format (round-trips through [`ZernikeSet::from_toml_str`]).
    pub fn to_toml_string(&self) -> String {
        let mut s = format!(
            "pupil_diameter_mm = {:?}\nwavelength_nm = {:?}\n",
            self.pupil_diameter_mm, self.wavelength_nm
        );
        for &(n, m, v) in &self.coefficients {
            s.push_str(&format!("\n[[term]]\nn = {n}\nm = {m}\num = {v:?}\n"));
        }
        s
    }
}

const PRESETS: [(&str, &str); 5] = [
    (
        "healthy",
        include_str!("../scenes/aberrations/healthy.toml"),
    ),
    ("myopia", include_str!("../scenes/aberrations/myopia.toml")),
    (
        "myopia3",
        include_str!("../scenes/aberrations/myopia3.toml"),
    ),
    (
        "astigmatism",
        include_str!("../scenes/aberrations/astigmatism.toml"),
    ),
    (
        "keratoconus",
        include_str!("../scenes/aberrations/keratoconus.toml"),
    ),
];

/// Names of the built-in presets.
pub fn preset_names() -> Vec<&'static str> {
    PRESETS.iter().map(|p| p.0).collect()
}

/// A built-in preset (the seed paper's test eyes), embedded in the binary.
pub fn preset(name: &str) -> Result<ZernikeSet, AberrationError> {
    let key = name.trim().to_ascii_lowercase();
    match PRESETS.iter().find(|p| p.0 == key) {
        Some((n, text)) => ZernikeSet::from_toml_str(text, &format!("preset {n}")),
        None => Err(AberrationError::UnknownPreset {
            name: name.into(),
            available: preset_names().join(", "),
        }),
    }
}
