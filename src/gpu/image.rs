//! Images (2D and 3D) and samplers.
//!
//! Every image lives in `GENERAL` layout from creation on: the passes use images as storage,
//! sampled and transfer targets in turn, and one layout everywhere removes per-use transition
//! bookkeeping at a cost that is negligible for compute work.

use std::sync::Arc;

use ash::vk;
use gpu_allocator::vulkan::Allocation;
use gpu_allocator::MemoryLocation;

use super::buffer::{allocate, creation_error};
use super::context::{Context, DeviceShared};
use super::error::{GpuError, GpuResult, VkContext};

/// Texel formats ocular uses, with their size and the name a person recognises.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum TexelFormat {
    Rgba16Float,
    Rgba32Float,
    R32Float,
    Rgba8Unorm,
    Rgba8Srgb,
    D32Float,
}

impl TexelFormat {
    pub fn vk(self) -> vk::Format {
        match self {
            TexelFormat::Rgba16Float => vk::Format::R16G16B16A16_SFLOAT,
            TexelFormat::Rgba32Float => vk::Format::R32G32B32A32_SFLOAT,
            TexelFormat::R32Float => vk::Format::R32_SFLOAT,
            TexelFormat::Rgba8Unorm => vk::Format::R8G8B8A8_UNORM,
            TexelFormat::Rgba8Srgb => vk::Format::R8G8B8A8_SRGB,
            TexelFormat::D32Float => vk::Format::D32_SFLOAT,
        }
    }

    pub fn bytes_per_texel(self) -> u64 {
        match self {
            TexelFormat::Rgba16Float => 8,
            TexelFormat::Rgba32Float => 16,
            TexelFormat::R32Float | TexelFormat::Rgba8Unorm | TexelFormat::Rgba8Srgb => 4,
            TexelFormat::D32Float => 4,
        }
    }

    pub fn name(self) -> &'static str {
        match self {
            TexelFormat::Rgba16Float => "RGBA16F",
            TexelFormat::Rgba32Float => "RGBA32F",
            TexelFormat::R32Float => "R32F",
            TexelFormat::Rgba8Unorm => "RGBA8",
            TexelFormat::Rgba8Srgb => "RGBA8 sRGB",
            TexelFormat::D32Float => "D32F",
        }
    }

    fn aspect(self) -> vk::ImageAspectFlags {
        match self {
            TexelFormat::D32Float => vk::ImageAspectFlags::DEPTH,
            _ => vk::ImageAspectFlags::COLOR,
        }
    }
}

/// How an image will be used; decides the Vulkan usage flags and which capabilities to check.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub struct ImageUsage {
    /// Read through a sampler with linear filtering.
    pub sampled_linear: bool,
    /// Written or read with imageLoad/imageStore.
    pub storage: bool,
    pub color_attachment: bool,
    pub depth_attachment: bool,
    /// Number of samples per texel (1 unless a multisampled render target).
    pub samples: u32,
}

impl ImageUsage {
    pub const SAMPLED: ImageUsage = ImageUsage {
        sampled_linear: true,
        storage: false,
        color_attachment: false,
        depth_attachment: false,
        samples: 1,
    };
    pub const STORAGE: ImageUsage = ImageUsage {
        sampled_linear: false,
        storage: true,
        color_attachment: false,
        depth_attachment: false,
        samples: 1,
    };

    /// Each use this image is put to, with the usage flag and the format features it needs.
    fn uses(self) -> [(bool, vk::ImageUsageFlags, vk::FormatFeatureFlags); 5] {
        use vk::{FormatFeatureFlags as F, ImageUsageFlags as U};
        [
            (
                true,
                U::TRANSFER_SRC | U::TRANSFER_DST,
                F::TRANSFER_SRC | F::TRANSFER_DST,
            ),
            (
                self.sampled_linear,
                U::SAMPLED,
                F::SAMPLED_IMAGE | F::SAMPLED_IMAGE_FILTER_LINEAR,
            ),
            (self.storage, U::STORAGE, F::STORAGE_IMAGE),
            (
                self.color_attachment,
                U::COLOR_ATTACHMENT,
                F::COLOR_ATTACHMENT,
            ),
            (
                self.depth_attachment,
                U::DEPTH_STENCIL_ATTACHMENT,
                F::DEPTH_STENCIL_ATTACHMENT,
            ),
        ]
    }

