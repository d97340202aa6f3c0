//! A kernel grid asked for by its axes and settings (`ocular kernels`): checked, with errors
//! that name the command-line options, and narrowed to what a scene's depth range needs.

use crate::psf::axes::{GridAxes, KernelSettings, Screen};
use crate::psf::plan::{plan_for_scene, SceneNeeds};
use crate::{Error, Result};

/// The kernel settings of a grid of `axes` for `screen`, with its largest radius (px) and the
/// fraction of each PSF's energy a kernel keeps and the object axis' blend tolerance; the axes,
/// screen and settings are checked.
pub fn grid_settings(
    axes: &GridAxes,
    screen: &Screen,
    rmax_cap: u32,
    energy: f64,
    object_tolerance: f64,
) -> Result<KernelSettings> {
    axes.validate()
        .map_err(|e| Error::input(format!("--{e}")))?;
    screen
        .validate()
        .map_err(|e| Error::input(format!("--{e}")))?;
    let settings = KernelSettings {
        max_radius_cap: rmax_cap,
        energy,
        object_tolerance,
        ..KernelSettings::default()
    };
    settings.validate().map_err(|e| {
        Error::input(
            e.replace("max_radius_cap", "--rmax-cap")
                .replace("object_tolerance", "--object-tolerance")
                .replace("energy", "--energy"),
        )
    })?;
    Ok(settings)
}

/// A grid narrowed to a scene's dioptre range, and what that left out.
#[derive(Clone, Debug)]
pub struct SceneGrid {
    pub axes: GridAxes,
    pub skipped_psfs: usize,
    pub notes: Vec<String>,
}

/// Keeps only the object distances a scene spanning `lo..hi` D needs, at every focus and
/// pupil of `axes`.
pub fn scene_grid(axes: &GridAxes, screen: Screen, (lo, hi): (f64, f64)) -> Result<SceneGrid> {
    let needs = SceneNeeds {
        dioptre_min: lo,
        dioptre_max: hi,
        focus_d: axes.focus_d.clone(),
        pupils_mm: axes.pupils_mm.clone(),
        screen,
    };
    let plan = plan_for_scene(&needs, axes).map_err(|e| Error::input(format!("--scene-d: {e}")))?;
    Ok(SceneGrid {
        axes: plan.axes,
        skipped_psfs: plan.skipped_psfs,
        notes: plan.notes,
    })
}
