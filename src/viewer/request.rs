//! A client's settings: parsed from its JSON, checked as the CLI checks its options (with the
//! CLI's option names in every message), and turned back into the equivalent command line.

use serde::Deserialize;

use super::catalog::Catalog;
use crate::eye::correction::{parse_rx, DEFAULT_VERTEX_MM};
use crate::render::frame::Method;
use crate::render::frame_plan::{check_vertex_mm, Correction, FocusAsked, IolPower};
use crate::render::live::LiveOptions;
use crate::render::splat::Quality;

/// What a server allows a client to ask for.
#[derive(Clone, Copy, Debug)]
pub struct Bounds {
    /// Largest frame, width × height.
    pub max_pixels: u64,
    pub max_side_px: u32,
    pub max_layers: u32,
}

/// The settings a page sends with every change.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SettingsIn {
    pub scene: String,
    pub size: [u32; 2],
    pub a: SideIn,
    #[serde(default)]
    pub b: Option<SideIn>,
    #[serde(default)]
    pub focus: FocusIn,
    #[serde(default)]
    pub pupil: PupilIn,
    pub age: f64,
    pub quality: String,
    #[serde(default = "one")]
    pub layers: u32,
    #[serde(default)]
    pub off_axis: bool,
    #[serde(default)]
    pub time_s: f64,
    /// `a` is the left eye and `b` (or `a` again) the right of one binocular pair: two eyes at
    /// their own positions, converged on the focus, sharing one accommodation.
    #[serde(default)]
    pub binocular: bool,
    /// The pair's interpupillary distance (default 63 mm).
    #[serde(default)]
    pub ipd_mm: Option<f64>,
}

fn one() -> u32 {
    1
}

/// One eye of the view (two when comparing), with what is put in front of it.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SideIn {
    pub eye: EyeIn,
    #[serde(default)]
    pub correction: CorrectionIn,
}

#[derive(Deserialize)]
#[serde(tag = "kind", rename_all = "lowercase", deny_unknown_fields)]
pub enum EyeIn {
    Preset {
        name: String,
    },
    File {
        name: String,
    },
    /// A prescription "S C x A" measured at `pupil_mm`: an eye is estimated from it.
    Rx {
        rx: String,
        pupil_mm: f64,
    },
}

#[derive(Deserialize, Default)]
#[serde(tag = "kind", rename_all = "lowercase", deny_unknown_fields)]
pub enum CorrectionIn {
    #[default]
    None,
    Glasses {
        rx: String,
        #[serde(default)]
        vertex_mm: Option<f64>,
    },
    Contact {
        rx: String,
    },
    /// `power`: dioptres, or `auto` for the emmetropic power.
    Iol {
        power: String,
    },
}

#[derive(Deserialize, Default)]
#[serde(tag = "mode", rename_all = "lowercase", deny_unknown_fields)]
pub enum FocusIn {
    /// The scene's focus, else the depth at the frame's centre.
    #[default]
    Scene,
    D {
        d: f64,
    },
    /// The depth under pixel (x, y) of the full frame.
    At {
        x: u32,
        y: u32,
    },
}

#[derive(Deserialize, Default)]
#[serde(tag = "mode", rename_all = "lowercase", deny_unknown_fields)]
pub enum PupilIn {
    /// The scene's pupil or luminance, else the frame's mean luminance.
    #[default]
    Auto,
    Mm {
        mm: f64,
    },
    Luminance {
        cdm2: f64,
    },
}

/// An eye as a client chose it.
#[derive(Clone, Debug, PartialEq)]
pub enum EyeChoice {
    Preset(String),
    File(String),
    Rx { rx: String, pupil_mm: f64 },
}

/// One checked side.
#[derive(Clone, Debug)]
pub struct Side {
    pub eye: EyeChoice,
    pub correction: Correction,
    /// The correction's options as `ocular render` takes them.
    correction_cli: Vec<String>,
}

/// A checked request: everything a frame needs, every value in range.
#[derive(Clone, Debug)]
pub struct ViewRequest {
    pub scene: String,
    pub size: (u32, u32),
    pub sides: Vec<Side>,
    /// Options shared by the sides (their corrections are each side's own).
    pub options: LiveOptions,
    pub time_s: f64,
    /// A binocular pair's interpupillary distance (mm): `sides` are then left and right.
    pub binocular_ipd_mm: Option<f64>,
}

type Checked<T> = std::result::Result<T, String>;

