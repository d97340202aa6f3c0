//! Fragment pass: one fragment per pixel with its dioptre index and per-channel blur radius.
//! See glsl/render/splat/fragments.comp.

use crate::gpu::{
    shader_block, Bindable, Binding, Buffer, Context, GpuResult, Recorder,
    Residency,
};

use super::{Resources, FRAGMENT_BYTES};

/// The frame's fragments: one buffer, bound to every pass as [`FRAGMENT_CHUNKS`] consecutive
/// ranges (`FRAGMENT_BUFFERS` in glsl/common/splat.glsl: blocks `Fragments0` … `Fragments3`,
/// which a pass binds at once as "Fragments"). A 3840×2160 frame holds 380 MiB of
/// fragments; lavapipe binds at most 128 MiB per storage buffer, so a frame is split into
/// ranges the device can bind instead of being refused.
pub(super) struct FragmentStore {
    pub buffer: Buffer,
    /// Fragments per range (the last may hold fewer); `FrameUniform::fragments_per_chunk`.
    pub per_chunk: u32,
}

pub(super) const FRAGMENT_CHUNKS: u64 = 4;

/// Ranges start at multiples of this many fragments, which keeps every offset a multiple of
/// 256 bytes, the largest `minStorageBufferOffsetAlignment` Vulkan allows.
const CHUNK_ALIGN_FRAGMENTS: u64 = 256;

/// Fragments per range for `pixels` fragments when one binding may hold `binding_bytes`: all
/// in the first range when they fit, else split evenly (aligned). `None` when even four ranges
/// cannot hold them.
pub(super) fn fragments_per_chunk(pixels: u64, binding_bytes: u64) -> Option<u64> {
    let fit = binding_bytes / FRAGMENT_BYTES / CHUNK_ALIGN_FRAGMENTS * CHUNK_ALIGN_FRAGMENTS;
    if pixels <= fit {
        return Some(pixels.max(1));
    }
    let per = pixels
        .div_ceil(FRAGMENT_CHUNKS)
        .next_multiple_of(CHUNK_ALIGN_FRAGMENTS);
    (per <= fit && per <= u64::from(u32::MAX)).then_some(per)
}

impl FragmentStore {
    pub fn new(ctx: &Context, pixels: u64, per_chunk: u64) -> GpuResult<Self> {
        Ok(FragmentStore {
            buffer: Buffer::new(
                ctx,
                "fragments",
                pixels.max(1) * FRAGMENT_BYTES,
                Residency::Device,
            )?,
            per_chunk: per_chunk as u32,
        })
    }

    /// The four ranges, first to last. Ranges past the data repeat the first one (a shader
    /// never indexes them: its fragment indices stop at the frame's pixel count).
    pub fn ranges(&self) -> [Binding<'_>; FRAGMENT_CHUNKS as usize] {
        let total = self.buffer.size_bytes();
        let chunk = u64::from(self.per_chunk) * FRAGMENT_BYTES;
        let range = |k: u64| {
            let offset = k * chunk;
            if offset >= total {
                Binding::BufferRange(&self.buffer, 0, chunk.min(total))
            } else {
                Binding::BufferRange(&self.buffer, offset, chunk.min(total - offset))
            }
        };
        [range(0), range(1), range(2), range(3)]
    }
}

/// Binds the four ranges as `Fragments0` … `Fragments3`.
impl<'a> Bindable<'a> for &'a FragmentStore {
    fn resources(self) -> impl IntoIterator<Item = (Option<usize>, Binding<'a>)> {
        self.ranges().resources()
    }
}

/// How hidden-layer fragments are judged (`FragmentsPush`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct HiddenLight {
    /// Keep only the light of each hidden fragment that passes the nearer surfaces on its
    /// way to the pupil (false: all of it, away from the frame's border).
    pub pupil_visibility: bool,
    /// The vergence the eye is focused on (D): where this frame's kernels are smallest.
    pub focus_d: f32,
    /// Screen parallax (pixels) per dioptre for a ray through the pupil's edge: pupil
    /// radius (m) × focal length (pixels).
    pub parallax_px_per_d: f32,
}

shader_block! {
    /// Push constants of the fragments pass. Mirrors `FragmentsPush` in
    /// glsl/render/splat/fragments.comp; see [`HiddenLight`].
    #[derive(Clone, Copy, Debug, PartialEq, bytemuck::Pod, bytemuck::Zeroable)]
    pub(super) struct FragmentsPush {
        pub pupil_visibility: u32,
        pub focus_d: f32,
        pub parallax_px_per_d: f32,
    }
}

super::passes::compute_pass!(FragmentsPass, "fragments", RENDER_SPLAT_FRAGMENTS_COMP, push: FragmentsPush);

impl FragmentsPass {
    pub fn record(
        &self,
        rec: &mut Recorder<'_>,
        r: &Resources<'_>,
        hidden: HiddenLight,
    ) -> GpuResult<()> {
        let p = r.block.values;
        rec.compute(&self.pipeline)
            .read("color_in", &r.frame.color_in)
            .read("depth_in", &r.frame.depth_in)
            .read("Radii", r.radii)
            .read("Field", r.field_table)
            .write("Fragments", &r.frame.fragments)
            .read("FrameUniform", r.block.buffer)
            .push(&FragmentsPush {
                pupil_visibility: u32::from(hidden.pupil_visibility),
                focus_d: hidden.focus_d,
                parallax_px_per_d: hidden.parallax_px_per_d,
            })
            .dispatch([p.width.div_ceil(8), (p.height * p.layers).div_ceil(8), 1])
    }
}