    fn flags(self) -> vk::ImageUsageFlags {
        self.uses()
            .into_iter()
            .filter(|u| u.0)
            .fold(vk::ImageUsageFlags::empty(), |f, u| f | u.1)
    }

    fn format_features(self) -> vk::FormatFeatureFlags {
        self.uses()
            .into_iter()
            .filter(|u| u.0)
            .fold(vk::FormatFeatureFlags::empty(), |f, u| f | u.2)
    }
}

pub struct Image {
    shared: Arc<DeviceShared>,
    raw: vk::Image,
    view: vk::ImageView,
    allocation: Option<Allocation>,
    extent: vk::Extent3D,
    format: TexelFormat,
    name: String,
    is_3d: bool,
    samples: u32,
}

impl Image {
    /// A 2D image of `width × height`.
    pub fn new_2d(
        ctx: &Context,
        name: &str,
        width: u32,
        height: u32,
        format: TexelFormat,
        usage: ImageUsage,
    ) -> GpuResult<Image> {
        Image::new(ctx, name, [width, height, 1], false, format, usage)
    }

    /// A 3D image of `width × height × depth` texels.
    pub fn new_3d(
        ctx: &Context,
        name: &str,
        extent: [u32; 3],
        format: TexelFormat,
        usage: ImageUsage,
    ) -> GpuResult<Image> {
        Image::new(ctx, name, extent, true, format, usage)
    }

