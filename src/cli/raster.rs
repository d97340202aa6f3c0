//! `ocular raster`: rasterise a scene to linear HDR colour and metric depth (EXR), to inspect
//! the renderer's inputs or feed other tools.

use std::path::PathBuf;

use clap::{Args, ValueEnum};

use super::outputs::Outputs;
use super::Cli;
use crate::gpu::Context;
use crate::image_io::{self, Tonemap, TonemapMode};
use crate::render::Rasterizer;
use crate::scene::Scene;
use crate::{Error, Result};

#[derive(Debug, Clone, Copy, ValueEnum)]
pub enum TonemapArg {
    Clamp,
    Reinhard,
}

impl TonemapArg {
    pub(super) fn mode(self) -> TonemapMode {
        match self {
            TonemapArg::Clamp => TonemapMode::Clamp,
            TonemapArg::Reinhard => TonemapMode::Reinhard,
        }
    }
}

#[derive(Debug, Args)]
#[command(after_help = "Examples:\n  \
    ocular raster --scene primitives -o colour.exr --depth-out depth.exr\n  \
    ocular raster --scene my_room.toml --size 640x360 --time 2.5 --png preview.png\n\n\
Colour is linear Rec.709 RGB whose luminance Y = 0.2126R + 0.7152G + 0.0722B is in cd/m²; \
depth is the distance along the view direction in metres (32-bit float, channel Z). \
Built-in scenes: primitives, chart, colonnade, walk (see scenes/README.md for the file format).")]
pub struct RasterArgs {
    /// Built-in scene name (primitives, chart, colonnade, walk) or path to a scene .toml file.
    #[arg(long, value_name = "NAME|FILE")]
    pub scene: String,

    /// Frame size in pixels (default: the scene's camera resolution).
    #[arg(long, value_name = "WxH", value_parser = parse_size)]
    pub size: Option<(u32, u32)>,

    /// Time in seconds at which to evaluate the scene's keyframes.
    #[arg(long, value_name = "SECONDS", default_value_t = 0.0)]
    pub time: f64,

    /// Write linear HDR colour here (OpenEXR, RGBA 32-bit float).
    #[arg(short = 'o', long = "output", value_name = "FILE.exr")]
    pub output: Option<PathBuf>,

    /// Write depth in metres here (OpenEXR, one channel Z).
    #[arg(long, value_name = "FILE.exr")]
    pub depth_out: Option<PathBuf>,

    /// Also write an 8-bit sRGB preview.
    #[arg(long, value_name = "FILE.png")]
    pub png: Option<PathBuf>,

    /// Preview exposure in stops (default: middle grey at the log-average luminance).
    #[arg(long, value_name = "EV", allow_negative_numbers = true)]
    pub exposure: Option<f32>,

    /// Preview tone curve.
    #[arg(long, value_enum, default_value = "reinhard")]
    pub tonemap: TonemapArg,
}

pub(crate) fn parse_size(text: &str) -> std::result::Result<(u32, u32), String> {
    let (w, h) = text
        .split_once(['x', 'X', '×'])
        .ok_or_else(|| format!("\"{text}\": expected WIDTHxHEIGHT, e.g. 1280x720"))?;
    let parse = |s: &str| {
        s.trim()
            .parse::<u32>()
            .ok()
            .filter(|&v| (1..=16384).contains(&v))
            .ok_or_else(|| format!("\"{text}\": sizes are whole numbers from 1 to 16384"))
    };
    Ok((parse(w)?, parse(h)?))
}

pub use crate::limits::MIN_FRAME_SIDE;

/// `WxH` for the commands that render through an eye (render, video, compare, bench): the
/// parser states the limit the renderer enforces.
pub(crate) fn parse_frame_size(text: &str) -> std::result::Result<(u32, u32), String> {
    let (w, h) = parse_size(text)?;
    if w < MIN_FRAME_SIDE || h < MIN_FRAME_SIDE {
        return Err(format!(
            "\"{text}\": frames through an eye are {MIN_FRAME_SIDE} to 16384 pixels on each side"
        ));
    }
    Ok((w, h))
}

pub fn run(cli: &Cli, args: &RasterArgs) -> Result<()> {
    if args.output.is_none() && args.depth_out.is_none() && args.png.is_none() {
        return Err(Error::input(
            "nothing to write: give -o colour.exr, --depth-out depth.exr and/or --png preview.png",
        ));
    }
    if !args.time.is_finite() {
        return Err(Error::input("--time must be a finite number of seconds"));
    }
    let mut outputs = Outputs::new();
    if let Some(path) = &args.output {
        outputs.add("-o", path, &["exr"])?;
    }
    if let Some(path) = &args.depth_out {
        outputs.add("--depth-out", path, &["exr"])?;
    }
    if let Some(path) = &args.png {
        outputs.add("--png", path, &["png"])?;
    }
    outputs.probe()?;
    let started = std::time::Instant::now();
    let scene = Scene::load(&args.scene)?;
    let loaded_s = started.elapsed().as_secs_f64();
    let (width, height) = args
        .size
        .unwrap_or((scene.resolution[0], scene.resolution[1]));
    let ctx = Context::new(&cli.context_options())?;
    let mut rasterizer = Rasterizer::new(&ctx)?;
    let state = scene.at_time(args.time);
    let render_started = std::time::Instant::now();
    let frame = rasterizer.render(&ctx, &state, width, height)?;
    let render_s = render_started.elapsed().as_secs_f64();

    let color = frame.color_image();
    let mut wrote = Vec::new();
    if let Some(path) = &args.output {
        image_io::write_exr_rgba(outputs.temporary(path), &color)?;
        wrote.push(format!("wrote {} (linear RGB, cd/m²)", path.display()));
    }
    if let Some(path) = &args.depth_out {
        image_io::write_exr_depth(outputs.temporary(path), &frame.depth_image())?;
        wrote.push(format!("wrote {} (depth, m)", path.display()));
    }
    if let Some(path) = &args.png {
        let tonemap = Tonemap {
            exposure_ev: args
                .exposure
                .unwrap_or_else(|| Tonemap::auto_exposure_ev(&color)),
            mode: args.tonemap.mode(),
        };
        image_io::write_png(outputs.temporary(path), &color, tonemap)?;
        wrote.push(format!(
            "wrote {} (preview, exposure {:+.2} EV)",
            path.display(),
            tonemap.exposure_ev
        ));
    }
    outputs.commit()?;
    for line in wrote {
        println!("{line}");
    }
    let passes: Vec<String> = frame
        .timings
        .passes
        .iter()
        .map(|p| format!("{} {:.2} ms", p.name, p.ms))
        .collect();
    println!(
        "{}: {} triangles, {width}×{height} at t = {} s on {}; scene load {:.2} s, render {:.3} s (GPU: {})",
        scene.name,
        scene.geometry.triangle_count(),
        args.time,
        ctx.device_info().name,
        loaded_s,
        render_s,
        passes.join(", ")
    );
    Ok(())
}
