//! Two eyes: where each sits and looks, and the one accommodative response they share.
//!
//! - Geometry. The scene's camera is the cyclopean eye, midway between the two. Each eye sits
//!   half the interpupillary distance to its side, along the camera's horizontal right
//!   vector, and turns (yaw and pitch, no torsion) to look at the fixation point, as the eyes
//!   converge on what a person looks at. A fixation at infinity leaves both parallel to the
//!   camera.
//! - Accommodation is yoked: both lenses receive one accommodative response (in dioptres of
//!   object vergence, from each eye's far point). The eye that can see the target sharp with
//!   the least accommodation drives it; where neither can, the eye that comes closest does. The
//!   other eye gets the same response, limited by its own amplitude, and keeps the defocus
//!   that leaves ([`yoke`]). This is why monovision works: the distance eye drives for far
//!   targets, the near eye for near ones, and each image stays blurred in the other eye.

use std::sync::Arc;

use crate::eye::Eye;
use crate::render::focus::signed_far_point_d;
use crate::render::frame::HostFrame;
use crate::render::frame_plan::{Correction, FocusAsked};
use crate::render::live::{self, LiveFrame, LiveOptions, LiveRenderer, SceneArg};
use crate::scene::{Camera, Scene};
use crate::Result;

/// The adult mean interpupillary distance, in millimetres: 63 mm (Dodgson, "Variation and
/// extrema of human interpupillary distance", Proc. SPIE 5291, 2004: mean 63.4 mm for adult
/// men and 61.7 mm for women in the 1988 US Army anthropometric survey).
pub const DEFAULT_IPD_MM: f64 = 63.0;

/// The range `--ipd-mm` accepts: the extremes Dodgson reports for adults are about 52 and
/// 78 mm; children reach down to about 40.
pub const IPD_RANGE_MM: (f64, f64) = (40.0, 80.0);

/// `ipd_mm` as `--ipd-mm` takes it; the error says what is allowed.
pub fn check_ipd_mm(ipd_mm: f64) -> std::result::Result<f64, String> {
    let (lo, hi) = IPD_RANGE_MM;
    if ipd_mm.is_finite() && (lo..=hi).contains(&ipd_mm) {
        Ok(ipd_mm)
    } else {
        Err(format!("--ipd-mm {ipd_mm} is outside {lo} to {hi} mm"))
    }
}

/// Which eye: index 0 is the left, 1 the right.
pub const SIDES: [&str; 2] = ["left", "right"];

/// The camera's horizontal right vector (world +Y up, no roll).
fn right_vector(camera: &Camera) -> [f64; 3] {
    let yaw = camera.yaw_deg.to_radians();
    [yaw.cos(), 0.0, -yaw.sin()]
}

/// Each eye's position (left, right), half `ipd_m` either side of the camera.
pub fn eye_positions(camera: &Camera, ipd_m: f64) -> [[f64; 3]; 2] {
    let r = right_vector(camera);
    let p = camera.position_m;
    [-0.5, 0.5].map(|s| [0, 1, 2].map(|k| p[k] + s * ipd_m * r[k]))
}

/// The point `distance_m` straight ahead of the camera; None at infinity.
pub fn point_ahead(camera: &Camera, distance_m: f64) -> Option<[f64; 3]> {
    if !(distance_m.is_finite() && distance_m > 0.0) {
        return None;
    }
    let f = camera.forward();
    Some([0, 1, 2].map(|k| camera.position_m[k] + distance_m * f[k]))
}

/// The eyes' cameras (left, right): at [`eye_positions`], looking at `fixation` (None:
/// infinity, parallel to the camera). Field of view and clipping planes are the camera's.
pub fn eye_cameras(camera: &Camera, ipd_m: f64, fixation: Option<[f64; 3]>) -> [Camera; 2] {
    eye_positions(camera, ipd_m).map(|position_m| {
        let mut c = *camera;
        c.position_m = position_m;
        if let Some(p) = fixation {
            if let Some((yaw, pitch)) =
                Camera::angles_towards([0, 1, 2].map(|k| p[k] - position_m[k]))
            {
                c.yaw_deg = yaw;
                c.pitch_deg = pitch;
            }
        }
        c
    })
}

