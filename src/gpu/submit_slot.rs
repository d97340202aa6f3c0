//! The objects one submission needs besides its commands — a command buffer, a fence, a
//! timestamp pool and descriptor pools — kept by the device between submissions. A
//! steady-state frame resets them instead of creating and destroying them, so recording a
//! frame creates no Vulkan objects once the first frame has run (`objects_created` counts
//! every creation, for `ocular bench`'s counters and the engine tests).

use ash::vk;

use super::context::DeviceShared;
use super::error::{GpuResult, VkContext};

/// Timestamp pairs per submission; more passes than this in one submission are not timed.
pub(crate) const MAX_TIMED_PASSES: u32 = 64;
/// Descriptor sets per pool before the recorder opens another pool.
pub(crate) const SETS_PER_POOL: u32 = 256;

pub(crate) struct SubmitSlot {
    pub(crate) cmd: vk::CommandBuffer,
    pub(crate) fence: vk::Fence,
    pub(crate) query_pool: Option<vk::QueryPool>,
    /// Pools in the order the recorder filled them; all reset together after a submission.
    pub(crate) descriptor_pools: Vec<vk::DescriptorPool>,
}

impl SubmitSlot {
    /// A free slot of `shared`, or a new one.
    pub(crate) fn take(shared: &DeviceShared) -> GpuResult<SubmitSlot> {
        if let Some(slot) = shared.lock_slots().pop() {
            return Ok(slot);
        }
        let device = &shared.device;
        let alloc = vk::CommandBufferAllocateInfo::default()
            .level(vk::CommandBufferLevel::PRIMARY)
            .command_buffer_count(1);
        let cmd = {
            let pool = shared.lock_command_pool();
            // SAFETY: the pool belongs to this device and is locked (externally synchronised).
            unsafe { device.allocate_command_buffers(&alloc.command_pool(*pool)) }
                .vk("vkAllocateCommandBuffers")?[0]
        };
        shared.count_created(1);
        let mut slot = SubmitSlot {
            cmd,
            fence: vk::Fence::null(),
            query_pool: None,
            descriptor_pools: Vec::new(),
        };
        // SAFETY: valid create info on a live device; on error the slot is destroyed below.
        let fence = unsafe { device.create_fence(&vk::FenceCreateInfo::default(), None) };
        match fence.vk("vkCreateFence") {
            Ok(f) => slot.fence = f,
            Err(e) => {
                slot.destroy(shared);
                return Err(e);
            }
        }
        shared.count_created(1);
        if shared.timestamp_valid_bits > 0 {
            let info = vk::QueryPoolCreateInfo::default()
                .query_type(vk::QueryType::TIMESTAMP)
                .query_count(2 * MAX_TIMED_PASSES);
            // SAFETY: valid create info on a live device.
            slot.query_pool = unsafe { device.create_query_pool(&info, None) }.ok();
            shared.count_created(u64::from(slot.query_pool.is_some()));
        }
        Ok(slot)
    }

    /// The `index`-th descriptor pool of this slot, created on first use.
    pub(crate) fn descriptor_pool(
        &mut self,
        shared: &DeviceShared,
        index: usize,
    ) -> GpuResult<vk::DescriptorPool> {
        if let Some(&pool) = self.descriptor_pools.get(index) {
            return Ok(pool);
        }
        let sizes = [
            (vk::DescriptorType::STORAGE_BUFFER, 8),
            (vk::DescriptorType::UNIFORM_BUFFER, 2),
            (vk::DescriptorType::COMBINED_IMAGE_SAMPLER, 4),
            (vk::DescriptorType::STORAGE_IMAGE, 4),
        ]
        .map(|(ty, per_set)| vk::DescriptorPoolSize {
            ty,
            descriptor_count: SETS_PER_POOL * per_set,
        });
        let info = vk::DescriptorPoolCreateInfo::default()
            .max_sets(SETS_PER_POOL)
            .pool_sizes(&sizes);
        // SAFETY: valid create info; destroyed with the slot.
        let pool = unsafe { shared.device.create_descriptor_pool(&info, None) }
            .vk("vkCreateDescriptorPool")?;
        shared.count_created(1);
        self.descriptor_pools.push(pool);
        Ok(pool)
    }

    /// Returns the slot for the next submission once its work has completed (`completed`);
    /// otherwise waits for the device and destroys it, since its objects may still be in use.
    pub(crate) fn give_back(mut self, shared: &DeviceShared, completed: bool) {
        let device = &shared.device;
        let reset = completed
            // SAFETY: the submission that used these objects has completed (or never ran), so
            // none is in use; the command buffer's pool allows individual resets.
            && unsafe {
                self.descriptor_pools.iter().all(|&pool| {
                    device
                        .reset_descriptor_pool(pool, vk::DescriptorPoolResetFlags::empty())
                        .is_ok()
                }) && device
                    .reset_command_buffer(self.cmd, vk::CommandBufferResetFlags::empty())
                    .is_ok()
                    && device.reset_fences(&[self.fence]).is_ok()
            };
        if reset {
            let mut slots = shared.lock_slots();
            // Concurrent submissions from several threads leave several slots; keep a few.
            if slots.len() < 4 {
                slots.push(self);
                return;
            }
        } else {
            // SAFETY: waiting for idle makes every object of the slot unused.
            let _ = unsafe { device.device_wait_idle() };
        }
        self.destroy(shared);
    }

    pub(crate) fn destroy(&mut self, shared: &DeviceShared) {
        let device = &shared.device;
        // SAFETY: the slot's objects are unused (completed, or the device is idle); null
        // handles are ignored.
        unsafe {
            for pool in self.descriptor_pools.drain(..) {
                device.destroy_descriptor_pool(pool, None);
            }
            if let Some(pool) = self.query_pool.take() {
                device.destroy_query_pool(pool, None);
            }
            device.destroy_fence(self.fence, None);
            let pool = shared.lock_command_pool();
            device.free_command_buffers(*pool, &[self.cmd]);
        }
    }
}
