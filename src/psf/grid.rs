//! The PSF grid precomputation: eye → per (pupil, focus) state → per wavelength and object
//! distance a PSF → screen kernels at every radius (see [`super::kernels`] for the layout).
//!
//! Work is shared where the optics allows: one accommodation per (pupil, focus), one aberration
//! measurement and one β expansion per (λ, pupil, focus) ([`ColumnOptics`]); only the defocus
//! parameter f changes with the object distance. PSFs run in parallel (rayon), each on one
//! core.

use super::axes::{GridAxes, KernelSettings, Screen};
use super::defocus::ColumnOptics;
use super::field_psf::cropped_psf;
use super::integrate::BoxIntegrator;
use super::kernels::{
    kernel_side, level_block_radius, level_count, level_radius_px, texels_below_level, KernelGrid,
    KernelSet,
};
use super::level_band;
use super::object_knots::{brackets, initial_knots, midpoint, open_intervals, weight};
use super::project::{PsfMethod, MAX_BINS};
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
    /// Worst pupil energy missed by any PSF of the column, per channel: the β truncation of
    /// the PSFs computed by the ENZ series, 0 for those computed by FFT (which sample the whole
    /// pupil function).
    pub missed_energy: [f64; 3],
    /// PSFs of the column computed by FFT, per channel (the rest by the ENZ series).
    pub fft_psfs: [usize; 3],
    /// PSFs computed per channel: the object knots ([`super::object_knots`]); the other
    /// samples are blends of them.
    pub psfs: [usize; 3],
}

/// Largest pupil energy a kernel's PSF may miss; beyond it the report carries a warning.
pub const MISSED_ENERGY_LIMIT: f64 = 1e-3;

/// What a grid computation did.
#[derive(Clone, Debug, Serialize)]
pub struct GridReport {
    pub psfs_computed: usize,
    /// Object samples filled by the blend of the computed ones around them.
    pub psfs_filled: usize,
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
    /// PSFs computed by FFT (the rest by the ENZ series).
    pub psfs_fft: usize,
    /// Worst missed pupil energy over every PSF, and the limit it is held to.
    pub worst_missed_energy: f64,
    pub missed_energy_limit: f64,
    /// Kernels whose PSF missed more than the limit (one line per column and channel).
    pub warnings: Vec<String>,
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
    measure_columns(eye, axes, settings, [0.0, 0.0], progress)
}

