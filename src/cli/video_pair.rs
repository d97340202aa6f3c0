//! `ocular video --binocular` (or `--eye-right`): an animation through two eyes. Every frame is
//! the pair `render --binocular` makes at that instant for a focus straight ahead: the eyes sit
//! either side of the scene's camera, converge on the frame's focus (the scene's keyframed
//! focus, or the sweep's), share one pupil (from the camera's frame, as the monocular export's)
//! and one accommodation (`render::binocular::yoke`, each eye's far point measured at that
//! pupil). Each eye's kernels are planned once from the whole animation, its own views and its
//! own yoked focus at the planning frames, so splits render the same bytes as one run.

use std::collections::HashMap;

use super::binocular::StereoOutput;
use super::video::VideoArgs;
use super::video_frame;
use crate::eye::age::HofstetterLine;
use crate::eye::Eye;
use crate::gpu::Context;
use crate::psf::axes::{KernelSettings, Screen};
use crate::psf::plan::SceneNeeds;
use crate::render::binocular::{self, pair_instant, yoked_focus, PairInstant, SIDES};
use crate::render::focus::signed_far_point_d;
use crate::render::frame::{dioptre_range, scene_needs, EyeState, FrameRenderer, KernelOptions};
use crate::render::frame_plan::{corrected_eye, Correction, Physiology};
use crate::render::splat::SplatSettings;
use crate::render::timeline::{planning_frames, Timeline};
use crate::render::Rasterizer;
use crate::{Error, Result};

/// Refuses the pair's options without a pair, and what a pair cannot take.
pub(super) fn check(args: &VideoArgs) -> Result<()> {
    args.pair.check(&[("--stereo", args.stereo.is_some())])?;
    if !args.pair.asked() {
        return Ok(());
    }
    if args.side_by_side.is_some() {
        return Err(Error::input(
            "--side-by-side compares two eyes' views from one place; --binocular renders a pair: \
             choose one",
        ));
    }
    if args.off_axis {
        return Err(Error::input(
            "--binocular does not take --off-axis yet (each eye's field would need its own plan)",
        ));
    }
    if args.mp4.is_some() && stereo(args) == StereoOutput::Separate {
        return Err(Error::input(
            "--mp4 encodes one frame per instant: with --stereo separate there are two; use \
             --stereo side-by-side or anaglyph",
        ));
    }
    Ok(())
}

/// How the pair is written: side by side unless asked (one file per instant, as a stereo video
/// takes it).
pub(super) fn stereo(args: &VideoArgs) -> StereoOutput {
    args.stereo.unwrap_or(StereoOutput::SideBySide)
}

/// `--stereo` as the manifest records it.
pub(super) fn stereo_name(args: &VideoArgs) -> &'static str {
    match stereo(args) {
        StereoOutput::Separate => "separate",
        StereoOutput::SideBySide => "side-by-side",
        StereoOutput::Anaglyph => "anaglyph",
    }
}

/// The files of frame `index`: one, or for `separate` the left eye's and the right's.
pub(super) fn frame_names(args: &VideoArgs, index: usize) -> Vec<String> {
    let name = super::video::frame_name(index, args.format);
    if !args.pair.asked() || stereo(args) != StereoOutput::Separate {
        return vec![name];
    }
    let (stem, ext) = name
        .rsplit_once('.')
        .expect("frame names have an extension");
    SIDES
        .iter()
        .map(|side| format!("{stem}-{side}.{ext}"))
        .collect()
}

/// What stays fixed over the export: both eyes as loaded, their corrections and the age, and
/// each eye corrected (its amplitude, spectacle magnification).
pub(super) struct PairSetup {
    pub specs: [String; 2],
    base: [Eye; 2],
    corrections: [Correction; 2],
    age: (f64, HofstetterLine),
    pub ipd_m: f64,
    pub eyes: [(Eye, Physiology); 2],
}

impl PairSetup {
    pub fn from_args(args: &VideoArgs) -> Result<PairSetup> {
        let (specs, base) = args.pair.eyes(&args.eye)?;
        let left = args.correction.correction();
        let right = args.pair.right_correction(&left);
        let corrections = [left, right];
        let age = (args.age, HofstetterLine::Mean);
        let eyes = [
            corrected_eye(&base[0], &corrections[0], Some(age))?,
            corrected_eye(&base[1], &corrections[1], Some(age))?,
        ];
        Ok(PairSetup {
            specs,
            base,
            corrections,
            age,
            ipd_m: args.pair.ipd_mm.unwrap_or(binocular::DEFAULT_IPD_MM) * 1e-3,
            eyes,
        })
    }

