//! The off-axis lattice on the GPU: the Field buffer tells the fragment and convolution passes
//! where the lattice's nodes lie in the visual field and each node's radii
//! (glsl/common/field.glsl); on axis the lattice is one node, so the passes run the same code
//! either way. Where each node's kernels lie in the PSF texture is the atlas's (`atlas.rs`).

use crate::gpu::{Buffer, Context, GpuResult, Residency};
use crate::psf::field::FieldAxes;
use crate::psf::kernels::{GridBlend, KernelGrid};

/// The Field buffer: its header and every node's blended radii, rewritten when the eye's
/// state changes (a few kB).
pub(super) struct FieldTable {
    pub buffer: Buffer,
    pub staging: Buffer,
    header: [[f32; 4]; 2],
}

impl FieldTable {
    pub fn new(ctx: &Context, field: Option<&FieldAxes>, objects: usize) -> GpuResult<FieldTable> {
        let lattice = field.map_or([1, 1], |f| [f.h_deg.len(), f.v_deg.len()]);
        let nodes = (lattice[0] * lattice[1]) as u64;
        let bytes = 32 + nodes * objects as u64 * 16;
        let (first, step) = match field {
            None => ([0.0, 0.0], [1.0, 1.0]),
            Some(f) => {
                let (h, v) = (first_and_step(&f.h_deg), first_and_step(&f.v_deg));
                ([h.0, v.0], [h.1, v.1])
            }
        };
        Ok(FieldTable {
            buffer: Buffer::new(ctx, "field table", bytes, Residency::Device)?,
            staging: Buffer::new(ctx, "field table staging", bytes, Residency::Upload)?,
            header: [
                [lattice[0] as f32, lattice[1] as f32, 0.0, 0.0],
                [first[0], step[0], first[1], step[1]],
            ],
        })
    }

    /// The table's contents for `blend`: the header, then each node's blended radii.
    pub fn contents(&self, grids: &[KernelGrid], blend: &GridBlend) -> Vec<[f32; 4]> {
        let mut out = self.header.to_vec();
        for g in grids {
            out.extend(
                g.blended_radii(blend)
                    .iter()
                    .map(|r| [r[0], r[1], r[2], 0.0]),
            );
        }
        out
    }
}

/// First angle and step of a uniform field axis (a single node: its angle and step 1).
fn first_and_step(axis: &[f64]) -> (f32, f32) {
    let n = axis.len();
    let step = if n > 1 {
        (axis[n - 1] - axis[0]) / (n - 1) as f64
    } else {
        1.0
    };
    (axis[0] as f32, step as f32)
}