/// The vergence (D) of `fixation` seen from each eye: the accommodative demand of a target
/// there (0 at infinity).
pub fn demands_d(positions: &[[f64; 3]; 2], fixation: Option<[f64; 3]>) -> [f64; 2] {
    positions.map(|e| match fixation {
        Some(p) => {
            let d = [0, 1, 2].map(|k| p[k] - e[k]);
            1.0 / (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt()
        }
        None => 0.0,
    })
}

/// One accommodative response for two eyes.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct Yoke {
    /// The eye that drives accommodation (0 left, 1 right).
    pub driver: usize,
    /// The response both lenses receive (D of object vergence from each far point), before
    /// each eye's own amplitude limits it.
    pub accommodation_d: f64,
    /// Where each eye then focuses (D of object vergence).
    pub focus_d: [f64; 2],
    /// Each eye's defocus at the target: its demand minus where it focuses (D; positive: the
    /// eye focuses beyond the target).
    pub residual_d: [f64; 2],
}

/// Defocus (D) an eye's own target may keep and still count as seen sharp when the yoke picks
/// the eye that drives: half the 0.25 D step refractions are prescribed in, below which a
/// refractionist finds no better lens.
pub const SHARP_ENOUGH_D: f64 = 0.125;

/// The response a person makes to a target of `demand_d` (per eye, D) with eyes whose far
/// points are `far_point_d` (D; 0 at infinity) and amplitudes `amplitude_d` (None: unlimited).
///
/// Each eye alone would accommodate `demand − far point` (a far point beyond infinity is
/// negative, so a hyperopic eye spends accommodation even on a distant target), clamped to
/// [0, amplitude]. The driver is the eye that sees its target sharp, within
/// [`SHARP_ENOUGH_D`], with the least accommodation; if neither does, the eye left with the
/// smaller defocus (the less accommodation on a tie). A slightly myopic eye that cannot relax
/// the last 0.07 D to a far target therefore still drives against a hyperopic eye that
/// would have to accommodate 1.7 D: the person keeps the image they get for free, as
/// anisometropic hyperopes do (the more hyperopic eye is the one left blurred).
pub fn yoke(demand_d: [f64; 2], far_point_d: [f64; 2], amplitude_d: [Option<f64>; 2]) -> Yoke {
    let amplitude = amplitude_d.map(|a| a.unwrap_or(f64::INFINITY).max(0.0));
    let wanted = [0, 1].map(|e| demand_d[e] - far_point_d[e]);
    let alone = [0, 1].map(|e| wanted[e].clamp(0.0, amplitude[e]));
    let miss = [0, 1].map(|e| (wanted[e] - alone[e]).abs());
    let reaches = [0, 1].map(|e| miss[e] <= SHARP_ENOUGH_D + 1e-9);
    let driver = match reaches {
        [true, true] => usize::from(alone[1] < alone[0]),
        [true, false] => 0,
        [false, true] => 1,
        [false, false] => {
            if (miss[0] - miss[1]).abs() <= 1e-9 {
                usize::from(alone[1] < alone[0])
            } else {
                usize::from(miss[1] < miss[0])
            }
        }
    };
    let response = alone[driver];
    let focus_d = [0, 1].map(|e| far_point_d[e] + response.min(amplitude[e]));
    Yoke {
        driver,
        accommodation_d: response,
        focus_d,
        residual_d: [0, 1].map(|e| demand_d[e] - focus_d[e]),
    }
}

/// Where the eyes look: the point of the focus asked, along its pixel's ray (`--focus-at`) or
/// straight ahead, measured on the camera's own `frame`; None at infinity. Returns the point
/// and the words naming it.
pub fn fixation(
    camera: &Camera,
    frame: &HostFrame,
    asked: Option<FocusAsked>,
) -> Result<(Option<[f64; 3]>, String)> {
    let (vergence_d, from) = frame.focus_d(asked)?;
    if vergence_d <= 0.0 {
        return Ok((None, from));
    }
    let f = camera.forward();
    let direction = match asked {
        Some(FocusAsked::AtPixel(x, y)) => {
            let r = right_vector(camera);
            let u = [
                r[1] * f[2] - r[2] * f[1],
                r[2] * f[0] - r[0] * f[2],
                r[0] * f[1] - r[1] * f[0],
            ];
            let focal = camera.focal_length_px(frame.height);
            let tx = (f64::from(x) + 0.5 - 0.5 * f64::from(frame.width)) / focal;
            let ty = (0.5 * f64::from(frame.height) - f64::from(y) - 0.5) / focal;
            let d = [0, 1, 2].map(|k| f[k] + tx * r[k] + ty * u[k]);
            let n = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt();
            d.map(|c| c / n)
        }
        _ => f,
    };
    let distance_m = 1.0 / vergence_d;
    let p = [0, 1, 2].map(|k| camera.position_m[k] + distance_m * direction[k]);
    Ok((Some(p), from))
}

