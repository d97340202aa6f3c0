//! The graphics-pipeline builder: the raster counterpart of `ComputePipeline`. A pass declares
//! its vertex layout, bindings, push constants and render targets once; the pipeline owns a
//! classic render pass (Vulkan 1.2, no dynamic rendering) whose attachments all stay in
//! `GENERAL` layout like every other image of this layer, and makes framebuffers for it.
//!
//! Attachment order inside the render pass: the colour targets (in `location` order), then one
//! resolve target for each colour target declared with `resolve`, then the depth target.

use std::sync::Arc;

use ash::vk;

use super::context::{Context, DeviceShared};
use super::error::{GpuError, GpuResult, VkContext};
use super::image::{Image, TexelFormat};
use super::pipeline::{Layout, PipelineParts};
use super::reflect::BindingKind;

/// The type of one vertex attribute (32-bit floats).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum VertexFormat {
    Float,
    Float2,
    Float3,
    Float4,
}

impl VertexFormat {
    fn vk(self) -> vk::Format {
        match self {
            VertexFormat::Float => vk::Format::R32_SFLOAT,
            VertexFormat::Float2 => vk::Format::R32G32_SFLOAT,
            VertexFormat::Float3 => vk::Format::R32G32B32_SFLOAT,
            VertexFormat::Float4 => vk::Format::R32G32B32A32_SFLOAT,
        }
    }
}

/// `layout(location = location) in …` at byte `offset` of each vertex.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct VertexAttribute {
    pub location: u32,
    pub format: VertexFormat,
    pub offset: u32,
}

/// How a fragment's depth is compared with the stored one; `Greater` suits reversed-Z.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum DepthCompare {
    Less,
    LessOrEqual,
    Greater,
    GreaterOrEqual,
    Always,
}

impl DepthCompare {
    fn vk(self) -> vk::CompareOp {
        match self {
            DepthCompare::Less => vk::CompareOp::LESS,
            DepthCompare::LessOrEqual => vk::CompareOp::LESS_OR_EQUAL,
            DepthCompare::Greater => vk::CompareOp::GREATER,
            DepthCompare::GreaterOrEqual => vk::CompareOp::GREATER_OR_EQUAL,
            DepthCompare::Always => vk::CompareOp::ALWAYS,
        }
    }
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum CullMode {
    None,
    /// Culls triangles wound clockwise in framebuffer space.
    Back,
}

#[derive(Clone, Copy, Debug)]
struct ColorTarget {
    format: TexelFormat,
    resolve: bool,
}

pub struct GraphicsPipeline {
    shared: Arc<DeviceShared>,
    name: String,
    colors: Vec<ColorTarget>,
    depth: Option<TexelFormat>,
    samples: u32,
    render_pass: vk::RenderPass,
    pipeline: vk::Pipeline,
    // Declared last: dropped after the pipeline that uses it.
    layout: Layout,
}

pub struct GraphicsPipelineBuilder<'a> {
    name: &'a str,
    vertex_spirv: &'a [u8],
    fragment_spirv: &'a [u8],
    vertex_stride: u32,
    attributes: Vec<VertexAttribute>,
    /// Binding kinds the pass declares, if it does (checked against the shaders).
    kinds: Option<Vec<BindingKind>>,
    push: super::pipeline::PushDecl,
    colors: Vec<ColorTarget>,
    depth: Option<(TexelFormat, DepthCompare)>,
    samples: u32,
    cull: CullMode,
}

/// The images a render pass draws into, for one frame size.
pub struct Framebuffer {
    shared: Arc<DeviceShared>,
    raw: vk::Framebuffer,
    width: u32,
    height: u32,
    attachment_count: usize,
}

/// The parts of a pipeline the recorder needs to begin its render pass.
pub(crate) struct RenderPassParts {
    pub(crate) render_pass: vk::RenderPass,
    pub(crate) color_count: usize,
    pub(crate) resolve_count: usize,
    pub(crate) has_depth: bool,
}

