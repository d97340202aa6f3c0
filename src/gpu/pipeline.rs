//! The compute-pipeline builder every pass uses: a pass names its shader, its push-constant
//! type and any specialisation constants; the descriptor-set layout comes from the shader
//! (SPIR-V reflection), and dispatches bind resources by the shader's names (src/gpu/bind.rs).

use std::sync::Arc;

use ash::vk;

use super::block::{check_block, ShaderBlock};
use super::buffer::Buffer;
use super::context::{Context, DeviceShared};
use super::error::{GpuError, GpuResult, VkContext};
use super::image::{Image, Sampler};
use super::reflect::{reflect, Access, BindingKind, BlockLayout};

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
    pub(crate) layout: &'p Layout,
    pub(crate) pipeline: vk::Pipeline,
    pub(crate) bind_point: vk::PipelineBindPoint,
}

/// The push-constant struct a pass declares: its size, and the check of its members against
/// the shader's block (`check_block`).
#[derive(Clone, Copy)]
pub(crate) struct PushDecl {
    pub(crate) bytes: u32,
    check: fn(&str, Option<&BlockLayout>) -> Result<(), String>,
}

impl PushDecl {
    pub(crate) fn of<T: ShaderBlock>() -> PushDecl {
        PushDecl {
            bytes: std::mem::size_of::<T>() as u32,
            check: check_block::<T>,
        }
    }
}

/// One binding of a pass's descriptor set, as its shaders declare it.
#[derive(Clone, Debug, PartialEq, Eq)]
pub(crate) struct Slot {
    pub(crate) kind: BindingKind,
    /// Over every stage that uses it: what the barriers are derived from.
    pub(crate) access: Access,
    /// The GLSL name a pass binds it by (`ReflectedBinding::name`).
    pub(crate) name: String,
    /// Bytes of a uniform block: a buffer bound to it must hold at least this many.
    pub(crate) block_bytes: Option<u32>,
}

/// The descriptor-set and pipeline layouts of a pass, built by one code path for compute and
/// graphics pipelines from what its shaders declare (SPIR-V reflection): set-0 bindings
/// 0, 1, … with their names, kinds and access (readonly / writeonly, kept for the recorder to
/// derive barriers from), and the push-constant block, whose size must be the pass's struct's.
/// A pass may still declare its binding kinds (`bindings`, `uniform`), which are then checked
/// against the shaders: a list that disagrees is an error when the pipeline is built, not a
/// validation message (or undefined behaviour) when it runs.
pub(crate) struct Layout {
    shared: Arc<DeviceShared>,
    pub(crate) slots: Vec<Slot>,
    pub(crate) push_constant_bytes: u32,
    pub(crate) stages: vk::ShaderStageFlags,
    pub(crate) set_layout: vk::DescriptorSetLayout,
    pub(crate) layout: vk::PipelineLayout,
}

impl Layout {
    pub(crate) fn new(
        shared: &Arc<DeviceShared>,
        name: &str,
        declared: Option<&[BindingKind]>,
        uniform_bytes: &[(u32, u32)],
        push: PushDecl,
        stages: vk::ShaderStageFlags,
        modules: &[&[u8]],
    ) -> GpuResult<Layout> {
        let push_constant_bytes = push.bytes;
        let usage = |message: String| GpuError::Usage {
            pass: name.to_string(),
            message,
        };
        let max_push = shared.properties.limits.max_push_constants_size;
        if push_constant_bytes > max_push {
            return Err(GpuError::Unsupported(format!(
                "{push_constant_bytes} bytes of push constants in pass \"{name}\" (limit {max_push})"
            )));
        }
        let slots = slots_of_shaders(declared, uniform_bytes, push, modules).map_err(usage)?;
        let mut out = Layout {
            shared: shared.clone(),
            slots,
            push_constant_bytes,
            stages,
            set_layout: vk::DescriptorSetLayout::null(),
            layout: vk::PipelineLayout::null(),
        };
        let layout_bindings: Vec<_> = out
            .slots
            .iter()
            .enumerate()
            .map(|(i, slot)| {
                vk::DescriptorSetLayoutBinding::default()
                    .binding(i as u32)
                    .descriptor_type(slot.kind.descriptor_type())
                    .descriptor_count(1)
                    .stage_flags(stages)
            })
            .collect();
        let device = &shared.device;
        // SAFETY: create infos reference locals that outlive each call; on early return the
        // partially built layout's Drop destroys what was created.
        unsafe {
            let set_info = vk::DescriptorSetLayoutCreateInfo::default().bindings(&layout_bindings);
            out.set_layout = device
                .create_descriptor_set_layout(&set_info, None)
                .vk("vkCreateDescriptorSetLayout")?;
            let ranges = [vk::PushConstantRange::default()
                .stage_flags(stages)
                .offset(0)
                .size(push_constant_bytes)];
            let set_layouts = [out.set_layout];
            let mut layout_info = vk::PipelineLayoutCreateInfo::default().set_layouts(&set_layouts);
            if push_constant_bytes > 0 {
                layout_info = layout_info.push_constant_ranges(&ranges);
            }
            out.layout = device
                .create_pipeline_layout(&layout_info, None)
                .vk("vkCreatePipelineLayout")?;
        }
        Ok(out)
    }
}

