//! Memory and buffers, allocated by hand.
//!
//! Vulkan never allocates behind the app's back. A device offers a few memory
//! *types* (fast device-local memory, memory the CPU can map, cached or not);
//! each buffer or image reports which types it may live in, and the app picks one
//! with the properties it needs, allocates, and binds. (Large apps sub-allocate
//! from big blocks, e.g. with VMA; this app has seven allocations, so one each.)
//!
//! The GPU reads scene data fastest from device-local memory, which the CPU may
//! or may not be able to map: an integrated GPU's is, a discrete GPU's only
//! through a 256 MiB window or with Resizable BAR. So that one code path works
//! on every device, scene buffers are filled by writing into a host-visible
//! *staging* buffer and letting the GPU copy it across.

use crate::barrier;
use crate::device::Device;
use crate::pipeline_barrier::{self, On};
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
    // SAFETY: `index` is a memory type of this device that `needs` allows, and the size is what the
    // resource asked for; the caller stores the memory in the object that frees it.
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
        // SAFETY: a create on the live device from a local info; `b` destroys the buffer on drop,
        // on success or error.
        b.buffer =
            unsafe { b.device.create_buffer(&info, None) }.map_err(|e| too_large(e, size, what))?;
        // SAFETY: a query on the buffer just made.
        let needs = unsafe { b.device.get_buffer_memory_requirements(b.buffer) };
        let (memory, flags) = allocate(device, needs, wishes, what)?;
        b.memory = memory;
        b.memory_flags = flags;
        b.needs_flush =
            flags.contains(Flags::HOST_VISIBLE) && !flags.contains(Flags::HOST_COHERENT);
        // SAFETY: the buffer has no memory yet; the allocation was sized from its requirements and
        // of a type they allow; offset 0 meets any alignment.
        unsafe { b.device.bind_buffer_memory(b.buffer, b.memory, 0) }
            .with_context(|| format!("binding the {what}"))?;
        Ok(b)
    }

    /// A buffer in host-visible, coherent memory (system RAM on a discrete GPU),
    /// written directly by the CPU: what a naive app does. The GPU then reads the
    /// scene across the bus on every access; `--vk-memory host` (TWINRAY_VK_MEMORY=host) selects it
    /// to measure that cost.
    pub fn host_visible(
        device: &Device,
        size: usize,
        usage: vk::BufferUsageFlags,
        what: &str,
    ) -> Result<Buffer> {
        Buffer::new(device, size as u64, usage, &UPLOAD, what)
    }

    /// A host-visible buffer holding `bytes`.
    pub fn host_visible_with(
        device: &Device,
        bytes: &[u8],
        usage: vk::BufferUsageFlags,
        what: &str,
    ) -> Result<Buffer> {
        let buffer = Buffer::host_visible(device, bytes.len(), usage, what)?;
        buffer.write(bytes)?;
        Ok(buffer)
    }

    /// Copies `bytes` into a host-visible buffer.
    pub fn write(&self, bytes: &[u8]) -> Result<()> {
        self.fill(bytes.len(), |mapped| mapped.copy_from_slice(bytes))
    }

    /// Lets `write` fill the first `len` bytes of a host-visible buffer in
    /// place, through a mapping: the bytes are made where the GPU or the copy
    /// reads them, with no copy of them in between.
    pub fn fill(&self, len: usize, write: impl FnOnce(&mut [u8])) -> Result<()> {
        self.check_mappable(len as u64)?;
        let d = &self.device;
        // SAFETY: the memory is host-visible and not mapped (every map here is
        // undone before its function returns); only this thread maps it, and no
        // pending GPU work uses it: a staging or host buffer is written before
        // any submission that reads it, and a staging buffer again only after
        // the copy that read it has been waited for.
        let ptr =
            unsafe { d.map_memory(self.memory, 0, vk::WHOLE_SIZE, vk::MemoryMapFlags::empty()) }
                .context("mapping memory")?;
        // SAFETY: the mapping covers the whole allocation, at least `size` bytes,
        // and check_mappable made sure `len` is no more; nothing else refers to
        // the mapping while `write` runs.
        write(unsafe { std::slice::from_raw_parts_mut(ptr.cast::<u8>(), len) });
        let range = vk::MappedMemoryRange::default()
            .memory(self.memory)
            .size(vk::WHOLE_SIZE);
        let flushed = if self.needs_flush {
            // SAFETY: the range is the whole of this memory, which is mapped.
            unsafe { d.flush_mapped_memory_ranges(&[range]) }
        } else {
            Ok(())
        };
        // SAFETY: mapped above; `write` has returned and kept no reference.
        unsafe { d.unmap_memory(self.memory) };
        flushed.context("flushing mapped memory")
    }

    /// Copies a host-visible buffer's contents out, as `T`s. (Copied rather than
    /// cast in place: the mapping is aligned, a `Vec<u8>` copy of it need not be.)
    pub fn read<T: bytemuck::Pod>(&self) -> Result<Vec<T>> {
        self.check_mappable(self.size)?;
        let d = &self.device;
        // SAFETY: the memory is host-visible and not mapped; the GPU's writes
        // to it have finished (the caller waited for the copy and its HOST
        // barrier); only this thread uses it.
        let ptr =
            unsafe { d.map_memory(self.memory, 0, vk::WHOLE_SIZE, vk::MemoryMapFlags::empty()) }
                .context("mapping memory")?;
        let range = vk::MappedMemoryRange::default()
            .memory(self.memory)
            .size(vk::WHOLE_SIZE);
        let fresh = if self.needs_flush {
            // SAFETY: the range is the whole of this memory, which is mapped.
            unsafe { d.invalidate_mapped_memory_ranges(&[range]) }
        } else {
            Ok(())
        };
        // SAFETY: the mapping covers the whole allocation, at least `size` bytes,
        // stays mapped until after the copy below, and nothing writes it meanwhile.
        let bytes = unsafe { std::slice::from_raw_parts(ptr.cast::<u8>(), self.size as usize) };
        let data = bytemuck::pod_collect_to_vec(bytes);
        // SAFETY: mapped above; `bytes` is not used after this.
        unsafe { d.unmap_memory(self.memory) };
        fresh.context("invalidating mapped memory")?;
        Ok(data)
    }
}

