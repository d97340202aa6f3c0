//! `ocular devices`: what the Vulkan loader sees, and which device ocular would pick.

use clap::Args;

use super::Cli;
use crate::gpu::{resolve_device, DeviceInfo};
use crate::{Error, Result};

#[derive(Debug, Args)]
pub struct DevicesArgs {
    /// Print JSON instead of a table.
    #[arg(long)]
    pub json: bool,
}

#[derive(serde::Serialize)]
struct Report<'a> {
    selected: usize,
    devices: &'a [DeviceInfo],
}

pub fn run(cli: &Cli, args: &DevicesArgs) -> Result<()> {
    let (devices, selected) = resolve_device(cli.device_query().as_deref())?;
    if args.json {
        let text = serde_json::to_string_pretty(&Report {
            selected,
            devices: &devices,
        })
        .map_err(|e| Error::input(format!("cannot encode JSON: {e}")))?;
        println!("{text}");
        return Ok(());
    }
    println!(
        "  {:>3}  {:<40} {:<15} {:<8} {:>10}  driver",
        "#", "name", "type", "vulkan", "memory"
    );
    for d in &devices {
        let mark = if d.index == selected { "*" } else { " " };
        println!(
            "{mark} {:>3}  {:<40} {:<15} {:<8} {:>7} MiB  {}{}",
            d.index,
            d.name,
            d.kind.label(),
            d.vulkan_version,
            d.device_local_mib,
            d.driver,
            d.unsuitable
                .as_ref()
                .map(|r| format!("  (unusable: {r})"))
                .unwrap_or_default()
        );
    }
    println!("* = used by default; choose another with --device <index|name> or OCULAR_DEVICE");
    Ok(())
}