fn check_eye(e: EyeIn, catalog: &Catalog) -> Checked<EyeChoice> {
    match e {
        EyeIn::Preset { name } => {
            let presets = crate::eye::file::preset_names();
            // only the listed names: `resolve` would take a path too
            match presets.iter().find(|p| p.eq_ignore_ascii_case(name.trim())) {
                Some(p) => Ok(EyeChoice::Preset(p.to_string())),
                None => Err(format!(
                    "--eye {name:?} is not a preset ({})",
                    presets.join(", ")
                )),
            }
        }
        EyeIn::File { name } => {
            if catalog.eye_files.contains_key(&name) {
                Ok(EyeChoice::File(name))
            } else if catalog.eye_files.is_empty() {
                Err(format!(
                    "--eye {name:?}: this server has no eye files (start it with --eyes FOLDER)"
                ))
            } else {
                Err(format!(
                    "--eye {name:?} is not an eye file of this server ({})",
                    catalog
                        .eye_files
                        .keys()
                        .cloned()
                        .collect::<Vec<_>>()
                        .join(", ")
                ))
            }
        }
        EyeIn::Rx { rx, pupil_mm } => {
            crate::limits::PUPIL_MM
                .check("the prescription's --pupil-mm", pupil_mm)
                .map_err(|e| format!("--rx {rx:?}: {e}"))?;
            // the checks `ocular eye estimate --rx` makes, before any fitting
            crate::eye::estimate::prescription::RxTarget::new(&rx, pupil_mm, None, None).map_err(
                |e| {
                    let text = e.to_string();
                    let text = text.strip_prefix("--rx: ").unwrap_or(&text).to_string();
                    format!("--rx {rx:?}: {text}")
                },
            )?;
            Ok(EyeChoice::Rx {
                rx: rx.trim().to_string(),
                pupil_mm,
            })
        }
    }
}

fn check_correction(c: CorrectionIn) -> Checked<(Correction, Vec<String>)> {
    Ok(match c {
        CorrectionIn::None => (Correction::default(), Vec::new()),
        CorrectionIn::Glasses { rx, vertex_mm } => {
            let vertex = check_vertex_mm(vertex_mm.unwrap_or(DEFAULT_VERTEX_MM))
                .map_err(|e| format!("--vertex-mm: {e}"))?;
            let s = parse_rx(&rx, vertex).map_err(|e| format!("--correct {rx:?}: {e}"))?;
            (
                Correction {
                    spectacle: Some(s),
                    vertex_mm: Some(vertex),
                    ..Correction::default()
                },
                vec![
                    "--correct".into(),
                    rx.trim().into(),
                    "--vertex-mm".into(),
                    format!("{vertex}"),
                ],
            )
        }
        CorrectionIn::Contact { rx } => {
            let s = parse_rx(&rx, 0.0).map_err(|e| format!("--correct {rx:?}: {e}"))?;
            (
                Correction {
                    spectacle: Some(s),
                    contact: true,
                    ..Correction::default()
                },
                vec![
                    "--correct".into(),
                    rx.trim().into(),
                    "--correct-contact".into(),
                ],
            )
        }
        CorrectionIn::Iol { power } => {
            let iol = IolPower::parse(&power).map_err(|e| format!("--iol-d {power:?}: {e}"))?;
            (
                Correction {
                    iol: Some(iol),
                    ..Correction::default()
                },
                vec!["--iol-d".into(), power.trim().to_ascii_lowercase()],
            )
        }
    })
}

fn check_side(s: SideIn, catalog: &Catalog) -> Checked<Side> {
    let eye = check_eye(s.eye, catalog)?;
    let (correction, correction_cli) = check_correction(s.correction)?;
    Ok(Side {
        eye,
        correction,
        correction_cli,
    })
}

fn check_size([w, h]: [u32; 2], bounds: &Bounds) -> Checked<(u32, u32)> {
    let lo = crate::limits::MIN_FRAME_SIDE;
    let hi = bounds.max_side_px;
    if !(lo..=hi).contains(&w) || !(lo..=hi).contains(&h) {
        return Err(format!(
            "--size {w}x{h}: each side must be {lo} to {hi} pixels"
        ));
    }
    if u64::from(w) * u64::from(h) > bounds.max_pixels {
        return Err(format!(
            "--size {w}x{h}: this server renders at most {} pixels a frame (its --max-pixels)",
            bounds.max_pixels
        ));
    }
    Ok((w, h))
}

