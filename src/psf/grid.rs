//! The PSF grid precomputation: eye → per (pupil, focus) state → per wavelength and object
//! distance a PSF → screen kernels at every radius (see [`super::kernels`] for the layout).
//!
//! Work is shared where the optics allows: one accommodation per (pupil, focus), one aberration
//! measurement and one β expansion per (λ, pupil, focus) ([`ColumnOptics`]); only the defocus
//! parameter f changes with the object distance. PSFs run in parallel (rayon), each on one
//! core.

use super::axes::{GridAxes, KernelSettings, Screen};
use super::defocus::ColumnOptics;
use super::kernels::{
    kernel_side, level_block_radius, level_count, level_radius_px, KernelGrid, KernelSet,
};
use super::project::{cropped_psf, CroppedPsf};
use crate::eye::Eye;
use crate::{Error, Result};
use rayon::prelude::*;
use serde::Serialize;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::time::Instant;

/// Stages reported to a progress callback as (stage, done, total).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Stage {
    /// Accommodation and aberration measurement per (pupil, focus).
    Optics,
    /// One PSF per (pupil, focus, wavelength, object).
    Psfs,
    /// Resampling to every radius, per (pupil, focus, object).
    Kernels,
}

/// A progress callback; must be cheap and thread-safe.
pub type Progress<'a> = &'a (dyn Fn(Stage, usize, usize) + Sync);

/// No progress reporting.
pub fn no_progress(_: Stage, _: usize, _: usize) {}

/// Per (pupil, focus) state: how the eye was focused and what is left at each wavelength.
#[derive(Clone, Debug, Serialize)]
pub struct ColumnReport {
    pub pupil_mm: f64,
    pub focus_d: f64,
    pub lens_diameter_mm: f64,
    pub beyond_far_point: bool,
    /// Refraction left at the focus distance per channel (D, negative = focused in front
    /// of the retina, i.e. myopic).
    pub residual_d: [f64; 3],
    pub beta_degree: [u32; 3],
    pub beta_truncation_error: [f64; 3],
}

/// What a grid computation did.
#[derive(Clone, Debug, Serialize)]
pub struct GridReport {
    pub psfs_computed: usize,
    /// PSFs of a reference grid that were not needed (see [`super::plan`]); 0 otherwise.
    pub psfs_skipped: usize,
    pub max_radius_px: u32,
    /// Largest natural radius before the cap (px).
    pub natural_max_radius_px: f64,
    /// Natural radii clamped to the cap.
    pub clamped_radii: usize,
    pub min_kept_energy: f64,
    pub largest_psf_side: usize,
    pub bytes_per_set: u64,
    pub seconds_optics: f64,
    pub seconds_psfs: f64,
    pub seconds_kernels: f64,
    pub columns: Vec<ColumnReport>,
}

/// Focuses and measures the eye for every (pupil, focus) pair, pupil-major.
pub fn columns_for(
    eye: &Eye,
    axes: &GridAxes,
    settings: &KernelSettings,
    progress: Progress,
) -> Result<Vec<ColumnOptics>> {
    axes.validate().map_err(Error::input)?;
    settings.validate().map_err(Error::input)?;
    eye.validate()?;
    let pairs: Vec<(f64, f64)> = axes
        .pupils_mm
        .iter()
        .flat_map(|&p| axes.focus_d.iter().map(move |&f| (p, f)))
        .collect();
    let done = AtomicUsize::new(0);
    pairs
        .par_iter()
        .map(|&(p, f)| {
            let c = ColumnOptics::new(eye, p, f, axes.wavelengths_nm, settings);
            progress(
                Stage::Optics,
                done.fetch_add(1, Ordering::Relaxed) + 1,
                pairs.len(),
            );
            c
        })
        .collect()
}

/// Everything: columns, PSFs, kernels.
pub fn compute_grid(
    eye: &Eye,
    axes: &GridAxes,
    screen: &Screen,
    settings: &KernelSettings,
    progress: Progress,
) -> Result<(KernelGrid, GridReport)> {
    let t0 = Instant::now();
    let columns = columns_for(eye, axes, settings, progress)?;
    let seconds_optics = t0.elapsed().as_secs_f64();
    let (grid, mut report) = kernels_from_columns(&columns, axes, screen, settings, progress)?;
    report.seconds_optics = seconds_optics;
    Ok((grid, report))
}

