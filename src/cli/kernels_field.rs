//! `ocular kernels --field-deg H0..H1:N,V0..V1:M`: one kernel grid per field direction, each
//! taken from the cache when it is there and computed (and stored) only when it is not. `-o`
//! names an index (TOML) of the directions; each grid is written next to it as STEM.hI.vJ.bin
//! (I, J the indices of its angles on the two axes).

use super::outputs::Outputs;
use crate::eye::Eye;
use crate::psf::axes::{GridAxes, KernelSettings, Screen};
use crate::psf::cache::{cached, write_grid, CacheOutcome};
use crate::psf::field::{compute_field_grid, field_grid_key, FieldAxes};
use crate::psf::field_plan::FieldPlan;
use crate::psf::grid::no_progress;
use crate::{Error, Result};
use std::path::{Path, PathBuf};
use std::time::Instant;

/// The file of direction (h index, v index)'s grid: `STEM.hI.vJ.bin` next to the index.
pub fn node_path(index: &Path, ij: [usize; 2]) -> PathBuf {
    let stem = index
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_else(|| "kernels".into());
    index.with_file_name(format!("{stem}.h{}.v{}.bin", ij[0], ij[1]))
}

/// (h index, v index) of every node in the order of [`FieldAxes::nodes`].
fn indices(field: &FieldAxes) -> Vec<[usize; 2]> {
    let nv = field.v_deg.len();
    (0..field.h_deg.len() * nv)
        .map(|k| [k / nv, k % nv])
        .collect()
}

#[derive(serde::Serialize)]
struct Node {
    h_deg: f64,
    v_deg: f64,
    file: String,
    key: String,
    max_radius_px: u32,
    cached: bool,
    seconds: f64,
}

#[derive(serde::Serialize)]
struct Index {
    eye: String,
    fov_y_deg: f64,
    height_px: u32,
    h_deg: Vec<f64>,
    v_deg: Vec<f64>,
    node: Vec<Node>,
}

/// The directions a frame needs ([`crate::psf::field_plan::plan_for_frame`]).
pub fn plan(eye: &Eye, axes: &GridAxes, screen: &Screen, width_px: u32) -> Result<FieldPlan> {
    crate::psf::field_plan::plan_for_frame(eye, axes, screen, width_px)
}

/// Registers the index and every node's file (so that a bad name fails before any work).
pub fn register(outputs: &mut Outputs, index: &Path, field: &FieldAxes) -> Result<()> {
    outputs.add("-o", index, &["toml"])?;
    for ij in indices(field) {
        outputs.add("-o", &node_path(index, ij), &[])?;
    }
    Ok(())
}

#[allow(clippy::too_many_arguments)]
pub fn run(
    outputs: Outputs,
    index: &Path,
    eye_spec: &str,
    eye: &Eye,
    axes: &GridAxes,
    screen: &Screen,
    settings: &KernelSettings,
    field: &FieldAxes,
    cache_dir: Option<&Path>,
    json: bool,
) -> Result<()> {
    let mut nodes = Vec::new();
    for (n, ij) in field.nodes().into_iter().zip(indices(field)) {
        let t = Instant::now();
        let key = field_grid_key(eye, axes, screen, settings, n);
        let (grid, report, outcome) = cached(cache_dir, &key, || {
            compute_field_grid(eye, axes, screen, settings, n, &no_progress)
        })?;
        for w in report.iter().flat_map(|r| r.warnings.iter()) {
            eprintln!("warning: field ({}, {})°: {w}", n[0], n[1]);
        }
        if let CacheOutcome::WriteFailed(w) = &outcome {
            eprintln!("warning: {w}");
        }
        let path = node_path(index, ij);
        write_grid(outputs.temporary(&path), &grid, &key)?;
        nodes.push(Node {
            h_deg: n[0],
            v_deg: n[1],
            file: path
                .file_name()
                .map(|s| s.to_string_lossy().into_owned())
                .unwrap_or_default(),
            key,
            max_radius_px: grid.max_radius_px,
            cached: matches!(outcome, CacheOutcome::Hit(_)),
            seconds: t.elapsed().as_secs_f64(),
        });
    }
    let idx = Index {
        eye: eye_spec.to_string(),
        fov_y_deg: screen.fov_y_deg,
        height_px: screen.height_px,
        h_deg: field.h_deg.clone(),
        v_deg: field.v_deg.clone(),
        node: nodes,
    };
    let text = toml::to_string_pretty(&idx)
        .map_err(|e| Error::input(format!("cannot encode the index: {e}")))?;
    std::fs::write(
        outputs.temporary(index),
        format!("# ocular kernels over the field: one grid file per direction\n{text}"),
    )
    .map_err(|e| Error::file(index, e))?;
    outputs.commit()?;
    if json {
        let text = serde_json::to_string_pretty(&idx)
            .map_err(|e| Error::input(format!("cannot encode JSON: {e}")))?;
        println!("{text}");
    } else {
        println!(
            "{}: {} directions ({} × {})",
            index.display(),
            idx.node.len(),
            idx.h_deg.len(),
            idx.v_deg.len()
        );
        for n in &idx.node {
            println!(
                "  ({:+.2}, {:+.2})°: {} Rmax {} px, {}",
                n.h_deg,
                n.v_deg,
                n.file,
                n.max_radius_px,
                if n.cached {
                    "from the cache".to_string()
                } else {
                    format!("computed in {:.1} s", n.seconds)
                }
            );
        }
    }
    Ok(())
}
