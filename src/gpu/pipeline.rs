//! The compute-pipeline builder every pass uses: a pass declares its bindings (in binding
//! order), its push-constant type and any specialisation constants once; dispatches then pass
//! resources in the same order and the recorder writes the descriptors.

use std::sync::Arc;

use ash::vk;

use super::buffer::Buffer;
use super::context::{Context, DeviceShared};
use super::error::{GpuError, GpuResult, VkContext};
use super::image::{Image, Sampler};

/// The kind of resource a shader binding expects.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum BindingKind {
    StorageBuffer,
    UniformBuffer,
    /// `sampler2D` / `sampler3D`: image plus sampler.
    SampledImage,
    /// `image2D` / `image3D` with imageLoad / imageStore.
    StorageImage,
}

impl BindingKind {
    pub(crate) fn descriptor_type(self) -> vk::DescriptorType {
        match self {
            BindingKind::StorageBuffer => vk::DescriptorType::STORAGE_BUFFER,
            BindingKind::UniformBuffer => vk::DescriptorType::UNIFORM_BUFFER,
            BindingKind::SampledImage => vk::DescriptorType::COMBINED_IMAGE_SAMPLER,
            BindingKind::StorageImage => vk::DescriptorType::STORAGE_IMAGE,
        }
    }
}

/// A resource bound to one binding slot at dispatch time.
#[derive(Clone, Copy)]
pub enum Binding<'a> {
    /// A whole buffer, as a storage or uniform buffer.
    Buffer(&'a Buffer),
    /// `size` bytes of a buffer from `offset` (for splitting work under binding-size limits).
    BufferRange(&'a Buffer, u64, u64),
    Sampled(&'a Image, &'a Sampler),
    Storage(&'a Image),
}

impl Binding<'_> {
    pub(crate) fn matches(&self, kind: BindingKind) -> bool {
        matches!(
            (self, kind),
            (
                Binding::Buffer(_) | Binding::BufferRange(..),
                BindingKind::StorageBuffer | BindingKind::UniformBuffer
            ) | (Binding::Sampled(..), BindingKind::SampledImage)
                | (Binding::Storage(_), BindingKind::StorageImage)
        )
    }
}

/// What the recorder needs to bind any pipeline, compute or graphics, with its resources.
pub(crate) struct PipelineParts<'p> {
    pub(crate) name: &'p str,
    pub(crate) kinds: &'p [BindingKind],
    pub(crate) push_constant_bytes: u32,
    pub(crate) set_layout: vk::DescriptorSetLayout,
    pub(crate) layout: vk::PipelineLayout,
    pub(crate) pipeline: vk::Pipeline,
    pub(crate) bind_point: vk::PipelineBindPoint,
    pub(crate) stages: vk::ShaderStageFlags,
}

pub struct ComputePipeline {
    shared: Arc<DeviceShared>,
    pub(crate) name: String,
    pub(crate) kinds: Vec<BindingKind>,
    pub(crate) push_constant_bytes: u32,
    pub(crate) set_layout: vk::DescriptorSetLayout,
    pub(crate) layout: vk::PipelineLayout,
    pub(crate) pipeline: vk::Pipeline,
}

pub struct ComputePipelineBuilder<'a> {
    name: &'a str,
    spirv: &'a [u8],
    kinds: Vec<BindingKind>,
    push_constant_bytes: u32,
    specialization: Vec<(u32, u32)>,
}

impl ComputePipeline {
    /// Starts a pipeline for the compute shader `spirv` (a constant from `crate::shaders`).
    pub fn builder<'a>(name: &'a str, spirv: &'a [u8]) -> ComputePipelineBuilder<'a> {
        ComputePipelineBuilder {
            name,
            spirv,
            kinds: Vec::new(),
            push_constant_bytes: 0,
            specialization: Vec::new(),
        }
    }

    pub fn name(&self) -> &str {
        &self.name
    }

    pub(crate) fn parts(&self) -> PipelineParts<'_> {
        PipelineParts {
            name: &self.name,
            kinds: &self.kinds,
            push_constant_bytes: self.push_constant_bytes,
            set_layout: self.set_layout,
            layout: self.layout,
            pipeline: self.pipeline,
            bind_point: vk::PipelineBindPoint::COMPUTE,
            stages: vk::ShaderStageFlags::COMPUTE,
        }
    }
}

impl<'a> ComputePipelineBuilder<'a> {
    /// Declares bindings 0, 1, 2, … of set 0, in order.
    pub fn bindings(mut self, kinds: &[BindingKind]) -> Self {
        self.kinds = kinds.to_vec();
        self
    }