    /// Eye `e` as the yoke renders it where its focus lies beyond infinity: its amplitude
    /// limited to what it exerts (`binocular::yoked_focus`).
    fn limited(&self, e: usize, amplitude_d: f64) -> Result<Eye> {
        let correction = Correction {
            accommodation_max_d: Some(amplitude_d),
            ..self.corrections[e].clone()
        };
        Ok(corrected_eye(&self.base[e], &correction, Some(self.age))?.0)
    }
}

/// Each eye's far point (D, signed) per pupil, measured once per pupil.
#[derive(Default)]
struct FarPoints(HashMap<u64, [f64; 2]>);

impl FarPoints {
    /// The pair at frame `i` of `timeline` with `pupil_mm`, and each eye's far point there.
    fn instant(
        &mut self,
        setup: &PairSetup,
        timeline: &Timeline,
        i: usize,
        pupil_mm: f64,
    ) -> Result<(PairInstant, [f64; 2])> {
        let far = match self.0.get(&pupil_mm.to_bits()) {
            Some(f) => *f,
            None => {
                let settings = KernelSettings::default();
                let eyes = &setup.eyes;
                let f = [
                    signed_far_point_d(&eyes[0].0, pupil_mm, &settings)?,
                    signed_far_point_d(&eyes[1].0, pupil_mm, &settings)?,
                ];
                self.0.insert(pupil_mm.to_bits(), f);
                f
            }
        };
        let state = timeline.state(i);
        let amplitude = [0, 1].map(|e| setup.eyes[e].1.accommodation_max_d);
        let focus_d = timeline.focus_d(i, &state);
        Ok((
            pair_instant(&state.camera, setup.ipd_m, focus_d, far, amplitude),
            far,
        ))
    }
}

const IDENTITY: [[f64; 2]; 2] = [[1.0, 0.0], [0.0, 1.0]];

fn magnification(p: &Physiology) -> [[f64; 2]; 2] {
    p.spectacle_magnification.unwrap_or(IDENTITY)
}

/// Each eye's needs, planned from the animation's planning frames, and frame 0's automatic
/// exposure: the camera's frame gives the pupil (and the exposure), each eye's own view (from
/// where it sits, through its spectacle) its distances, and the yoke its focus there.
pub(super) fn plan(
    ctx: &Context,
    rasterizer: &mut Rasterizer,
    setup: &PairSetup,
    timeline: &Timeline,
    (width, height): (u32, u32),
    args: &VideoArgs,
) -> Result<([SceneNeeds; 2], Option<f32>)> {
    let fov_y_deg = timeline.state(0).camera.fov_y_deg;
    let mut far_points = FarPoints::default();
    let mut ranges: [Vec<(f64, f64)>; 2] = [Vec::new(), Vec::new()];
    let mut states: [Vec<EyeState>; 2] = [Vec::new(), Vec::new()];
    let mut exposure_ev = None;
    for i in planning_frames(timeline.count) {
        let state = timeline.state(i);
        rasterizer.set_view_magnification(IDENTITY);
        let camera_frame = rasterizer.render(ctx, &state, width, height)?;
        if args.exposure.is_none() && exposure_ev.is_none() {
            exposure_ev = Some(crate::image_io::Tonemap::auto_exposure_ev_of(
                &camera_frame.color,
            ));
        }
        let pupil_mm = video_frame::pupil_for(
            args,
            &state,
            Some(&camera_frame),
            (width, height),
            fov_y_deg,
        )?;
        let (instant, far) = far_points.instant(setup, timeline, i, pupil_mm)?;
        for e in 0..2 {
            let mut eye_state = state;
            eye_state.camera = instant.cameras[e];
            rasterizer.set_view_magnification(magnification(&setup.eyes[e].1));
            let frame = rasterizer.render(ctx, &eye_state, width, height)?;
            ranges[e].push(dioptre_range(&frame.depth_m, width, height, fov_y_deg));
            states[e].push(EyeState {
                focus_d: yoked_focus(far[e], instant.yoke.focus_d[e]).0,
                pupil_mm,
            });
        }
    }
    let screen = Screen {
        fov_y_deg,
        height_px: height,
    };
    Ok((
        [0, 1].map(|e| scene_needs(&ranges[e], &states[e], screen)),
        exposure_ev,
    ))
}

