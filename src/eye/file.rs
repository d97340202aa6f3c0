//! Eye files: the structure of an eye (`[eye]`) and, for estimated eyes, the record of the fit
//! (`[estimate]`: input, achieved coefficients, residuals, loss, settings, convergence), as
//! TOML. A bare structure without the `[eye]` wrapper is read as well. Named eyes (presets)
//! resolve before files, so `ocular eye show myopia` needs no path.

use super::error::EyeError;
use super::estimate::Report;
use super::model::Eye;
use serde::{Deserialize, Serialize};
use std::path::Path;

/// An eye with the record of how it was estimated, when it was.
#[derive(Debug, Clone, PartialEq)]
pub struct EyeFile {
    pub eye: Eye,
    pub estimate: Option<Report>,
}

#[derive(Serialize)]
struct Out<'a> {
    eye: &'a Eye,
    #[serde(skip_serializing_if = "Option::is_none")]
    estimate: Option<&'a Report>,
}

#[derive(Deserialize)]
struct In {
    estimate: Option<Report>,
}

/// Estimated eyes shipped with ocular (text under scenes/eyes/, each reproducible with the
/// command in its header).
const ESTIMATED: [(&str, &str); 4] = [
    ("healthy", include_str!("../../scenes/eyes/healthy.toml")),
    ("myopia", include_str!("../../scenes/eyes/myopia.toml")),
    (
        "astigmatism",
        include_str!("../../scenes/eyes/astigmatism.toml"),
    ),
    (
        "keratoconus",
        include_str!("../../scenes/eyes/keratoconus.toml"),
    ),
];

/// Names of every eye preset: the built-in structures and the estimated eyes.
pub fn preset_names() -> Vec<&'static str> {
    super::presets::PRESET_NAMES.to_vec()
}

/// An eye preset by name (case-insensitive), with its estimate record where it has one.
pub fn preset(name: &str) -> Option<EyeFile> {
    let key = name.trim().to_ascii_lowercase();
    if let Some(eye) = super::presets::builtin_preset(&key) {
        return Some(EyeFile {
            eye,
            estimate: None,
        });
    }
    ESTIMATED
        .iter()
        .find(|e| e.0 == key)
        .map(|e| parse(e.1).expect("shipped eye presets are valid"))
}

// Here rather than with the built-in presets: the estimated eyes are files, and this module
// already reads both kinds.
impl Eye {
    /// A preset by name: `navarro`, `navarro-wide`, `mean`, or one of the estimated eyes (`healthy`,
    /// `myopia`, `astigmatism`, `keratoconus`; see `eye::file`).
    pub fn preset(name: &str) -> Option<Eye> {
        super::presets::builtin_preset(name).or_else(|| preset(name).map(|f| f.eye))
    }
}

/// Parses an eye file's text.
pub fn parse(text: &str) -> Result<EyeFile, EyeError> {
    let eye = Eye::from_toml_str(text)?;
    let record: In = toml::from_str(text)
        .map_err(|e| EyeError::Invalid(format!("eye file: [estimate]: {}", e.message())))?;
    Ok(EyeFile {
        eye,
        estimate: record.estimate,
    })
}

/// Reads an eye file; errors name the file.
pub fn load(path: &Path) -> crate::Result<EyeFile> {
    let text = std::fs::read_to_string(path).map_err(|e| crate::Error::file(path, e))?;
    parse(&text).map_err(|e| crate::Error::file(path, e))
}

/// A preset name, or else a path to an eye file.
pub fn resolve(spec: &str) -> crate::Result<EyeFile> {
    if let Some(f) = preset(spec) {
        return Ok(f);
    }
    // The hand-made eyes of the kernel benchmarks are accepted too, but not advertised.
    if let Some(eye) = super::hand_made_eyes::hand_made_eye(spec) {
        return Ok(EyeFile {
            eye,
            estimate: None,
        });
    }
    let path = Path::new(spec);
    if !path.exists() {
        return Err(crate::Error::input(format!(
            "eye {spec:?} is neither a preset ({}) nor an existing file",
            preset_names().join(", ")
        )));
    }
    load(path)
}

/// The eye file text: `header` lines become comments at the top.
pub fn to_toml(eye: &Eye, estimate: Option<&Report>, header: &str) -> String {
    let mut s = String::new();
    for line in header.lines() {
        s.push_str("# ");
        s.push_str(line);
        s.push('\n');
    }
    if !header.is_empty() {
        s.push('\n');
    }
    s.push_str(
        &toml::to_string_pretty(&Out { eye, estimate }).expect("an eye file always serialises"),
    );
    s
}