impl ViewRequest {
    /// Checks what a client sent; the error is the CLI's one-line message.
    pub fn check(s: SettingsIn, catalog: &Catalog, bounds: &Bounds) -> Checked<ViewRequest> {
        if !catalog.scenes.contains_key(&s.scene) {
            return Err(format!(
                "--scene {:?} is not a scene of this server ({})",
                s.scene,
                catalog
                    .scenes
                    .keys()
                    .cloned()
                    .collect::<Vec<_>>()
                    .join(", ")
            ));
        }
        let size = check_size(s.size, bounds)?;
        let mut sides = vec![check_side(s.a, catalog)?];
        if let Some(b) = s.b {
            sides.push(check_side(b, catalog).map_err(|e| format!("second eye: {e}"))?);
        }
        let binocular_ipd_mm = if s.binocular {
            if sides.len() == 1 {
                sides.push(sides[0].clone());
            }
            check_pair(&sides, s.off_axis)?;
            Some(match s.ipd_mm {
                Some(ipd) => crate::render::binocular::check_ipd_mm(ipd)?,
                None => crate::render::binocular::DEFAULT_IPD_MM,
            })
        } else {
            if s.ipd_mm.is_some() {
                return Err("--ipd-mm applies to two eyes: choose the binocular pair".into());
            }
            None
        };
        let focus = match s.focus {
            FocusIn::Scene => None,
            FocusIn::D { d } => {
                if !(d.is_finite()
                    && (0.0..=crate::render::focus::MAX_OBJECT_VERGENCE_D).contains(&d))
                {
                    return Err(format!(
                        "--focus-d {d} is outside 0 to {} D",
                        crate::render::focus::MAX_OBJECT_VERGENCE_D
                    ));
                }
                Some(FocusAsked::Dioptres(d))
            }
            FocusIn::At { x, y } => {
                if x >= size.0 || y >= size.1 {
                    return Err(format!(
                        "--focus-at {x},{y} lies outside the {}x{} frame",
                        size.0, size.1
                    ));
                }
                Some(FocusAsked::AtPixel(x, y))
            }
        };
        let (pupil_mm, luminance_cdm2) = match s.pupil {
            PupilIn::Auto => (None, None),
            PupilIn::Mm { mm } => (Some(crate::limits::PUPIL_MM.check("--pupil-mm", mm)?), None),
            PupilIn::Luminance { cdm2 } => {
                if !(cdm2.is_finite() && cdm2 >= 0.0) {
                    return Err(format!(
                        "--luminance-cdm2 {cdm2} must be a non-negative number of cd/m²"
                    ));
                }
                (None, Some(cdm2))
            }
        };
        let age = crate::render::frame_plan::parse_age_years(&s.age.to_string())
            .map_err(|e| format!("--age: {e}"))?;
        let quality =
            <Quality as clap::ValueEnum>::from_str(s.quality.trim(), true).map_err(|_| {
                format!(
                    "--quality {:?} is not one of exact, balanced, fast",
                    s.quality
                )
            })?;
        if !(1..=bounds.max_layers).contains(&s.layers) {
            return Err(format!(
                "--layers {} : this server takes 1 to {} (its --max-layers)",
                s.layers, bounds.max_layers
            ));
        }
        if !(s.time_s.is_finite() && s.time_s >= 0.0) {
            return Err(format!(
                "--time {} must be a non-negative number of seconds",
                s.time_s
            ));
        }
        Ok(ViewRequest {
            scene: s.scene,
            size,
            sides,
            options: LiveOptions {
                focus,
                pupil_mm,
                luminance_cdm2,
                age,
                method: Method::Splat,
                layers: s.layers,
                off_axis: s.off_axis,
                exposure_ev: None,
                quality,
                correction: Correction::default(),
            },
            time_s: s.time_s,
            binocular_ipd_mm,
        })
    }

