//! Memory and buffers, allocated by hand.
//!
//! Vulkan never allocates behind the app's back. A device offers a few memory
//! *types* (fast device-local memory, memory the CPU can map, cached or not);
//! each buffer or image reports which types it may live in, and the app picks one
//! with the properties it needs, allocates, and binds. (Large apps sub-allocate
//! from big blocks, e.g. with VMA; this app has seven allocations, so one each.)
//!
//! The GPU reads scene data fastest from device-local memory, which on a
//! discrete GPU the CPU cannot map. So scene buffers are filled by writing into a
//! host-visible *staging* buffer and letting the GPU copy it across.

use crate::device::Device;
use anyhow::{anyhow, Context, Result};
use ash::vk;
use ash::vk::MemoryPropertyFlags as Flags;
use twinray_common::explain;

/// Allocates memory for `needs` from the first allowed type that has every property
/// of the earliest wish it can meet (an empty wish accepts any allowed type).
/// Returns the memory and the chosen type's properties.
pub fn allocate(
    device: &Device,
    needs: vk::MemoryRequirements,
    wishes: &[Flags],
    what: &str,
) -> Result<(vk::DeviceMemory, Flags)> {
    let props = &device.memory_properties;
    let types = &props.memory_types[..props.memory_type_count as usize];
    // Bit i of memory_type_bits set = the resource may live in memory type i.
    let allowed = |i: usize| needs.memory_type_bits & (1 << i) != 0;
    let (index, flags) = wishes
        .iter()
        .find_map(|&wish| {
            (0..types.len())
                .find(|&i| allowed(i) && types[i].property_flags.contains(wish))
                .map(|i| (i, types[i].property_flags))
        })
        .ok_or_else(|| anyhow!("no memory type suits the {what} ({wishes:?})"))?;
    let info = vk::MemoryAllocateInfo::default()
        .allocation_size(needs.size)
        .memory_type_index(index as u32);
    let memory = unsafe { device.device.allocate_memory(&info, None) }
        .map_err(|e| too_large(e, needs.size, what))?;
    Ok((memory, flags))
}

/// A failed creation or allocation of `bytes` for `what`. Every buffer and image
/// size follows from --size or the scene, so a device that is out of memory for
/// one was given a job too large for it: bad input (exit 2), said so.
pub fn too_large(e: vk::Result, bytes: u64, what: &str) -> anyhow::Error {
    match e {
        vk::Result::ERROR_OUT_OF_DEVICE_MEMORY | vk::Result::ERROR_OUT_OF_HOST_MEMORY => {
            twinray_common::error::bad_input(format!(
                "this device cannot hold the {what} ({}, {e}): use a smaller --size or fewer primitives",
                twinray_common::limits::gib(bytes)
            ))
        }
        e => anyhow::Error::new(e).context(format!(
            "creating or allocating the {what} ({} KiB)",
            bytes.div_ceil(1024)
        )),
    }
}

/// A buffer and the memory behind it.
pub struct Buffer {
    device: ash::Device,
    pub buffer: vk::Buffer,
    memory: vk::DeviceMemory,
    pub size: u64,
    /// Host-visible but not coherent: CPU writes need a flush, CPU reads an invalidate.
    needs_flush: bool,
    /// The properties of the memory type it landed in.
    pub memory_flags: Flags,
}

impl Buffer {
    pub fn new(
        device: &Device,
        size: u64,
        usage: vk::BufferUsageFlags,
        wishes: &[Flags],
        what: &str,
    ) -> Result<Buffer> {
        // Destroy functions accept null handles, so a half-built Buffer drops cleanly.
        let mut b = Buffer {
            device: device.device.clone(),
            buffer: vk::Buffer::null(),
            memory: vk::DeviceMemory::null(),
            size,
            needs_flush: false,
            memory_flags: Flags::empty(),
        };
        let info = vk::BufferCreateInfo::default()
            .size(size)
            .usage(usage)
            .sharing_mode(vk::SharingMode::EXCLUSIVE);
        b.buffer =
            unsafe { b.device.create_buffer(&info, None) }.map_err(|e| too_large(e, size, what))?;
        let needs = unsafe { b.device.get_buffer_memory_requirements(b.buffer) };
        let (memory, flags) = allocate(device, needs, wishes, what)?;
        b.memory = memory;
        b.memory_flags = flags;
        b.needs_flush =
            flags.contains(Flags::HOST_VISIBLE) && !flags.contains(Flags::HOST_COHERENT);
        unsafe { b.device.bind_buffer_memory(b.buffer, b.memory, 0) }
            .with_context(|| format!("binding the {what}"))?;
        Ok(b)
    }

    /// A buffer in host-visible, coherent memory (system RAM on a discrete GPU),
    /// written directly by the CPU: what a naive app does. The GPU then reads the
    /// scene across the bus on every access; `--vk-memory host` (TWINRAY_VK_MEMORY=host) selects it
    /// to measure that cost.
    pub fn host_visible_with(
        device: &Device,
        bytes: &[u8],
        usage: vk::BufferUsageFlags,
        what: &str,
    ) -> Result<Buffer> {
        let wishes = [
            Flags::HOST_VISIBLE | Flags::HOST_COHERENT,
            Flags::HOST_VISIBLE,
        ];
        let buffer = Buffer::new(device, bytes.len() as u64, usage, &wishes, what)?;
        buffer.write(bytes)?;
        Ok(buffer)
    }

