//! Recording and submitting work: `Context::submit` hands a `Recorder` to a closure, submits
//! what it recorded, waits, and returns the GPU time of every named pass.

use ash::vk;

use super::access::{binding_access, Hazards, Resource};
use super::buffer::{Buffer, Residency};
use super::context::Context;
use super::error::{GpuError, GpuResult, VkContext};
use super::image::Image;
use super::pipeline::{Binding, ComputePipeline, PipelineParts};
use super::reflect::BindingKind;
use super::submit_slot::{SubmitSlot, MAX_TIMED_PASSES, SETS_PER_POOL};

/// GPU time of each timed pass of one submission, in recording order. A timed pass is a
/// timestamp label, the span from [`Recorder::begin_pass`] to the next `begin_pass` or
/// `end_pass`: it may cover several pipelines, copies or a Vulkan render pass, and is neither a
/// pipeline nor a `vk::RenderPass` (those are `begin_render_pass`'s, `render_pass.rs`).
#[derive(Clone, Debug, Default, serde::Serialize)]
pub struct Timings {
    pub passes: Vec<PassTime>,
}

/// One timed pass: its label and its GPU time.
#[derive(Clone, Debug, serde::Serialize)]
pub struct PassTime {
    pub name: String,
    pub ms: f64,
}

impl Timings {
    pub fn total_ms(&self) -> f64 {
        self.passes.iter().map(|p| p.ms).sum()
    }

    /// Sum over passes with this name (a pass may run several times in one submission).
    pub fn ms(&self, name: &str) -> Option<f64> {
        let matching: Vec<f64> = self
            .passes
            .iter()
            .filter(|p| p.name == name)
            .map(|p| p.ms)
            .collect();
        (!matching.is_empty()).then(|| matching.iter().sum())
    }

    pub fn extend(&mut self, other: Timings) {
        self.passes.extend(other.passes);
    }
}

pub struct Recorder<'a> {
    ctx: &'a Context,
    pub(super) cmd: vk::CommandBuffer,
    slot: Option<SubmitSlot>,
    /// Descriptor pools of the slot filled so far, and sets left in the last.
    pools_used: usize,
    sets_left_in_pool: u32,
    query_pool: Option<vk::QueryPool>,
    next_query: u32,
    open_pass: Option<(String, u32)>,
    passes: Vec<(String, u32)>,
    /// Buffers that must live until the submission has completed (staging data).
    keep_alive: Vec<Buffer>,
    /// Name of the pipeline whose render pass is open, if one is.
    pub(super) render_pass_open: Option<String>,
    /// What the commands since the last barrier read and wrote.
    pub(super) hazards: Hazards,
}

impl Context {
    /// Records work with `record`, submits it, waits for it, and returns the pass timings.
    /// Validation messages produced meanwhile turn into an error.
    pub fn submit<F>(&self, record: F) -> GpuResult<Timings>
    where
        F: FnOnce(&mut Recorder<'_>) -> GpuResult<()>,
    {
        let shared = &self.shared;
        let slot = SubmitSlot::take(shared)?;
        let mut recorder = Recorder {
            ctx: self,
            cmd: slot.cmd,
            query_pool: slot.query_pool,
            slot: Some(slot),
            pools_used: 0,
            sets_left_in_pool: 0,
            next_query: 0,
            open_pass: None,
            passes: Vec::new(),
            keep_alive: Vec::new(),
            render_pass_open: None,
            hazards: Hazards::default(),
        };
        let result = recorder.record_and_run(record);
        let timings = result.and_then(|()| recorder.read_timings());
        // A failed recording or submission may leave the command buffer pending or half
        // recorded: the slot is then destroyed (after an idle wait) rather than reused.
        if let Some(slot) = recorder.slot.take() {
            slot.give_back(shared, timings.is_ok());
        }
        recorder.keep_alive.clear();
        let timings = timings?;
        shared.check_validation()?;
        Ok(timings)
    }
}

impl<'a> Recorder<'a> {
    pub(super) fn device(&self) -> &ash::Device {
        &self.ctx.shared.device
    }

