//! The options that put a correction in front of the eye (or an IOL in it) and limit its
//! accommodation, shared by render, video, compare, kernels and `eye measure`. Each value is
//! range-checked where clap parses it, so a bad one is a one-line error naming the option.

use crate::eye::age::{HofstetterLine, MAX_AMPLITUDE_D};
use crate::eye::correction::{parse_rx, Spectacle, DEFAULT_VERTEX_MM};
use crate::eye::Eye;
use crate::render::frame_plan::{corrected_eye, Correction};
pub use crate::render::frame_plan::{IolPower, Physiology};
use crate::{Error, Result};

#[derive(clap::Args, Debug, Clone, Default)]
pub struct CorrectionArgs {
    /// Spectacle lens in front of the eye, "S C x A": sphere and cylinder in dioptres
    /// (sphere -25 to 25, cylinder -10 to 10; minus-cylinder form, a plus cylinder is
    /// transposed) and axis 1 to 180 degrees. It is traced with the eye (kernels, focus,
    /// measurement), not applied to the image.
    #[arg(long, value_name = "S C x A", value_parser = parse_correct, allow_hyphen_values = true)]
    pub correct: Option<Spectacle>,
    /// Vertex distance of --correct, lens to cornea, in mm (0 to 16; default 12).
    #[arg(long, value_name = "MM", value_parser = parse_vertex_mm, requires = "correct", allow_hyphen_values = true)]
    pub vertex_mm: Option<f64>,
    /// --correct is a contact lens (vertex distance 0).
    #[arg(long, requires = "correct", conflicts_with = "vertex_mm")]
    pub correct_contact: bool,
    /// Monofocal intraocular lens in place of the crystalline lens: its power in dioptres
    /// (-10 to 40), or `auto` for the power that makes the eye emmetropic (3 mm pupil,
    /// 549 nm). An IOL does not accommodate.
    #[arg(long, value_name = "D|auto", value_parser = parse_iol, allow_hyphen_values = true)]
    pub iol_d: Option<IolPower>,
    /// Amplitude of accommodation in dioptres (0 to 20), instead of the eye file's
    /// accommodation_max_d or the age model's.
    #[arg(long, value_name = "D", value_parser = parse_amplitude_d, allow_hyphen_values = true)]
    pub accommodation_max_d: Option<f64>,
}

/// A finite number from an option's text (clap value parsers of correction and refract).
pub(super) fn number(text: &str) -> std::result::Result<f64, String> {
    text.trim()
        .parse::<f64>()
        .ok()
        .filter(|v| v.is_finite())
        .ok_or_else(|| format!("{text:?} is not a number"))
}

fn range(v: f64, (lo, hi): (f64, f64), unit: &str) -> std::result::Result<f64, String> {
    if v >= lo && v <= hi {
        Ok(v)
    } else {
        Err(format!("{v} is outside {lo} to {hi} {unit}"))
    }
}

pub(super) fn parse_correct(text: &str) -> std::result::Result<Spectacle, String> {
    parse_rx(text, DEFAULT_VERTEX_MM)
}

fn parse_vertex_mm(text: &str) -> std::result::Result<f64, String> {
    crate::render::frame_plan::check_vertex_mm(number(text)?)
}

fn parse_iol(text: &str) -> std::result::Result<IolPower, String> {
    IolPower::parse(text)
}

pub(crate) fn parse_amplitude_d(text: &str) -> std::result::Result<f64, String> {
    range(number(text)?, (0.0, MAX_AMPLITUDE_D), "D")
}

impl CorrectionArgs {
    /// Whether any correction option was given.
    pub fn corrects(&self) -> bool {
        self.correct.is_some() || self.iol_d.is_some()
    }

    /// `eye` with the correction, the IOL and the amplitude of accommodation these options
    /// (and `age`, when the command has one) give it.
    pub fn apply(
        &self,
        eye: &Eye,
        age: Option<(f64, HofstetterLine)>,
    ) -> Result<(Eye, Physiology)> {
        corrected_eye(eye, &self.correction(), age)
    }

    /// The correction these options describe.
    pub fn correction(&self) -> Correction {
        Correction {
            spectacle: self.correct,
            vertex_mm: self.vertex_mm,
            contact: self.correct_contact,
            iol: self.iol_d,
            accommodation_max_d: self.accommodation_max_d,
        }
    }
}

impl CorrectionArgs {
    /// The eyes of a side-by-side export, labelled: `--eye` with these options, and the
    /// `--side-by-side` eye (`uncorrected`: the same eye without the correction) with only the
    /// amplitude options.
    pub fn labelled_eyes(
        &self,
        spec: &str,
        eye: Eye,
        side_by_side: Option<&str>,
        load: impl Fn(&str) -> Result<Eye>,
        age: Option<(f64, HofstetterLine)>,
    ) -> Result<Vec<(String, Eye)>> {
        let (corrected, physiology) = self.apply(&eye, age)?;
        // Labels fit a panel: the prescription alone when the other panel is the same eye.
        let same = side_by_side.is_some_and(|o| o.eq_ignore_ascii_case("uncorrected"));
        let what = match (&e_notation(&corrected), physiology.iol_d) {
            (Some(c), _) => Some(c.clone()),
            (None, Some(p)) => Some(format!("IOL {p:.1} D")),
            _ => None,
        };
        let label = match (what, same) {
            (Some(w), true) => w,
            (Some(w), false) => format!("{spec} {w}"),
            (None, _) => spec.to_string(),
        };
        let mut eyes = vec![(label, corrected)];
        if let Some(other) = side_by_side {
            let (e, label) = if other.eq_ignore_ascii_case("uncorrected") {
                if !self.corrects() {
                    return Err(Error::input(
                        "--side-by-side uncorrected compares with --correct or --iol-d; neither is given",
                    ));
                }
                (eye, "uncorrected".to_string())
            } else {
                (load(other)?, other.to_string())
            };
            let plain = CorrectionArgs {
                accommodation_max_d: self.accommodation_max_d,
                ..Default::default()
            };
            eyes.push((label, plain.apply(&e, age)?.0));
        }
        Ok(eyes)
    }
}

fn e_notation(eye: &Eye) -> Option<String> {
    eye.correction.map(|s| s.notation())
}

/// Checks a vertex distance given outside `CorrectionArgs` (`eye refract`).
pub(crate) fn parse_vertex_option(text: &str) -> std::result::Result<f64, String> {
    parse_vertex_mm(text)
}
