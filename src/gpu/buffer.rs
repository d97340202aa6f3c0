//! Buffers: device memory with staging upload and read-back.

use std::sync::Arc;

use ash::vk;
use gpu_allocator::vulkan::{Allocation, AllocationCreateDesc, AllocationScheme};
use gpu_allocator::MemoryLocation;

use super::context::{Context, DeviceShared};
use super::error::{GpuError, GpuResult, VkContext};

/// Where a buffer lives: on the device for passes, or host-visible for transfers.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Residency {
    Device,
    Upload,
    Readback,
}

impl Residency {
    fn location(self) -> MemoryLocation {
        match self {
            Residency::Device => MemoryLocation::GpuOnly,
            Residency::Upload => MemoryLocation::CpuToGpu,
            Residency::Readback => MemoryLocation::GpuToCpu,
        }
    }
}

pub struct Buffer {
    shared: Arc<DeviceShared>,
    raw: vk::Buffer,
    allocation: Option<Allocation>,
    size_bytes: u64,
    name: String,
}

pub(crate) fn out_of_memory(what: &str, bytes: u64) -> GpuError {
    GpuError::OutOfDeviceMemory {
        what: format!("{what} ({:.1} MiB)", bytes as f64 / (1024.0 * 1024.0)),
    }
}

/// What a failed `call` creating `what` (e.g. `image "psf texture"`) of `bytes` means: running
/// out of memory names the resource and its size, so that the user can shrink it.
pub(crate) fn creation_error(
    call: &'static str,
    what: &str,
    bytes: u64,
    e: vk::Result,
) -> GpuError {
    match e {
        vk::Result::ERROR_OUT_OF_DEVICE_MEMORY | vk::Result::ERROR_OUT_OF_HOST_MEMORY => {
            out_of_memory(what, bytes)
        }
        e => GpuError::Vulkan { call, result: e },
    }
}

/// Memory for a just-created buffer or image, counted in [`Context::allocations`]; `what` names
/// the resource in errors as in [`creation_error`].
pub(crate) fn allocate(
    shared: &DeviceShared,
    (name, what, bytes): (&str, &str, u64),
    requirements: vk::MemoryRequirements,
    location: MemoryLocation,
    linear: bool,
) -> GpuResult<Allocation> {
    shared
        .allocations
        .fetch_add(1, std::sync::atomic::Ordering::Relaxed);
    shared
        .allocator()
        .allocate(&AllocationCreateDesc {
            name,
            requirements,
            location,
            linear,
            allocation_scheme: AllocationScheme::GpuAllocatorManaged,
        })
        .map_err(|e| match e {
            gpu_allocator::AllocationError::OutOfMemory => out_of_memory(what, bytes),
            e => GpuError::Unsupported(format!("allocating {what}: {e}")),
        })
}

impl Context {
    /// Buffers and images allocated on this device so far, by anyone: a steady-state frame
    /// leaves it unchanged.
    pub fn allocations(&self) -> u64 {
        self.shared
            .allocations
            .load(std::sync::atomic::Ordering::Relaxed)
    }
}

