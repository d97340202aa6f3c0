//! `ocular compare --binocular` (or `--eye-right`): the comparison of each eye of a pair. The
//! eyes stand where `render --binocular` puts them for the scene's focus straight ahead, share
//! its pupil and one accommodation (`render::binocular::yoke`), and every method of each eye is
//! judged against that eye's own truth, drawn from where the eye stands. As for one eye,
//! compare draws without a spectacle's magnification (every method and the truth alike).

use super::compare::CompareArgs;
use crate::eye::Eye;
use crate::gpu::Context;
use crate::psf::axes::KernelSettings;
use crate::render::binocular::{self, pair_instant, yoked_focus, Yoke, SIDES};
use crate::render::focus::signed_far_point_d;
use crate::render::frame_plan::{corrected_eye, Correction};
use crate::scene::Scene;
use crate::{Error, Result};

/// Refuses the pair's options without a pair, and what a pair cannot take.
pub(super) fn check(args: &CompareArgs) -> Result<()> {
    args.pair.check(&[])?;
    if !args.pair.asked() {
        return Ok(());
    }
    let one_eye = [
        ("--truth-in", args.truth_in.is_some()),
        ("--judge", !args.judge.is_empty()),
        ("--off-axis", args.splat.off_axis),
    ];
    if let Some((name, _)) = one_eye.iter().find(|(_, on)| *on) {
        return Err(Error::input(format!(
            "{name} judges one eye's frame: leave out --binocular"
        )));
    }
    Ok(())
}

/// One compared eye: the scene seen from where it stands, the eye as rendered there (corrected,
/// its amplitude limited where its focus lies beyond infinity) and its focus; `side` names it
/// in a pair.
pub(super) struct EyeView {
    pub side: Option<&'static str>,
    pub spec: String,
    pub scene: Scene,
    pub eye: Eye,
    /// The focus the eye is rendered at (D); None: the scene's, as for one eye.
    pub focus_d: Option<f64>,
}

/// The pair's state: what the JSON report adds to the two eyes' reports.
#[derive(serde::Serialize)]
pub(super) struct PairState {
    pub ipd_mm: f64,
    pub pupil_mm: f64,
    pub demand_d: [f64; 2],
    pub far_point_d: [f64; 2],
    pub yoke: Yoke,
    pub driver: &'static str,
}

/// Both eyes' views of `scene` (the cyclopean frame gives the pupil and the focus, as one
/// eye's compare takes them), and the pair's state.
pub(super) fn views(
    ctx: &Context,
    args: &CompareArgs,
    scene: &Scene,
) -> Result<(Vec<EyeView>, PairState)> {
    let (specs, base) = args.pair.eyes(&args.eye)?;
    let left = args.correction.correction();
    let right = args.pair.right_correction(&left);
    let corrections = [left, right];
    let corrected = [
        corrected_eye(&base[0], &corrections[0], None)?,
        corrected_eye(&base[1], &corrections[1], None)?,
    ];
    let (_, state, _) = super::measured_scene_frame(ctx, scene, args.size, args.pupil_mm, false)?;
    let settings = KernelSettings::default();
    let far_point_d = [
        signed_far_point_d(&corrected[0].0, state.pupil_mm, &settings)?,
        signed_far_point_d(&corrected[1].0, state.pupil_mm, &settings)?,
    ];
    let amplitude_d = [0, 1].map(|e| corrected[e].1.accommodation_max_d);
    let ipd_mm = args.pair.ipd_mm.unwrap_or(binocular::DEFAULT_IPD_MM);
    let camera = scene.at_time(0.0).camera;
    let instant = pair_instant(
        &camera,
        ipd_mm * 1e-3,
        state.focus_d,
        far_point_d,
        amplitude_d,
    );
    let mut views = Vec::new();
    for e in 0..2 {
        let (focus_d, limited) = yoked_focus(far_point_d[e], instant.yoke.focus_d[e]);
        let eye = match limited {
            None => corrected[e].0.clone(),
            Some(a) => {
                let c = Correction {
                    accommodation_max_d: Some(a),
                    ..corrections[e].clone()
                };
                corrected_eye(&base[e], &c, None)?.0
            }
        };
        views.push(EyeView {
            side: Some(SIDES[e]),
            spec: specs[e].clone(),
            scene: scene.clone().seen_from(instant.cameras[e]),
            eye,
            focus_d: Some(focus_d),
        });
    }
    let pair = PairState {
        ipd_mm,
        pupil_mm: state.pupil_mm,
        demand_d: instant.demand_d,
        far_point_d,
        yoke: instant.yoke,
        driver: SIDES[instant.yoke.driver],
    };
    Ok((views, pair))
}

/// A file of one eye: `view.exr` → `view-left.exr` (`render --binocular`'s naming).
pub(super) fn eye_path(path: &std::path::Path, side: Option<&str>) -> std::path::PathBuf {
    match side {
        Some(side) => super::binocular::eye_output(path, side),
        None => path.to_path_buf(),
    }
}
