//! Command-line front end: one file per subcommand; `main.rs` only parses and calls `run`.

use clap::{Parser, Subcommand};

use crate::gpu::ContextOptions;
use crate::Result;

mod devices;
mod eye;
mod eye_plot;

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
    /// Eyes: estimate one from a wavefront or prescription, show, measure, draw, list presets.
    Eye(Box<eye::EyeArgs>),
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
        Command::Eye(args) => eye::run(args),
    }
}

/// Writes `bytes` to `path` through a temporary file in the same folder and a rename, so a
/// reader never sees a partial file and a failed run leaves no file behind.
pub(crate) fn write_atomic(path: &std::path::Path, bytes: &[u8]) -> Result<()> {
    let dir = match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d.to_path_buf(),
        _ => std::path::PathBuf::from("."),
    };
    let name = path
        .file_name()
        .ok_or_else(|| crate::Error::input(format!("{}: not a file name", path.display())))?;
    let tmp = dir.join(format!(
        ".{}.{}.tmp",
        name.to_string_lossy(),
        std::process::id()
    ));
    let result = std::fs::write(&tmp, bytes).and_then(|_| std::fs::rename(&tmp, path));
    if let Err(e) = result {
        let _ = std::fs::remove_file(&tmp);
        return Err(crate::Error::file(path, format!("cannot write: {e}")));
    }
    Ok(())
}
