//! Scenes: what the rasteriser draws and how it changes over time.
//!
//! A scene file (TOML, documented in scenes/README.md) gives a camera, objects (OBJ files or
//! built-in primitives, optotypes and letter charts), lights, a background, the eye's focus and
//! pupil, and keyframes. Loading builds world-space triangle geometry once; `Scene::at_time`
//! evaluates the animated parts (camera, focus, pupil, luminance) for one frame.
//!
//! Photometry: colours are linear Rec.709 RGB and pixel luminance
//! Y = 0.2126 R + 0.7152 G + 0.0722 B is in cd/m². A Lambertian surface of reflectance ρ under
//! illuminance E (lux) has luminance ρE/π; emitters and the background give luminance directly.

mod animation;
mod camera;
pub mod mesh;
pub mod obj;
mod objects;
pub mod optotype;
mod spec;

use std::path::Path;
use std::sync::atomic::{AtomicU64, Ordering};

pub use animation::{unwrap_degrees, Track, Track3};
pub use camera::{Camera, MAX_PITCH_DEG};
pub use mesh::{Batch, Geometry, Material, Texture, Vertex};
pub use spec::MAX_LIGHTS;

use crate::{Error, Result};

/// A light in world space; colours are pre-multiplied by the photometric amount.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Light {
    /// Illuminance (lux, per channel) reaching every surface regardless of orientation.
    Ambient { rgb_lux: [f32; 3] },
    /// Illuminance (lux) on a surface facing the light; `direction` is the way light travels.
    Directional {
        direction: [f32; 3],
        rgb_lux: [f32; 3],
    },
    /// Luminous intensity (cd) of an isotropic point: illuminance I·cosθ / r².
    Point {
        position_m: [f32; 3],
        rgb_cd: [f32; 3],
    },
}

#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) enum Orientation {
    Target([f64; 3]),
    Angles(f64, f64),
}

#[derive(Clone, Debug, PartialEq)]
pub(crate) enum OrientationTrack {
    Target(Track3),
    /// Yaw (unwrapped for the shortest turn) and pitch, degrees.
    Angles(Track, Track),
}

/// Keyframed channels; an empty channel keeps the scene's base value.
#[derive(Clone, Debug, Default, PartialEq)]
pub(crate) struct Timeline {
    pub(crate) position: Track3,
    pub(crate) orientation: Option<OrientationTrack>,
    pub(crate) fov_y_deg: Track,
    pub(crate) focus_dpt: Track,
    pub(crate) pupil_mm: Track,
    pub(crate) ln_luminance: Track,
}

#[derive(Clone, Debug)]
pub struct Scene {
    id: u64,
    pub name: String,
    /// The file it came from, or "built-in scene NAME".
    pub source: String,
    pub geometry: Geometry,
    pub lights: Vec<Light>,
    /// Linear RGB of pixels no object covers (luminance in cd/m²).
    pub background_rgb: [f32; 3],
    /// Default frame size [width, height].
    pub resolution: [u32; 2],
    /// The camera at time 0 before keyframes apply.
    pub base_camera: Camera,
    base_orientation: Orientation,
    /// Accommodation target in dioptres (0 = infinity).
    pub focus_dpt: f64,
    pub pupil_mm: Option<f64>,
    pub luminance_cd_m2: Option<f64>,
    timeline: Timeline,
}

/// Everything about one instant of a scene that a renderer needs.
#[derive(Clone, Copy, Debug)]
pub struct FrameState<'a> {
    pub scene: &'a Scene,
    pub time_s: f64,
    pub camera: Camera,
    /// Focus distance in metres (infinite when focused at infinity).
    pub focus_m: f64,
    /// Pupil diameter when the scene fixes it; otherwise the pupil model decides from
    /// luminance.
    pub pupil_mm: Option<f64>,
    /// Adapting luminance when the scene fixes it; otherwise the renderer measures the frame.
    pub luminance_cd_m2: Option<f64>,
}

impl FrameState<'_> {
    pub fn focus_dpt(&self) -> f64 {
        1.0 / self.focus_m
    }
}

static NEXT_SCENE_ID: AtomicU64 = AtomicU64::new(1);

fn next_scene_id() -> u64 {
    NEXT_SCENE_ID.fetch_add(1, Ordering::Relaxed)
}

/// Scenes shipped in the binary: (name, TOML text).
const BUILTIN: [(&str, &str); 4] = [
    ("primitives", include_str!("../../scenes/primitives.toml")),
    ("chart", include_str!("../../scenes/chart.toml")),
    ("colonnade", include_str!("../../scenes/colonnade.toml")),
    ("walk", include_str!("../../scenes/walk.toml")),
];

