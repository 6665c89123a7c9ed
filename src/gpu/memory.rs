//! Buffers: vertex data, uniforms, staging for uploads and readback.
//! Memory comes from gpu-allocator; a `Buffer` frees it and destroys itself on drop.

use std::sync::Arc;

use ash::vk;
use gpu_allocator::MemoryLocation;
use gpu_allocator::vulkan::{Allocation, AllocationCreateDesc, AllocationScheme};

use super::context::{Context, Device};

use super::error::{GpuError, Result, VkContext};

/// A host-visible buffer (vertex data, uniforms, staging). lavapipe's memory is all
/// host-visible; on a discrete GPU these live in mappable memory, which is what the
/// texture-era code did with its vertex arrays too.
pub struct Buffer {
    dev: Arc<Device>,
    pub(crate) raw: vk::Buffer,
    allocation: Option<Allocation>,
    size: u64,
}

impl Buffer {
    pub(crate) fn new(
        dev: &Arc<Device>,
        size: u64,
        usage: vk::BufferUsageFlags,
        location: MemoryLocation,
        name: &str,
    ) -> Result<Buffer> {
        let dev = dev.clone();
        let size = size.max(4);
        let info =
            vk::BufferCreateInfo::default().size(size).usage(usage).sharing_mode(vk::SharingMode::EXCLUSIVE);
        // SAFETY: valid device and create info.
        let raw = unsafe { dev.raw.create_buffer(&info, None) }.vk("vkCreateBuffer")?;
        // SAFETY: `raw` was just created.
        let requirements = unsafe { dev.raw.get_buffer_memory_requirements(raw) };
        let mut buffer = Buffer { dev, raw, allocation: None, size };
        // From here on `buffer`'s Drop cleans up whatever was created if a step fails (the
        // same guard as a texture's).
        let allocation =
            super::error::lock(&buffer.dev.allocator, "allocator")?.allocate(&AllocationCreateDesc {
                name,
                requirements,
                location,
                linear: true,
                allocation_scheme: AllocationScheme::GpuAllocatorManaged,
            })?;
        let a = buffer.allocation.insert(allocation);
        // SAFETY: memory and offset come from the allocator for this buffer's requirements.
        unsafe { buffer.dev.raw.bind_buffer_memory(raw, a.memory(), a.offset()) }.vk("vkBindBufferMemory")?;
        Ok(buffer)
    }

    /// A buffer holding `data`, usable as vertex input, index list, uniform block and copy source.
    pub fn with_data<T: Pod>(ctx: &Context, data: &[T], name: &str) -> Result<Buffer> {
        let bytes = as_bytes(data);
        let mut b =
            Buffer::new(&ctx.dev, bytes.len() as u64, Self::HOST_USAGE, MemoryLocation::CpuToGpu, name)?;
        b.write(0, bytes)?;
        Ok(b)
    }

    /// A buffer of `size` bytes the GPU copies into and the host reads (see
    /// `Recorder::readback_into`).
    pub fn readback_for(ctx: &Context, size: u64) -> Result<Buffer> {
        Buffer::readback(&ctx.dev, size)
    }

    pub(crate) fn readback(dev: &Arc<Device>, size: u64) -> Result<Buffer> {
        Buffer::new(dev, size, vk::BufferUsageFlags::TRANSFER_DST, MemoryLocation::GpuToCpu, "readback")
    }

    /// A host-writable buffer of `size` bytes (vertex data or uniforms rewritten between submits).
    pub fn host(ctx: &Context, size: u64, name: &str) -> Result<Buffer> {
        Buffer::new(&ctx.dev, size, Self::HOST_USAGE, MemoryLocation::CpuToGpu, name)
    }

    const HOST_USAGE: vk::BufferUsageFlags = vk::BufferUsageFlags::from_raw(
        vk::BufferUsageFlags::VERTEX_BUFFER.as_raw()
            | vk::BufferUsageFlags::INDEX_BUFFER.as_raw()
            | vk::BufferUsageFlags::UNIFORM_BUFFER.as_raw()
            | vk::BufferUsageFlags::TRANSFER_SRC.as_raw(),
    );

    pub fn size(&self) -> u64 {
        self.size
    }