    fn new(
        ctx: &Context,
        name: &str,
        extent: [u32; 3],
        is_3d: bool,
        format: TexelFormat,
        usage: ImageUsage,
    ) -> GpuResult<Image> {
        let shared = ctx.shared.clone();
        let image_type = if is_3d {
            vk::ImageType::TYPE_3D
        } else {
            vk::ImageType::TYPE_2D
        };
        let kind = if is_3d { "3D" } else { "2D" };
        if extent.contains(&0) {
            return Err(GpuError::Usage {
                pass: name.into(),
                message: format!(
                    "{kind} image of {}×{}×{} texels has no texels",
                    extent[0], extent[1], extent[2]
                ),
            });
        }
        if !ctx.format_supports(format.vk(), usage.format_features()) {
            return Err(GpuError::Unsupported(format!(
                "{} images used as {:?} (image \"{name}\"); pick another texture format",
                format.name(),
                usage
            )));
        }
        let samples = vk::SampleCountFlags::from_raw(usage.samples.max(1));
        let props = ctx.image_format_properties(format.vk(), image_type, usage.flags());
        let max = props.map(|p| p.max_extent).unwrap_or_default();
        let sample_counts = props.map(|p| p.sample_counts).unwrap_or_default();
        if !sample_counts.contains(samples) {
            return Err(GpuError::Unsupported(format!(
                "{} images with {} samples per texel (image \"{name}\"); use fewer MSAA samples",
                format.name(),
                usage.samples.max(1)
            )));
        }
        if extent[0] > max.width || extent[1] > max.height || extent[2] > max.depth {
            return Err(GpuError::Unsupported(format!(
                "{kind} {} images of {}×{}×{} texels (image \"{name}\"; this device allows up to {}×{}×{}); \
                 reduce the maximum blur radius or the number of object distances",
                format.name(),
                extent[0],
                extent[1],
                extent[2],
                max.width,
                max.height,
                max.depth
            )));
        }
        let info = vk::ImageCreateInfo::default()
            .image_type(image_type)
            .format(format.vk())
            .extent(vk::Extent3D {
                width: extent[0],
                height: extent[1],
                depth: extent[2],
            })
            .mip_levels(1)
            .array_layers(1)
            .samples(samples)
            .tiling(vk::ImageTiling::OPTIMAL)
            .usage(usage.flags())
            .sharing_mode(vk::SharingMode::EXCLUSIVE)
            .initial_layout(vk::ImageLayout::UNDEFINED);
        let bytes = extent.iter().map(|&e| e as u64).product::<u64>()
            * format.bytes_per_texel()
            * u64::from(usage.samples.max(1));
        let what = format!("image \"{name}\"");
        // SAFETY: valid create info on a live device.
        let raw = unsafe { shared.device.create_image(&info, None) }
            .map_err(|e| creation_error("vkCreateImage", &what, bytes, e))?;
        // SAFETY: `raw` was just created on this device.
        let requirements = unsafe { shared.device.get_image_memory_requirements(raw) };
        let location = MemoryLocation::GpuOnly;
        let allocation = allocate(&shared, (name, &what, bytes), requirements, location, false)
            .inspect_err(|_| {
                // SAFETY: the image is unused and unbound.
                unsafe { shared.device.destroy_image(raw, None) }
            })?;
        let mut image = Image {
            shared: shared.clone(),
            raw,
            view: vk::ImageView::null(),
            allocation: Some(allocation),
            extent: vk::Extent3D {
                width: extent[0],
                height: extent[1],
                depth: extent[2],
            },
            format,
            name: name.to_string(),
            is_3d,
            samples: usage.samples.max(1),
        };
        let allocation = image.allocation.as_ref().expect("just set");
        // SAFETY: memory and image belong to this device; the allocator honours alignment.
        unsafe {
            shared
                .device
                .bind_image_memory(raw, allocation.memory(), allocation.offset())
        }
        .vk("vkBindImageMemory")?;
        let view_info = vk::ImageViewCreateInfo::default()
            .image(raw)
            .view_type(if is_3d {
                vk::ImageViewType::TYPE_3D
            } else {
                vk::ImageViewType::TYPE_2D
            })
            .format(format.vk())
            .subresource_range(image.subresource_range());
        // SAFETY: the image is bound to memory and the view matches its type and format.
        image.view =
            unsafe { shared.device.create_image_view(&view_info, None) }.vk("vkCreateImageView")?;
        let layout_target = &image;
        ctx.submit(|rec| {
            rec.transition_to_general(layout_target);
            Ok(())
        })?;
        Ok(image)
    }

    pub(crate) fn subresource_range(&self) -> vk::ImageSubresourceRange {
        vk::ImageSubresourceRange {
            aspect_mask: self.format.aspect(),
            base_mip_level: 0,
            level_count: 1,
            base_array_layer: 0,
            layer_count: 1,
        }
    }

    fn subresource_layers(&self) -> vk::ImageSubresourceLayers {
        vk::ImageSubresourceLayers {
            aspect_mask: self.format.aspect(),
            mip_level: 0,
            base_array_layer: 0,
            layer_count: 1,
        }
    }

    /// A copy of every texel between this image and a tightly packed buffer.
    pub(crate) fn whole_copy(&self) -> vk::BufferImageCopy {
        vk::BufferImageCopy::default()
            .image_subresource(self.subresource_layers())
            .image_extent(self.vk_extent())
    }

    pub fn raw(&self) -> vk::Image {
        self.raw
    }

    pub fn view(&self) -> vk::ImageView {
        self.view
    }

    pub fn extent(&self) -> [u32; 3] {
        [self.extent.width, self.extent.height, self.extent.depth]
    }

    pub(crate) fn vk_extent(&self) -> vk::Extent3D {
        self.extent
    }

    pub fn format(&self) -> TexelFormat {
        self.format
    }

    pub fn name(&self) -> &str {
        &self.name
    }

    pub fn is_3d(&self) -> bool {
        self.is_3d
    }

    /// Samples per texel: 1 except for multisampled render targets.
    pub fn samples(&self) -> u32 {
        self.samples
    }