impl Buffer {
    /// A buffer of `size_bytes` (at least 16: Vulkan has no empty buffers). Device buffers can
    /// be storage, copy source and copy destination; host buffers are transfer buffers.
    pub fn new(
        ctx: &Context,
        name: &str,
        size_bytes: u64,
        residency: Residency,
    ) -> GpuResult<Buffer> {
        let size_bytes = size_bytes.max(16);
        let usage = vk::BufferUsageFlags::STORAGE_BUFFER
            | vk::BufferUsageFlags::TRANSFER_SRC
            | vk::BufferUsageFlags::TRANSFER_DST
            | vk::BufferUsageFlags::INDIRECT_BUFFER
            | vk::BufferUsageFlags::VERTEX_BUFFER
            | vk::BufferUsageFlags::INDEX_BUFFER
            | vk::BufferUsageFlags::UNIFORM_BUFFER;
        let shared = ctx.shared.clone();
        let info = vk::BufferCreateInfo::default()
            .size(size_bytes)
            .usage(usage)
            .sharing_mode(vk::SharingMode::EXCLUSIVE);
        let what = format!("buffer \"{name}\"");
        // SAFETY: valid create info on a live device.
        let raw = unsafe { shared.device.create_buffer(&info, None) }
            .map_err(|e| creation_error("vkCreateBuffer", &what, size_bytes, e))?;
        // SAFETY: `raw` was just created on this device.
        let requirements = unsafe { shared.device.get_buffer_memory_requirements(raw) };
        let location = residency.location();
        let allocation = allocate(
            &shared,
            (name, &what, size_bytes),
            requirements,
            location,
            true,
        )
        .inspect_err(|_| {
            // SAFETY: the buffer is unused and unbound.
            unsafe { shared.device.destroy_buffer(raw, None) }
        })?;
        // SAFETY: memory and buffer come from the same device; the offset is aligned by the
        // allocator according to the requirements.
        let bound = unsafe {
            shared
                .device
                .bind_buffer_memory(raw, allocation.memory(), allocation.offset())
        };
        let buffer = Buffer {
            shared,
            raw,
            allocation: Some(allocation),
            size_bytes,
            name: name.to_string(),
        };
        bound.vk("vkBindBufferMemory")?;
        Ok(buffer)
    }

    /// A device buffer holding `data`, uploaded through a staging buffer.
    pub fn from_slice<T: bytemuck::Pod>(
        ctx: &Context,
        name: &str,
        data: &[T],
    ) -> GpuResult<Buffer> {
        let buffer = Buffer::new(
            ctx,
            name,
            std::mem::size_of_val(data) as u64,
            Residency::Device,
        )?;
        buffer.upload(ctx, data)?;
        Ok(buffer)
    }

    pub fn raw(&self) -> vk::Buffer {
        self.raw
    }

    pub fn size_bytes(&self) -> u64 {
        self.size_bytes
    }

    pub fn name(&self) -> &str {
        &self.name
    }

    /// The mapped bytes of a host-visible buffer.
    pub fn mapped_bytes_mut(&mut self) -> Option<&mut [u8]> {
        let size = self.size_bytes as usize;
        self.allocation
            .as_mut()
            .and_then(|a| a.mapped_slice_mut())
            .map(|s| &mut s[..size])
    }

    pub fn mapped_bytes(&self) -> Option<&[u8]> {
        let size = self.size_bytes as usize;
        self.allocation
            .as_ref()
            .and_then(|a| a.mapped_slice())
            .map(|s| &s[..size])
    }

    /// Writes `data` through the mapping of this host-visible buffer (`Upload`), starting at
    /// element `first` (elements of `T`). Nothing is submitted: a command recorded after this
    /// reads it.
    pub fn write_mapped<T: bytemuck::Pod>(&mut self, first: usize, data: &[T]) -> GpuResult<()> {
        let bytes: &[u8] = bytemuck::cast_slice(data);
        let start = first * std::mem::size_of::<T>();
        if let Some(error) = self.mapped_range_error(start, bytes.len()) {
            return Err(error);
        }
        match self.mapped_bytes_mut() {
            Some(mapped) => {
                mapped[start..start + bytes.len()].copy_from_slice(bytes);
                Ok(())
            }
            None => Err(self.not_mapped()),
        }
    }

    /// Reads `count` `T`s from element `first` through the mapping of this host-visible buffer
    /// (`Readback`, or `Upload`), once the submission that wrote them has completed.
    pub fn read_mapped<T: bytemuck::Pod>(&self, first: usize, count: usize) -> GpuResult<Vec<T>> {
        let size = std::mem::size_of::<T>();
        if let Some(error) = self.mapped_range_error(first * size, count * size) {
            return Err(error);
        }
        let bytes = self.mapped_bytes().ok_or_else(|| self.not_mapped())?;
        // The mapped pointer need not be aligned for T: copy element-wise.
        Ok(bytemuck::pod_collect_to_vec(
            &bytes[first * size..(first + count) * size],
        ))
    }