    /// Copies `bytes` into the buffer at `offset` (host-visible memory, no submit needed;
    /// host writes before a submission are visible to it).
    pub fn write(&mut self, offset: u64, bytes: &[u8]) -> Result<()> {
        let size = self.size;
        let slice = self
            .allocation
            .as_mut()
            .and_then(|a| a.mapped_slice_mut())
            .ok_or(GpuError::Internal("buffer memory is not host-visible"))?;
        let start = offset as usize;
        let end = start.checked_add(bytes.len()).filter(|&e| e as u64 <= size).ok_or_else(|| {
            GpuError::Usage(format!(
                "write of {} bytes at {offset} overflows a {size}-byte buffer",
                bytes.len()
            ))
        })?;
        slice[start..end].copy_from_slice(bytes);
        Ok(())
    }

    /// Copies `data` into the buffer at element `offset` (in units of `T`).
    pub fn write_slice<T: Pod>(&mut self, offset: usize, data: &[T]) -> Result<()> {
        self.write((offset * std::mem::size_of::<T>()) as u64, as_bytes(data))
    }

    /// The buffer's contents as values (after the submission that filled it has completed).
    pub fn to_vec<T: Pod>(&self) -> Result<Vec<T>> {
        Ok(from_bytes(self.bytes()?))
    }

    /// The buffer's contents viewed as values without copying (after the submission that
    /// filled it has completed); a trailing partial value is left out.
    pub fn view<T: Pod>(&self) -> Result<&[T]> {
        let bytes = self.bytes()?;
        if bytes.as_ptr().align_offset(std::mem::align_of::<T>()) != 0 {
            return Err(GpuError::Internal("mapped buffer memory is not aligned for this type"));
        }
        let n = bytes.len() / std::mem::size_of::<T>();
        // SAFETY: aligned (checked), `n` values lie inside the mapped bytes, Pod accepts any
        // bit pattern, and the borrow of `self` keeps the mapping alive.
        Ok(unsafe { std::slice::from_raw_parts(bytes.as_ptr() as *const T, n) })
    }

    /// The buffer's bytes (after the submission that filled it has completed).
    pub fn bytes(&self) -> Result<&[u8]> {
        let size = self.size as usize;
        self.allocation
            .as_ref()
            .and_then(|a| a.mapped_slice())
            .map(|s| &s[..size.min(s.len())])
            .ok_or(GpuError::Internal("buffer memory is not host-visible"))
    }
}

impl Drop for Buffer {
    fn drop(&mut self) {
        if let Some(a) = self.allocation.take() {
            self.dev.free(a, "a buffer");
        }
        // SAFETY: submissions wait for completion, so the buffer is idle.
        unsafe { self.dev.raw.destroy_buffer(self.raw, None) };
    }
}

/// Plain old data: types whose every byte is initialized and every bit pattern valid,
/// so slices of them can be uploaded and read back as raw bytes.
///
/// # Safety
/// Implement only for types without padding, pointers or invalid bit patterns.
pub unsafe trait Pod: Copy + Default + 'static {}

// SAFETY: primitive numbers and arrays of them have no padding and no invalid patterns.
unsafe impl Pod for f32 {}
unsafe impl Pod for u32 {}
unsafe impl Pod for i32 {}
unsafe impl Pod for u16 {}
unsafe impl Pod for u8 {}
unsafe impl<T: Pod, const N: usize> Pod for [T; N] where [T; N]: Default {}

/// The bytes of a slice of plain-old-data values.
pub fn as_bytes<T: Pod>(data: &[T]) -> &[u8] {
    // SAFETY: Pod guarantees every byte is initialized; the length covers exactly the data.
    unsafe { std::slice::from_raw_parts(data.as_ptr() as *const u8, std::mem::size_of_val(data)) }
}

/// Copies bytes into a vector of plain-old-data values (any trailing partial value is dropped).
pub fn from_bytes<T: Pod>(bytes: &[u8]) -> Vec<T> {
    let n = bytes.len() / std::mem::size_of::<T>();
    let mut out = vec![T::default(); n];
    // SAFETY: Pod accepts any bit pattern; the destination holds exactly n values.
    unsafe {
        std::ptr::copy_nonoverlapping(
            bytes.as_ptr(),
            out.as_mut_ptr() as *mut u8,
            n * std::mem::size_of::<T>(),
        )
    };
    out
}