    /// The `ocular render` command (after `ocular eye estimate` for a prescription) that
    /// renders `side` of this view into `output` (a binocular pair: both eyes, into
    /// OUTPUT-left and OUTPUT-right).
    pub fn command_line(&self, side: usize, catalog: &Catalog, output: &str) -> String {
        let s = &self.sides[side];
        let mut prefix = String::new();
        let mut eye_word = |choice: &EyeChoice, file: &str| match choice {
            EyeChoice::Preset(p) => p.clone(),
            EyeChoice::File(f) => catalog
                .eye_files
                .get(f)
                .map_or_else(|| f.clone(), |e| e.cli.clone()),
            EyeChoice::Rx { rx, pupil_mm } => {
                prefix.push_str(&format!(
                    "{} && ",
                    shell_words(&[
                        "ocular",
                        "eye",
                        "estimate",
                        "--rx",
                        rx,
                        "--pupil-mm",
                        &format!("{pupil_mm}"),
                        "-o",
                        file,
                    ])
                ));
                file.to_string()
            }
        };
        if let Some(ipd_mm) = self.binocular_ipd_mm {
            let (left, right) = (&self.sides[0], &self.sides[1]);
            let left_eye = eye_word(&left.eye, "eye-rx-left.toml");
            let mut pair: Vec<String> = vec!["--binocular".into(), "--eye".into(), left_eye];
            if right.eye != left.eye {
                let right_eye = eye_word(&right.eye, "eye-rx-right.toml");
                pair.extend(["--eye-right".into(), right_eye]);
            }
            pair.extend(left.correction_cli.iter().cloned());
            if let (Some(l), Some(r)) = (
                correction_value(left, "--correct"),
                correction_value(right, "--correct"),
            ) {
                if l != r {
                    pair.extend(["--correct-right".into(), r.to_string()]);
                }
            }
            if left.correction.iol != right.correction.iol {
                let power = correction_value(right, "--iol-d").unwrap_or("none");
                pair.extend(["--iol-d-right".into(), power.to_string()]);
            }
            if ipd_mm != crate::render::binocular::DEFAULT_IPD_MM {
                pair.extend(["--ipd-mm".into(), format!("{ipd_mm}")]);
            }
            return format!("{prefix}{}", self.render_words(catalog, pair, output));
        }
        let eye = eye_word(&s.eye, "eye-rx.toml");
        let mut words: Vec<String> = vec!["--eye".into(), eye];
        words.extend(s.correction_cli.iter().cloned());
        format!("{prefix}{}", self.render_words(catalog, words, output))
    }

    /// `ocular render` with this view's scene, size and shared options around `eye_words`
    /// (the eyes and their corrections).
    fn render_words(&self, catalog: &Catalog, eye_words: Vec<String>, output: &str) -> String {
        let scene = catalog
            .scenes
            .get(&self.scene)
            .map_or_else(|| self.scene.clone(), |e| e.cli.clone());
        let o = &self.options;
        let mut words: Vec<String> = vec![
            "ocular".into(),
            "render".into(),
            "--scene".into(),
            scene,
            "--size".into(),
            format!("{}x{}", self.size.0, self.size.1),
        ];
        words.extend(eye_words);
        words.extend(["--age".into(), format!("{}", o.age)]);
        if self.time_s != 0.0 {
            words.extend(["--time".into(), format!("{}", self.time_s)]);
        }
        match o.focus {
            Some(FocusAsked::Dioptres(d)) => words.extend(["--focus-d".into(), format!("{d}")]),
            Some(FocusAsked::AtPixel(x, y)) => {
                words.extend(["--focus-at".into(), format!("{x},{y}")])
            }
            Some(FocusAsked::DistanceM(m)) => words.extend(["--focus-m".into(), format!("{m}")]),
            None => {}
        }
        if let Some(p) = o.pupil_mm {
            words.extend(["--pupil-mm".into(), format!("{p}")]);
        }
        if let Some(l) = o.luminance_cdm2 {
            words.extend(["--luminance-cdm2".into(), format!("{l}")]);
        }
        words.extend(["--quality".into(), o.quality.name().into()]);
        if o.layers > 1 {
            words.extend(["--layers".into(), format!("{}", o.layers)]);
        }
        if o.off_axis {
            words.push("--off-axis".into());
        }
        words.extend(["-o".into(), output.into()]);
        let refs: Vec<&str> = words.iter().map(String::as_str).collect();
        shell_words(&refs)
    }
}

/// The value a side's correction words give `option` (`--correct`'s prescription, `--iol-d`'s
/// power), as typed.
fn correction_value<'a>(side: &'a Side, option: &str) -> Option<&'a str> {
    let words = &side.correction_cli;
    words
        .iter()
        .position(|w| w == option)
        .and_then(|i| words.get(i + 1))
        .map(String::as_str)
}

/// What `ocular render --binocular` can express of two eyes' corrections: the right eye may
/// have its own spectacle or contact lens prescription (`--correct-right`), of the left's
/// kind and vertex distance, and its own IOL or none (`--iol-d-right`).
fn check_pair(sides: &[Side], off_axis: bool) -> Checked<()> {
    if off_axis {
        return Err("--binocular does not take --off-axis yet".into());
    }
    let (l, r) = (&sides[0].correction, &sides[1].correction);
    let kind = |c: &Correction| (c.spectacle.is_some(), c.contact, c.vertex_mm);
    let (kl, kr) = (kind(l), kind(r));
    if kl.0 && kr.0 && (kl.1, kl.2) != (kr.1, kr.2) {
        return Err(
            "a binocular pair's lenses are of one kind and vertex distance: glasses at \
                    one --vertex-mm, or contact lenses, for both eyes"
                .into(),
        );
    }
    if kl.0 != kr.0 {
        return Err(
            "give both eyes a lens in a binocular pair (a plano \"0\" for an eye that \
                    needs none)"
                .into(),
        );
    }
    Ok(())
}