    /// Declares the push-constant block as the bytes of `T` (a `#[repr(C)]` Pod struct that
    /// mirrors the GLSL block with std430 layout).
    pub fn push_constants<T: bytemuck::Pod>(mut self) -> Self {
        self.push_constant_bytes = std::mem::size_of::<T>() as u32;
        self
    }

    /// Sets `layout(constant_id = id) const uint … ` to `value`.
    pub fn specialize(mut self, id: u32, value: u32) -> Self {
        self.specialization.push((id, value));
        self
    }

    pub fn build(self, ctx: &Context) -> GpuResult<ComputePipeline> {
        let shared = ctx.shared.clone();
        let device = &shared.device;
        let max_push = shared.properties.limits.max_push_constants_size;
        if self.push_constant_bytes > max_push {
            return Err(GpuError::Unsupported(format!(
                "{} bytes of push constants in pass \"{}\" (limit {max_push})",
                self.push_constant_bytes, self.name
            )));
        }
        let words = ash::util::read_spv(&mut std::io::Cursor::new(self.spirv)).map_err(|e| {
            GpuError::Usage {
                pass: self.name.to_string(),
                message: format!("invalid SPIR-V: {e}"),
            }
        })?;
        let layout_bindings: Vec<_> = self
            .kinds
            .iter()
            .enumerate()
            .map(|(i, kind)| {
                vk::DescriptorSetLayoutBinding::default()
                    .binding(i as u32)
                    .descriptor_type(kind.descriptor_type())
                    .descriptor_count(1)
                    .stage_flags(vk::ShaderStageFlags::COMPUTE)
            })
            .collect();
        let mut pipeline = ComputePipeline {
            shared: shared.clone(),
            name: self.name.to_string(),
            kinds: self.kinds.clone(),
            push_constant_bytes: self.push_constant_bytes,
            set_layout: vk::DescriptorSetLayout::null(),
            layout: vk::PipelineLayout::null(),
            pipeline: vk::Pipeline::null(),
        };
        // SAFETY: create infos reference locals that outlive each call; on early return the
        // partially built pipeline's Drop destroys what was created.
        unsafe {
            let set_info = vk::DescriptorSetLayoutCreateInfo::default().bindings(&layout_bindings);
            pipeline.set_layout = device
                .create_descriptor_set_layout(&set_info, None)
                .vk("vkCreateDescriptorSetLayout")?;
            let ranges = [vk::PushConstantRange::default()
                .stage_flags(vk::ShaderStageFlags::COMPUTE)
                .offset(0)
                .size(self.push_constant_bytes)];
            let set_layouts = [pipeline.set_layout];
            let mut layout_info = vk::PipelineLayoutCreateInfo::default().set_layouts(&set_layouts);
            if self.push_constant_bytes > 0 {
                layout_info = layout_info.push_constant_ranges(&ranges);
            }
            pipeline.layout = device
                .create_pipeline_layout(&layout_info, None)
                .vk("vkCreatePipelineLayout")?;
            let module_info = vk::ShaderModuleCreateInfo::default().code(&words);
            let module = device
                .create_shader_module(&module_info, None)
                .vk("vkCreateShaderModule")?;
            let entries: Vec<_> = self
                .specialization
                .iter()
                .enumerate()
                .map(|(i, &(id, _))| vk::SpecializationMapEntry {
                    constant_id: id,
                    offset: (i * 4) as u32,
                    size: 4,
                })
                .collect();
            let data: Vec<u8> = self
                .specialization
                .iter()
                .flat_map(|&(_, v)| v.to_ne_bytes())
                .collect();
            let spec = vk::SpecializationInfo::default()
                .map_entries(&entries)
                .data(&data);
            let stage = vk::PipelineShaderStageCreateInfo::default()
                .stage(vk::ShaderStageFlags::COMPUTE)
                .module(module)
                .name(c"main")
                .specialization_info(&spec);
            let info = [vk::ComputePipelineCreateInfo::default()
                .stage(stage)
                .layout(pipeline.layout)];
            let created = device.create_compute_pipelines(vk::PipelineCache::null(), &info, None);
            device.destroy_shader_module(module, None);
            pipeline.pipeline = created.map_err(|(_, e)| e).vk("vkCreateComputePipelines")?[0];
        }
        Ok(pipeline)
    }
}

impl Drop for ComputePipeline {
    fn drop(&mut self) {
        // SAFETY: submissions complete before returning; null handles are ignored by Vulkan.
        unsafe {
            let device = &self.shared.device;
            device.destroy_pipeline(self.pipeline, None);
            device.destroy_pipeline_layout(self.layout, None);
            device.destroy_descriptor_set_layout(self.set_layout, None);
        }
    }
}