/// The pair while it renders: each eye's renderer, and those of an eye limited beyond
/// infinity (made when a frame first needs one).
pub(super) struct PairExport {
    setup: PairSetup,
    needs: [SceneNeeds; 2],
    options: KernelOptions,
    splat: SplatSettings,
    renderers: Vec<FrameRenderer>,
    limited: HashMap<(usize, u64), FrameRenderer>,
    far_points: FarPoints,
}

/// An amplitude as the key of a limited eye's renderer: rounded to 0.001 D, far below what a
/// kernel can show, so that frames whose far points differ by a pupil's rounding share one.
fn amplitude_key(amplitude_d: f64) -> u64 {
    (amplitude_d * 1000.0).round().max(0.0) as u64
}

impl PairExport {
    pub fn new(
        ctx: &Context,
        setup: PairSetup,
        needs: [SceneNeeds; 2],
        options: KernelOptions,
        splat: SplatSettings,
    ) -> Result<PairExport> {
        let mut renderers = Vec::new();
        for (e, need) in needs.iter().enumerate() {
            let eye = &setup.eyes[e].0;
            let kernels = super::prepare_kernels(eye, need, &options)?;
            renderers.push(FrameRenderer::new(
                ctx,
                eye.clone(),
                kernels,
                options.settings.clone(),
                splat,
            ));
        }
        Ok(PairExport {
            setup,
            needs,
            options,
            splat,
            renderers,
            limited: HashMap::new(),
            far_points: FarPoints::default(),
        })
    }

    /// Frame `i`: both eyes' linear frames (left, right).
    pub fn render(
        &mut self,
        ctx: &Context,
        rasterizer: &mut Rasterizer,
        timeline: &Timeline,
        (i, size): (usize, (u32, u32)),
        args: &VideoArgs,
    ) -> Result<[Vec<[f32; 4]>; 2]> {
        let state = timeline.state(i);
        let fov_y_deg = timeline.state(0).camera.fov_y_deg;
        // the pupil from the camera's frame, read back only where it follows the light
        let measured = if video_frame::pupil_needs_frame(args, &state) {
            rasterizer.set_view_magnification(IDENTITY);
            Some(rasterizer.render(ctx, &state, size.0, size.1)?)
        } else {
            None
        };
        let pupil_mm = video_frame::pupil_for(args, &state, measured.as_ref(), size, fov_y_deg)?;
        let (instant, far) = self
            .far_points
            .instant(&self.setup, timeline, i, pupil_mm)?;
        let layers = args.layers.unwrap_or(crate::render::raster::DEFAULT_LAYERS);
        let gap_d = crate::render::blend::DEFAULT_GROUP_TOLERANCE_D;
        let mut out = [Vec::new(), Vec::new()];
        for (e, colour) in out.iter_mut().enumerate() {
            let (focus_d, limited) = yoked_focus(far[e], instant.yoke.focus_d[e]);
            rasterizer.set_view_magnification(magnification(&self.setup.eyes[e].1));
            let renderer = match limited {
                None => &mut self.renderers[e],
                Some(a) => self.limited_renderer(ctx, e, a)?,
            };
            let mut eye_state = state;
            eye_state.camera = instant.cameras[e];
            let mut frame = rasterizer
                .scene_frame(ctx, &eye_state, size)
                .peeled(layers, gap_d);
            *colour = renderer
                .render_recorded(&mut frame, EyeState { focus_d, pupil_mm })?
                .color;
        }
        Ok(out)
    }

    /// The renderer of eye `e` limited to `amplitude_d`, focused at infinity
    /// (`binocular::yoked_focus`): its kernels planned as the eye's, at that one focus.
    fn limited_renderer(
        &mut self,
        ctx: &Context,
        e: usize,
        amplitude_d: f64,
    ) -> Result<&mut FrameRenderer> {
        let key = (e, amplitude_key(amplitude_d));
        if !self.limited.contains_key(&key) {
            let eye = self.setup.limited(e, key.1 as f64 / 1000.0)?;
            let needs = SceneNeeds {
                focus_d: vec![0.0],
                ..self.needs[e].clone()
            };
            let kernels = super::prepare_kernels(&eye, &needs, &self.options)?;
            let renderer =
                FrameRenderer::new(ctx, eye, kernels, self.options.settings.clone(), self.splat);
            self.limited.insert(key, renderer);
        }
        Ok(self.limited.get_mut(&key).expect("inserted above"))
    }
}
