//! The parametric eye (Navarro-based, extended as in Csoba & Kunkli 2021): structure,
//! exact ray tracing, paraxial optics, accommodation and aberration measurement.
//!
//! The submodules are private: the `pub use` items below are the module's public surface.

pub(crate) mod accommodate;
pub(crate) mod age;
pub(crate) mod correction;
pub(crate) mod draw;
pub(crate) mod error;
pub(crate) mod estimate;
pub(crate) mod field;
pub(crate) mod file;
pub(crate) mod fit;
pub(crate) mod hand_made_eyes;
pub(crate) mod lens;
pub(crate) mod measure;
pub(crate) mod media;
pub(crate) mod model;
pub(crate) mod paraxial;
pub(crate) mod presets;
pub(crate) mod refract;
pub(crate) mod show;
pub(crate) mod surface;
pub(crate) mod system;
pub(crate) mod trace;

// The eye's structure, its media, and the eyes shipped with the crate.
pub use lens::{lens_geometry, max_volume_mm3, LENS_THICKNESS_RATIO};
pub use media::{eye_index, refractive_index, Medium};
pub use model::{Cornea, CornealSurface, ElevationTerm, Eye, Lens, Retina};
pub use presets::{navarro_accommodated, NAVARRO_VITREOUS_MM};
pub use surface::Surface;
pub use system::OpticalSystem;
// Eye files and presets: reading, resolving and describing an eye.
pub use draw::cross_section_svg;
pub use file::{load, preset, preset_names, resolve};
pub use hand_made_eyes::{hand_made_eye, keratoconus_like, HAND_MADE_EYE_NAMES};
pub use show::describe;
// Tracing, paraxial optics and measurement, on axis and across the field.
pub use field::{eccentricity_deg, measure_field};
pub use measure::{measure, Measurement, Measurer, Refraction};
pub use paraxial::{paraxial, Paraxial};
pub use trace::{trace, trace_range, Ray};
// Accommodation and its decline with age.
pub use accommodate::{
    accommodate, exerted_accommodation_d, focus_within_range, Accommodation, FocusLimit, Focused,
};
pub use age::{hofstetter_amplitude_d, HofstetterLine};
// Corrections (spectacles, intraocular lenses) and refraction.
pub use correction::{Iol, Spectacle};
pub use refract::{emmetropic_iol_power_d, refract};
// Estimating an eye from measurements.
pub use estimate::params::{prior_centre, Groups, ParamMap, ParamSpec};
pub use estimate::{estimate, Estimate, Method, Settings};
// Errors.
pub use error::EyeError;
