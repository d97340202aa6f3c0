//! Layer-aware OpenEXR reading: which channels of a renderer's file are the colour and which
//! the depth.
//!
//! Renderers name channels `layer.pass.channel` (Blender: `ViewLayer.Combined.R`,
//! `ViewLayer.Depth.Z`, `Composite.Combined.G`; its File Output node: `Image.R`, `Depth.V`),
//! may spread them over several parts (each part's name then prefixes its channels) and may
//! carry several views (a part's `view` attribute, or a view component before the channel).
//! Every channel is known here by its full name: part name (when the channel does not already
//! start with it), the channel's own layer and pass components, the view, then the channel.
//! A *group* is a full name without its last component (`ViewLayer.Combined`), and its *pass*
//! is the group's last component once a view name is dropped.
//!
//! Choices are never silent guesses: when the rule below finds more than one candidate, or
//! none, the error lists what the file holds and names the option that chooses.

use std::path::Path;

use crate::image_types::{ImageGray, ImageRgba};
use crate::{Error, Result};

/// Blender passes (and similar) that hold one value per pixel but are not view-axis depth:
/// never taken as depth unless named with `--depth-channel`.
const NOT_DEPTH_PASSES: [&str; 8] = [
    "mist", "normal", "vector", "ao", "shadow", "indexob", "indexma", "alpha",
];

/// One channel of a file, with its samples as f32.
#[derive(Clone, Debug)]
pub struct Channel {
    /// `part.layer.pass.view.channel`, as described in the module documentation.
    pub full_name: String,
    /// The full name without the channel component ("" for a bare `R`).
    pub group: String,
    /// The last component (`R`, `Z`, `V`).
    pub channel: String,
    /// The group's pass, view dropped (`Combined`, `Depth`, `Denoising Depth`; "" if none).
    pub pass: String,
    /// The group's first component when it has a pass below it (`ViewLayer`), else "".
    pub layer: String,
    /// The view (`left`, `right`) of a multi-view file, else "".
    pub view: String,
    /// Stored as 16-bit floats (background may then read 65504, the largest half).
    pub half: bool,
    pub width: u32,
    pub height: u32,
    pub values: Vec<f32>,
}

/// Every channel of every part of an EXR file.
pub struct ExrChannels {
    pub channels: Vec<Channel>,
    /// The views the file names (its `multiView` list, then its parts' `view` attributes),
    /// without repeats; empty for a single-view file.
    pub views: Vec<String>,
    /// The view a channel without one belongs to: the first of the `multiView` list.
    pub default_view: Option<String>,
}

fn file_error(path: &Path, message: impl std::fmt::Display) -> Error {
    Error::file(path, message)
}

fn exr_error(path: &Path, error: exr::error::Error) -> Error {
    match error {
        exr::error::Error::Io(e) if e.kind() == std::io::ErrorKind::NotFound => {
            file_error(path, "no such file")
        }
        exr::error::Error::Io(e) => file_error(path, format!("cannot read: {e}")),
        exr::error::Error::NotSupported(m) => {
            file_error(path, format!("unsupported EXR feature: {m}"))
        }
        e => file_error(path, format!("not a valid EXR file ({e})")),
    }
}

/// Splits a group name into (layer, pass, view): a component naming one of the file's views
/// is the view wherever it stands (OpenEXR puts it before the channel, multi-part files may put
/// it in the part name), the last other component is the pass and the first the layer.
fn layer_pass_view(group: &str, views: &[String]) -> (String, String, String) {
    let mut view = String::new();
    let mut parts: Vec<&str> = Vec::new();
    for p in group.split('.').filter(|p| !p.is_empty()) {
        if view.is_empty() && views.iter().any(|v| v == p) {
            view = p.to_string();
        } else {
            parts.push(p);
        }
    }
    let pass = parts.last().map_or(String::new(), |p| p.to_string());
    let layer = if parts.len() > 1 {
        parts[0].to_string()
    } else {
        String::new()
    };
    (layer, pass, view)
}