impl Drop for Layout {
    fn drop(&mut self) {
        // SAFETY: submissions complete before returning, and the pipeline using this layout
        // is destroyed first (it is dropped before its layout field); null handles are ignored.
        unsafe {
            let device = &self.shared.device;
            device.destroy_pipeline_layout(self.layout, None);
            device.destroy_descriptor_set_layout(self.set_layout, None);
        }
    }
}

impl Layout {
    /// The binding named `name`, or what names there are.
    pub(crate) fn slot(&self, name: &str) -> Result<usize, String> {
        self.slots
            .iter()
            .position(|s| s.name == name)
            .ok_or_else(|| {
                let names: Vec<&str> = self.slots.iter().map(|s| s.name.as_str()).collect();
                format!(
                    "the shader has no binding named \"{name}\" (its bindings: {})",
                    names.join(", ")
                )
            })
    }
}

/// The bindings 0, 1, … of set 0 over every module in `modules` (access joined over the
/// stages), checked against the declared kinds (when the pass declares them) and uniform-block
/// sizes (binding, bytes), and the push-constant block against the pass's struct.
fn slots_of_shaders(
    declared: Option<&[BindingKind]>,
    uniform_bytes: &[(u32, u32)],
    push: PushDecl,
    modules: &[&[u8]],
) -> Result<Vec<Slot>, String> {
    let mut found: std::collections::BTreeMap<u32, Slot> = Default::default();
    let mut push_block = None;
    for spirv in modules {
        let r = reflect(spirv)?;
        push_block = push_block.or(r.push_constants);
        for b in r.bindings {
            if let Some(kinds) = declared {
                let Some(kind) = kinds.get(b.binding as usize) else {
                    return Err(format!(
                        "the shader uses binding {} but the pass declares {} bindings",
                        b.binding,
                        kinds.len()
                    ));
                };
                if b.kind != *kind {
                    return Err(format!(
                        "binding {} is a {:?} in the shader, declared as {kind:?}",
                        b.binding, b.kind
                    ));
                }
            }
            if let (Some(block), Some(&(_, bytes))) = (
                &b.block,
                uniform_bytes.iter().find(|(i, _)| *i == b.binding),
            ) {
                if block.bytes != bytes {
                    return Err(format!(
                        "the uniform block at binding {} is {} bytes in the shader, the pass's struct {bytes}",
                        b.binding, block.bytes
                    ));
                }
            }
            let slot = Slot {
                kind: b.kind,
                access: b.access,
                name: b.name,
                block_bytes: b.block.map(|block| block.bytes),
            };
            match found.get_mut(&b.binding) {
                None => {
                    found.insert(b.binding, slot);
                }
                Some(seen) if seen.kind != slot.kind || seen.name != slot.name => {
                    return Err(format!(
                        "binding {} is {} {:?} in one stage and {} {:?} in another",
                        b.binding, seen.name, seen.kind, slot.name, slot.kind
                    ));
                }
                Some(seen) if seen.access != slot.access => seen.access = Access::ReadWrite,
                Some(_) => {}
            }
        }
    }
    (push.check)("push-constant", push_block.as_ref())?;
    let count = declared.map_or(found.len(), <[BindingKind]>::len);
    let slots: Vec<Slot> = (0..count as u32)
        .map(|i| {
            found.remove(&i).ok_or(match declared {
                Some(_) => format!("binding {i} is declared but the shader has none"),
                None => format!(
                    "the shader's set-0 bindings skip {i} (ocular binds 0, 1, 2, … without gaps)"
                ),
            })
        })
        .collect::<Result<_, _>>()?;
    let mut names: Vec<&str> = slots
        .iter()
        .map(|s| s.name.as_str())
        .filter(|n| !n.is_empty())
        .collect();
    names.sort_unstable();
    if let Some(w) = names.windows(2).find(|w| w[0] == w[1]) {
        return Err(format!("two bindings are named \"{}\"", w[0]));
    }
    Ok(slots)
}