impl GraphicsPipeline {
    /// Starts a pipeline from a vertex and a fragment shader (constants from `crate::shaders`).
    pub fn builder<'a>(
        name: &'a str,
        vertex_spirv: &'a [u8],
        fragment_spirv: &'a [u8],
    ) -> GraphicsPipelineBuilder<'a> {
        GraphicsPipelineBuilder {
            name,
            vertex_spirv,
            fragment_spirv,
            vertex_stride: 0,
            attributes: Vec::new(),
            kinds: None,
            push: super::pipeline::PushDecl::of::<()>(),
            colors: Vec::new(),
            depth: None,
            samples: 1,
            cull: CullMode::None,
        }
    }

    pub fn name(&self) -> &str {
        &self.name
    }

    pub fn samples(&self) -> u32 {
        self.samples
    }

    /// Starts binding a draw's resources by their names in the shaders; `finish` gives the
    /// list `draw` and `draw_indexed` take.
    pub fn bind(&self) -> super::bind::NamedBindings<'_> {
        super::bind::NamedBindings::new(&self.name, &self.layout)
    }

    pub(crate) fn parts(&self) -> PipelineParts<'_> {
        PipelineParts {
            name: &self.name,
            layout: &self.layout,
            pipeline: self.pipeline,
            bind_point: vk::PipelineBindPoint::GRAPHICS,
        }
    }

    pub(crate) fn render_pass_parts(&self) -> RenderPassParts {
        RenderPassParts {
            render_pass: self.render_pass,
            color_count: self.colors.len(),
            resolve_count: self.colors.iter().filter(|c| c.resolve).count(),
            has_depth: self.depth.is_some(),
        }
    }

    /// Framebuffer for this pipeline's render pass: `colors` match the declared colour targets
    /// (format and sample count), `resolves` the targets declared with `resolve` (one sample),
    /// `depth` the depth target. All images must have the same 2D size.
    pub fn framebuffer(
        &self,
        ctx: &Context,
        colors: &[&Image],
        resolves: &[&Image],
        depth: Option<&Image>,
    ) -> GpuResult<Framebuffer> {
        let usage = |message: String| GpuError::Usage {
            pass: self.name.clone(),
            message,
        };
        let wanted_resolves = self.colors.iter().filter(|c| c.resolve).count();
        if colors.len() != self.colors.len() || resolves.len() != wanted_resolves {
            return Err(usage(format!(
                "framebuffer with {} colour and {} resolve images; the pipeline declares {} and {}",
                colors.len(),
                resolves.len(),
                self.colors.len(),
                wanted_resolves
            )));
        }
        if depth.is_some() != self.depth.is_some() {
            return Err(usage(
                "depth image given without a declared depth target, or missing".into(),
            ));
        }
        let first = colors
            .first()
            .copied()
            .or(depth)
            .ok_or_else(|| usage("a framebuffer needs at least one attachment".into()))?;
        let [width, height, _] = first.extent();
        let check = |image: &Image, format: TexelFormat, samples: u32| -> GpuResult<()> {
            if image.is_3d() || image.extent() != [width, height, 1] {
                return Err(usage(format!(
                    "image \"{}\" is {:?}; every attachment must be a {width}×{height} 2D image",
                    image.name(),
                    image.extent()
                )));
            }
            if image.format() != format || image.samples() != samples {
                return Err(usage(format!(
                    "image \"{}\" is {} with {} sample(s); the pipeline expects {} with {samples}",
                    image.name(),
                    image.format().name(),
                    image.samples(),
                    format.name()
                )));
            }
            Ok(())
        };
        let mut views = Vec::new();
        for (image, target) in colors.iter().zip(&self.colors) {
            check(image, target.format, self.samples)?;
            views.push(image.view());
        }
        let resolve_targets = self.colors.iter().filter(|c| c.resolve);
        for (image, target) in resolves.iter().zip(resolve_targets) {
            check(image, target.format, 1)?;
            views.push(image.view());
        }
        if let (Some(image), Some(format)) = (depth, self.depth) {
            check(image, format, self.samples)?;
            views.push(image.view());
        }
        let info = vk::FramebufferCreateInfo::default()
            .render_pass(self.render_pass)
            .attachments(&views)
            .width(width)
            .height(height)
            .layers(1);
        // SAFETY: the views belong to live images of this device and match the render pass.
        let raw = unsafe { ctx.shared.device.create_framebuffer(&info, None) }
            .vk("vkCreateFramebuffer")?;
        Ok(Framebuffer {
            shared: ctx.shared.clone(),
            raw,
            width,
            height,
            attachment_count: views.len(),
        })
    }
}

impl Framebuffer {
    pub fn raw(&self) -> vk::Framebuffer {
        self.raw
    }

    pub fn width(&self) -> u32 {
        self.width
    }

    pub fn height(&self) -> u32 {
        self.height
    }

    pub(crate) fn attachment_count(&self) -> usize {
        self.attachment_count
    }
}

