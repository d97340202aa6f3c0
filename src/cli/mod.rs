//! Command-line front end: one file per subcommand; `main.rs` only parses and calls `run`.

use clap::{Parser, Subcommand};

use crate::gpu::ContextOptions;
use crate::Result;

mod devices;
pub mod kernels;
mod psf;
mod raster;

#[derive(Debug, Parser)]
#[command(
    name = "ocular",
    version,
    about = "Render a 3D scene as a particular human eye sees it",
    long_about = "ocular turns a wavefront measurement (Zernike coefficients) or a spectacle \
                  prescription into a physical eye model, computes its point-spread functions \
                  through focus, and renders colour + depth frames through them on the GPU with \
                  tiled PSF splatting (Csoba & Kunkli 2021)."
)]
pub struct Cli {
    /// GPU to use: an index or a name substring as `ocular devices` lists them (default: the
    /// most capable device; a discrete GPU first, a CPU implementation last).
    #[arg(long, global = true, env = "OCULAR_DEVICE", value_name = "INDEX|NAME")]
    pub device: Option<String>,

    #[command(subcommand)]
    pub command: Command,
}

#[derive(Debug, Subcommand)]
pub enum Command {
    /// List the Vulkan devices and mark the one ocular would use.
    Devices(devices::DevicesArgs),
    /// Precompute an eye's PSF kernel grid (cached), with an optional contact sheet and plot.
    Kernels(Box<kernels::KernelsArgs>),
    /// Compute one point-spread function from Zernike coefficients (EXR + JSON sidecar).
    Psf(psf::PsfArgs),
    /// Rasterise a scene to linear HDR colour and metric depth (EXR), plus an optional PNG.
    Raster(raster::RasterArgs),
}

impl Cli {
    pub fn context_options(&self) -> ContextOptions {
        ContextOptions {
            device: self.device.clone().filter(|d| !d.is_empty()),
            ..ContextOptions::default()
        }
    }
}

pub fn run(cli: Cli) -> Result<()> {
    match &cli.command {
        Command::Devices(args) => devices::run(&cli, args),
        Command::Kernels(args) => kernels::run(args),
        Command::Raster(args) => raster::run(&cli, args),
        Command::Psf(args) => psf::run(args),
    }
}
