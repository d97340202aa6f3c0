//! Model only what a scene requires: from a frame's or an animation's depth range, focus and
//! pupil values, the grid axes that cover them (with a margin), and what that leaves out of a
//! full reference grid.

use super::axes::{GridAxes, Screen};
use super::kernels::DioptreAxis;
use serde::Serialize;

/// What a frame or an animation needs.
#[derive(Clone, Debug, PartialEq)]
pub struct SceneNeeds {
    /// Smallest and largest object vergence in the scene (D; 0 = infinity).
    pub dioptre_min: f64,
    pub dioptre_max: f64,
    /// Every focus state (D) and pupil diameter (mm) the frames use.
    pub focus_d: Vec<f64>,
    pub pupils_mm: Vec<f64>,
    pub screen: Screen,
}

/// The axes to compute and what was left out.
#[derive(Clone, Debug, Serialize)]
pub struct Plan {
    pub axes: GridAxes,
    pub screen: Screen,
    pub psfs: usize,
    /// PSFs of the reference grid that are not computed.
    pub skipped_psfs: usize,
    pub notes: Vec<String>,
}

/// Object samples added beyond the scene's range on each side (the runtime interpolates
/// between two neighbours).
pub const OBJECT_MARGIN_SAMPLES: i64 = 1;

/// Up to this many distinct values of an axis are computed exactly as used; more are covered
/// by the reference axis points that bracket them (the runtime interpolates between them).
pub const EXACT_VALUES: usize = 2;

/// The most (px) that the geometric blur radius may change between neighbouring object
/// samples of the default axis: a quarter pixel, the radius levels' own step below 2 px. The
/// splat's layer kernels (one texture read per pixel and fragment) replace the levels only
/// where neighbouring distances' radii lie within one level of each other, so an axis coarser
/// than this near focus falls back to the levels (up to six reads).
pub const OBJECT_STEP_BLUR_PX: f64 = 0.25;

/// `objects` with its step halved (its samples kept, so its phase too) until one step moves
/// the geometric blur radius, (pupil/2)·step·(px per radian), by at most
/// [`OBJECT_STEP_BLUR_PX`] at `pupil_mm`: the 1/16 D default at 3840×2160 and a 60° field
/// moves it by 0.29 px at a 5 mm pupil, and is halved there; up to 1920×1080 it is kept. At
/// most three halvings (1/128 D from the default).
pub fn objects_for_screen(objects: DioptreAxis, screen: &Screen, pupil_mm: f64) -> DioptreAxis {
    let blur_px_per_d = 0.5e-3 * pupil_mm * screen.px_per_radian();
    let mut axis = objects;
    for _ in 0..3 {
        if !(blur_px_per_d * axis.step_d > OBJECT_STEP_BLUR_PX && axis.count > 1) {
            break;
        }
        axis = DioptreAxis {
            min_d: axis.min_d,
            step_d: 0.5 * axis.step_d,
            count: 2 * axis.count - 1,
        };
    }
    axis
}

/// Plans against `reference` (usually [`GridAxes::default`]): objects keep its spacing and
/// phase, so planned sets coincide with the reference grid's samples.
pub fn plan_for_scene(needs: &SceneNeeds, reference: &GridAxes) -> Result<Plan, String> {
    let (lo, hi) = (needs.dioptre_min, needs.dioptre_max);
    if !(lo.is_finite() && hi.is_finite() && lo >= 0.0 && hi >= lo && hi <= 50.0) {
        return Err(format!(
            "scene dioptre range {lo}..{hi} must satisfy 0 <= min <= max <= 50"
        ));
    }
    needs.screen.validate()?;
    let r = reference.objects;
    // Bracket the range, add the margin, but extend past the reference axis only as far as
    // the scene itself goes (the runtime clamps at the axis ends), and never below 0 D.
    let f0 = ((lo - r.min_d) / r.step_d + 1e-9).floor() as i64;
    let f1 = ((hi - r.min_d) / r.step_d - 1e-9).ceil() as i64;
    let last = r.count as i64 - 1;
    let lowest = (-(r.min_d / r.step_d) - 1e-9).ceil() as i64;
    let i0 = (f0 - OBJECT_MARGIN_SAMPLES).max(f0.min(0)).max(lowest);
    let i1 = (f1 + OBJECT_MARGIN_SAMPLES).min(f1.max(last)).max(i0);
    let objects = DioptreAxis {
        min_d: r.min_d + i0 as f64 * r.step_d,
        step_d: r.step_d,
        count: (i1 - i0 + 1) as usize,
    };
    let mut notes = Vec::new();
    let focus_d = sub_axis("focus", &needs.focus_d, &reference.focus_d, &mut notes)?;
    let pupils_mm = sub_axis("pupil", &needs.pupils_mm, &reference.pupils_mm, &mut notes)?;
    let axes = GridAxes {
        objects,
        focus_d,
        pupils_mm,
        wavelengths_nm: reference.wavelengths_nm,
    };
    axes.validate()?;
    let psfs = axes.psf_count();
    notes.push(format!(
        "objects {:.3}..{:.3} D in {} samples (scene {lo:.3}..{hi:.3} D, margin {} sample(s))",
        objects.min_d,
        objects.max_d(),
        objects.count,
        OBJECT_MARGIN_SAMPLES
    ));
    Ok(Plan {
        axes,
        screen: needs.screen,
        psfs,
        skipped_psfs: reference.psf_count().saturating_sub(psfs),
        notes,
    })
}

/// The used values themselves when there are few, else the reference points bracketing them.
fn sub_axis(
    name: &str,
    used: &[f64],
    reference: &[f64],
    notes: &mut Vec<String>,
) -> Result<Vec<f64>, String> {
    if used.is_empty() || used.iter().any(|v| !v.is_finite()) {
        return Err(format!(
            "scene {name} values: at least one finite value is required"
        ));
    }
    let mut v = used.to_vec();
    v.sort_by(f64::total_cmp);
    v.dedup_by(|a, b| (*a - *b).abs() < 1e-9);
    if v.len() <= EXACT_VALUES {
        notes.push(format!("{name}: {} value(s) used exactly", v.len()));
        return Ok(v);
    }
    let (lo, hi) = (v[0], v[v.len() - 1]);
    let mut out: Vec<f64> = reference
        .iter()
        .copied()
        .filter(|&x| x > lo && x < hi)
        .collect();
    // bracket the ends with the nearest reference point outside, or the value itself
    let below = reference
        .iter()
        .copied()
        .filter(|&x| x <= lo)
        .fold(f64::NAN, f64::max);
    let above = reference
        .iter()
        .copied()
        .filter(|&x| x >= hi)
        .fold(f64::NAN, f64::min);
    out.push(if below.is_nan() { lo } else { below });
    out.push(if above.is_nan() { hi } else { above });
    out.sort_by(f64::total_cmp);
    out.dedup_by(|a, b| (*a - *b).abs() < 1e-9);
    notes.push(format!(
        "{name}: {} values in {lo}..{hi} covered by {} grid point(s)",
        v.len(),
        out.len()
    ));
    Ok(out)
}