impl Drop for Framebuffer {
    fn drop(&mut self) {
        // SAFETY: submissions complete before returning, so no command uses it any more.
        unsafe { self.shared.device.destroy_framebuffer(self.raw, None) };
    }
}

impl<'a> GraphicsPipelineBuilder<'a> {
    /// One interleaved vertex buffer of `stride_bytes` per vertex.
    pub fn vertex_layout(mut self, stride_bytes: u32, attributes: &[VertexAttribute]) -> Self {
        self.vertex_stride = stride_bytes;
        self.attributes = attributes.to_vec();
        self
    }

    /// Optional: declares bindings 0, 1, 2, … of set 0, to be checked against the shaders
    /// when the pipeline is built. Without it the layout is the shaders' (both stages see
    /// every binding; draws bind by name).
    pub fn bindings(mut self, kinds: &[BindingKind]) -> Self {
        self.kinds = Some(kinds.to_vec());
        self
    }

    /// The push-constant block (both stages) as the bytes of `T` (see
    /// `ComputePipelineBuilder::push_constants`).
    pub fn push_constants<T: super::ShaderBlock>(mut self) -> Self {
        self.push = super::pipeline::PushDecl::of::<T>();
        self
    }

    /// Samples per pixel of the colour and depth targets (1 = no MSAA).
    pub fn samples(mut self, samples: u32) -> Self {
        self.samples = samples.max(1);
        self
    }

    /// Adds the next colour target (`layout(location = n) out`); with `resolve`, the render
    /// pass also averages its samples into a single-sample image of the same format.
    pub fn color_target(mut self, format: TexelFormat, resolve: bool) -> Self {
        self.colors.push(ColorTarget { format, resolve });
        self
    }

    pub fn depth_target(mut self, format: TexelFormat, compare: DepthCompare) -> Self {
        self.depth = Some((format, compare));
        self
    }

    pub fn cull(mut self, cull: CullMode) -> Self {
        self.cull = cull;
        self
    }

