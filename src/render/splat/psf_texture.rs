//! PSF texture pass: blends the resident kernel sets of up to four (pupil, focus) grid states
//! into the 3D texture the convolution samples. See glsl/render/splat/psf_texture.comp.

use crate::gpu::{
    shader_block, Binding, Buffer, Context, GpuResult, Image, ImageUsage,
    Recorder, TexelFormat,
};
use crate::psf::kernels::{
    level_block_radius, level_count, texels_below_level, GridBlend, KernelGrid, KernelSet,
};

use super::atlas::BlockKernels;
use super::Resources;

shader_block! {
    /// Push constants of one PSF-texture dispatch (a chunk of radius levels of one field node, its
    /// plain kernels or one block side's). Mirrors `PsfTexturePush` in
    /// glsl/render/splat/psf_texture.comp (std430: the vec4 sits at offset 16, right after the
    /// four uints).
    #[derive(Clone, Copy, Debug, PartialEq, bytemuck::Pod, bytemuck::Zeroable)]
    pub(super) struct PsfTexturePush {
        /// The chunk's radius levels [first_level, end_level).
        pub first_level: u32,
        pub end_level: u32,
        /// Index of the chunk's first texel in a whole kernel set.
        pub first_texel: u32,
        /// The field node (h-major; on axis 0) whose region of the atlas is written
        /// (`atlas::TextureLayout`).
        pub node: u32,
        /// Bilinear weights of the (up to) four grid states; unused corners weigh zero.
        pub corner_weights: [f32; 4],
        /// 0: the plain kernels; 4, 8, 16 or 32: the kernels summed over blocks of that side.
        pub block_side: u32,
        /// To the block's 48 bytes (std430 rounds it to the vec4's alignment).
        pub pad0: u32,
        pub pad1: u32,
        pub pad2: u32,
    }
}

/// Texel format of the PSF texture: half floats halve memory and bandwidth; kernels are
/// stored scaled by (2r+1)² so that half precision keeps about three significant digits.
#[derive(
    Clone, Copy, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize, clap::ValueEnum,
)]
#[serde(rename_all = "lowercase")]
pub enum PsfTextureFormat {
    /// Half floats on a GPU (half the memory traffic of the filtered reads), single floats on
    /// a CPU implementation such as lavapipe, whose software filter converts every half-float
    /// texel it reads (measured there: the convolution takes about 1.7× longer with halves).
    #[value(name = "auto")]
    #[serde(rename = "auto")]
    Auto,
    #[value(name = "rgba16f")]
    #[serde(rename = "rgba16f")]
    Rgba16Float,
    #[value(name = "rgba32f")]
    #[serde(rename = "rgba32f")]
    Rgba32Float,
}

impl PsfTextureFormat {
    /// The format `Auto` stands for on a device of this kind; others stand for themselves.
    pub fn for_device(self, kind: crate::gpu::DeviceKind) -> PsfTextureFormat {
        match (self, kind) {
            (PsfTextureFormat::Auto, crate::gpu::DeviceKind::Cpu) => PsfTextureFormat::Rgba32Float,
            (PsfTextureFormat::Auto, _) => PsfTextureFormat::Rgba16Float,
            (f, _) => f,
        }
    }

    /// Bytes of one texel (`Auto` counts as the larger, until resolved for a device).
    pub fn texel_bytes(self) -> u64 {
        match self {
            PsfTextureFormat::Rgba16Float => 8,
            PsfTextureFormat::Rgba32Float | PsfTextureFormat::Auto => 16,
        }
    }

    pub fn texel_format(self) -> TexelFormat {
        match self {
            PsfTextureFormat::Rgba16Float => TexelFormat::Rgba16Float,
            PsfTextureFormat::Rgba32Float | PsfTextureFormat::Auto => TexelFormat::Rgba32Float,
        }
    }
}

pub(super) fn create_texture(
    ctx: &Context,
    extent: [u32; 3],
    format: PsfTextureFormat,
) -> GpuResult<Image> {
    let usage = ImageUsage {
        storage: true,
        ..ImageUsage::SAMPLED
    };
    Image::new_3d(ctx, "PSF texture", extent, format.texel_format(), usage)
}

/// One set's texels for the radii [first_level, end_level), small enough for one binding.
pub(super) struct Chunk {
    buffer: Buffer,
    first_level: u32,
    end_level: u32,
    first_texel: u32,
}

/// Every kernel set of the grid, on the GPU, split into chunks by radius range (the same
/// ranges for every set, so a dispatch can read one chunk of each of four sets).
pub(super) struct ResidentGrid {
    /// `sets[set][chunk]`.
    sets: Vec<Vec<Chunk>>,
}

/// Radius ranges whose texels fit `limit_bytes` each.
/// Ranges of radius levels whose texels fit one storage-buffer binding.
fn chunk_ranges(objects: usize, max_radius: u32, limit_bytes: u64) -> Vec<(u32, u32)> {
    let bytes_of =
        |a: u32, b: u32| (objects * (texels_below_level(b) - texels_below_level(a))) as u64 * 12;
    let levels = level_count(max_radius);
    let mut ranges = Vec::new();
    let mut start = 0;
    while start < levels {
        let mut end = start + 1;
        while end < levels && bytes_of(start, end + 1) <= limit_bytes {
            end += 1;
        }
        ranges.push((start, end));
        start = end;
    }
    ranges
}

