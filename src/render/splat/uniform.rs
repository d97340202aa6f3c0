//! The frame's uniform block: values every pass and every dispatch of a splat frame shares
//! (glsl/common/splat.glsl), as opposed to each pass's own push constants.

use crate::gpu::Buffer;
use crate::render::blend::BlendMode;

use super::{FrameResources, Splatter};

/// Mirrors the uniform block `FrameUniform` in glsl/common/splat.glsl: what every pass and
/// every dispatch of a frame shares, written once per frame through a persistent mapping
/// (values that change between dispatches are each pass's own push constants). std140 lays
/// out scalars as `repr(C)` does; a buffer bound to the block must hold its size, and its
/// members' names and offsets are checked by a test (`block_layouts`).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, bytemuck::Pod, bytemuck::Zeroable)]
pub(crate) struct FrameUniform {
    pub width: u32,
    pub height: u32,
    pub tiles_x: u32,
    pub tiles_y: u32,
    pub tile_size: u32,
    pub object_count: u32,
    pub max_radius: u32,
    pub fragment_count: u32,
    pub dioptre_min: f32,
    pub dioptre_step: f32,
    pub merge_min_radius: f32,
    pub merge_color_error: f32,
    pub merge_dioptre_tolerance: f32,
    pub focal_px: f32,
    pub group_tolerance_d: f32,
    pub blend_mode: u32,
    pub wide_field: u32,
    pub saturation_epsilon: f32,
    /// Fragments per bound range of the fragment buffer (`fragments::FragmentStore`).
    pub fragments_per_chunk: u32,
    /// Depth layers stacked in the inputs and the fragment buffer (1 = the visible surface).
    pub layers: u32,
    /// 1: the convolution reads the layer texture (`layer_kernels`), 0: the radius levels.
    pub layered: u32,
    /// Layered: the largest radius step (px) between neighbouring object distances; else 0.
    pub radius_step: f32,
}

/// Bytes of frame uniforms a splat frame sends the device.
pub const FRAME_UNIFORM_BYTES: u64 = std::mem::size_of::<FrameUniform>() as u64;

/// A frame's uniform values (for dispatch sizes on the host) and the buffer the shaders read
/// them from (the block `FrameUniform`).
#[derive(Clone, Copy)]
pub(super) struct FrameBlock<'a> {
    pub values: &'a FrameUniform,
    pub buffer: &'a Buffer,
}

impl Splatter {
    /// The frame's uniform values for `frame`'s size under this splatter's settings.
    pub(super) fn params(&self, frame: &FrameResources, focal_px: f32) -> FrameUniform {
        let merge = &self.settings.merge;
        FrameUniform {
            width: frame.width,
            height: frame.height,
            tiles_x: frame.tiles_x,
            tiles_y: frame.tiles_y,
            tile_size: self.settings.tile_size,
            object_count: self.grid.objects.count as u32,
            max_radius: self.grid.max_radius_px,
            fragment_count: frame.width * frame.height * frame.layers,
            dioptre_min: self.grid.objects.min_d as f32,
            dioptre_step: self.grid.objects.step_d as f32,
            merge_min_radius: merge.min_radius_px,
            // in the frame's own units: a fraction of the value shown as white
            merge_color_error: merge.color_error * merge.white,
            merge_dioptre_tolerance: merge.dioptre_tolerance,
            focal_px,
            group_tolerance_d: self.settings.blend.group_tolerance_d,
            blend_mode: match self.settings.blend.mode {
                BlendMode::Grouped => 0,
                BlendMode::PerFragment => 1,
            },
            wide_field: u32::from(self.settings.blend.wide_field),
            saturation_epsilon: self.settings.saturation_epsilon,
            fragments_per_chunk: frame.fragments.per_chunk,
            layers: frame.layers,
            layered: 0,
            radius_step: 0.0,
        }
    }
}