    pub fn build(self, ctx: &Context) -> GpuResult<GraphicsPipeline> {
        let shared = ctx.shared.clone();
        let device = &shared.device;
        let usage = |message: String| GpuError::Usage {
            pass: self.name.to_string(),
            message,
        };
        let samples = vk::SampleCountFlags::from_raw(self.samples);
        let limits = &shared.properties.limits;
        let supported =
            limits.framebuffer_color_sample_counts & limits.framebuffer_depth_sample_counts;
        if !supported.contains(samples) || !self.samples.is_power_of_two() {
            return Err(GpuError::Unsupported(format!(
                "{} samples per pixel in pass \"{}\"; use fewer MSAA samples",
                self.samples, self.name
            )));
        }
        if self.colors.is_empty() && self.depth.is_none() {
            return Err(usage(
                "a graphics pipeline needs a colour or depth target".into(),
            ));
        }
        let read = |spirv: &[u8]| {
            ash::util::read_spv(&mut std::io::Cursor::new(spirv))
                .map_err(|e| usage(format!("invalid SPIR-V: {e}")))
        };
        let vertex_words = read(self.vertex_spirv)?;
        let fragment_words = read(self.fragment_spirv)?;

        let layout = Layout::new(
            &shared,
            self.name,
            self.kinds.as_deref(),
            &[],
            self.push,
            vk::ShaderStageFlags::VERTEX | vk::ShaderStageFlags::FRAGMENT,
            &[self.vertex_spirv, self.fragment_spirv],
        )?;
        let mut pipeline = GraphicsPipeline {
            shared: shared.clone(),
            name: self.name.to_string(),
            colors: self.colors.clone(),
            depth: self.depth.map(|(f, _)| f),
            samples: self.samples,
            render_pass: vk::RenderPass::null(),
            pipeline: vk::Pipeline::null(),
            layout,
        };

        // Attachments: colours, their resolves, depth; all kept in GENERAL like every image.
        let general = vk::ImageLayout::GENERAL;
        let mut attachments = Vec::new();
        let mut color_refs = Vec::new();
        for target in &self.colors {
            color_refs.push(vk::AttachmentReference {
                attachment: attachments.len() as u32,
                layout: general,
            });
            attachments.push(stored_attachment(
                target.format.vk(),
                samples,
                vk::AttachmentLoadOp::CLEAR,
            ));
        }
        let any_resolve = self.colors.iter().any(|c| c.resolve);
        let mut resolve_refs = Vec::new();
        for target in &self.colors {
            if target.resolve {
                resolve_refs.push(vk::AttachmentReference {
                    attachment: attachments.len() as u32,
                    layout: general,
                });
                attachments.push(stored_attachment(
                    target.format.vk(),
                    vk::SampleCountFlags::TYPE_1,
                    vk::AttachmentLoadOp::DONT_CARE,
                ));
            } else {
                resolve_refs.push(vk::AttachmentReference {
                    attachment: vk::ATTACHMENT_UNUSED,
                    layout: vk::ImageLayout::UNDEFINED,
                });
            }
        }
        if any_resolve && self.samples == 1 {
            return Err(usage(
                "a resolve target needs a multisampled colour target".into(),
            ));
        }
        let depth_ref = self.depth.map(|(format, _)| {
            let reference = vk::AttachmentReference {
                attachment: attachments.len() as u32,
                layout: general,
            };
            attachments.push(stored_attachment(
                format.vk(),
                samples,
                vk::AttachmentLoadOp::CLEAR,
            ));
            reference
        });
        let mut subpass = vk::SubpassDescription::default()
            .pipeline_bind_point(vk::PipelineBindPoint::GRAPHICS)
            .color_attachments(&color_refs);
        if any_resolve {
            subpass = subpass.resolve_attachments(&resolve_refs);
        }
        if let Some(reference) = depth_ref.as_ref() {
            subpass = subpass.depth_stencil_attachment(reference);
        }
        // Work before and after the pass (uploads, compute passes, copies) is ordered against
        // it here, since barriers cannot be recorded inside a render pass without
        // self-dependencies.
        let attachment_access = vk::AccessFlags::COLOR_ATTACHMENT_READ
            | vk::AccessFlags::COLOR_ATTACHMENT_WRITE
            | vk::AccessFlags::DEPTH_STENCIL_ATTACHMENT_READ
            | vk::AccessFlags::DEPTH_STENCIL_ATTACHMENT_WRITE;
        let graphics_stages = vk::PipelineStageFlags::ALL_GRAPHICS;
        let dependencies = [
            vk::SubpassDependency::default()
                .src_subpass(vk::SUBPASS_EXTERNAL)
                .dst_subpass(0)
                .src_stage_mask(vk::PipelineStageFlags::ALL_COMMANDS)
                .dst_stage_mask(graphics_stages)
                .src_access_mask(vk::AccessFlags::MEMORY_WRITE)
                .dst_access_mask(
                    attachment_access
                        | vk::AccessFlags::SHADER_READ
                        | vk::AccessFlags::UNIFORM_READ
                        | vk::AccessFlags::VERTEX_ATTRIBUTE_READ
                        | vk::AccessFlags::INDEX_READ,
                ),
            vk::SubpassDependency::default()
                .src_subpass(0)
                .dst_subpass(vk::SUBPASS_EXTERNAL)
                .src_stage_mask(graphics_stages)
                .dst_stage_mask(vk::PipelineStageFlags::ALL_COMMANDS)
                .src_access_mask(attachment_access)
                .dst_access_mask(vk::AccessFlags::MEMORY_READ | vk::AccessFlags::MEMORY_WRITE),
        ];

        // SAFETY: create infos reference locals that outlive each call; on early return the
        // partially built pipeline's Drop destroys what was created.
        unsafe {
            let subpasses = [subpass];
            let pass_info = vk::RenderPassCreateInfo::default()
                .attachments(&attachments)
                .subpasses(&subpasses)
                .dependencies(&dependencies);
            pipeline.render_pass = device
                .create_render_pass(&pass_info, None)
                .vk("vkCreateRenderPass")?;

            let vertex_module = device
                .create_shader_module(
                    &vk::ShaderModuleCreateInfo::default().code(&vertex_words),
                    None,
                )
                .vk("vkCreateShaderModule")?;
            let fragment_module = match device.create_shader_module(
                &vk::ShaderModuleCreateInfo::default().code(&fragment_words),
                None,
            ) {
                Ok(m) => m,
                Err(e) => {
                    device.destroy_shader_module(vertex_module, None);
                    return Err(e).vk("vkCreateShaderModule");
                }
            };
            let stages = [
                vk::PipelineShaderStageCreateInfo::default()
                    .stage(vk::ShaderStageFlags::VERTEX)
                    .module(vertex_module)
                    .name(c"main"),
                vk::PipelineShaderStageCreateInfo::default()
                    .stage(vk::ShaderStageFlags::FRAGMENT)
                    .module(fragment_module)
                    .name(c"main"),
            ];
            let vertex_bindings = [vk::VertexInputBindingDescription {
                binding: 0,
                stride: self.vertex_stride,
                input_rate: vk::VertexInputRate::VERTEX,
            }];
            let vertex_attributes: Vec<_> = self
                .attributes
                .iter()
                .map(|a| vk::VertexInputAttributeDescription {
                    location: a.location,
                    binding: 0,
                    format: a.format.vk(),
                    offset: a.offset,
                })
                .collect();
            let mut vertex_input = vk::PipelineVertexInputStateCreateInfo::default();
            if !self.attributes.is_empty() {
                vertex_input = vertex_input
                    .vertex_binding_descriptions(&vertex_bindings)
                    .vertex_attribute_descriptions(&vertex_attributes);
            }
            let input_assembly = vk::PipelineInputAssemblyStateCreateInfo::default()
                .topology(vk::PrimitiveTopology::TRIANGLE_LIST);
            // Viewport and scissor are dynamic so that one pipeline serves every frame size.
            let viewport = vk::PipelineViewportStateCreateInfo::default()
                .viewport_count(1)
                .scissor_count(1);
            let rasterization = vk::PipelineRasterizationStateCreateInfo::default()
                .polygon_mode(vk::PolygonMode::FILL)
                .cull_mode(match self.cull {
                    CullMode::None => vk::CullModeFlags::NONE,
                    CullMode::Back => vk::CullModeFlags::BACK,
                })
                .front_face(vk::FrontFace::COUNTER_CLOCKWISE)
                .line_width(1.0);
            let multisample =
                vk::PipelineMultisampleStateCreateInfo::default().rasterization_samples(samples);
            let (depth_test, compare) = match self.depth {
                Some((_, compare)) => (true, compare.vk()),
                None => (false, vk::CompareOp::ALWAYS),
            };
            let depth_stencil = vk::PipelineDepthStencilStateCreateInfo::default()
                .depth_test_enable(depth_test)
                .depth_write_enable(depth_test)
                .depth_compare_op(compare);
            let blend_attachments: Vec<_> = self
                .colors
                .iter()
                .map(|_| {
                    vk::PipelineColorBlendAttachmentState::default()
                        .blend_enable(false)
                        .color_write_mask(vk::ColorComponentFlags::RGBA)
                })
                .collect();
            let blend =
                vk::PipelineColorBlendStateCreateInfo::default().attachments(&blend_attachments);
            let dynamic_states = [vk::DynamicState::VIEWPORT, vk::DynamicState::SCISSOR];
            let dynamic =
                vk::PipelineDynamicStateCreateInfo::default().dynamic_states(&dynamic_states);
            let info = [vk::GraphicsPipelineCreateInfo::default()
                .stages(&stages)
                .vertex_input_state(&vertex_input)
                .input_assembly_state(&input_assembly)
                .viewport_state(&viewport)
                .rasterization_state(&rasterization)
                .multisample_state(&multisample)
                .depth_stencil_state(&depth_stencil)
                .color_blend_state(&blend)
                .dynamic_state(&dynamic)
                .layout(pipeline.layout.layout)
                .render_pass(pipeline.render_pass)
                .subpass(0)];
            let created = device.create_graphics_pipelines(vk::PipelineCache::null(), &info, None);
            device.destroy_shader_module(vertex_module, None);
            device.destroy_shader_module(fragment_module, None);
            pipeline.pipeline = created
                .map_err(|(_, e)| e)
                .vk("vkCreateGraphicsPipelines")?[0];
        }
        shared.check_validation()?;
        Ok(pipeline)
    }
}

impl Drop for GraphicsPipeline {
    fn drop(&mut self) {
        // SAFETY: submissions complete before returning; null handles are ignored by Vulkan.
        unsafe {
            let device = &self.shared.device;
            device.destroy_pipeline(self.pipeline, None);
            device.destroy_render_pass(self.render_pass, None);
        }
    }
}

/// An attachment kept in GENERAL like every image and stored after the pass (no stencil).
fn stored_attachment(
    format: vk::Format,
    samples: vk::SampleCountFlags,
    load: vk::AttachmentLoadOp,
) -> vk::AttachmentDescription {
    let general = vk::ImageLayout::GENERAL;
    vk::AttachmentDescription::default()
        .format(format)
        .samples(samples)
        .load_op(load)
        .store_op(vk::AttachmentStoreOp::STORE)
        .stencil_load_op(vk::AttachmentLoadOp::DONT_CARE)
        .stencil_store_op(vk::AttachmentStoreOp::DONT_CARE)
        .initial_layout(general)
        .final_layout(general)
}