/// The eye focused (on axis) for every (pupil, focus) pair, pupil-major, and measured for the
/// field direction `field_deg`, in parallel; the inputs are checked by the caller.
pub(super) fn measure_columns(
    eye: &Eye,
    axes: &GridAxes,
    settings: &KernelSettings,
    field_deg: [f64; 2],
    progress: Progress,
) -> Result<Vec<ColumnOptics>> {
    let pairs = axes.column_states();
    let done = AtomicUsize::new(0);
    pairs
        .par_iter()
        .map(|&(p, f)| {
            let c = ColumnOptics::new_in_field(eye, p, f, axes.wavelengths_nm, settings, field_deg);
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
    let psfs = psfs_of_columns(columns, axes, screen, settings, progress)?;
    let radius = psfs.natural_max_radius_px().ceil() as u32;
    grid_from_psfs(
        columns,
        psfs,
        axes,
        screen,
        settings,
        progress,
        (radius, true),
    )
}

/// The PSFs of a grid's columns, kept as their pixel-integration bins: what the kernels are
/// made from at any largest radius (grids that share one texture share their largest radius,
/// so it is chosen only once every PSF is known). Indexed (column·3 + channel)·objects +
/// object; `None` where the object sample is filled from the knots around it
/// ([`super::object_knots`]).
pub(crate) struct ColumnPsfs {
    psfs: Vec<Option<PsfSummary>>,
    seconds: f64,
}

impl ColumnPsfs {
    /// Largest natural PSF radius over every PSF (px, before any cap). Filled samples lie
    /// between their knots' radii.
    pub fn natural_max_radius_px(&self) -> f64 {
        self.computed()
            .map(|p| p.natural_radius_px)
            .fold(0.0f64, f64::max)
    }

    fn computed(&self) -> impl Iterator<Item = &PsfSummary> + Clone {
        self.psfs.iter().flatten()
    }
}

/// Every PSF `columns` need (per column, channel and object knot): the knots start a dioptre
/// apart and intervals are halved, all columns and channels together round by round, while
/// the kernel at an interval's midpoint differs from the blend of its ends by more than
/// `settings.object_tolerance`.
pub(crate) fn psfs_of_columns(
    columns: &[ColumnOptics],
    axes: &GridAxes,
    screen: &Screen,
    settings: &KernelSettings,
    progress: Progress,
) -> Result<ColumnPsfs> {
    screen.validate().map_err(Error::input)?;
    settings.validate().map_err(Error::input)?;
    if columns.len() != axes.pupils_mm.len() * axes.focus_d.len() {
        return Err(Error::input(
            "one column per (pupil, focus) pair is required",
        ));
    }
    let no = axes.objects.count;
    let series = columns.len() * 3;
    let t1 = Instant::now();
    let compute = |s: usize, o: usize| -> Result<PsfSummary> {
        let ch = &columns[s / 3].channels[s % 3];
        let p = cropped_psf(ch, axes.objects.value_d(o), screen, settings)?;
        Ok(PsfSummary {
            natural_radius_px: p.natural_radius_px(),
            natural_half_samples: p.natural_half_samples,
            kept_energy: p.kept_energy,
            grid_side: p.grid_side,
            method: p.method,
            missed_energy: p.missed_energy,
            bins: p.integrator(settings.max_radius_cap, MAX_BINS),
        })
    };
    // Each PSF is kept only as its pixel-integration bins (a set's full-resolution PSFs would
    // not fit in memory for a whole grid); the largest radius is known at the end.
    let mut psfs: Vec<Option<PsfSummary>> = (0..series * no).map(|_| None).collect();
    let first = initial_knots(no, axes.objects.step_d, settings.object_tolerance);
    let mut jobs: Vec<(usize, usize)> = (0..series)
        .flat_map(|s| first.iter().map(move |&o| (s, o)))
        .collect();
    let mut intervals: Vec<(usize, (usize, usize))> = (0..series)
        .flat_map(|s| open_intervals(&first).into_iter().map(move |i| (s, i)))
        .collect();
    let done = AtomicUsize::new(0);
    loop {
        // The total grows round by round: what is known so far.
        let total = done.load(Ordering::Relaxed) + jobs.len();
        let part: Vec<PsfSummary> = jobs
            .par_iter()
            .map(|&(s, o)| {
                let summary = compute(s, o)?;
                progress(Stage::Psfs, done.fetch_add(1, Ordering::Relaxed) + 1, total);
                Ok(summary)
            })
            .collect::<Result<_>>()?;
        for (&(s, o), p) in jobs.iter().zip(part) {
            psfs[s * no + o] = Some(p);
        }
        // The midpoints just computed judge their intervals.
        let split: Vec<bool> = intervals
            .par_iter()
            .map(|&(s, (a, b))| {
                let m = midpoint((a, b));
                let at = |o: usize| psfs[s * no + o].as_ref();
                match (at(a), at(m), at(b)) {
                    (Some(pa), Some(pm), Some(pb)) => {
                        blend_error(pa, pm, pb, weight(a, m, b), settings.max_radius_cap)
                            > settings.object_tolerance
                    }
                    _ => false,
                }
            })
            .collect();
        let mut next = Vec::new();
        for (&(s, (a, b)), split) in intervals.iter().zip(split) {
            let m = midpoint((a, b));
            if psfs[s * no + m].is_none() {
                // first visit: compute the midpoint, judge next round
                next.push((s, (a, b)));
            } else if split {
                next.extend(open_intervals(&[a, m, b]).into_iter().map(|i| (s, i)));
            }
        }
        intervals = next;
        jobs = intervals
            .iter()
            .map(|&(s, i)| (s, midpoint(i)))
            .filter(|&(s, o)| psfs[s * no + o].is_none())
            .collect();
        if jobs.is_empty() {
            break;
        }
    }
    Ok(ColumnPsfs {
        psfs,
        seconds: t1.elapsed().as_secs_f64(),
    })
}

/// L1 distance between the kernel of `m` and the runtime's blend of `a` and `b` (weight `t`
/// on `b`) drawn where the runtime would draw it: at the radius blended the same way. Both
/// on one block, each at its own natural radius as the grid stores it.
fn blend_error(a: &PsfSummary, m: &PsfSummary, b: &PsfSummary, t: f64, cap: u32) -> f64 {
    let radius = |p: &PsfSummary| p.natural_radius_px.min(f64::from(cap));
    let (r_m, r_blend) = (radius(m), (1.0 - t) * radius(a) + t * radius(b));
    let block = r_m.max(r_blend).ceil().max(1.0) as u32;
    let drawn = |p: &PsfSummary, r: f64| p.bins.kernel(block, p.natural_half_samples / (r + 0.5));
    let (truth, ka, kb) = (drawn(m, r_m), drawn(a, r_blend), drawn(b, r_blend));
    truth
        .iter()
        .zip(ka.iter().zip(&kb))
        .map(|(x, (p, q))| (x - ((1.0 - t) * p + t * q)).abs())
        .sum()
}

/// The grid of `columns` from their PSFs, with kernels up to `radius_px` (at least every
/// natural radius, at most the settings' cap).
pub(crate) fn grid_from_psfs(
    columns: &[ColumnOptics],
    summaries: ColumnPsfs,
    axes: &GridAxes,
    screen: &Screen,
    settings: &KernelSettings,
    progress: Progress,
    (radius_px, band): (u32, bool),
) -> Result<(KernelGrid, GridReport)> {
    let no = axes.objects.count;
    let seconds_psfs = summaries.seconds;
    let natural_max = summaries.natural_max_radius_px();
    let psfs = summaries.psfs;
    if psfs.len() != columns.len() * 3 * no {
        return Err(Error::input(
            "one PSF per column, channel and object is required",
        ));
    }
    let psf = |s: usize, c: usize, o: usize| psfs[(s * 3 + c) * no + o].as_ref();
    let max_radius = radius_px
        .max(natural_max.ceil() as u32)
        .min(settings.max_radius_cap);
    let computed = || psfs.iter().flatten();
    let clamped_radii = computed()
        .filter(|p| p.natural_radius_px > max_radius as f64)
        .count();

    let t2 = Instant::now();
    let done = AtomicUsize::new(0);
    let total_blocks = columns.len() * no;
    let mut sets: Vec<KernelSet> = columns
        .iter()
        .map(|col| KernelSet::zeroed(col.pupil_mm, col.focus_d, axes.objects, max_radius))
        .collect();
    // Per set and channel, the knots around every object sample (a knot is its own), and the
    // natural radii, the filled samples' blended like their kernels.
    let arounds: Vec<Brackets> = (0..columns.len())
        .map(|s| std::array::from_fn(|c| brackets(no, |o| psf(s, c, o).is_some())))
        .collect();
    for (s, (set, around)) in sets.iter_mut().zip(&arounds).enumerate() {
        for (c, around) in around.iter().enumerate() {
            let r = |k: usize| psf(s, c, k).map_or(0.0, |p| p.natural_radius_px);
            for (radii, &(a, b, t)) in set.radius_px.iter_mut().zip(around) {
                radii[c] = ((1.0 - t) * r(a) + t * r(b)).min(max_radius as f64) as f32;
            }
        }
    }
    let tops = held_levels(&sets, &arounds, axes, band);
    for (s, set) in sets.iter_mut().enumerate() {
        let around = &arounds[s];
        let (reads, held) = &tops[s];
        set.top_level.clone_from(held);
        // Blocks are laid out level-major (level, then object). First the knots' blocks from
        // their PSFs, in parallel over objects, each PSF's running sums shared by its levels,
        // up to the levels its filled neighbours read from it.
        let levels = level_count(max_radius);
        let mut per_object: Vec<Vec<LevelBlock>> = (0..no).map(|_| Vec::new()).collect();
        let mut rest: &mut [[f32; 3]] = &mut set.texels;
        for level in 0..levels {
            let n = kernel_side(level_block_radius(level)).pow(2);
            for blocks in per_object.iter_mut() {
                let (head, tail) = rest.split_at_mut(n);
                blocks.push((level, head));
                rest = tail;
            }
        }
        per_object
            .par_iter_mut()
            .enumerate()
            .for_each(|(o, blocks)| {
                for c in 0..3 {
                    let Some(p) = psf(s, c, o) else { continue };
                    let sums = p.bins.summed_area();
                    for (level, block) in blocks.iter_mut().take(reads[o] as usize + 1) {
                        let radius = level_block_radius(*level);
                        // the natural half-width spans r + ½ px: pixels of half_samples / (r + ½)
                        let scale = p.natural_half_samples / (level_radius_px(*level) + 0.5);
                        let k = p.bins.kernel_with(&sums, radius, scale);
                        for (t, v) in block.iter_mut().zip(&k) {
                            t[c] = *v as f32;
                        }
                    }
                }
                progress(
                    Stage::Kernels,
                    done.fetch_add(1, Ordering::Relaxed) + 1,
                    total_blocks,
                );
            });
        drop(per_object);
        // Then the samples between knots: the runtime's blend of their knots' blocks.
        let mut per_level: Vec<(u32, &mut [[f32; 3]])> = Vec::new();
        let mut rest: &mut [[f32; 3]] = &mut set.texels;
        for level in 0..levels {
            let n = kernel_side(level_block_radius(level)).pow(2);
            let (head, tail) = rest.split_at_mut(n * no);
            per_level.push((level, head));
            rest = tail;
        }
        debug_assert_eq!(
            per_level.iter().map(|(_, l)| l.len()).sum::<usize>(),
            no * texels_below_level(levels)
        );
        per_level.par_iter_mut().for_each(|(level, texels)| {
            let n = kernel_side(level_block_radius(*level)).pow(2);
            for (c, around) in around.iter().enumerate() {
                for (o, &(a, b, t)) in around.iter().enumerate() {
                    if a == o || *level > held[o] {
                        continue;
                    }
                    let t = t as f32;
                    for i in 0..n {
                        let blend = (1.0 - t) * texels[a * n + i][c] + t * texels[b * n + i][c];
                        texels[o * n + i][c] = blend;
                    }
                }
            }
            // A knot's levels above what its distance holds served its neighbours' fill only.
            for (o, block) in texels.chunks_exact_mut(n).enumerate() {
                if *level > held[o] && *level <= reads[o] {
                    block.fill([0.0; 3]);
                }
            }
        });
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
    let column_reports: Vec<ColumnReport> = columns
        .iter()
        .enumerate()
        .map(|(s, c)| {
            let mut r = column_report(c);
            for ch in 0..3 {
                let these = (0..no).filter_map(|o| psf(s, ch, o));
                r.missed_energy[ch] = these.clone().map(|p| p.missed_energy).fold(0.0, f64::max);
                r.fft_psfs[ch] = these.clone().filter(|p| p.method == PsfMethod::Fft).count();
                r.psfs[ch] = these.count();
            }
            r
        })
        .collect();
    let mut warnings = Vec::new();
    for c in &column_reports {
        for ch in 0..3 {
            if c.missed_energy[ch] > MISSED_ENERGY_LIMIT {
                warnings.push(format!(
                    "pupil {} mm, focus {} D, {} nm: the PSFs miss {:.2e} of the pupil energy \
                     (limit {MISSED_ENERGY_LIMIT:e}); their kernels are too small",
                    c.pupil_mm, c.focus_d, axes.wavelengths_nm[ch], c.missed_energy[ch]
                ));
            }
        }
    }
    let psfs_computed = computed().count();
    let report = GridReport {
        psfs_computed,
        psfs_filled: psfs.len() - psfs_computed,
        psfs_skipped: 0,
        max_radius_px: max_radius,
        natural_max_radius_px: natural_max,
        clamped_radii,
        min_kept_energy: computed().map(|p| p.kept_energy).fold(1.0, f64::min),
        largest_psf_side: computed().map(|p| p.grid_side).max().unwrap_or(0),
        bytes_per_set: grid.sets.first().map_or(0, KernelSet::size_bytes),
        psfs_fft: computed().filter(|p| p.method == PsfMethod::Fft).count(),
        worst_missed_energy: computed().map(|p| p.missed_energy).fold(0.0, f64::max),
        missed_energy_limit: MISSED_ENERGY_LIMIT,
        warnings,
        seconds_optics: 0.0,
        seconds_psfs,
        seconds_kernels,
        columns: column_reports,
    };
    Ok((grid, report))
}

/// Per set, the levels each object distance's knots are integrated to (what they and the
/// samples filled from them read) and the levels it holds ([`super::level_band`]); every
/// level everywhere without `band` (a field node's grid, whose kernels the four-node mix
/// reads at its neighbours' radii).
fn held_levels(
    sets: &[KernelSet],
    arounds: &[Brackets],
    axes: &GridAxes,
    band: bool,
) -> Vec<(Vec<u32>, Vec<u32>)> {
    let no = axes.objects.count;
    if !band || sets.is_empty() {
        let last = sets.first().map_or(0, |s| level_count(s.max_radius_px) - 1);
        return sets
            .iter()
            .map(|_| (vec![last; no], vec![last; no]))
            .collect();
    }
    // The widest gap between a set's knots: a filled sample lies that far from the knot
    // whose levels it blends, so a knot is integrated over a window that much wider.
    let window: Vec<usize> = arounds
        .iter()
        .map(|around| {
            let gap = around
                .iter()
                .flatten()
                .map(|&(a, b, _)| b - a)
                .max()
                .unwrap_or(0);
            level_band::window_samples(axes.objects.step_d) + gap
        })
        .collect();
    let radii: Vec<Vec<[f32; 3]>> = sets.iter().map(|s| s.radius_px.clone()).collect();
    let shape = (axes.pupils_mm.len(), axes.focus_d.len());
    let max_radius = sets[0].max_radius_px;
    let own = vec![level_band::window_samples(axes.objects.step_d); sets.len()];
    let knots = level_band::read_tops(&radii, shape, &window, max_radius);
    let held = level_band::read_tops(&radii, shape, &own, max_radius);
    knots.into_iter().zip(held).collect()
}

/// Per channel, the knots around every object sample and the weight of the upper one
/// ([`brackets`]).
type Brackets = [Vec<(usize, usize, f64)>; 3];

/// One radius level's block of one object's kernel (texels RGB).
type LevelBlock<'a> = (u32, &'a mut [[f32; 3]]);

/// What the kernel stage keeps of one PSF.
struct PsfSummary {
    natural_radius_px: f64,
    natural_half_samples: f64,
    kept_energy: f64,
    grid_side: usize,
    method: PsfMethod,
    missed_energy: f64,
    bins: BoxIntegrator,
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
        missed_energy: [0.0; 3],
        fft_psfs: [0; 3],
        psfs: [0; 3],
    }
}