/// A scene to render through two eyes.
pub struct PairRequest<'a> {
    pub scene: &'a Arc<Scene>,
    /// Left, right.
    pub eyes: [&'a Eye; 2],
    /// What both share: the focus asked (the fixation), pupil, age, quality (its correction
    /// is replaced by each eye's own).
    pub options: LiveOptions,
    /// Each eye's spectacle, contact lens or IOL (left, right).
    pub corrections: [Correction; 2],
    pub size: (u32, u32),
    pub time_s: f64,
    pub ipd_m: f64,
}

/// Where the two eyes of a scene pair sit and look (a pair from files has the cameras its
/// renderer gave it, unknown here).
#[derive(Clone, Copy, Debug)]
pub struct PairGeometry {
    pub positions_m: [[f64; 3]; 2],
    pub cameras: [Camera; 2],
    /// Interpupillary distance (m).
    pub ipd_m: f64,
}

/// Two frames and how they were made.
pub struct Pair {
    pub frames: [LiveFrame; 2],
    /// None for a pair from files.
    pub geometry: Option<PairGeometry>,
    pub fixation_m: Option<[f64; 3]>,
    pub fixation_from: String,
    pub demand_d: [f64; 2],
    pub far_point_d: [f64; 2],
    pub amplitude_d: [Option<f64>; 2],
    /// Each eye's correction in `--correct` form.
    pub corrections: [Option<String>; 2],
    pub yoke: Yoke,
    pub pupil_mm: f64,
    pub pupil_from: String,
    /// The exposure both frames are shown at: the camera frame's (a file pair: the left
    /// frame's).
    pub exposure_ev: f32,
    pub warnings: Vec<String>,
}

/// Each eye's far point (D) and amplitude of accommodation, with the options' correction and
/// age, at `pupil_mm`.
fn eye_limits(
    eye: &Eye,
    o: &LiveOptions,
    pupil_mm: f64,
) -> Result<(f64, Option<f64>, Option<String>)> {
    let (corrected, physiology) = live::physiology(eye, o)?;
    let settings = crate::psf::axes::KernelSettings::default();
    // Signed: a hyperopic eye's far point lies beyond infinity, and reaching even infinity
    // spends some of its amplitude.
    let far = signed_far_point_d(&corrected, pupil_mm, &settings)?;
    let iol = physiology.iol_d.map(|p| format!("IOL {p:.2} D"));
    let correction = match (physiology.correction, iol) {
        (Some(c), Some(i)) => Some(format!("{c}, {i}")),
        (c, i) => c.or(i),
    };
    Ok((far, physiology.accommodation_max_d, correction))
}

/// What both kinds of pair share once the demands, the pupil and the exposure are known: each
/// eye's limits, the one accommodation ([`yoke`]), and each eye's frame from `render` (eye
/// index, its options with the yoked focus).
struct Yoked<'a> {
    eyes: [&'a Eye; 2],
    options: &'a LiveOptions,
    corrections: &'a [Correction; 2],
    demand_d: [f64; 2],
    pupil: (f64, String),
    exposure_ev: f32,
}

