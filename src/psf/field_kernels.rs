//! Kernels over the visual field for the runtime: one kernel grid per node of a (h, v) lattice
//! ([`super::field_plan`] chooses it from the frame), all sharing one largest radius. They
//! share the PSF texture, whose radius levels must mean the same in every node, so the radius
//! is chosen only once every node's PSFs are known (one pass over the PSFs, not two).
//!
//! Between nodes a fragment's kernel is the bilinear mix, in field angle, of the four nodes'
//! kernels at the fragment's own radius (itself the bilinear mix of the nodes' natural radii):
//! exact at the nodes, and between them a mix of shapes at one scale rather than of blurs of
//! different sizes, which would double the edge of a defocus disc.

use super::axes::{GridAxes, KernelSettings, Screen};
use super::cache::{cache_path, key_of, read_grid, write_grid, CacheOutcome};
use super::field::{field_column, field_grid_key, FieldAxes};
use super::grid::{grid_from_psfs, psfs_of_columns, GridReport, Progress, Stage};
use super::kernels::KernelGrid;
use crate::eye::Eye;
use crate::{Error, Result};
use std::path::Path;
use std::time::Instant;

/// One kernel grid per field node, h-major (the order of [`FieldAxes::nodes`]).
#[derive(Clone, Debug, PartialEq)]
pub struct KernelField {
    pub axes: FieldAxes,
    pub grids: Vec<KernelGrid>,
}

/// Position of `x` on a uniform axis: (lower node, upper node, fraction), clamped to its ends.
pub fn axis_position(nodes: &[f64], x: f64) -> (usize, usize, f64) {
    let n = nodes.len();
    if n <= 1 {
        return (0, 0, 0.0);
    }
    let step = (nodes[n - 1] - nodes[0]) / (n - 1) as f64;
    let t = ((x - nodes[0]) / step).clamp(0.0, (n - 1) as f64);
    let lo = (t.floor() as usize).min(n - 2);
    (lo, lo + 1, t - lo as f64)
}

impl KernelField {
    /// Nodes per axis (h, v).
    pub fn node_counts(&self) -> [usize; 2] {
        [self.axes.h_deg.len(), self.axes.v_deg.len()]
    }

    pub fn max_radius_px(&self) -> u32 {
        self.grids.first().map_or(0, |g| g.max_radius_px)
    }

    /// The four nodes around field `field_deg` and their bilinear weights (clamped at the
    /// lattice's edges), as indices into `grids`.
    pub fn weights(&self, field_deg: [f64; 2]) -> [(usize, f64); 4] {
        let (h0, h1, th) = axis_position(&self.axes.h_deg, field_deg[0]);
        let (v0, v1, tv) = axis_position(&self.axes.v_deg, field_deg[1]);
        let nv = self.axes.v_deg.len();
        [
            (h0 * nv + v0, (1.0 - th) * (1.0 - tv)),
            (h0 * nv + v1, (1.0 - th) * tv),
            (h1 * nv + v0, th * (1.0 - tv)),
            (h1 * nv + v1, th * tv),
        ]
    }

    /// The node nearest the axis (the largest weight at field (0, 0)).
    pub fn nearest_to_axis(&self) -> usize {
        self.weights([0.0, 0.0])
            .iter()
            .copied()
            .fold((0, -1.0), |a, b| if b.1 > a.1 { b } else { a })
            .0
    }

    /// Every node's grid valid, on the same axes and radius, one per node, axes uniform.
    pub fn validate(&self) -> std::result::Result<(), String> {
        let [nh, nv] = self.node_counts();
        if nh == 0 || nv == 0 || self.grids.len() != nh * nv {
            return Err(format!(
                "{} kernel grids for {nh} × {nv} field nodes",
                self.grids.len()
            ));
        }
        for axis in [&self.axes.h_deg, &self.axes.v_deg] {
            if axis.iter().any(|v| !v.is_finite()) || axis.windows(2).any(|w| w[1] <= w[0]) {
                return Err(format!("field axis {axis:?} is not increasing"));
            }
            let n = axis.len();
            if n > 2 {
                let step = (axis[n - 1] - axis[0]) / (n - 1) as f64;
                if axis
                    .windows(2)
                    .any(|w| ((w[1] - w[0]) - step).abs() > 1e-6 * step)
                {
                    return Err(format!("field axis {axis:?} is not uniform"));
                }
            }
        }
        let first = &self.grids[0];
        for (i, g) in self.grids.iter().enumerate() {
            g.validate().map_err(|e| format!("field node {i}: {e}"))?;
            let same = g.pupils_mm == first.pupils_mm
                && g.focus_d == first.focus_d
                && g.objects == first.objects
                && g.max_radius_px == first.max_radius_px
                && g.wavelengths_nm == first.wavelengths_nm
                && g.height_px == first.height_px
                && g.fov_y_deg == first.fov_y_deg;
            if !same {
                return Err(format!(
                    "field node {i} has other axes or another largest radius than node 0"
                ));
            }
        }
        Ok(())
    }
}

/// What computing (or loading) a field's kernels did.
pub struct FieldKernelsOutcome {
    pub field: KernelField,
    /// Per node, when computed now (empty when every node came from the cache).
    pub reports: Vec<GridReport>,
    pub cache: CacheOutcome,
}

