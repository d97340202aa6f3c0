//! `ocular serve`: the live viewer (`crate::viewer`) on a local web server.

use std::net::{IpAddr, Ipv4Addr, SocketAddr};
use std::path::PathBuf;

use clap::Args;

use super::Cli;
use crate::viewer::request::Bounds;
use crate::viewer::{serve, ServeConfig};
use crate::{Error, Result};

#[derive(Debug, Args)]
#[command(after_help = "Examples:\n  \
    ocular serve                                 # http://127.0.0.1:8321/\n  \
    ocular serve --scenes my-scenes --eyes my-eyes --port 9000\n\n\
Open the address it prints in a browser. The page changes the scene, the eye (a preset, an eye \
file of --eyes, or a prescription), its correction, the focus (click the image, or a slider), \
the pupil, the age and the quality, compares two eyes side by side or with a split, and exports \
the frame (PNG, EXR) with the `ocular render` command that makes it. One device and one kernel \
cache serve every client; a client's newer change replaces the frame it waits for.\n\n\
Security: the server binds 127.0.0.1 and answers only to loopback host names. --host with \
another address lets every machine that reaches it use this GPU and read the scenes and eyes \
of the folders given (nothing else: requests name entries, never paths); there is no \
authentication. Use it only on a network you trust.")]
pub struct ServeArgs {
    /// Port to listen on (0: any free port; the address is printed).
    #[arg(long, default_value_t = 8321)]
    pub port: u16,
    /// Address to bind. Anything but a loopback address exposes the viewer to the network
    /// (see below); it needs --allow-remote.
    #[arg(long, value_name = "IP", default_value = "127.0.0.1")]
    pub host: IpAddr,
    /// Confirms a --host that is not a loopback address.
    #[arg(long)]
    pub allow_remote: bool,
    /// Folder of scene .toml files the page offers besides the built-in scenes.
    #[arg(long, value_name = "DIR")]
    pub scenes: Option<PathBuf>,
    /// Folder of eye .toml files (from `ocular eye estimate`) the page offers besides the
    /// presets.
    #[arg(long, value_name = "DIR")]
    pub eyes: Option<PathBuf>,
    /// Largest frame a client may ask for, in pixels (width × height).
    #[arg(long, value_name = "PIXELS", default_value_t = 1920 * 1080)]
    pub max_pixels: u64,
    /// Most depth layers a client may ask for (1 to 8).
    #[arg(long, value_name = "K", default_value_t = 4)]
    pub max_layers: u32,
    /// Most clients connected at once.
    #[arg(long, value_name = "N", default_value_t = 32)]
    pub max_clients: usize,
    #[command(flatten)]
    pub cache: super::CacheArgs,
}

pub fn run(cli: &Cli, args: &ServeArgs) -> Result<()> {
    if !args.host.is_loopback() && !args.allow_remote {
        return Err(Error::input(format!(
            "--host {}: not a loopback address; this exposes the viewer (and this GPU) to every \
             machine that reaches it, without authentication: add --allow-remote to confirm",
            args.host
        )));
    }
    let most_layers = crate::inputs::layered::MAX_LAYERS as u32;
    if !(1..=most_layers).contains(&args.max_layers) {
        return Err(Error::input(format!(
            "--max-layers {} is not a number of layers from 1 to {most_layers}",
            args.max_layers
        )));
    }
    let min_pixels = u64::from(super::raster::MIN_FRAME_SIDE).pow(2);
    if !(min_pixels..=16384 * 16384).contains(&args.max_pixels) {
        return Err(Error::input(format!(
            "--max-pixels {} is outside {min_pixels} to {}",
            args.max_pixels,
            16384u64 * 16384
        )));
    }
    if !(1..=1024).contains(&args.max_clients) {
        return Err(Error::input(format!(
            "--max-clients {} is outside 1 to 1024",
            args.max_clients
        )));
    }
    serve(ServeConfig {
        addr: SocketAddr::new(args.host, args.port),
        scenes_dir: args.scenes.clone(),
        eyes_dir: args.eyes.clone(),
        bounds: Bounds {
            max_pixels: args.max_pixels,
            max_side_px: 16384,
            max_layers: args.max_layers,
        },
        max_clients: args.max_clients,
        device: cli.context_options(),
        cache_dir: args.cache.dir(),
        on_listen: Box::new(|addr, device| {
            let shown = if addr.ip().is_unspecified() {
                SocketAddr::new(IpAddr::V4(Ipv4Addr::LOCALHOST), addr.port())
            } else {
                addr
            };
            println!("ocular viewer on http://{shown}/ ({device}); Ctrl-C stops it");
            use std::io::Write;
            let _ = std::io::stdout().flush();
        }),
    })
}
