//! Off-axis kernels on the GPU (`--off-axis`): the PSF texture holds one tile per node of the
//! field lattice ([`crate::psf::field_kernels`]), and the Field buffer tells the fragment and
//! convolution passes where the nodes lie and each node's radii (glsl/common/field.glsl). On
//! axis the lattice is a single node whose tile is the whole texture, so the passes run the
//! same code either way.

use crate::gpu::{Buffer, Context, GpuResult, Residency};
use crate::psf::field::FieldAxes;
use crate::psf::kernels::{level_count, GridBlend, KernelGrid};

/// Zero texels around each off-axis tile: bilinear reads at a kernel's edge reach one texel
/// past its block, and with neighbouring tiles that texel must be zero, as the sampler's
/// border is for a single tile.
const TILE_MARGIN: u32 = 1;

/// The off-axis PSF texture may always take this much (bytes), where one allocation can hold
/// it: lavapipe's whole heap, and what every earlier release allowed.
const FIELD_TEXTURE_FLOOR_BYTES: u64 = 2 << 30;

/// Largest off-axis PSF texture (bytes) on a device with `device_local_bytes` of local memory
/// and `max_allocation_bytes` per allocation: a quarter of the local memory (the frame's lists
/// and images need the rest), never less than [`FIELD_TEXTURE_FLOOR_BYTES`], and never more
/// than one allocation. Memory stays bounded whatever the lattice, and a large GPU is not held
/// to a small one's budget (an H100's 80 GiB took the astigmatic eye's 3.5 GiB texture, which
/// a fixed 2 GiB refused).
pub(super) fn field_texture_limit_bytes(device_local_bytes: u64, max_allocation_bytes: u64) -> u64 {
    (device_local_bytes / 4)
        .max(FIELD_TEXTURE_FLOOR_BYTES)
        .min(max_allocation_bytes)
}

/// Where each node's kernels lie in the PSF texture.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct TextureLayout {
    pub nodes: [u32; 2],
    pub pitch: u32,
    pub margin: u32,
    pub layers: u32,
}

impl TextureLayout {
    pub fn new(grid: &KernelGrid, field: Option<&FieldAxes>) -> TextureLayout {
        let side = 2 * grid.max_radius_px + 1;
        let layers = grid.objects.count as u32 * level_count(grid.max_radius_px);
        match field {
            None => TextureLayout {
                nodes: [1, 1],
                pitch: side,
                margin: 0,
                layers,
            },
            Some(f) => TextureLayout {
                nodes: [f.h_deg.len() as u32, f.v_deg.len() as u32],
                pitch: side + 2 * TILE_MARGIN,
                margin: TILE_MARGIN,
                layers,
            },
        }
    }

    pub fn extent(&self) -> [u32; 3] {
        [
            self.nodes[0] * self.pitch,
            self.nodes[1] * self.pitch,
            self.layers,
        ]
    }

    /// Bytes of the texture at `texel_bytes` per texel.
    pub fn bytes(&self, texel_bytes: u64) -> u64 {
        let [x, y, z] = self.extent();
        u64::from(x) * u64::from(y) * u64::from(z) * texel_bytes
    }

    /// The psf-texture pass's code for node `index` (h-major): column | row << 10 | margin << 20.
    pub fn tile_code(&self, index: usize) -> u32 {
        let nv = self.nodes[1] as usize;
        let (column, row) = ((index / nv) as u32, (index % nv) as u32);
        column | (row << 10) | (self.margin << 20)
    }

    /// A texture this device can create: every side within its 3D-image limit, and off axis
    /// no larger than [`field_texture_limit_bytes`].
    pub fn check(&self, ctx: &Context, texel_bytes: u64) -> crate::Result<()> {
        let bytes = self.bytes(texel_bytes);
        let info = ctx.device_info();
        let limit =
            field_texture_limit_bytes(info.device_local_mib << 20, info.max_allocation_mib << 20);
        if self.nodes != [1, 1] && bytes > limit {
            return Err(crate::Error::input(format!(
                "--off-axis: the PSF texture for {} × {} field nodes with kernels up to {} px \
                 would take {} MiB, over the {} MiB this device allows (a quarter of its memory, \
                 at least 2048 MiB, at most one allocation); lower the largest radius (smaller \
                 pupil, field of view or resolution)",
                self.nodes[0],
                self.nodes[1],
                (self.pitch - 2 * self.margin - 1) / 2,
                bytes >> 20,
                limit >> 20
            )));
        }
        let limit = ctx.limits().max_image_dimension3_d;
        let [x, y, z] = self.extent();
        if x.max(y).max(z) > limit {
            return Err(crate::Error::input(format!(
                "the PSF texture would be {x}×{y}×{z} texels ({} × {} field nodes, kernels up to \
                 {} px), over this device's 3D-image limit of {limit} per side; lower the \
                 kernels' largest radius (a smaller field of view or pupil) or the field nodes",
                self.nodes[0],
                self.nodes[1],
                (self.pitch - 2 * self.margin - 1) / 2
            )));
        }
        Ok(())
    }
}

/// The Field buffer: its header and every node's blended radii, rewritten when the eye's
/// state changes (a few kB).
pub(super) struct FieldTable {
    pub buffer: Buffer,
    pub staging: Buffer,
    header: [[f32; 4]; 2],
}

impl FieldTable {
    pub fn new(
        ctx: &Context,
        layout: &TextureLayout,
        field: Option<&FieldAxes>,
        objects: usize,
    ) -> GpuResult<FieldTable> {
        let nodes = (layout.nodes[0] * layout.nodes[1]) as u64;
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
                [
                    layout.nodes[0] as f32,
                    layout.nodes[1] as f32,
                    layout.pitch as f32,
                    layout.margin as f32,
                ],
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tiles_are_column_major_with_a_margin() {
        let layout = TextureLayout {
            nodes: [3, 2],
            pitch: 13,
            margin: 1,
            layers: 10,
        };
        assert_eq!(layout.extent(), [39, 26, 10]);
        // node 3 = h index 1, v index 1
        assert_eq!(layout.tile_code(3), 1 | (1 << 10) | (1 << 20));
        assert_eq!(layout.tile_code(4), 2 | (1 << 20));
    }

    #[test]
    fn the_field_texture_bound_follows_the_device() {
        const GIB: u64 = 1 << 30;
        // lavapipe: a 2 GiB heap that one allocation may fill keeps the 2 GiB of before.
        assert_eq!(field_texture_limit_bytes(2 * GIB, 2 * GIB), 2 * GIB);
        // An 80 GiB GPU: a quarter of its memory, so the astigmatic eye's 3.5 GiB fits.
        assert_eq!(field_texture_limit_bytes(80 * GIB, u64::MAX), 20 * GIB);
        assert!(field_texture_limit_bytes(80 * GIB, u64::MAX) > 3577 << 20);
        // Never past one allocation, even where the floor or the quarter would allow it.
        assert_eq!(field_texture_limit_bytes(80 * GIB, 4 * GIB), 4 * GIB);
        assert_eq!(field_texture_limit_bytes(GIB, GIB / 2), GIB / 2);
        // A small GPU gets the floor, not a quarter of its memory.
        assert_eq!(field_texture_limit_bytes(4 * GIB, 8 * GIB), 2 * GIB);
    }
}