/// Device-local buffers filled through one small staging buffer: each
/// [`Uploads::add`] makes a buffer and fills it a chunk at a time (the CPU
/// writes a chunk into the staging buffer, the GPU copies it across, and the
/// CPU waits before writing the next), so that a scene of any size needs only
/// a few tens of MiB of host-visible memory. [`Uploads::finish`] records one
/// barrier for them all and hands the buffers over; until then they are only
/// reachable here, so nothing can use one before its copies have run.
pub struct Uploads<'a> {
    device: &'a Device,
    staging: Buffer,
    /// Filled, but not yet made visible to the shaders.
    filled: Vec<Buffer>,
}

/// Coherent memory needs no flush after writing, but any mappable type will do.
const UPLOAD: [Flags; 2] = [
    Flags::from_raw(Flags::HOST_VISIBLE.as_raw() | Flags::HOST_COHERENT.as_raw()),
    Flags::HOST_VISIBLE,
];

impl<'a> Uploads<'a> {
    /// Uploads whose chunks are at most `chunk` bytes long.
    pub fn new(device: &'a Device, chunk: u64) -> Result<Uploads<'a>> {
        let usage = vk::BufferUsageFlags::TRANSFER_SRC;
        let staging = Buffer::new(device, chunk, usage, &UPLOAD, "staging buffer")?;
        Ok(Uploads {
            device,
            staging,
            filled: Vec::new(),
        })
    }

    /// A device-local buffer of `size` bytes, filled in `chunks` (byte ranges
    /// of at most the staging buffer's size): `write(offset, bytes)` writes
    /// the contents from `offset` into `bytes`, which is the staging buffer.
    pub fn add(
        &mut self,
        size: usize,
        (usage, what): (vk::BufferUsageFlags, &str),
        chunks: &[std::ops::Range<usize>],
        write: impl Fn(usize, &mut [u8]),
    ) -> Result<()> {
        let device = self.device;
        let d = &device.device;
        let usage = usage | vk::BufferUsageFlags::TRANSFER_DST;
        let wishes = [Flags::DEVICE_LOCAL, Flags::empty()];
        let buffer = Buffer::new(device, size as u64, usage, &wishes, what)?;
        for chunk in chunks {
            let len = chunk.len();
            self.staging.fill(len, |bytes| write(chunk.start, bytes))?;
            device.run_once(&format!("uploading the {what}"), |cmd| {
                let region = vk::BufferCopy::default()
                    .dst_offset(chunk.start as u64)
                    .size(len as u64);
                // SAFETY: `cmd` is run_once's, recording; both buffers are alive
                // until run_once has waited for the queue; the region lies
                // within both (a chunk is at most the staging buffer's size and
                // lies within `size`).
                unsafe { d.cmd_copy_buffer(cmd, self.staging.buffer, buffer.buffer, &[region]) };
            })?;
        }
        explain::numbered(5, &format!("VkBuffer + VkDeviceMemory: {what}"), || {
            format!(
                "{size} bytes, usage {usage:?}, memory {:?}\nfilled through a {}-byte HOST_VISIBLE staging buffer: {} vkCmdCopyBuffer, then the one barrier of all uploads, printed when recorded",
                buffer.memory_flags,
                self.staging.size,
                chunks.len()
            )
        });
        self.filled.push(buffer);
        Ok(())
    }

    /// Makes every copy visible to the shaders (one barrier for all the
    /// buffers) and returns the buffers in the order they were added. The
    /// staging buffer goes: every copy from it has been waited for.
    pub fn finish(self) -> Result<Vec<Buffer>> {
        // Read after write: the fragment (or compute) shader of every later
        // submission reads what the copies wrote; queue order alone does not
        // order memory.
        let barrier = barrier::SCENE_UPLOAD;
        let buffers: Vec<vk::Buffer> = self.filled.iter().map(|b| b.buffer).collect();
        self.device.run_once("uploading the scene", |cmd| {
            // SAFETY: `cmd` is run_once's, recording; every buffer is in
            // `self.filled`, alive until run_once has waited for the queue.
            unsafe {
                pipeline_barrier::record(self.device, cmd, &[(barrier, On::Buffers(&buffers))])
            };
        })?;
        Ok(self.filled)
    }
}

impl Buffer {
    /// What map, write and read assume: host-visible memory holding `bytes`.
    fn check_mappable(&self, bytes: u64) -> Result<()> {
        if !self.memory_flags.contains(Flags::HOST_VISIBLE) || bytes > self.size {
            return Err(anyhow!(
                "mapping {bytes} bytes of a {}-byte buffer in {:?} memory",
                self.size,
                self.memory_flags
            ));
        }
        Ok(())
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