/// The cache key of a whole field set (its nodes' keys, in order).
pub fn field_set_key(
    eye: &Eye,
    axes: &GridAxes,
    screen: &Screen,
    settings: &KernelSettings,
    field: &FieldAxes,
) -> String {
    let nodes: Vec<String> = field
        .nodes()
        .into_iter()
        .map(|n| field_grid_key(eye, axes, screen, settings, n))
        .collect();
    let mut parts: Vec<&str> = vec!["field set"];
    parts.extend(nodes.iter().map(String::as_str));
    key_of(&parts)
}

fn node_key(set_key: &str, node: usize) -> String {
    key_of(&[set_key, &format!("node {node}")])
}

/// Loads every node of the set from the cache, or None if any is missing or unusable.
fn load_set(dir: &Path, set_key: &str, nodes: usize) -> Option<Vec<KernelGrid>> {
    (0..nodes)
        .map(|i| {
            read_grid(
                &cache_path(dir, &node_key(set_key, i)),
                Some(&node_key(set_key, i)),
            )
            .ok()
        })
        .collect()
}

/// Every node's kernel grid for `field`, with one largest radius, through the cache.
pub fn compute_kernel_field(
    eye: &Eye,
    axes: &GridAxes,
    screen: &Screen,
    settings: &KernelSettings,
    field: &FieldAxes,
    cache_dir: Option<&Path>,
    progress: Progress,
) -> Result<FieldKernelsOutcome> {
    let nodes = field.nodes();
    let set_key = field_set_key(eye, axes, screen, settings, field);
    if let Some(dir) = cache_dir {
        if let Some(grids) = load_set(dir, &set_key, nodes.len()) {
            let kf = KernelField {
                axes: field.clone(),
                grids,
            };
            if kf.validate().is_ok() {
                return Ok(FieldKernelsOutcome {
                    field: kf,
                    reports: Vec::new(),
                    cache: CacheOutcome::Hit(cache_path(dir, &node_key(&set_key, 0))),
                });
            }
        }
    }
    let pairs = axes.column_states();
    // Every node's PSFs first: the common largest radius is the largest natural one.
    let mut staged = Vec::with_capacity(nodes.len());
    for (i, &n) in nodes.iter().enumerate() {
        let t = Instant::now();
        let columns = pairs
            .iter()
            .map(|&(p, f)| field_column(eye, p, f, axes.wavelengths_nm, settings, n))
            .collect::<Result<Vec<_>>>()
            .map_err(|e| Error::input(format!("field node ({}, {})°: {e}", n[0], n[1])))?;
        let seconds_optics = t.elapsed().as_secs_f64();
        let psfs = psfs_of_columns(&columns, axes, screen, settings, &|_, _, _| {})?;
        progress(Stage::Psfs, i + 1, nodes.len());
        staged.push((columns, psfs, seconds_optics));
    }
    let radius = staged
        .iter()
        .map(|(_, p, _)| p.natural_max_radius_px())
        .fold(0.0f64, f64::max)
        .ceil() as u32;
    let mut grids = Vec::with_capacity(nodes.len());
    let mut reports = Vec::with_capacity(nodes.len());
    for (i, (columns, psfs, seconds_optics)) in staged.into_iter().enumerate() {
        let (grid, mut report) = grid_from_psfs(
            &columns,
            psfs,
            axes,
            screen,
            settings,
            &|_, _, _| {},
            // every level: the four-node mix reads a node's kernels at its neighbours' radii
            (radius, false),
        )?;
        report.seconds_optics = seconds_optics;
        progress(Stage::Kernels, i + 1, nodes.len());
        grids.push(grid);
        reports.push(report);
    }
    let kf = KernelField {
        axes: field.clone(),
        grids,
    };
    kf.validate()
        .map_err(|e| Error::input(format!("field kernels came out invalid: {e}")))?;
    let cache = match cache_dir {
        None => CacheOutcome::Disabled,
        Some(dir) => {
            let written = kf.grids.iter().enumerate().try_for_each(|(i, g)| {
                let key = node_key(&set_key, i);
                write_grid(&cache_path(dir, &key), g, &key)
            });
            match written {
                Ok(()) => CacheOutcome::Stored {
                    path: cache_path(dir, &node_key(&set_key, 0)),
                    warning: None,
                },
                Err(e) => CacheOutcome::WriteFailed(format!("cannot write the cache: {e}")),
            }
        }
    };
    Ok(FieldKernelsOutcome {
        field: kf,
        reports,
        cache,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn weights_are_bilinear_and_clamped() {
        let axes = FieldAxes {
            h_deg: vec![-20.0, 0.0, 20.0],
            v_deg: vec![-10.0, 10.0],
        };
        let kf = KernelField {
            axes,
            grids: Vec::new(),
        };
        // h = 5: between nodes 1 and 2 at 1/4; v = 0: halfway.
        let w = kf.weights([5.0, 0.0]);
        let expect = [(2, 0.375), (3, 0.375), (4, 0.125), (5, 0.125)];
        for (a, b) in w.iter().zip(expect) {
            assert_eq!(a.0, b.0);
            assert!((a.1 - b.1).abs() < 1e-12, "{w:?}");
        }
        // beyond the lattice: the edge node alone
        let w = kf.weights([40.0, 30.0]);
        let total: f64 = w.iter().filter(|(i, _)| *i == 5).map(|(_, x)| x).sum();
        assert!((total - 1.0).abs() < 1e-12, "{w:?}");
        assert_eq!(axis_position(&[3.0], 7.0), (0, 0, 0.0));
    }
}
