//! Synthetic EXR files with the exact channel names Blender 3.4 writes (recorded from Cycles
//! and Eevee renders; see issue 19), for the input tests.

use std::path::Path;

use exr::prelude::*;
use ocular::inputs::FileInputOptions;

/// One channel: its full name and a value per pixel.
pub struct Plane {
    pub name: String,
    pub values: Vec<f32>,
    pub half: bool,
}

pub fn plane(name: &str, values: Vec<f32>) -> Plane {
    Plane {
        name: name.to_string(),
        values,
        half: false,
    }
}

pub fn half_plane(name: &str, values: Vec<f32>) -> Plane {
    Plane {
        name: name.to_string(),
        values,
        half: true,
    }
}

fn channels(planes: Vec<Plane>) -> AnyChannels<FlatSamples> {
    let list: Vec<AnyChannel<FlatSamples>> = planes
        .into_iter()
        .map(|p| {
            let samples = if p.half {
                FlatSamples::F16(p.values.iter().map(|&v| f16::from_f32(v)).collect())
            } else {
                FlatSamples::F32(p.values)
            };
            AnyChannel::new(p.name.as_str(), samples)
        })
        .collect();
    AnyChannels::sort(list.into())
}

/// A single-part file (Blender's multilayer EXR: every pass in one part, named
/// `layer.pass.channel`).
pub fn write_single_part(path: &Path, (w, h): (usize, usize), planes: Vec<Plane>) {
    let layer = Layer::new(
        (w, h),
        LayerAttributes::default(),
        Encoding::FAST_LOSSLESS,
        channels(planes),
    );
    Image::from_layer(layer).write().to_file(path).unwrap();
}

/// A multi-part file: each part named, with its own channels.
pub fn write_multi_part(path: &Path, size: (usize, usize), parts: Vec<(&str, Vec<Plane>)>) {
    let parts = parts
        .into_iter()
        .map(|(name, planes)| (LayerAttributes::named(name), planes))
        .collect();
    write_parts(path, size, parts);
}

/// A stereo multi-part file: one part per (name, view), the `view` attribute set.
pub fn write_views(path: &Path, size: (usize, usize), parts: Vec<(&str, &str, Vec<Plane>)>) {
    let parts = parts
        .into_iter()
        .map(|(name, view, planes)| {
            let mut attributes = LayerAttributes::named(name);
            attributes.view_name = Some(Text::from(view));
            (attributes, planes)
        })
        .collect();
    write_parts(path, size, parts);
}

fn write_parts(path: &Path, (w, h): (usize, usize), parts: Vec<(LayerAttributes, Vec<Plane>)>) {
    let layers: Vec<Layer<AnyChannels<FlatSamples>>> = parts
        .into_iter()
        .map(|(attributes, planes)| {
            Layer::new(
                (w, h),
                attributes,
                Encoding::FAST_LOSSLESS,
                channels(planes),
            )
        })
        .collect();
    Image::from_layers(
        ImageAttributes::new(IntegerBounds::from_dimensions((w, h))),
        layers,
    )
    .write()
    .to_file(path)
    .unwrap();
}

/// R, G and B planes of `n` pixels, each one value throughout.
pub fn uniform_rgb(n: usize, [r, g, b]: [f32; 3]) -> Vec<Plane> {
    vec![
        plane("R", vec![r; n]),
        plane("G", vec![g; n]),
        plane("B", vec![b; n]),
    ]
}

/// `<layer>.Combined.{R,G,B,A}` with distinct, recognisable values: R = `base` + x, G = 2·base,
/// B = 3·base, A = 1.
pub fn combined(layer: &str, (w, h): (usize, usize), base: f32) -> Vec<Plane> {
    let n = w * h;
    vec![
        plane(
            &format!("{layer}.Combined.R"),
            (0..n).map(|i| base + (i % w) as f32).collect(),
        ),
        plane(&format!("{layer}.Combined.G"), vec![2.0 * base; n]),
        plane(&format!("{layer}.Combined.B"), vec![3.0 * base; n]),
        plane(&format!("{layer}.Combined.A"), vec![1.0; n]),
    ]
}

/// Depth in metres that varies by row, so that a wrong channel cannot pass for it:
/// `near + 0.25·y`, with the top-left pixel as background (`background`).
pub fn depth_values((w, h): (usize, usize), near: f32, background: f32) -> Vec<f32> {
    let mut v: Vec<f32> = (0..w * h).map(|i| near + 0.25 * (i / w) as f32).collect();
    v[0] = background;
    v
}

/// Everything Cycles writes for one view layer with Mist and denoising data on: Combined,
/// Depth.Z (view axis, background 1e10), Mist.Z, Denoising Depth.Z (along the ray, 0 for
/// background), Denoising Albedo and Denoising Normal.
pub fn cycles_layer(layer: &str, size: (usize, usize), base: f32, near: f32) -> Vec<Plane> {
    let n = size.0 * size.1;
    let mut planes = combined(layer, size, base);
    planes.push(plane(
        &format!("{layer}.Depth.Z"),
        depth_values(size, near, 1e10),
    ));
    planes.push(plane(&format!("{layer}.Mist.Z"), vec![0.5; n]));
    planes.push(plane(
        &format!("{layer}.Denoising Depth.Z"),
        depth_values(size, near * 1.1, 0.0),
    ));
    for c in ["R", "G", "B"] {
        planes.push(plane(
            &format!("{layer}.Denoising Albedo.{c}"),
            vec![0.8; n],
        ));
    }
    for c in ["X", "Y", "Z"] {
        planes.push(plane(
            &format!("{layer}.Denoising Normal.{c}"),
            vec![0.3; n],
        ));
    }
    planes
}

/// Options that load `color` alone: no depth file, layer or channel chosen, scale 1, no repair.
pub fn options(color: &Path) -> FileInputOptions {
    FileInputOptions {
        color: color.to_path_buf(),
        depth: None,
        color_layer: None,
        depth_channel: None,
        depth_scale: 1.0,
        white_cdm2: None,
        repair_nonfinite: false,
        view: None,
    }
}
