//! The parametric eye (Navarro-based, extended as in Csoba & Kunkli 2021): structure,
//! exact ray tracing, paraxial optics, accommodation and aberration measurement.

pub mod accommodate;
pub mod age;
pub mod correction;
pub mod draw;
pub mod error;
pub mod estimate;
pub mod field;
pub mod file;
pub mod fit;
pub mod hand_made_eyes;
pub mod lens;
pub mod measure;
pub mod media;
pub mod model;
pub mod paraxial;
pub mod presets;
pub mod refract;
pub mod show;
pub mod surface;
pub mod system;
pub mod trace;

pub use accommodate::{accommodate, focus_within_range, Accommodation, FocusLimit, Focused};
pub use error::EyeError;
pub use measure::{measure, Measurement, Measurer, Refraction};
pub use model::{Cornea, CornealSurface, ElevationTerm, Eye, Lens, Retina};
pub use paraxial::{paraxial, Paraxial};
pub use presets::navarro_accommodated;
pub use system::OpticalSystem;