/// Words joined for a POSIX shell, each quoted where it needs it.
pub fn shell_words(words: &[&str]) -> String {
    words
        .iter()
        .map(|w| {
            let plain = !w.is_empty()
                && w.chars()
                    .all(|c| c.is_ascii_alphanumeric() || "_./:,=+-@%".contains(c));
            if plain {
                w.to_string()
            } else {
                format!("'{}'", w.replace('\'', r"'\''"))
            }
        })
        .collect::<Vec<_>>()
        .join(" ")
}

#[cfg(test)]
mod tests {
    use super::*;

    fn bounds() -> Bounds {
        Bounds {
            max_pixels: 1920 * 1080,
            max_side_px: 4096,
            max_layers: 4,
        }
    }

    fn settings(json: &str) -> SettingsIn {
        serde_json::from_str(json).unwrap()
    }

    const BASE: &str = r#"{"scene":"chart","size":[640,360],"a":{"eye":{"kind":"preset","name":"myopia"}},"age":30,"quality":"fast"}"#;

    #[test]
    fn a_good_request_gives_its_command_line() {
        let catalog = Catalog::load(None, None).unwrap();
        let mut s = settings(BASE);
        s.a.correction = CorrectionIn::Glasses {
            rx: "-2 -0.5 x 90".into(),
            vertex_mm: None,
        };
        s.focus = FocusIn::At { x: 10, y: 20 };
        let r = ViewRequest::check(s, &catalog, &bounds()).unwrap();
        assert_eq!(
            r.command_line(0, &catalog, "ocular.png"),
            "ocular render --scene chart --size 640x360 --eye myopia --correct '-2 -0.5 x 90' \
             --vertex-mm 12 --age 30 --focus-at 10,20 --quality fast -o ocular.png"
        );
    }

    #[test]
    fn bad_values_name_the_option() {
        let catalog = Catalog::load(None, None).unwrap();
        type Change<'a> = &'a dyn Fn(&mut SettingsIn);
        let cases: [(Change, &str); 8] = [
            (&|s| s.scene = "../etc/passwd".into(), "--scene"),
            (&|s| s.size = [100000, 10], "--size"),
            (&|s| s.size = [1920, 1920], "--max-pixels"),
            (&|s| s.age = 5.0, "--age"),
            (&|s| s.quality = "best".into(), "--quality"),
            (&|s| s.layers = 9, "--layers"),
            (
                &|s| {
                    s.a.eye = EyeIn::Preset {
                        name: "/etc/hosts".into(),
                    }
                },
                "--eye",
            ),
            (
                &|s| {
                    s.a.eye = EyeIn::Rx {
                        rx: "-2 -1 x".into(),
                        pupil_mm: 5.0,
                    }
                },
                "--rx",
            ),
        ];
        for (change, option) in cases {
            let mut s = settings(BASE);
            change(&mut s);
            let e = ViewRequest::check(s, &catalog, &bounds()).unwrap_err();
            assert!(e.contains(option), "{e} should name {option}");
            assert!(!e.contains('\n'), "{e}");
        }
    }

    #[test]
    fn a_pair_with_an_iol_in_one_eye_is_one_command() {
        let catalog = Catalog::load(None, None).unwrap();
        let eye = r#"{"kind":"preset","name":"myopia"}"#;
        let pair = |a: &str, b: &str| {
            let json = format!(
                r#"{{"scene":"chart","size":[640,360],"age":30,"quality":"fast","binocular":true,"a":{{"eye":{eye},"correction":{a}}},"b":{{"eye":{eye},"correction":{b}}}}}"#
            );
            let r = ViewRequest::check(settings(&json), &catalog, &bounds()).unwrap();
            r.command_line(0, &catalog, "pair.png")
        };
        let none = r#"{"kind":"none"}"#;
        let line = pair(r#"{"kind":"iol","power":"auto"}"#, none);
        assert!(
            line.contains("--binocular --eye myopia --iol-d auto --iol-d-right none"),
            "{line}"
        );
        let line = pair(none, r#"{"kind":"iol","power":"21.5"}"#);
        assert!(line.contains("--eye myopia --iol-d-right 21.5"), "{line}");
        assert!(!line.contains("--iol-d "), "{line}");
    }

    #[test]
    fn quoting_survives_a_shell() {
        assert_eq!(shell_words(&["a", "it's", ""]), r"a 'it'\''s' ''");
    }
}