    /// Every whole `T` this host-visible buffer holds, read through its mapping.
    pub fn read_mapped_all<T: bytemuck::Pod>(&self) -> GpuResult<Vec<T>> {
        self.read_mapped(0, self.size_bytes as usize / std::mem::size_of::<T>())
    }

    fn mapped_range_error(&self, start: usize, len: usize) -> Option<GpuError> {
        (start as u64 + len as u64 > self.size_bytes).then(|| GpuError::Usage {
            pass: self.name.clone(),
            message: format!(
                "mapped access to bytes {start}..{} of a buffer of {}",
                start + len,
                self.size_bytes
            ),
        })
    }

    fn not_mapped(&self) -> GpuError {
        GpuError::Usage {
            pass: self.name.clone(),
            message: "mapped access to a buffer that is not host-visible".into(),
        }
    }

    /// Copies `data` to the start of this buffer (via a staging buffer when device-local).
    pub fn upload<T: bytemuck::Pod>(&self, ctx: &Context, data: &[T]) -> GpuResult<()> {
        let bytes: &[u8] = bytemuck::cast_slice(data);
        if bytes.len() as u64 > self.size_bytes {
            return Err(GpuError::Usage {
                pass: self.name.clone(),
                message: format!(
                    "upload of {} bytes into a buffer of {}",
                    bytes.len(),
                    self.size_bytes
                ),
            });
        }
        if bytes.is_empty() {
            return Ok(());
        }
        ctx.upload_staged(&self.name, bytes, |rec, staging| {
            rec.copy_buffer(staging, self, bytes.len() as u64)
        })
    }

    /// Reads the whole buffer back as `T`s (via a read-back buffer).
    pub fn read<T: bytemuck::Pod>(&self, ctx: &Context) -> GpuResult<Vec<T>> {
        let readback = ctx.read_staged(&self.name, self.size_bytes, |rec, readback| {
            rec.copy_buffer(self, readback, self.size_bytes)
        })?;
        readback.read_mapped_all()
    }
}

impl std::fmt::Debug for Buffer {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "Buffer(\"{}\", {} bytes)", self.name, self.size_bytes)
    }
}

impl Drop for Buffer {
    fn drop(&mut self) {
        if let Some(allocation) = self.allocation.take() {
            let _ = self.shared.allocator().free(allocation);
        }
        // SAFETY: submissions wait for completion before returning, so the GPU no longer uses
        // this buffer.
        unsafe { self.shared.device.destroy_buffer(self.raw, None) };
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Typed mapped writes land at their element offset and read back as written; an access
    /// past the end is an error, not a panic. (Not tested: a device buffer that is not
    /// host-visible; lavapipe maps all its memory.)
    #[test]
    fn mapped_reads_and_writes_are_typed_and_checked() {
        let ctx = crate::gpu::testing::gpu();
        let mut upload = Buffer::new(&ctx, "typed", 64, Residency::Upload).unwrap();
        upload.write_mapped(0, &[[1.0f32, 2.0]]).unwrap();
        upload.write_mapped(3, &[7u32, 8]).unwrap();
        assert_eq!(upload.read_mapped::<u32>(3, 2).unwrap(), [7, 8]);
        assert_eq!(upload.read_mapped::<f32>(0, 2).unwrap(), [1.0, 2.0]);
        assert_eq!(upload.read_mapped_all::<[u32; 4]>().unwrap().len(), 4);
        let past = upload.write_mapped(15, &[1u32, 2]).unwrap_err().to_string();
        assert!(past.contains("bytes 60..68 of a buffer of 64"), "{past}");
        assert!(upload.read_mapped::<u64>(8, 1).is_err());
        drop(upload);
        crate::gpu::testing::finish(ctx);
    }
}