impl Yoked<'_> {
    fn render(
        self,
        render: impl Fn(usize, &LiveOptions) -> Result<LiveFrame>,
        geometry: Option<PairGeometry>,
        (fixation_m, fixation_from): (Option<[f64; 3]>, String),
        mut warnings: Vec<String>,
    ) -> Result<Pair> {
        let (pupil_mm, pupil_from) = self.pupil;
        let options = [0, 1].map(|e| LiveOptions {
            correction: self.corrections[e].clone(),
            ..self.options.clone()
        });
        let limits = [
            eye_limits(self.eyes[0], &options[0], pupil_mm)?,
            eye_limits(self.eyes[1], &options[1], pupil_mm)?,
        ];
        let far_point_d = [limits[0].0, limits[1].0];
        let amplitude_d = [limits[0].1, limits[1].1];
        let yoke = yoke(self.demand_d, far_point_d, amplitude_d);
        let one = |e: usize| {
            render(
                e,
                &LiveOptions {
                    pupil_mm: Some(pupil_mm),
                    luminance_cdm2: None,
                    exposure_ev: Some(f64::from(self.exposure_ev)),
                    ..at_accommodation(&options[e], far_point_d[e], yoke.focus_d[e])
                },
            )
        };
        let mut frames = [one(0)?, one(1)?];
        for (e, f) in frames.iter_mut().enumerate() {
            // Each frame reports the pair's state of its eye: the signed far point and the
            // yoked focus (an eye rendered beyond infinity was rendered at infinity with its
            // amplitude set to what it exerts; its own amplitude is the pair's).
            let r = &mut f.report;
            r.far_point_d = far_point_d[e];
            r.focus.requested_d = self.demand_d[e];
            r.focus.actual_d = yoke.focus_d[e];
            if yoke.focus_d[e] < 0.0 {
                r.focus.limit = crate::eye::FocusLimit::Reached;
                r.focus.beyond_far_point = false;
                r.physiology.accommodation_max_d = amplitude_d[e];
            }
        }
        for (e, f) in frames.iter().enumerate() {
            warnings.extend(
                f.report
                    .warnings
                    .iter()
                    .map(|w| format!("{} eye: {w}", SIDES[e])),
            );
        }
        let [l0, l1] = limits;
        Ok(Pair {
            frames,
            geometry,
            fixation_m,
            fixation_from,
            demand_d: self.demand_d,
            far_point_d,
            amplitude_d,
            corrections: [l0.2, l1.2],
            yoke,
            pupil_mm,
            pupil_from,
            exposure_ev: self.exposure_ev,
            warnings,
        })
    }
}

/// What an eye is rendered at to focus where the yoke puts it: (the focus asked of it, an
/// amplitude of accommodation that replaces its own). At `focus_d` itself where that is a real
/// point (the eye accommodates to it); else (a hyperopic eye that exerts less than it would
/// need for infinity, its focus beyond infinity) at infinity with the amplitude limited to
/// what it exerts, `focus_d − far_point_d`, so that the eye stops at exactly that
/// accommodation.
pub fn yoked_focus(far_point_d: f64, focus_d: f64) -> (f64, Option<f64>) {
    if focus_d >= 0.0 {
        (focus_d, None)
    } else {
        (0.0, Some((focus_d - far_point_d).max(0.0)))
    }
}

/// `o` focused where the yoke puts the eye ([`yoked_focus`]).
fn at_accommodation(o: &LiveOptions, far_point_d: f64, focus_d: f64) -> LiveOptions {
    let (focus_d, amplitude_d) = yoked_focus(far_point_d, focus_d);
    LiveOptions {
        focus: Some(FocusAsked::Dioptres(focus_d)),
        correction: Correction {
            accommodation_max_d: amplitude_d.or(o.correction.accommodation_max_d),
            ..o.correction.clone()
        },
        ..o.clone()
    }
}

/// Two eyes at one instant of an animation, fixating the point `focus_d` straight ahead of the
/// camera (0: infinity, the eyes parallel).
#[derive(Clone, Copy, Debug)]
pub struct PairInstant {
    /// Left, right: where each eye sits and looks.
    pub cameras: [Camera; 2],
    pub demand_d: [f64; 2],
    pub yoke: Yoke,
}

/// The pair at one instant, given each eye's far point (D, signed) and amplitude at that
/// instant's pupil: what `ocular video --binocular` renders each frame from, the geometry and
/// the accommodation of [`render_pair`] for a focus straight ahead.
pub fn pair_instant(
    camera: &Camera,
    ipd_m: f64,
    focus_d: f64,
    far_point_d: [f64; 2],
    amplitude_d: [Option<f64>; 2],
) -> PairInstant {
    let fixation = if focus_d > 0.0 {
        point_ahead(camera, 1.0 / focus_d)
    } else {
        None
    };
    let demand_d = demands_d(&eye_positions(camera, ipd_m), fixation);
    PairInstant {
        cameras: eye_cameras(camera, ipd_m, fixation),
        demand_d,
        yoke: yoke(demand_d, far_point_d, amplitude_d),
    }
}