/// The kernels of already focused and measured columns (as [`columns_for`] returns them).
pub fn kernels_from_columns(
    columns: &[ColumnOptics],
    axes: &GridAxes,
    screen: &Screen,
    settings: &KernelSettings,
    progress: Progress,
) -> Result<(KernelGrid, GridReport)> {
    screen.validate().map_err(Error::input)?;
    settings.validate().map_err(Error::input)?;
    if columns.len() != axes.pupils_mm.len() * axes.focus_d.len() {
        return Err(Error::input(
            "one column per (pupil, focus) pair is required",
        ));
    }
    let no = axes.objects.count;
    let t1 = Instant::now();
    let jobs: Vec<(usize, usize, usize)> = (0..columns.len())
        .flat_map(|s| (0..3).flat_map(move |c| (0..no).map(move |o| (s, c, o))))
        .collect();
    let done = AtomicUsize::new(0);
    let psfs: Vec<CroppedPsf> = jobs
        .par_iter()
        .map(|&(s, c, o)| {
            let p = cropped_psf(
                &columns[s].channels[c],
                axes.objects.value_d(o),
                screen,
                settings,
            );
            progress(
                Stage::Psfs,
                done.fetch_add(1, Ordering::Relaxed) + 1,
                jobs.len(),
            );
            p
        })
        .collect::<Result<_>>()?;
    let seconds_psfs = t1.elapsed().as_secs_f64();
    let psf = |s: usize, c: usize, o: usize| &psfs[(s * 3 + c) * no + o];

    let natural_max = psfs
        .iter()
        .map(CroppedPsf::natural_radius_px)
        .fold(0.0f64, f64::max);
    let max_radius = (natural_max.ceil() as u32).min(settings.max_radius_cap);
    let clamped_radii = psfs
        .iter()
        .filter(|p| p.natural_radius_px() > max_radius as f64)
        .count();

    let t2 = Instant::now();
    let done = AtomicUsize::new(0);
    let total_blocks = columns.len() * no;
    let mut sets = Vec::with_capacity(columns.len());
    for (s, col) in columns.iter().enumerate() {
        let mut set = KernelSet::zeroed(col.pupil_mm, col.focus_d, axes.objects, max_radius);
        for o in 0..no {
            for c in 0..3 {
                set.radius_px[o][c] =
                    psf(s, c, o).natural_radius_px().min(max_radius as f64) as f32;
            }
        }
        // Blocks are laid out level-major: split the texels into one slice per (level, o).
        let levels = level_count(max_radius);
        let mut blocks: Vec<(u32, usize, &mut [[f32; 3]])> = Vec::new();
        let mut rest: &mut [[f32; 3]] = &mut set.texels;
        for level in 0..levels {
            let n = kernel_side(level_block_radius(level)).pow(2);
            for o in 0..no {
                let (head, tail) = rest.split_at_mut(n);
                blocks.push((level, o, head));
                rest = tail;
            }
        }
        // Group by object so progress counts (set, object) units; levels run in parallel.
        blocks.par_iter_mut().for_each(|(level, o, block)| {
            let (radius, support) = (level_block_radius(*level), level_radius_px(*level) + 0.5);
            for c in 0..3 {
                let k = psf(s, c, *o).resample(radius, support);
                for (t, v) in block.iter_mut().zip(&k) {
                    t[c] = *v as f32;
                }
            }
            if *level == levels - 1 {
                progress(
                    Stage::Kernels,
                    done.fetch_add(1, Ordering::Relaxed) + 1,
                    total_blocks,
                );
            }
        });
        sets.push(set);
    }
    let seconds_kernels = t2.elapsed().as_secs_f64();
    let grid = KernelGrid {
        pupils_mm: axes.pupils_mm.clone(),
        focus_d: axes.focus_d.clone(),
        wavelengths_nm: axes.wavelengths_nm,
        objects: axes.objects,
        max_radius_px: max_radius,
        fov_y_deg: screen.fov_y_deg,
        height_px: screen.height_px,
        sets,
    };
    grid.validate()
        .map_err(|e| Error::input(format!("kernel grid came out invalid: {e}")))?;
    let report = GridReport {
        psfs_computed: psfs.len(),
        psfs_skipped: 0,
        max_radius_px: max_radius,
        natural_max_radius_px: natural_max,
        clamped_radii,
        min_kept_energy: psfs.iter().map(|p| p.kept_energy).fold(1.0, f64::min),
        largest_psf_side: psfs.iter().map(|p| p.grid_side).max().unwrap_or(0),
        bytes_per_set: grid.sets.first().map_or(0, KernelSet::size_bytes),
        seconds_optics: 0.0,
        seconds_psfs,
        seconds_kernels,
        columns: columns.iter().map(column_report).collect(),
    };
    Ok((grid, report))
}

fn column_report(c: &ColumnOptics) -> ColumnReport {
    let r2 = (0.5 * c.pupil_mm).powi(2);
    ColumnReport {
        pupil_mm: c.pupil_mm,
        focus_d: c.focus_d,
        lens_diameter_mm: c.lens_diameter_mm,
        beyond_far_point: c.beyond_far_point,
        residual_d: c
            .channels
            .each_ref()
            .map(|ch| -4.0 * 3f64.sqrt() * ch.residual_c20_um / r2),
        beta_degree: c.channels.each_ref().map(|ch| ch.pupil.beta.degree),
        beta_truncation_error: c
            .channels
            .each_ref()
            .map(|ch| ch.pupil.beta.truncation_error),
    }
}