pub struct ComputePipeline {
    pub(crate) name: String,
    pub(crate) pipeline: vk::Pipeline,
    pub(crate) layout: Layout,
}

pub struct ComputePipelineBuilder<'a> {
    name: &'a str,
    spirv: &'a [u8],
    /// Binding kinds the pass declares, if it does (checked against the shader).
    kinds: Option<Vec<BindingKind>>,
    /// (binding, bytes) of the uniform blocks declared with a struct.
    uniform_bytes: Vec<(u32, u32)>,
    push: PushDecl,
    specialization: Vec<(u32, u32)>,
}

impl ComputePipeline {
    /// Starts a pipeline for the compute shader `spirv` (a constant from `crate::shaders`).
    pub fn builder<'a>(name: &'a str, spirv: &'a [u8]) -> ComputePipelineBuilder<'a> {
        ComputePipelineBuilder {
            name,
            spirv,
            kinds: None,
            uniform_bytes: Vec::new(),
            push: PushDecl::of::<()>(),
            specialization: Vec::new(),
        }
    }

    pub fn name(&self) -> &str {
        &self.name
    }

    /// Bytes of the pass's push-constant block.
    pub fn push_constant_bytes(&self) -> u32 {
        self.layout.push_constant_bytes
    }

    pub(crate) fn parts(&self) -> PipelineParts<'_> {
        PipelineParts {
            name: &self.name,
            layout: &self.layout,
            pipeline: self.pipeline,
            bind_point: vk::PipelineBindPoint::COMPUTE,
        }
    }
}

impl<'a> ComputePipelineBuilder<'a> {
    /// Optional: declares the next bindings of set 0 (from 0, 1, 2, …), in order, to be
    /// checked against the shader when the pipeline is built. Without it the layout is the
    /// shader's (passes bind by name and need no list).
    pub fn bindings(mut self, kinds: &[BindingKind]) -> Self {
        self.kinds
            .get_or_insert_with(Vec::new)
            .extend_from_slice(kinds);
        self
    }

    /// Optional, with `bindings`: declares the next binding as a uniform buffer holding a `T`
    /// (a `#[repr(C)]` Pod struct that mirrors the GLSL block with std140 layout); the block's
    /// size is checked against the shader's when the pipeline is built.
    pub fn uniform<T: bytemuck::Pod>(mut self) -> Self {
        let kinds = self.kinds.get_or_insert_with(Vec::new);
        self.uniform_bytes
            .push((kinds.len() as u32, std::mem::size_of::<T>() as u32));
        kinds.push(BindingKind::UniformBuffer);
        self
    }

    /// Declares the push-constant block as the bytes of `T`: a struct that mirrors the GLSL
    /// block with std430 layout, made with `shader_block!` so that its members are checked
    /// against the shader's when the pipeline is built (a plain `u32` or array: its size).
    pub fn push_constants<T: ShaderBlock>(mut self) -> Self {
        self.push = PushDecl::of::<T>();
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
        let words = ash::util::read_spv(&mut std::io::Cursor::new(self.spirv)).map_err(|e| {
            GpuError::Usage {
                pass: self.name.to_string(),
                message: format!("invalid SPIR-V: {e}"),
            }
        })?;
        let layout = Layout::new(
            &shared,
            self.name,
            self.kinds.as_deref(),
            &self.uniform_bytes,
            self.push,
            vk::ShaderStageFlags::COMPUTE,
            &[self.spirv],
        )?;
        let mut pipeline = ComputePipeline {
            name: self.name.to_string(),
            pipeline: vk::Pipeline::null(),
            layout,
        };
        // SAFETY: create infos reference locals that outlive each call; on early return the
        // partially built pipeline's Drop destroys what was created.
        unsafe {
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
                .layout(pipeline.layout.layout)];
            let created = device.create_compute_pipelines(vk::PipelineCache::null(), &info, None);
            device.destroy_shader_module(module, None);
            pipeline.pipeline = created.map_err(|(_, e)| e).vk("vkCreateComputePipelines")?[0];
        }
        Ok(pipeline)
    }
}

impl Drop for ComputePipeline {
    fn drop(&mut self) {
        // SAFETY: submissions complete before returning; a null handle is ignored. The layout
        // field is dropped after this, so the pipeline goes before its layout.
        unsafe {
            self.layout
                .shared
                .device
                .destroy_pipeline(self.pipeline, None);
        }
    }
}