/// The exposure asked, else the frame's automatic one.
fn exposure_of(o: &LiveOptions, frame: &HostFrame) -> f32 {
    o.exposure_ev.map_or_else(
        || crate::image_io::Tonemap::auto_exposure_ev_of(&frame.color),
        |ev| ev as f32,
    )
}

/// Renders `r` through both eyes: the fixation and the shared pupil and exposure from the
/// camera's own frame, the eyes converged on the fixation, one accommodation ([`yoke`]).
pub fn render_pair(live: &LiveRenderer, r: &PairRequest<'_>) -> Result<Pair> {
    let scene = SceneArg::Loaded(r.scene);
    let camera = r.scene.at_time(r.time_s).camera;
    let (centre, warnings) = live.scene_frame(scene, None, Some(r.size), r.time_s)?;
    let fixation = fixation(&camera, &centre, r.options.focus)?;
    let positions_m = eye_positions(&camera, r.ipd_m);
    let cameras = eye_cameras(&camera, r.ipd_m, fixation.0);
    Yoked {
        eyes: r.eyes,
        options: &r.options,
        corrections: &r.corrections,
        demand_d: demands_d(&positions_m, fixation.0),
        // One pupil for both (the consensual reflex), from the light the camera sees.
        pupil: live::pupil_diameter(&r.options, &centre)?,
        exposure_ev: exposure_of(&r.options, &centre),
    }
    .render(
        |e, o| {
            live.render_scene_from(
                scene,
                r.eyes[e],
                o,
                Some(r.size),
                r.time_s,
                Some(cameras[e]),
            )
            .map(|(frame, _)| frame)
        },
        Some(PairGeometry {
            positions_m,
            cameras,
            ipd_m: r.ipd_m,
        }),
        fixation,
        warnings,
    )
}

