//! Fragment pass: one fragment per pixel with its dioptre index and per-channel blur radius.
//! See glsl/render/splat/fragments.comp.

use crate::gpu::{
    Binding, BindingKind, Buffer, ComputePipeline, Context, GpuResult, Image, Recorder, Residency,
};

use super::{FrameBlock, FrameUniform, FRAGMENT_BYTES};

/// The frame's fragments: one buffer, bound to every pass as [`FRAGMENT_CHUNKS`] consecutive
/// ranges (`FRAGMENT_BUFFERS` in glsl/common/splat.glsl). A 3840×2160 frame holds 380 MiB of
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
    pub fn bindings(&self) -> [Binding<'_>; FRAGMENT_CHUNKS as usize] {
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

    /// `before` (the bindings ahead of the first range, in the pass's binding order), the
    /// first range, `after`, then the other three ranges: how every pass declares them.
    pub fn bind_with<'a>(
        &'a self,
        before: &[Binding<'a>],
        after: &[Binding<'a>],
    ) -> Vec<Binding<'a>> {
        let [first, rest @ ..] = self.bindings();
        let mut all = before.to_vec();
        all.push(first);
        all.extend_from_slice(after);
        all.extend_from_slice(&rest);
        all
    }
}

/// The binding kinds of a pass whose fragment ranges sit after `before` and before `after`.
pub(super) fn kinds_with_fragments(
    before: &[BindingKind],
    after: &[BindingKind],
) -> Vec<BindingKind> {
    let mut all = before.to_vec();
    all.push(BindingKind::StorageBuffer);
    all.extend_from_slice(after);
    all.extend(std::iter::repeat_n(
        BindingKind::StorageBuffer,
        FRAGMENT_CHUNKS as usize - 1,
    ));
    all
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

/// Push constants of the fragments pass. Mirrors `FragmentsPush` in
/// glsl/render/splat/fragments.comp; see [`HiddenLight`].
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, bytemuck::Pod, bytemuck::Zeroable)]
pub(super) struct FragmentsPush {
    pub pupil_visibility: u32,
    pub focus_d: f32,
    pub parallax_px_per_d: f32,
}

pub(super) struct FragmentsPass {
    pipeline: ComputePipeline,
}

impl FragmentsPass {
    pub fn new(ctx: &Context) -> GpuResult<Self> {
        let pipeline =
            ComputePipeline::builder("fragments", crate::shaders::RENDER_SPLAT_FRAGMENTS_COMP)
                .bindings(&kinds_with_fragments(
                    &[
                        BindingKind::StorageImage,
                        BindingKind::StorageImage,
                        BindingKind::StorageBuffer,
                    ],
                    &[BindingKind::StorageBuffer],
                ))
                .uniform::<FrameUniform>()
                .push_constants::<FragmentsPush>()
                .build(ctx)?;
        Ok(FragmentsPass { pipeline })
    }

    #[allow(clippy::too_many_arguments)]
    pub fn record(
        &self,
        rec: &mut Recorder<'_>,
        frame: FrameBlock<'_>,
        color: &Image,
        depth: &Image,
        radii: &Buffer,
        field_table: &Buffer,
        fragments: &FragmentStore,
        hidden: HiddenLight,
    ) -> GpuResult<()> {
        let mut bindings = fragments.bind_with(
            &[
                Binding::Storage(color),
                Binding::Storage(depth),
                Binding::Buffer(radii),
            ],
            &[Binding::Buffer(field_table)],
        );
        bindings.push(frame.binding());
        let p = frame.values;
        rec.dispatch(
            &self.pipeline,
            &bindings,
            &FragmentsPush {
                pupil_visibility: u32::from(hidden.pupil_visibility),
                focus_d: hidden.focus_d,
                parallax_px_per_d: hidden.parallax_px_per_d,
            },
            [p.width.div_ceil(8), (p.height * p.layers).div_ceil(8), 1],
        )
    }
}