    pub fn size_bytes(&self) -> u64 {
        self.extent().iter().map(|&e| e as u64).product::<u64>() * self.format.bytes_per_texel()
    }

    /// Replaces the whole image with `texels` (row-major x, then y, then z; tightly packed).
    pub fn upload<T: bytemuck::Pod>(&self, ctx: &Context, texels: &[T]) -> GpuResult<()> {
        let bytes: &[u8] = bytemuck::cast_slice(texels);
        if bytes.len() as u64 != self.size_bytes() {
            return Err(GpuError::Usage {
                pass: self.name.clone(),
                message: format!(
                    "upload of {} bytes into an image of {} bytes",
                    bytes.len(),
                    self.size_bytes()
                ),
            });
        }
        ctx.upload_staged(&self.name, bytes, |rec, staging| {
            rec.copy_buffer_to_image(staging, self)
        })
    }

    /// Reads the whole image back, tightly packed in the layout `upload` takes.
    pub fn read<T: bytemuck::Pod>(&self, ctx: &Context) -> GpuResult<Vec<T>> {
        let readback = ctx.read_staged(&self.name, self.size_bytes(), |rec, readback| {
            rec.copy_image_to_buffer(self, readback)
        })?;
        readback.read_mapped(0, self.size_bytes() as usize / std::mem::size_of::<T>())
    }
}

impl std::fmt::Debug for Image {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let [w, h, d] = self.extent();
        write!(
            f,
            "Image(\"{}\", {w}×{h}×{d} {})",
            self.name,
            self.format.name()
        )
    }
}

impl Drop for Image {
    fn drop(&mut self) {
        // SAFETY: submissions complete before returning, so nothing uses the image any more.
        unsafe {
            if self.view != vk::ImageView::null() {
                self.shared.device.destroy_image_view(self.view, None);
            }
            self.shared.device.destroy_image(self.raw, None);
        }
        if let Some(allocation) = self.allocation.take() {
            let _ = self.shared.allocator().free(allocation);
        }
    }
}

/// How a sampler treats coordinates outside the image.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Edge {
    /// Texels outside read as transparent black: a PSF kernel fades to zero at its border.
    ZeroBorder,
    ClampToEdge,
    /// Coordinates wrap around: tiled textures on meshes.
    Repeat,
}

pub struct Sampler {
    shared: Arc<DeviceShared>,
    raw: vk::Sampler,
}

impl Sampler {
    /// Linear (bilinear / trilinear for 3D) filtering, normalised coordinates, no mipmaps.
    pub fn linear(ctx: &Context, edge: Edge) -> GpuResult<Sampler> {
        let mode = match edge {
            Edge::ZeroBorder => vk::SamplerAddressMode::CLAMP_TO_BORDER,
            Edge::ClampToEdge => vk::SamplerAddressMode::CLAMP_TO_EDGE,
            Edge::Repeat => vk::SamplerAddressMode::REPEAT,
        };
        let info = vk::SamplerCreateInfo::default()
            .mag_filter(vk::Filter::LINEAR)
            .min_filter(vk::Filter::LINEAR)
            .mipmap_mode(vk::SamplerMipmapMode::NEAREST)
            .address_mode_u(mode)
            .address_mode_v(mode)
            .address_mode_w(mode)
            .border_color(vk::BorderColor::FLOAT_TRANSPARENT_BLACK)
            .min_lod(0.0)
            .max_lod(0.0)
            .unnormalized_coordinates(false);
        // SAFETY: valid create info on a live device.
        let raw = unsafe { ctx.shared.device.create_sampler(&info, None) }.vk("vkCreateSampler")?;
        Ok(Sampler {
            shared: ctx.shared.clone(),
            raw,
        })
    }

    pub fn raw(&self) -> vk::Sampler {
        self.raw
    }
}

impl Drop for Sampler {
    fn drop(&mut self) {
        // SAFETY: submissions complete before returning, so no command uses the sampler.
        unsafe { self.shared.device.destroy_sampler(self.raw, None) };
    }
}