impl ExrChannels {
    /// Reads every channel of every part (largest resolution level; deep data refused).
    pub fn read(path: &Path) -> Result<ExrChannels> {
        use exr::prelude::*;
        let image = read()
            .no_deep_data()
            .largest_resolution_level()
            .all_channels()
            .all_layers()
            .all_attributes()
            .from_file(path)
            .map_err(|e| exr_error(path, e))?;
        let mut views: Vec<String> = Vec::new();
        let mut default_view = None;
        for layer in &image.layer_data {
            if let Some(list) = &layer.attributes.multi_view_names {
                default_view = default_view.or_else(|| list.first().map(|v| v.to_string()));
                views.extend(list.iter().map(|v| v.to_string()));
            }
            if let Some(v) = &layer.attributes.view_name {
                views.push(v.to_string());
            }
        }
        let mut seen = Vec::new();
        views.retain(|v| {
            let new = !seen.contains(v);
            seen.push(v.clone());
            new
        });
        let mut channels = Vec::new();
        for layer in &image.layer_data {
            let part = layer
                .attributes
                .layer_name
                .as_ref()
                .map(|n| n.to_string())
                .unwrap_or_default();
            let view = layer.attributes.view_name.as_ref().map(|v| v.to_string());
            let (width, height) = (layer.size.width(), layer.size.height());
            for c in &layer.channel_data.list {
                let own = c.name.to_string();
                let (own_group, channel) = match own.rsplit_once('.') {
                    Some((g, c)) => (g.to_string(), c.to_string()),
                    None => (String::new(), own.clone()),
                };
                let mut group = if part.is_empty()
                    || own_group == part
                    || own_group.starts_with(&format!("{part}."))
                {
                    own_group
                } else if own_group.is_empty() {
                    part.clone()
                } else {
                    format!("{part}.{own_group}")
                };
                if let Some(v) = &view {
                    if !group.split('.').any(|p| p == v) {
                        group = if group.is_empty() {
                            v.clone()
                        } else {
                            format!("{group}.{v}")
                        };
                    }
                }
                let values: Vec<f32> = c.sample_data.values_as_f32().collect();
                if values.len() != width * height {
                    return Err(file_error(
                        path,
                        format!("channel {own} is subsampled; ocular needs full resolution"),
                    ));
                }
                let (layer_name, pass, view_name) = layer_pass_view(&group, &views);
                let full_name = if group.is_empty() {
                    channel.clone()
                } else {
                    format!("{group}.{channel}")
                };
                channels.push(Channel {
                    full_name,
                    group,
                    channel,
                    pass,
                    layer: layer_name,
                    view: view_name,
                    half: matches!(c.sample_data, FlatSamples::F16(_)),
                    width: width as u32,
                    height: height as u32,
                    values,
                });
            }
        }
        if channels.is_empty() {
            return Err(file_error(path, "the EXR file holds no channels"));
        }
        Ok(ExrChannels {
            channels,
            views,
            default_view,
        })
    }

    /// The channels of view `name` alone: those the file places in it, and those with no view
    /// when it is the file's default view (OpenEXR's multi-view convention). Errors name the
    /// views the file holds.
    pub fn only_view(self, path: &Path, name: &str) -> Result<ExrChannels> {
        if !self.views.iter().any(|v| v == name) {
            return Err(file_error(
                path,
                if self.views.is_empty() {
                    format!(
                        "has no views, so no {name} view (a stereo pair needs a multi-view EXR,                          such as Blender's stereoscopy output, or one file per eye)"
                    )
                } else {
                    format!(
                        "has no view named {name} (it holds {})",
                        self.views.join(", ")
                    )
                },
            ));
        }
        let default = self.default_view.as_deref() == Some(name);
        let channels: Vec<Channel> = self
            .channels
            .into_iter()
            .filter(|c| c.view == name || (default && c.view.is_empty()))
            .collect();
        if channels.is_empty() {
            return Err(file_error(path, format!("view {name} holds no channels")));
        }
        Ok(ExrChannels {
            channels,
            views: vec![name.to_string()],
            default_view: Some(name.to_string()),
        })
    }

    fn names(&self) -> String {
        let names: Vec<&str> = self.channels.iter().map(|c| c.full_name.as_str()).collect();
        names.join(", ")
    }

    /// Distinct groups in file order.
    fn groups(&self) -> Vec<&str> {
        let mut out: Vec<&str> = Vec::new();
        for c in &self.channels {
            if !out.contains(&c.group.as_str()) {
                out.push(&c.group);
            }
        }
        out
    }