    fn record_and_run<F>(&mut self, record: F) -> GpuResult<()>
    where
        F: FnOnce(&mut Recorder<'_>) -> GpuResult<()>,
    {
        let device = self.device().clone();
        let begin = vk::CommandBufferBeginInfo::default()
            .flags(vk::CommandBufferUsageFlags::ONE_TIME_SUBMIT);
        // SAFETY: the command buffer is freshly allocated and not in use.
        unsafe { device.begin_command_buffer(self.cmd, &begin) }.vk("vkBeginCommandBuffer")?;
        if let Some(pool) = self.query_pool {
            // SAFETY: recording; the pool has 2·MAX_TIMED_PASSES queries.
            unsafe { device.cmd_reset_query_pool(self.cmd, pool, 0, 2 * MAX_TIMED_PASSES) };
        }
        record(self)?;
        if let Some(name) = self.render_pass_open.take() {
            return Err(GpuError::Usage {
                pass: name,
                message: "render pass begun but never ended".into(),
            });
        }
        if self.open_pass.is_some() {
            self.end_pass();
        }
        if self.hazards.pending() {
            // The host reads results once the fence signals: make the last writes visible to it.
            self.memory_barrier(vk::PipelineStageFlags::HOST);
        }
        // SAFETY: recording is complete.
        unsafe { device.end_command_buffer(self.cmd) }.vk("vkEndCommandBuffer")?;
        // Catch recording errors (bad bindings, bad barriers) before the driver sees them.
        self.ctx.shared.check_validation()?;
        let fence = self.slot.as_ref().expect("slot held while recording").fence;
        let cmds = [self.cmd];
        let submit = [vk::SubmitInfo::default().command_buffers(&cmds)];
        let outcome = {
            let queue = self
                .ctx
                .shared
                .queue
                .lock()
                .unwrap_or_else(|e| e.into_inner());
            // SAFETY: the queue is locked (queues are externally synchronised); the command
            // buffer is executable.
            unsafe { device.queue_submit(*queue, &submit, fence) }.vk("vkQueueSubmit")
        }
        .and_then(|()| {
            // SAFETY: the fence belongs to this device and is reset (a slot's fence is reset
            // when the slot is given back).
            unsafe { device.wait_for_fences(&[fence], true, u64::MAX) }.vk("vkWaitForFences")
        });
        outcome
    }

    fn read_timings(&mut self) -> GpuResult<Timings> {
        let Some(pool) = self.query_pool else {
            return Ok(Timings::default());
        };
        if self.next_query == 0 {
            return Ok(Timings::default());
        }
        let mut ticks = vec![0u64; self.next_query as usize];
        // SAFETY: every query in 0..next_query was written by the completed submission.
        unsafe {
            self.device().get_query_pool_results(
                pool,
                0,
                &mut ticks,
                vk::QueryResultFlags::TYPE_64 | vk::QueryResultFlags::WAIT,
            )
        }
        .vk("vkGetQueryPoolResults")?;
        let bits = self.ctx.shared.timestamp_valid_bits;
        let mask = if bits >= 64 {
            u64::MAX
        } else {
            (1u64 << bits) - 1
        };
        let ns_per_tick = f64::from(self.ctx.shared.properties.limits.timestamp_period);
        let passes = self
            .passes
            .iter()
            .map(|(name, first)| {
                let start = ticks[*first as usize] & mask;
                let end = ticks[*first as usize + 1] & mask;
                PassTime {
                    name: name.clone(),
                    ms: end.wrapping_sub(start) as f64 * ns_per_tick * 1e-6,
                }
            })
            .collect();
        Ok(Timings { passes })
    }

    pub fn context(&self) -> &Context {
        self.ctx
    }

    /// Starts timing a named pass (a timestamp label over whatever is recorded next, not a
    /// Vulkan render pass); it ends at `end_pass` or at the next `begin_pass`.
    pub fn begin_pass(&mut self, name: &str) {
        if self.open_pass.is_some() {
            self.end_pass();
        }
        let Some(pool) = self.query_pool else { return };
        if self.next_query + 2 > 2 * MAX_TIMED_PASSES {
            return;
        }
        // SAFETY: recording; the query index is in range and was reset.
        unsafe {
            self.device().cmd_write_timestamp(
                self.cmd,
                vk::PipelineStageFlags::TOP_OF_PIPE,
                pool,
                self.next_query,
            )
        };
        self.open_pass = Some((name.to_string(), self.next_query));
        self.next_query += 2;
    }

    pub fn end_pass(&mut self) {
        let Some((name, first)) = self.open_pass.take() else {
            return;
        };
        let Some(pool) = self.query_pool else { return };
        // SAFETY: recording; `first + 1` was reserved by begin_pass.
        unsafe {
            self.device().cmd_write_timestamp(
                self.cmd,
                vk::PipelineStageFlags::BOTTOM_OF_PIPE,
                pool,
                first + 1,
            )
        };
        self.passes.push((name, first));
    }

    /// Orders the next command after everything recorded so far, when it touches what those
    /// commands wrote or writes what they read (see `access.rs`). Every command calls this with
    /// its own reads and writes before it is recorded.
    pub(super) fn sync(&mut self, reads: &[Resource], writes: &[Resource]) {
        if self.hazards.conflicts(reads, writes) {
            self.barrier();
        }
        self.hazards.add(reads, writes);
    }

    /// Barriers placed and commands recorded so far in this submission.
    pub fn barrier_counts(&self) -> (u32, u32) {
        (self.hazards.barriers, self.hazards.commands)
    }

    /// Makes all earlier shader and transfer writes visible to all later shader and transfer
    /// reads and writes: the one barrier `sync` places (a global memory barrier; the
    /// dependency, not the access mask, is what costs).
    pub(super) fn barrier(&mut self) {
        self.memory_barrier(vk::PipelineStageFlags::ALL_COMMANDS);
    }

    fn memory_barrier(&mut self, dst_stage: vk::PipelineStageFlags) {
        self.hazards.clear();
        self.hazards.barriers += 1;
        let all = vk::AccessFlags::SHADER_READ
            | vk::AccessFlags::SHADER_WRITE
            | vk::AccessFlags::TRANSFER_READ
            | vk::AccessFlags::TRANSFER_WRITE
            | vk::AccessFlags::INDIRECT_COMMAND_READ
            | vk::AccessFlags::COLOR_ATTACHMENT_WRITE
            | vk::AccessFlags::DEPTH_STENCIL_ATTACHMENT_WRITE;
        let dst = if dst_stage == vk::PipelineStageFlags::HOST {
            vk::AccessFlags::HOST_READ
        } else {
            all
        };
        let barrier = [vk::MemoryBarrier::default()
            .src_access_mask(all)
            .dst_access_mask(dst)];
        // SAFETY: recording; a global memory barrier has no resource references.
        unsafe {
            self.device().cmd_pipeline_barrier(
                self.cmd,
                vk::PipelineStageFlags::ALL_COMMANDS,
                dst_stage,
                vk::DependencyFlags::empty(),
                &barrier,
                &[],
                &[],
            )
        };
    }

    pub(crate) fn transition_to_general(&mut self, image: &Image) {
        let barrier = [vk::ImageMemoryBarrier::default()
            .old_layout(vk::ImageLayout::UNDEFINED)
            .new_layout(vk::ImageLayout::GENERAL)
            .src_access_mask(vk::AccessFlags::empty())
            .dst_access_mask(vk::AccessFlags::MEMORY_READ | vk::AccessFlags::MEMORY_WRITE)
            .src_queue_family_index(vk::QUEUE_FAMILY_IGNORED)
            .dst_queue_family_index(vk::QUEUE_FAMILY_IGNORED)
            .image(image.raw())
            .subresource_range(image.subresource_range())];
        // SAFETY: recording; the image belongs to this device.
        unsafe {
            self.device().cmd_pipeline_barrier(
                self.cmd,
                vk::PipelineStageFlags::TOP_OF_PIPE,
                vk::PipelineStageFlags::ALL_COMMANDS,
                vk::DependencyFlags::empty(),
                &[],
                &[],
                &barrier,
            )
        };
    }

    pub fn copy_buffer(&mut self, src: &Buffer, dst: &Buffer, size_bytes: u64) {
        self.copy_buffer_region(src, 0, dst, 0, size_bytes);
    }

    /// Copies `size_bytes` from `src` at `src_offset` to `dst` at `dst_offset`.
    pub fn copy_buffer_region(
        &mut self,
        src: &Buffer,
        src_offset: u64,
        dst: &Buffer,
        dst_offset: u64,
        size_bytes: u64,
    ) {
        assert!(
            src_offset + size_bytes <= src.size_bytes()
                && dst_offset + size_bytes <= dst.size_bytes(),
            "copy of {size_bytes} bytes outside {} or {}",
            src.name(),
            dst.name()
        );
        self.sync(
            &[Resource::buffer_range(src, src_offset, size_bytes)],
            &[Resource::buffer_range(dst, dst_offset, size_bytes)],
        );
        let region = [vk::BufferCopy {
            src_offset,
            dst_offset,
            size: size_bytes,
        }];
        // SAFETY: recording; sizes are within both buffers (callers check).
        unsafe {
            self.device()
                .cmd_copy_buffer(self.cmd, src.raw(), dst.raw(), &region)
        };
    }

    /// Fills the whole buffer with a repeated 32-bit value.
    pub fn fill_buffer(&mut self, buffer: &Buffer, value: u32) {
        self.sync(&[], &[Resource::buffer(buffer)]);
        // SAFETY: recording; WHOLE_SIZE covers the buffer, whose size is a multiple of 4.
        unsafe {
            self.device()
                .cmd_fill_buffer(self.cmd, buffer.raw(), 0, vk::WHOLE_SIZE, value)
        };
    }

    /// Uploads `data` into `dst` within this submission (the staging buffer lives until the
    /// submission completes).
    pub fn upload_buffer<T: bytemuck::Pod>(&mut self, dst: &Buffer, data: &[T]) -> GpuResult<()> {
        let bytes: &[u8] = bytemuck::cast_slice(data);
        if bytes.is_empty() {
            return Ok(());
        }
        if bytes.len() as u64 > dst.size_bytes() {
            return Err(GpuError::Usage {
                pass: dst.name().to_string(),
                message: format!(
                    "upload of {} bytes into a buffer of {}",
                    bytes.len(),
                    dst.size_bytes()
                ),
            });
        }
        let mut staging = Buffer::new(
            self.ctx,
            &format!("{} staging", dst.name()),
            bytes.len() as u64,
            super::Residency::Upload,
        )?;
        staging.write_mapped(0, bytes)?;
        self.copy_buffer(&staging, dst, bytes.len() as u64);
        self.keep_alive.push(staging);
        Ok(())
    }

    pub fn copy_buffer_to_image(&mut self, src: &Buffer, dst: &Image) {
        self.sync(&[Resource::buffer(src)], &[Resource::image(dst)]);
        let region = [dst.whole_copy()];
        // SAFETY: recording; the image is in GENERAL layout and the buffer holds every texel.
        unsafe {
            self.device().cmd_copy_buffer_to_image(
                self.cmd,
                src.raw(),
                dst.raw(),
                vk::ImageLayout::GENERAL,
                &region,
            )
        };
    }

    /// Copies the whole image into `dst`, tightly packed (row-major x, then y, then z).
    pub fn copy_image_to_buffer(&mut self, src: &Image, dst: &Buffer) {
        self.sync(&[Resource::image(src)], &[Resource::buffer(dst)]);
        let region = [src.whole_copy()];
        // SAFETY: recording; the image is in GENERAL layout and the buffer fits every texel.
        unsafe {
            self.device().cmd_copy_image_to_buffer(
                self.cmd,
                src.raw(),
                vk::ImageLayout::GENERAL,
                dst.raw(),
                &region,
            )
        };
    }

    /// Clears a colour image to `rgba`.
    pub fn clear_image(&mut self, image: &Image, rgba: [f32; 4]) {
        self.sync(&[], &[Resource::image(image)]);
        let color = vk::ClearColorValue { float32: rgba };
        // SAFETY: recording; the image is in GENERAL layout.
        unsafe {
            self.device().cmd_clear_color_image(
                self.cmd,
                image.raw(),
                vk::ImageLayout::GENERAL,
                &color,
                &[image.subresource_range()],
            )
        };
    }

    fn allocate_set(
        &mut self,
        set_layout: vk::DescriptorSetLayout,
    ) -> GpuResult<vk::DescriptorSet> {
        if self.sets_left_in_pool == 0 {
            let slot = self.slot.as_mut().expect("slot held while recording");
            slot.descriptor_pool(&self.ctx.shared, self.pools_used)?;
            self.pools_used += 1;
            self.sets_left_in_pool = SETS_PER_POOL;
        }
        let layouts = [set_layout];
        let info = vk::DescriptorSetAllocateInfo::default()
            .descriptor_pool(
                self.slot
                    .as_ref()
                    .expect("slot held while recording")
                    .descriptor_pools[self.pools_used - 1],
            )
            .set_layouts(&layouts);
        // SAFETY: the pool has room (at most 8 storage buffers per set are assumed; a pass with
        // more bindings of one kind would fail here with a Vulkan error, not UB).
        let set = unsafe { self.device().allocate_descriptor_sets(&info) }
            .vk("vkAllocateDescriptorSets")?[0];
        self.sets_left_in_pool -= 1;
        Ok(set)
    }

    /// Binds `bindings` (in the pipeline's binding order) and `push_constants`, and
    /// dispatches `groups` workgroups, after a barrier if it depends on earlier commands.
    /// Passes bind by name instead ([`Recorder::compute`]).
    pub fn dispatch<P: bytemuck::Pod>(
        &mut self,
        pipeline: &ComputePipeline,
        bindings: &[Binding<'_>],
        push_constants: &P,
        groups: [u32; 3],
    ) -> GpuResult<()> {
        self.dispatch_bytes(
            pipeline,
            bindings,
            bytemuck::bytes_of(push_constants),
            groups,
        )
    }

    pub(super) fn dispatch_bytes(
        &mut self,
        pipeline: &ComputePipeline,
        bindings: &[Binding<'_>],
        push: &[u8],
        groups: [u32; 3],
    ) -> GpuResult<()> {
        if let Some(open) = &self.render_pass_open {
            return Err(GpuError::Usage {
                pass: pipeline.name.clone(),
                message: format!("dispatch inside the render pass of \"{open}\""),
            });
        }
        self.bind(&pipeline.parts(), bindings, push)?;
        let max = self.ctx.limits().max_compute_work_group_count;
        if groups.iter().zip(max.iter()).any(|(g, m)| g > m) {
            return Err(GpuError::Usage {
                pass: pipeline.name.to_string(),
                message: format!(
                    "dispatch of {groups:?} workgroups exceeds the device limit {max:?}"
                ),
            });
        }
        if groups.contains(&0) {
            return Ok(());
        }
        let (reads, writes) = binding_access(bindings, &pipeline.layout.slots);
        self.sync(&reads, &writes);
        // SAFETY: recording; pipeline, set and push constants were bound by bind().
        unsafe {
            self.device()
                .cmd_dispatch(self.cmd, groups[0], groups[1], groups[2])
        };
        Ok(())
    }

    /// As `dispatch`, with the workgroup counts read from `args` (three u32 at `offset`).
    pub fn dispatch_indirect<P: bytemuck::Pod>(
        &mut self,
        pipeline: &ComputePipeline,
        bindings: &[Binding<'_>],
        push_constants: &P,
        args: &Buffer,
        offset: u64,
    ) -> GpuResult<()> {
        self.dispatch_indirect_bytes(
            pipeline,
            bindings,
            bytemuck::bytes_of(push_constants),
            args,
            offset,
        )
    }

    pub(super) fn dispatch_indirect_bytes(
        &mut self,
        pipeline: &ComputePipeline,
        bindings: &[Binding<'_>],
        push: &[u8],
        args: &Buffer,
        offset: u64,
    ) -> GpuResult<()> {
        if let Some(open) = &self.render_pass_open {
            return Err(GpuError::Usage {
                pass: pipeline.name.clone(),
                message: format!("dispatch inside the render pass of \"{open}\""),
            });
        }
        self.bind(&pipeline.parts(), bindings, push)?;
        let (mut reads, writes) = binding_access(bindings, &pipeline.layout.slots);
        reads.push(Resource::buffer_range(args, offset, 12));
        self.sync(&reads, &writes);
        // SAFETY: recording; the args buffer has INDIRECT usage and holds 12 bytes at offset.
        unsafe {
            self.device()
                .cmd_dispatch_indirect(self.cmd, args.raw(), offset)
        };
        Ok(())
    }

    pub(crate) fn bind(
        &mut self,
        pipeline: &PipelineParts<'_>,
        bindings: &[Binding<'_>],
        push: &[u8],
    ) -> GpuResult<()> {
        let usage = |message: String| GpuError::Usage {
            pass: pipeline.name.to_string(),
            message,
        };
        let slots = &pipeline.layout.slots;
        if bindings.len() != slots.len() {
            return Err(usage(format!(
                "{} bindings given, the pipeline declares {}",
                bindings.len(),
                slots.len()
            )));
        }
        if push.len() as u32 != pipeline.layout.push_constant_bytes {
            return Err(usage(format!(
                "{} bytes of push constants given, the pipeline declares {}",
                push.len(),
                pipeline.layout.push_constant_bytes
            )));
        }
        for (i, (binding, slot)) in bindings.iter().zip(slots).enumerate() {
            if !binding.matches(slot.kind) {
                return Err(usage(format!("binding {i} must be a {:?}", slot.kind)));
            }
        }
        let max_range = u64::from(self.ctx.limits().max_storage_buffer_range);
        let set = if slots.is_empty() {
            None
        } else {
            Some(self.allocate_set(pipeline.layout.set_layout)?)
        };
        let mut buffer_infos = Vec::with_capacity(bindings.len());
        let mut image_infos = Vec::with_capacity(bindings.len());
        for (i, binding) in bindings.iter().enumerate() {
            match *binding {
                Binding::Buffer(b) => {
                    if slots[i].kind == BindingKind::StorageBuffer && b.size_bytes() > max_range {
                        return Err(usage(format!(
                            "buffer \"{}\" of {} MiB exceeds this device's {} MiB storage-buffer binding limit; bind it in ranges",
                            b.name(),
                            b.size_bytes() >> 20,
                            max_range >> 20
                        )));
                    }
                    buffer_infos.push((
                        i,
                        vk::DescriptorBufferInfo {
                            buffer: b.raw(),
                            offset: 0,
                            range: vk::WHOLE_SIZE,
                        },
                    ));
                }
                Binding::BufferRange(b, offset, size) => {
                    if offset + size > b.size_bytes() || size > max_range {
                        return Err(usage(format!("range {offset}+{size} of buffer \"{}\" is out of bounds or over the binding limit", b.name())));
                    }
                    buffer_infos.push((
                        i,
                        vk::DescriptorBufferInfo {
                            buffer: b.raw(),
                            offset,
                            range: size,
                        },
                    ));
                }
                Binding::Sampled(image, sampler) => image_infos.push((
                    i,
                    vk::DescriptorImageInfo {
                        sampler: sampler.raw(),
                        image_view: image.view(),
                        image_layout: vk::ImageLayout::GENERAL,
                    },
                )),
                Binding::Storage(image) => image_infos.push((
                    i,
                    vk::DescriptorImageInfo {
                        sampler: vk::Sampler::null(),
                        image_view: image.view(),
                        image_layout: vk::ImageLayout::GENERAL,
                    },
                )),
            }
        }
        let mut writes = Vec::with_capacity(bindings.len());
        for (i, info) in &buffer_infos {
            writes.push(
                vk::WriteDescriptorSet::default()
                    .dst_set(set.unwrap_or_default())
                    .dst_binding(*i as u32)
                    .descriptor_type(slots[*i].kind.descriptor_type())
                    .buffer_info(std::slice::from_ref(info)),
            );
        }
        for (i, info) in &image_infos {
            writes.push(
                vk::WriteDescriptorSet::default()
                    .dst_set(set.unwrap_or_default())
                    .dst_binding(*i as u32)
                    .descriptor_type(slots[*i].kind.descriptor_type())
                    .image_info(std::slice::from_ref(info)),
            );
        }
        let device = self.device();
        // SAFETY: the set is freshly allocated for this layout; infos outlive the call; the
        // command buffer is recording.
        unsafe {
            device.cmd_bind_pipeline(self.cmd, pipeline.bind_point, pipeline.pipeline);
            if let Some(set) = set {
                device.update_descriptor_sets(&writes, &[]);
                device.cmd_bind_descriptor_sets(
                    self.cmd,
                    pipeline.bind_point,
                    pipeline.layout.layout,
                    0,
                    &[set],
                    &[],
                );
            }
            if !push.is_empty() {
                device.cmd_push_constants(
                    self.cmd,
                    pipeline.layout.layout,
                    pipeline.layout.stages,
                    0,
                    push,
                );
            }
        }
        Ok(())
    }
}

impl Context {
    /// Copies `bytes` to a resource named `name` through a new staging buffer, which `copy`
    /// reads in one submission.
    pub(crate) fn upload_staged(
        &self,
        name: &str,
        bytes: &[u8],
        copy: impl FnOnce(&mut Recorder<'_>, &Buffer),
    ) -> GpuResult<()> {
        let len = bytes.len() as u64;
        let mut staging = Buffer::new(self, &format!("{name} staging"), len, Residency::Upload)?;
        // Buffers are at least 16 bytes: a tiny upload fills only the start of its staging.
        staging.write_mapped(0, bytes)?;
        self.submit(|rec| {
            copy(rec, &staging);
            Ok(())
        })?;
        Ok(())
    }

    /// A new read-back buffer of `bytes` that `copy` fills from a resource named `name`, in one
    /// submission.
    pub(crate) fn read_staged(
        &self,
        name: &str,
        bytes: u64,
        copy: impl FnOnce(&mut Recorder<'_>, &Buffer),
    ) -> GpuResult<Buffer> {
        let readback = Buffer::new(
            self,
            &format!("{name} readback"),
            bytes,
            Residency::Readback,
        )?;
        self.submit(|rec| {
            copy(rec, &readback);
            Ok(())
        })?;
        Ok(readback)
    }
}