    /// A device-local buffer holding `bytes`, filled through a staging buffer.
    pub fn device_local_with(
        device: &Device,
        bytes: &[u8],
        usage: vk::BufferUsageFlags,
        what: &str,
    ) -> Result<Buffer> {
        let size = bytes.len() as u64;
        // Coherent memory needs no flush after writing, but any mappable type will do.
        let upload = [
            Flags::HOST_VISIBLE | Flags::HOST_COHERENT,
            Flags::HOST_VISIBLE,
        ];
        let staging = Buffer::new(
            device,
            size,
            vk::BufferUsageFlags::TRANSFER_SRC,
            &upload,
            &format!("staging buffer for {what}"),
        )?;
        staging.write(bytes)?;
        let usage = usage | vk::BufferUsageFlags::TRANSFER_DST;
        let buffer = Buffer::new(
            device,
            size,
            usage,
            &[Flags::DEVICE_LOCAL, Flags::empty()],
            what,
        )?;
        device.run_once(&format!("uploading the {what}"), |cmd| {
            let region = vk::BufferCopy::default().size(size);
            // The barrier makes the copied bytes visible to the fragment (or compute) shader of
            // every later submission: queue order alone does not order memory.
            let barrier = vk::BufferMemoryBarrier::default()
                .src_access_mask(vk::AccessFlags::TRANSFER_WRITE)
                .dst_access_mask(vk::AccessFlags::UNIFORM_READ | vk::AccessFlags::SHADER_READ)
                .src_queue_family_index(vk::QUEUE_FAMILY_IGNORED)
                .dst_queue_family_index(vk::QUEUE_FAMILY_IGNORED)
                .buffer(buffer.buffer)
                .size(vk::WHOLE_SIZE);
            unsafe {
                device
                    .device
                    .cmd_copy_buffer(cmd, staging.buffer, buffer.buffer, &[region]);
                device.device.cmd_pipeline_barrier(
                    cmd,
                    vk::PipelineStageFlags::TRANSFER,
                    vk::PipelineStageFlags::FRAGMENT_SHADER
                        | vk::PipelineStageFlags::COMPUTE_SHADER,
                    vk::DependencyFlags::empty(),
                    &[],
                    &[barrier],
                    &[],
                );
            }
        })?;
        explain::step(&format!("VkBuffer + VkDeviceMemory: {what}"), || {
            format!(
                "{size} bytes, usage {usage:?}, memory {:?}\nfilled from a HOST_VISIBLE staging buffer: vkCmdCopyBuffer, then a TRANSFER -> FRAGMENT_SHADER barrier",
                buffer.memory_flags
            )
        });
        Ok(buffer) // `staging` is dropped here: the copy has finished.
    }

    /// Copies `bytes` into a host-visible buffer.
    pub fn write(&self, bytes: &[u8]) -> Result<()> {
        let d = &self.device;
        let ptr =
            unsafe { d.map_memory(self.memory, 0, vk::WHOLE_SIZE, vk::MemoryMapFlags::empty()) }
                .context("mapping memory")?;
        // SAFETY: the mapping covers the whole buffer, which is bytes.len() long.
        unsafe { std::ptr::copy_nonoverlapping(bytes.as_ptr(), ptr.cast::<u8>(), bytes.len()) };
        let range = vk::MappedMemoryRange::default()
            .memory(self.memory)
            .size(vk::WHOLE_SIZE);
        let flushed = if self.needs_flush {
            unsafe { d.flush_mapped_memory_ranges(&[range]) }
        } else {
            Ok(())
        };
        unsafe { d.unmap_memory(self.memory) };
        flushed.context("flushing mapped memory")
    }

    /// Copies a host-visible buffer's contents out, as `T`s. (Copied rather than
    /// cast in place: the mapping is aligned, a Vec<u8> copy of it need not be.)
    pub fn read<T: bytemuck::Pod>(&self) -> Result<Vec<T>> {
        let d = &self.device;
        let ptr =
            unsafe { d.map_memory(self.memory, 0, vk::WHOLE_SIZE, vk::MemoryMapFlags::empty()) }
                .context("mapping memory")?;
        let range = vk::MappedMemoryRange::default()
            .memory(self.memory)
            .size(vk::WHOLE_SIZE);
        let fresh = if self.needs_flush {
            unsafe { d.invalidate_mapped_memory_ranges(&[range]) }
        } else {
            Ok(())
        };
        // SAFETY: the mapping covers the whole buffer, `size` bytes.
        let bytes = unsafe { std::slice::from_raw_parts(ptr.cast::<u8>(), self.size as usize) };
        let data = bytemuck::pod_collect_to_vec(bytes);
        unsafe { d.unmap_memory(self.memory) };
        fresh.context("invalidating mapped memory")?;
        Ok(data)
    }
}

impl Drop for Buffer {
    fn drop(&mut self) {
        // SAFETY: the GPU has finished with the buffer (see Commands::drop).
        unsafe {
            self.device.destroy_buffer(self.buffer, None);
            self.device.free_memory(self.memory, None);
        }
    }
}
