//! Layered EXR input: a multi-part file whose parts are named `layer0`, `layer1`, … (nearest
//! surface first), each with R, G, B and Z channels (Z = +∞ where that layer is empty), given
//! as `--color` (and optionally as `--depth` too). Layer 0 is the visible frame and goes
//! through the usual depth policy; a hidden layer is empty wherever its Z is a background
//! marker or invalid (+∞, 0, ≥ 1e9, NaN, negative), and holds colour 0 there.

use std::path::Path;

use super::depth::BACKGROUND_FROM;
use super::exr::ExrChannels;
use crate::{Error, Result};

/// Most layers a file may hold (the depth peeling's own limit).
pub const MAX_LAYERS: usize = 8;

/// One layer as read: colour (alpha 1) and raw Z in scene units.
pub struct RawLayer {
    pub color: Vec<[f32; 4]>,
    pub z: Vec<f32>,
    pub half: bool,
}

/// The file's layers when its parts are named `layer0`, `layer1`, …; None when it has no part
/// `layer0` (an ordinary EXR).
pub fn read_layers(path: &Path, file: &ExrChannels) -> Result<Option<(u32, u32, Vec<RawLayer>)>> {
    let has = |group: &str| file.channels.iter().any(|c| c.group == group);
    if !has("layer0") {
        return Ok(None);
    }
    let mut layers = Vec::new();
    let mut size = None;
    for k in 0.. {
        let group = format!("layer{k}");
        if !has(&group) {
            break;
        }
        if k == MAX_LAYERS {
            return Err(Error::file(
                path,
                format!("holds more than {MAX_LAYERS} layers (parts layer0 to layer{k})"),
            ));
        }
        let get = |name: &str| {
            file.channels
                .iter()
                .find(|c| c.group == group && c.channel == name)
                .ok_or_else(|| {
                    Error::file(
                        path,
                        format!("part {group} has no channel {name}; each layerN part needs R, G, B and Z"),
                    )
                })
        };
        let (r, g, b, z) = (get("R")?, get("G")?, get("B")?, get("Z")?);
        let this = (r.width, r.height);
        if [g, b, z].iter().any(|c| (c.width, c.height) != this) || size.is_some_and(|s| s != this)
        {
            return Err(Error::file(
                path,
                format!(
                    "part {group}'s channels differ in size from layer0's; all layers must match"
                ),
            ));
        }
        size = Some(this);
        let color = (0..r.values.len())
            .map(|i| [r.values[i], g.values[i], b.values[i], 1.0])
            .collect();
        layers.push(RawLayer {
            color,
            z: z.values.clone(),
            half: z.half,
        });
    }
    if let Some(extra) = file.channels.iter().map(|c| c.group.as_str()).find(|g| {
        g.starts_with("layer") && g[5..].parse::<usize>().is_ok_and(|k| k >= layers.len())
    }) {
        return Err(Error::file(
            path,
            format!(
                "part {extra} follows a missing layer{}: layers must be numbered from 0 without gaps",
                layers.len()
            ),
        ));
    }
    let (w, h) = size.expect("layer0 is there");
    Ok(Some((w, h, layers)))
}

/// A hidden layer's depth in metres: +∞ (empty) where Z marks the background or is invalid,
/// and colour 0 there; non-finite colour where the layer is not empty is refused.
pub fn hidden_layer(
    path: &Path,
    index: usize,
    layer: RawLayer,
    width: u32,
    scale: f64,
) -> Result<(Vec<[f32; 4]>, Vec<f32>)> {
    let near = crate::render::focus::nearest_supported_m();
    let mut color = layer.color;
    let mut depth = Vec::with_capacity(layer.z.len());
    for (i, (&z, c)) in layer.z.iter().zip(color.iter_mut()).enumerate() {
        let empty = !(z.is_finite() && z > 0.0)
            || z >= BACKGROUND_FROM
            || (layer.half && z >= super::depth::HALF_MAX);
        if empty {
            *c = [0.0; 4];
            depth.push(f32::INFINITY);
            continue;
        }
        if c.iter().any(|v| !v.is_finite()) {
            return Err(Error::file(
                path,
                format!(
                    "layer{index} has non-finite colour at ({}, {}) where it is not empty",
                    i % width.max(1) as usize,
                    i / width.max(1) as usize
                ),
            ));
        }
        depth.push(((f64::from(z) * scale) as f32).max(near));
    }
    Ok((color, depth))
}