impl Scene {
    /// Names accepted by `Scene::load` besides paths.
    pub fn builtin_names() -> Vec<&'static str> {
        BUILTIN.iter().map(|(n, _)| *n).collect()
    }

    /// The TOML text of a built-in scene.
    pub fn builtin_text(name: &str) -> Option<&'static str> {
        BUILTIN.iter().find(|(n, _)| *n == name).map(|(_, t)| *t)
    }

    /// A built-in scene by name, or a scene file by path (anything ending in .toml or naming
    /// an existing file).
    pub fn load(name_or_path: &str) -> Result<Scene> {
        let as_path = Path::new(name_or_path);
        if let Some(text) = Scene::builtin_text(name_or_path) {
            if !as_path.exists() {
                let label = format!("built-in scene {name_or_path}");
                return Scene::from_toml(text, &label, Path::new("."));
            }
        }
        if name_or_path.ends_with(".toml") || as_path.exists() {
            return Scene::from_file(as_path);
        }
        Err(Error::input(format!(
            "--scene {name_or_path}: no such built-in scene ({}) and no such .toml file",
            Scene::builtin_names().join(", ")
        )))
    }

    /// The scene seen through a camera of another vertical field (a headset's): the field is
    /// fixed at `fov_y_deg` for the whole animation (a keyframed field is dropped), and
    /// everything else is kept. It is a new scene to caches (its own id): frames kept for the
    /// scene it came from are not its frames.
    pub fn with_fov_y_deg(mut self, fov_y_deg: f64) -> Scene {
        self.id = next_scene_id();
        self.base_camera.fov_y_deg = fov_y_deg;
        self.timeline.fov_y_deg = Track::default();
        self
    }

    /// The scene seen from `camera` throughout: its position, orientation and field fixed (the
    /// camera's keyframes dropped), everything else kept; a new scene to caches, as
    /// [`Self::with_fov_y_deg`]. One eye of a pair, for the commands that draw a scene from its
    /// own camera (`ocular compare --binocular`).
    pub fn seen_from(mut self, camera: Camera) -> Scene {
        self.id = next_scene_id();
        self.base_camera = camera;
        self.base_orientation = Orientation::Angles(camera.yaw_deg, camera.pitch_deg);
        self.timeline.position = Track3::default();
        self.timeline.fov_y_deg = Track::default();
        self.timeline.orientation = None;
        self
    }

    pub fn from_file(path: &Path) -> Result<Scene> {
        let text = std::fs::read_to_string(path).map_err(|e| match e.kind() {
            std::io::ErrorKind::NotFound => Error::file(path, "scene file not found"),
            _ => Error::file(path, format!("cannot read scene file: {e}")),
        })?;
        let folder = path.parent().unwrap_or(Path::new("."));
        Scene::from_toml(&text, &path.display().to_string(), folder)
    }

    /// Parses scene text; `label` names it in errors, relative paths start at `folder`.
    pub fn from_toml(text: &str, label: &str, folder: &Path) -> Result<Scene> {
        spec::parse(text, &spec::Origin { label, folder })
    }

    /// Unique per loaded scene (renderers cache uploaded geometry by it).
    pub fn id(&self) -> u64 {
        self.id
    }

    /// Time of the last keyframe (0 for a still scene).
    pub fn duration_s(&self) -> f64 {
        let t = &self.timeline;
        let orientation = match &t.orientation {
            Some(OrientationTrack::Target(track)) => track.last_time(),
            Some(OrientationTrack::Angles(yaw, _)) => yaw.last_time(),
            None => None,
        };
        [
            t.position.last_time(),
            orientation,
            t.fov_y_deg.last_time(),
            t.focus_dpt.last_time(),
            t.pupil_mm.last_time(),
            t.ln_luminance.last_time(),
        ]
        .into_iter()
        .flatten()
        .fold(0.0, f64::max)
    }

    /// The camera, focus, pupil and luminance at `t_s` seconds.
    pub fn at_time(&self, t_s: f64) -> FrameState<'_> {
        let t = &self.timeline;
        let mut camera = self.base_camera;
        if let Some(p) = t.position.at(t_s) {
            camera.position_m = p;
        }
        if let Some(f) = t.fov_y_deg.at(t_s) {
            camera.fov_y_deg = f;
        }
        let target = match &t.orientation {
            Some(OrientationTrack::Target(track)) => track.at(t_s),
            Some(OrientationTrack::Angles(yaw, pitch)) => {
                camera.yaw_deg = yaw.at(t_s).unwrap_or(camera.yaw_deg);
                camera.pitch_deg = pitch
                    .at(t_s)
                    .unwrap_or(camera.pitch_deg)
                    .clamp(-MAX_PITCH_DEG, MAX_PITCH_DEG);
                None
            }
            // A still look-at point keeps the camera aimed at it while it moves.
            None => match self.base_orientation {
                Orientation::Target(p) => Some(p),
                Orientation::Angles(..) => None,
            },
        };
        if let Some(target) = target {
            let d = [0, 1, 2].map(|k| target[k] - camera.position_m[k]);
            if let Some((yaw, pitch)) = Camera::angles_towards(d) {
                camera.yaw_deg = yaw;
                camera.pitch_deg = pitch;
            }
        }
        let focus_dpt = t.focus_dpt.at(t_s).unwrap_or(self.focus_dpt).max(0.0);
        FrameState {
            scene: self,
            time_s: t_s,
            camera,
            focus_m: 1.0 / focus_dpt,
            pupil_mm: t.pupil_mm.at(t_s).or(self.pupil_mm),
            luminance_cd_m2: t
                .ln_luminance
                .at(t_s)
                .map(f64::exp)
                .or(self.luminance_cd_m2),
        }
    }
}