    fn in_group<'a>(&'a self, group: &str, channel: &str) -> Option<&'a Channel> {
        self.channels
            .iter()
            .find(|c| c.group == group && c.channel.eq_ignore_ascii_case(channel))
    }

    fn is_rgb(&self, group: &str) -> bool {
        ["R", "G", "B"]
            .iter()
            .all(|c| self.in_group(group, c).is_some())
    }

    fn is_luminance(&self, group: &str) -> bool {
        self.in_group(group, "Y").is_some() && !self.is_rgb(group)
    }

    fn group_label(group: &str) -> String {
        if group.is_empty() {
            "(unnamed: R, G, B)".to_string()
        } else {
            group.to_string()
        }
    }

    /// The colour: the group named by `layer` (a group, a layer whose `Combined` pass is
    /// meant, or a part), else the one `*.Combined` group, else the one RGB group, else the one
    /// luminance (Y) group. Returns the image and the group used.
    pub fn color(&self, path: &Path, layer: Option<&str>) -> Result<(ImageRgba, String)> {
        let groups = self.groups();
        let colour_groups: Vec<&str> = groups
            .iter()
            .copied()
            .filter(|g| self.is_rgb(g) || self.is_luminance(g))
            .collect();
        let listing = || {
            if colour_groups.is_empty() {
                format!(
                    "no colour layer (R, G, B or Y) among channels {}",
                    self.names()
                )
            } else {
                let labels: Vec<String> =
                    colour_groups.iter().map(|g| Self::group_label(g)).collect();
                format!("colour layers found: {}", labels.join(", "))
            }
        };
        let chosen: &str = if let Some(want) = layer {
            let exact = |g: &&str| *g == want || *g == format!("{want}.Combined");
            let loose = |g: &&str| {
                g.eq_ignore_ascii_case(want) || g.eq_ignore_ascii_case(&format!("{want}.Combined"))
            };
            let hits: Vec<&str> = colour_groups.iter().copied().filter(exact).collect();
            let hits = if hits.is_empty() {
                colour_groups.iter().copied().filter(loose).collect()
            } else {
                hits
            };
            // A part (or layer) name: the one colour group inside it, its Combined if several.
            let hits: Vec<&str> = if hits.is_empty() {
                let inside: Vec<&str> = colour_groups
                    .iter()
                    .copied()
                    .filter(|g| g.starts_with(&format!("{want}.")))
                    .collect();
                let combined: Vec<&str> = inside
                    .iter()
                    .copied()
                    .filter(|g| self.pass_of(g).eq_ignore_ascii_case("combined"))
                    .collect();
                if inside.len() > 1 && !combined.is_empty() {
                    combined
                } else {
                    inside
                }
            } else {
                hits
            };
            match hits.as_slice() {
                [one] => one,
                _ => {
                    return Err(file_error(
                        path,
                        format!(
                            "--color-layer {want:?} matches no colour layer; {}",
                            listing()
                        ),
                    ))
                }
            }
        } else {
            let combined: Vec<&str> = colour_groups
                .iter()
                .copied()
                .filter(|g| self.pass_of(g).eq_ignore_ascii_case("combined"))
                .collect();
            let rgb: Vec<&str> = colour_groups
                .iter()
                .copied()
                .filter(|g| self.is_rgb(g))
                .collect();
            let candidates = if !combined.is_empty() {
                combined
            } else if !rgb.is_empty() {
                rgb
            } else {
                colour_groups.clone()
            };
            match candidates.as_slice() {
                [one] => one,
                [] => return Err(file_error(path, listing())),
                many => {
                    let labels: Vec<String> = many.iter().map(|g| Self::group_label(g)).collect();
                    return Err(file_error(
                        path,
                        format!(
                            "several colour layers ({}); choose one with --color-layer NAME",
                            labels.join(", ")
                        ),
                    ));
                }
            }
        };
        let first = self
            .channels
            .iter()
            .find(|c| c.group == chosen)
            .expect("a chosen group has channels");
        let (width, height) = (first.width, first.height);
        let plane = |name: &str| self.in_group(chosen, name).map(|c| c.values.as_slice());
        let pixels: Vec<[f32; 4]> = if self.is_rgb(chosen) {
            let (r, g, b) = (
                plane("R").expect("rgb"),
                plane("G").expect("rgb"),
                plane("B").expect("rgb"),
            );
            let a = plane("A");
            (0..r.len())
                .map(|i| [r[i], g[i], b[i], a.map_or(1.0, |a| a[i])])
                .collect()
        } else {
            let y = plane("Y").expect("luminance group");
            let a = plane("A");
            (0..y.len())
                .map(|i| [y[i], y[i], y[i], a.map_or(1.0, |a| a[i])])
                .collect()
        };
        Ok((ImageRgba::new(width, height, pixels), chosen.to_string()))
    }

    fn pass_of(&self, group: &str) -> &str {
        self.channels
            .iter()
            .find(|c| c.group == group)
            .map_or("", |c| c.pass.as_str())
    }

    /// The depth channel: the one named by `channel` (a full name, or a group holding one
    /// channel), else the `Depth` pass (`<layer>.Depth.Z`, `Depth.V`) or a bare `Z`/`depth`
    /// channel — preferring the (layer, view) of `prefer` (the colour's) when several layers
    /// or views have one — else the only channel
    /// of a one-channel file. Denoising, Mist, Normal and similar passes are never guessed.
    /// Returns the channel and every automatic candidate.
    pub fn depth(
        &self,
        path: &Path,
        channel: Option<&str>,
        prefer: Option<(&str, &str)>,
    ) -> Result<(&Channel, Vec<String>)> {
        if let Some(want) = channel {
            let exact: Vec<&Channel> = self
                .channels
                .iter()
                .filter(|c| c.full_name == want)
                .collect();
            let found: Vec<&Channel> = if exact.is_empty() {
                let by_group: Vec<&Channel> =
                    self.channels.iter().filter(|c| c.group == want).collect();
                if by_group.len() == 1 {
                    by_group
                } else {
                    self.channels
                        .iter()
                        .filter(|c| c.full_name.eq_ignore_ascii_case(want))
                        .collect()
                }
            } else {
                exact
            };
            return match found.as_slice() {
                [one] => Ok((one, vec![one.full_name.clone()])),
                _ => Err(file_error(
                    path,
                    format!(
                        "--depth-channel {want:?} is not a channel of this file; channels: {}",
                        self.names()
                    ),
                )),
            };
        }
        let is_depth = |c: &Channel| {
            // a bare channel: no group, or only a view (`right.Z` in a multi-view file)
            let bare = c.layer.is_empty()
                && c.pass.is_empty()
                && (c.channel.eq_ignore_ascii_case("z") || c.channel.eq_ignore_ascii_case("depth"));
            let pass = c.pass.eq_ignore_ascii_case("depth")
                && self.channels.iter().filter(|o| o.group == c.group).count() == 1;
            bare || pass
        };
        let candidates: Vec<&Channel> = self.channels.iter().filter(|c| is_depth(c)).collect();
        let names: Vec<String> = candidates.iter().map(|c| c.full_name.clone()).collect();
        let hint = "choose one with --depth-channel NAME";
        match candidates.as_slice() {
            [one] => return Ok((one, names)),
            [] => {}
            many => {
                if let Some((layer, view)) = prefer {
                    let same: Vec<&&Channel> = many
                        .iter()
                        .filter(|c| c.layer == layer && c.view == view)
                        .collect();
                    if let [one] = same.as_slice() {
                        return Ok((one, names));
                    }
                }
                return Err(file_error(
                    path,
                    format!("several depth channels ({}); {hint}", names.join(", ")),
                ));
            }
        }
        if let [only] = self.channels.as_slice() {
            let lower = only.pass.to_ascii_lowercase();
            if !(NOT_DEPTH_PASSES.contains(&lower.as_str()) || lower.starts_with("denoising")) {
                return Ok((only, vec![only.full_name.clone()]));
            }
        }
        Err(file_error(
            path,
            format!(
                "no depth channel: found {}; expected a Depth pass (ViewLayer.Depth.Z, Depth.V), \
                 a channel Z or depth, or a one-channel file (Mist, Normal and Denoising passes \
                 are not view-axis depth); {hint}",
                self.names()
            ),
        ))
    }
}

/// A depth channel as read, before the depth policy.
pub struct RawDepth {
    pub image: ImageGray,
    pub channel: String,
    pub half: bool,
    pub candidates: Vec<String>,
}

impl RawDepth {
    pub fn from_channel(channel: &Channel, candidates: Vec<String>) -> RawDepth {
        RawDepth {
            image: ImageGray::new(channel.width, channel.height, channel.values.clone()),
            channel: channel.full_name.clone(),
            half: channel.half,
            candidates,
        }
    }
}
