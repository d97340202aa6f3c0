//! `ocular serve`: the live viewer. A local web server whose page changes the eye, the focus
//! and the pupil and shows the frame as that eye sees it, the seed paper's interaction.
//!
//! - [`catalog`]: the scenes and eyes a client may name, loaded at start (no path from a
//!   request is ever opened);
//! - [`request`]: a client's settings, checked as the CLI checks its options, and the
//!   equivalent command line;
//! - [`worker`]: the one render thread (one device, one kernel cache for every client), the
//!   latest request per client, previews before full frames;
//! - [`server`]: HTTP (the page, the catalog, stats) and one WebSocket per client.
//!
//! The page itself (`page/`) is plain HTML, CSS and JavaScript built into the binary.

pub mod catalog;
pub mod request;
pub mod server;
pub mod worker;

use std::net::SocketAddr;
use std::path::PathBuf;
use std::sync::Arc;

use crate::gpu::{Context, ContextOptions};
use crate::render::live::LiveRenderer;
use crate::{Error, Result};

/// Eye states whose kernels the server keeps on the device: a preview and a full frame of
/// two eyes in a comparison, and the state before the last change.
pub const KEPT_EYE_STATES: usize = 8;

/// Told the bound address and the device's name once the server listens.
pub type OnListen = Box<dyn FnOnce(SocketAddr, &str) + Send>;

/// How `ocular serve` was started.
pub struct ServeConfig {
    pub addr: SocketAddr,
    pub scenes_dir: Option<PathBuf>,
    pub eyes_dir: Option<PathBuf>,
    pub bounds: request::Bounds,
    pub max_clients: usize,
    pub device: ContextOptions,
    pub cache_dir: Option<PathBuf>,
    /// Called with the address once the server listens (the CLI prints it).
    pub on_listen: OnListen,
}

/// Host names the page answers to: the loopback names, and the address bound when it is not
/// a loopback or unspecified one.
fn hosts(addr: &SocketAddr) -> Vec<String> {
    let mut hosts: Vec<String> = ["127.0.0.1", "localhost", "[::1]"]
        .iter()
        .map(|s| s.to_string())
        .collect();
    let ip = addr.ip();
    if !ip.is_loopback() && !ip.is_unspecified() {
        hosts.push(match ip {
            std::net::IpAddr::V6(v6) => format!("[{v6}]"),
            std::net::IpAddr::V4(v4) => v4.to_string(),
        });
    }
    hosts
}

/// Loads the catalog, opens the device, and serves until interrupted.
pub fn serve(config: ServeConfig) -> Result<()> {
    let catalog = Arc::new(catalog::Catalog::load(
        config.scenes_dir.as_deref(),
        config.eyes_dir.as_deref(),
    )?);
    for s in &catalog.skipped {
        eprintln!("warning: skipped {s}");
    }
    let hub = worker::Hub::new();
    // The device is opened on the render thread that uses it; its name comes back here.
    let (ready_tx, ready_rx) = std::sync::mpsc::channel::<Result<String>>();
    let device = config.device.clone();
    let (cache_dir, worker_hub, worker_catalog) = (
        config.cache_dir.clone(),
        Arc::clone(&hub),
        Arc::clone(&catalog),
    );
    let render_thread = std::thread::Builder::new()
        .name("ocular-render".into())
        .spawn(move || {
            let live = match Context::new(&device) {
                Ok(ctx) => LiveRenderer::new(ctx, cache_dir, KEPT_EYE_STATES),
                Err(e) => {
                    let _ = ready_tx.send(Err(e.into()));
                    return;
                }
            };
            let _ = ready_tx.send(Ok(live.device()));
            worker::Worker::new(worker_hub, live, worker_catalog).run();
        })
        .map_err(|e| Error::input(format!("cannot start the render thread: {e}")))?;
    let device_name = ready_rx
        .recv()
        .map_err(|_| Error::input("the render thread stopped before opening the device"))??;
    let runtime = tokio::runtime::Builder::new_multi_thread()
        .worker_threads(2)
        .enable_all()
        .build()
        .map_err(|e| Error::input(format!("cannot start the server runtime: {e}")))?;
    let shared = Arc::new(server::Shared::new(
        Arc::clone(&hub),
        catalog,
        config.bounds,
        config.max_clients,
        device_name.clone(),
        hosts(&config.addr),
    ));
    let addr = config.addr;
    let served = runtime.block_on(async move {
        let listener = tokio::net::TcpListener::bind(addr)
            .await
            .map_err(|e| Error::input(format!("--host/--port: cannot listen on {addr}: {e}")))?;
        let bound = listener
            .local_addr()
            .map_err(|e| Error::input(format!("cannot read the bound address: {e}")))?;
        (config.on_listen)(bound, &device_name);
        server::serve(listener, shared)
            .await
            .map_err(|e| Error::input(format!("the server stopped: {e}")))
    });
    hub.shutdown();
    let _ = render_thread.join();
    served
}
