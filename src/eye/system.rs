//! A traceable optical system: surfaces in order, the medium after each, the stop and retina.

use super::media::{indices, Medium};
use super::surface::Surface;

/// Most surfaces a system may have (fixed-size index tables keep the tracer allocation-free).
pub const MAX_SURFACES: usize = 7;

#[derive(Debug, Clone)]
pub struct OpticalSystem {
    pub surfaces: Vec<Surface>,
    /// Medium after each surface; air precedes the first.
    pub media: Vec<Medium>,
    /// The iris lies in the vertex plane of this surface, in the medium before it.
    pub stop_index: usize,
    pub stop_z_mm: f64,
    /// The retina's vertex is at z = retina_z_mm on the axis.
    pub retina_z_mm: f64,
    /// Radius of the retinal sphere (mm, concave towards the light, centre on the axis in
    /// front of the vertex); infinite for a plane retina.
    pub retina_radius_mm: f64,
    /// Added to the lens index (Navarro's accommodating lens).
    pub lens_index_offset: f64,
}

impl OpticalSystem {
    /// Index before surface 0 and after each surface: `n[i]` before surface i, `n[i+1]` after.
    pub fn indices(&self, wavelength_nm: f64) -> [f64; MAX_SURFACES + 1] {
        assert!(self.surfaces.len() <= MAX_SURFACES);
        let table = indices(wavelength_nm, self.lens_index_offset);
        let mut n = [1.0; MAX_SURFACES + 1];
        for (i, m) in self.media.iter().enumerate() {
            n[i + 1] = table[*m as usize];
        }
        n
    }

    /// Index of the medium in front of the retina.
    pub fn image_index(&self, wavelength_nm: f64) -> f64 {
        self.indices(wavelength_nm)[self.surfaces.len()]
    }
}