impl ResidentGrid {
    pub fn upload(ctx: &Context, grid: &KernelGrid) -> GpuResult<ResidentGrid> {
        let limit = u64::from(ctx.limits().max_storage_buffer_range);
        let ranges = chunk_ranges(grid.objects.count, grid.max_radius_px, limit);
        let sets = grid
            .sets
            .iter()
            .enumerate()
            .map(|(i, set)| upload_set(ctx, i, set, &ranges))
            .collect::<GpuResult<Vec<_>>>()?;
        Ok(ResidentGrid { sets })
    }
}

fn upload_set(
    ctx: &Context,
    index: usize,
    set: &KernelSet,
    ranges: &[(u32, u32)],
) -> GpuResult<Vec<Chunk>> {
    let objects = set.objects.count;
    ranges
        .iter()
        .map(|&(a, b)| {
            let first = objects * texels_below_level(a);
            let end = objects * texels_below_level(b);
            let buffer = Buffer::from_slice(
                ctx,
                &format!("kernel set {index} radius levels {a}..{b}"),
                &set.texels[first..end],
            )?;
            Ok(Chunk {
                buffer,
                first_level: a,
                end_level: b,
                first_texel: first as u32,
            })
        })
        .collect()
}

super::passes::compute_pass!(PsfTexturePass, "psf texture", RENDER_SPLAT_PSF_TEXTURE_COMP, push: PsfTexturePush);

impl PsfTexturePass {
    /// Writes each field node's kernels for `blend` into its region of the PSF texture, whose
    /// layout the atlas holds (glsl/common/atlas.glsl): per node of `nodes` (on axis one), the
    /// plain kernels, then per block side of `blocks` its block-summed ones (a block's texels
    /// read the chunk's kernel sets, so each chunk writes its own levels of every kind).
    pub fn record(
        &self,
        rec: &mut Recorder<'_>,
        r: &Resources<'_>,
        nodes: &[ResidentGrid],
        blend: &GridBlend,
        blocks: &[BlockKernels],
    ) -> GpuResult<()> {
        for (node, grid) in nodes.iter().enumerate() {
            self.record_node(rec, r, (node as u32, grid), blend, blocks)?;
        }
        Ok(())
    }

    fn record_node(
        &self,
        rec: &mut Recorder<'_>,
        r: &Resources<'_>,
        (node, grid): (u32, &ResidentGrid),
        blend: &GridBlend,
        blocks: &[BlockKernels],
    ) -> GpuResult<()> {
        let chunks = grid.sets[blend.corners[0].0].len();
        for chunk in 0..chunks {
            // Unused corners repeat the first one with weight zero (never read).
            let corner =
                |k: usize| &grid.sets[blend.corners.get(k).unwrap_or(&blend.corners[0]).0][chunk];
            let weight = |k: usize| blend.corners.get(k).map_or(0.0, |c| c.1 as f32);
            let first = corner(0);
            let layers = (first.end_level - first.first_level) * r.block.values.object_count;
            let largest = level_block_radius(first.end_level - 1);
            // Plain kernels (side 0), then each block side whose levels this chunk holds; each
            // dispatch covers the chunk's largest slot with its ring of zeros.
            let kinds = std::iter::once((0, 2 * largest + 3)).chain(
                blocks
                    .iter()
                    .filter(|b| b.first_level < first.end_level)
                    .map(|b| (b.side, 2 * largest + b.side + 2)),
            );
            for (block_side, side) in kinds {
                let push = PsfTexturePush {
                    first_level: first.first_level,
                    end_level: first.end_level,
                    first_texel: first.first_texel,
                    node,
                    corner_weights: [weight(0), weight(1), weight(2), weight(3)],
                    block_side,
                    pad0: 0,
                    pad1: 0,
                    pad2: 0,
                };
                rec.compute(&self.pipeline)
                    .read(
                        "Set",
                        [0, 1, 2, 3].map(|k| Binding::Buffer(&corner(k).buffer)),
                    )
                    .write("psf_texture", r.texture)
                    .read("Atlas", r.atlas)
                    .read("FrameUniform", r.block.buffer)
                    .push(&push)
                    .dispatch([side.div_ceil(8), side.div_ceil(8), layers])?;
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn chunks_cover_all_levels_within_the_limit() {
        for limit in [1u64 << 10, 1 << 16, 128 << 20] {
            let ranges = chunk_ranges(41, 48, limit);
            assert_eq!(ranges.first().unwrap().0, 0);
            assert_eq!(ranges.last().unwrap().1, level_count(48));
            for w in ranges.windows(2) {
                assert_eq!(w[0].1, w[1].0);
            }
            for &(a, b) in &ranges {
                let bytes = (41 * (texels_below_level(b) - texels_below_level(a))) as u64 * 12;
                assert!(bytes <= limit || b == a + 1, "{a}..{b}: {bytes} > {limit}");
            }
        }
    }
}