/// A stereo pair rendered elsewhere (Blender's stereoscopy output, or one colour/depth pair
/// per eye): each eye sees its own frame.
pub struct FilePairRequest<'a> {
    /// Left, right: one size.
    pub frames: [&'a HostFrame; 2],
    pub eyes: [&'a Eye; 2],
    /// As [`PairRequest::options`]; the focus asked names a pixel or distance of the left
    /// frame.
    pub options: LiveOptions,
    pub corrections: [Correction; 2],
}

/// Renders a pair from files. The cameras are the renderer's, so nothing here moves them: the
/// fixation is resolved in the left frame (a pixel of it, or a distance), and both eyes demand
/// its vergence (their distances to it differ by well under a percent at reading distance and
/// beyond); pupil and exposure come from the left frame; accommodation is yoked as for scenes.
pub fn render_file_pair(live: &LiveRenderer, r: &FilePairRequest<'_>) -> Result<Pair> {
    let [left, right] = r.frames;
    if (left.width, left.height) != (right.width, right.height) {
        return Err(crate::Error::input(format!(
            "the left frame is {}×{} and the right {}×{}: a stereo pair needs one size",
            left.width, left.height, right.width, right.height
        )));
    }
    let (focus_d, from) = left.focus_d(r.options.focus)?;
    Yoked {
        eyes: r.eyes,
        options: &r.options,
        corrections: &r.corrections,
        demand_d: [focus_d; 2],
        pupil: live::pupil_diameter(&r.options, left)?,
        exposure_ev: exposure_of(&r.options, left),
    }
    .render(
        |e, o| live.render(r.eyes[e], o, r.frames[e]),
        None,
        (None, format!("{from}, in the left frame")),
        Vec::new(),
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn monovision_hands_each_distance_to_its_eye() {
        // Left emmetropic, right myopic by 1.5 D, both with 1 D of accommodation left.
        let (fp, amp) = ([0.0, 1.5], [Some(1.0), Some(1.0)]);
        let far = yoke([1.0 / 6.0; 2], fp, amp);
        assert_eq!(far.driver, 0);
        assert!((far.focus_d[0] - 1.0 / 6.0).abs() < 1e-12);
        assert!((far.focus_d[1] - (1.5 + 1.0 / 6.0)).abs() < 1e-12);
        assert!((far.residual_d[1] + 1.5).abs() < 1e-12);
        let near = yoke([2.5; 2], fp, amp);
        assert_eq!(near.driver, 1);
        assert!((near.focus_d[1] - 2.5).abs() < 1e-12);
        assert!((near.focus_d[0] - 1.0).abs() < 1e-12);
        assert!((near.residual_d[0] - 1.5).abs() < 1e-12);
    }

    #[test]
    fn the_eye_needing_less_drives_and_amplitudes_limit_the_other() {
        // Both reach 2 D; the right (far point 1 D) needs less.
        let y = yoke([2.0; 2], [0.0, 1.0], [Some(8.0), Some(8.0)]);
        assert_eq!((y.driver, y.accommodation_d), (1, 1.0));
        assert_eq!(y.focus_d, [1.0, 2.0]);
        // Neither reaches 6 D: the right comes closer (4 + 1 = 5 vs 0 + 3 = 3).
        let y = yoke([6.0; 2], [0.0, 1.0], [Some(3.0), Some(4.0)]);
        assert_eq!(y.driver, 1);
        assert_eq!(y.focus_d, [3.0, 5.0]);
        // A target beyond both far points: both stay relaxed.
        let y = yoke([0.0; 2], [0.5, 1.0], [Some(3.0), None]);
        assert_eq!((y.accommodation_d, y.focus_d), (0.0, [0.5, 1.0]));
    }

    #[test]
    fn a_hyperopic_eye_spends_accommodation_and_yields_to_an_eye_sharp_for_free() {
        // Far point −1.5 D: a target at 0.1 D needs 1.6 D of it, and its amplitude bounds
        // that. The left eye (far point 0.2 D) misses by 0.1 D relaxed: sharp enough, so it
        // drives, and the right eye stays relaxed, focused beyond infinity.
        let y = yoke([0.1; 2], [0.2, -1.5], [Some(4.0), Some(4.0)]);
        assert_eq!((y.driver, y.accommodation_d), (0, 0.0));
        assert_eq!(y.focus_d, [0.2, -1.5]);
        assert!((y.residual_d[1] - 1.6).abs() < 1e-12);
        // A left eye 0.3 D out even relaxed is not sharp: the hyperope drives with 1.6 D, and
        // the left eye receives the same 1.6 D.
        let y = yoke([0.0; 2], [0.3, -1.6], [Some(4.0), Some(4.0)]);
        assert_eq!(y.driver, 1);
        assert!((y.accommodation_d - 1.6).abs() < 1e-12);
        assert!(y.focus_d[1].abs() < 1e-12 && (y.focus_d[0] - 1.9).abs() < 1e-12);
        // With 1 D of amplitude neither sees sharp: the left eye, 0.3 D out, drives over the
        // hyperope left 0.6 D short.
        let y = yoke([0.0; 2], [0.3, -1.6], [Some(4.0), Some(1.0)]);
        assert_eq!((y.driver, y.accommodation_d), (0, 0.0));
    }

    #[test]
    fn eyes_sit_across_the_view_and_converge_on_the_fixation() {
        let camera = Camera {
            position_m: [1.0, 1.6, 2.0],
            yaw_deg: 90.0,
            pitch_deg: 0.0,
            fov_y_deg: 40.0,
            near_m: 0.01,
            far_m: 100.0,
        };
        // Looking along −X, the right eye is towards −Z.
        let [l, r] = eye_positions(&camera, 0.064);
        assert!((l[2] - 2.032).abs() < 1e-12 && (r[2] - 1.968).abs() < 1e-12);
        let p = point_ahead(&camera, 0.5).unwrap();
        let [cl, cr] = eye_cameras(&camera, 0.064, Some(p));
        // each turns inwards by atan(32 mm / 500 mm)
        let inward = (0.032f64 / 0.5).atan().to_degrees();
        assert!(
            (cl.yaw_deg - (90.0 - inward)).abs() < 1e-9,
            "{}",
            cl.yaw_deg
        );
        assert!(
            (cr.yaw_deg - (90.0 + inward)).abs() < 1e-9,
            "{}",
            cr.yaw_deg
        );
        let parallel = eye_cameras(&camera, 0.064, None);
        assert_eq!(parallel.map(|c| c.yaw_deg), [90.0; 2]);
    }
}
