//! Frames in flight (windowed mode only): the per-frame loop of acquire,
//! record, submit and present, and the fences and semaphores that order it.
//!
//! The CPU may prepare frame N+1 while the GPU still draws frame N, so each
//! frame "slot" has its own command buffer, its own timestamp queries and its
//! own synchronisation, and there are two slots:
//!
//! - an **in-flight fence** (GPU → CPU): the CPU waits on it before reusing the
//!   slot's command buffer; created signalled so the first wait passes;
//! - an **image-available semaphore** (presentation → GPU): signalled when the
//!   acquired swapchain image may be written; the submit waits on it at the
//!   stage of the image's first access (`Draw::first_image_access`,
//!   barrier.rs's `acquire_wait_stage`): the colour-output stage on the
//!   fragment path, which lets the fragment shader trace before the image is
//!   acquired; the blit on the compute path, which in Vulkan 1.0 is every
//!   transfer, so the dispatch, after the frame's uniform update and (through
//!   the storage image's transition) the previous frame's blit, waits for the
//!   acquire too. With `--vk-sync2` the wait is at the blit alone
//!   (docs/vulkan-walkthrough.md, step 22);
//! - the swapchain's per-image **render-finished semaphore** (GPU → presentation).
//!
//! Command buffers are **re-recorded every frame**, not pre-recorded once per
//! swapchain image: the camera moves (its uniform block is written inside the
//! command buffer with vkCmdUpdateBuffer), the framebuffer depends on which
//! image was acquired, and resizes and scene switches would invalidate
//! pre-recorded buffers anyway. Recording a dozen commands costs microseconds
//! beside a traced frame, and it is what the OpenGL driver does for every frame
//! too, so the two windowed loops do the same per-frame work.
//!
//! The two paths share everything here but the middle of the command buffer
//! ([`Draw`]): the fragment path runs a render pass into the swapchain image's
//! framebuffer; the compute path dispatches into its storage image and blits
//! that into the swapchain image (compute.rs, `WindowCompute::record`), with
//! the layout transitions a render pass would otherwise make.

use crate::barrier::{self, Access, Barrier, Recording};
use crate::compute::WindowCompute;
use crate::device::Device;
use crate::hooks::ForcedOutOfDate;
use crate::pipeline_barrier::{self, On};
use crate::scene::SceneResources;
use crate::swapchain::Swapchain;
use crate::timestamps::Timestamps;
use anyhow::{Context, Result};
use ash::{khr, vk};
use twinray_common::explain;
use twinray_common::gpu::layout::GpuFrame;

/// Two: the CPU records one frame while the GPU draws the other. More would
/// only add latency, since the GPU (the tracer) is the bottleneck.
pub const FRAMES_IN_FLIGHT: usize = 2;

struct Slot {
    cmd: vk::CommandBuffer,
    image_available: vk::Semaphore,
    in_flight: vk::Fence,
    timestamps: Option<Timestamps>,
    /// Whether this slot's queries hold a finished frame's times.
    submitted: bool,
}

pub enum FrameResult {
    /// Drawn and queued for presentation; the GPU time is that of the slot's
    /// previous frame (the newest one known to be finished).
    Presented {
        gpu_ms: Option<f64>,
        suboptimal: bool,
    },
    /// The swapchain no longer matches the window: rebuild it, draw nothing.
    OutOfDate,
}

/// What a frame draws with: the path and its per-scene objects.
#[derive(Clone, Copy)]
pub enum Draw<'a> {
    Fragment {
        render_pass: vk::RenderPass,
        scene: &'a SceneResources,
    },
    Compute(&'a WindowCompute),
}

impl Draw<'_> {
    /// The `Frame` uniform buffer the tracer reads.
    fn uniform(self) -> vk::Buffer {
        match self {
            Draw::Fragment { scene, .. } => scene.frame.buffer,
            Draw::Compute(c) => c.frame.buffer,
        }
    }

    /// The barrier from the uniform write to the tracer that reads it.
    fn uniform_to_tracer(self) -> Barrier {
        match self {
            Draw::Fragment { .. } => barrier::UNIFORM_TO_FRAGMENT,
            Draw::Compute(_) => barrier::UNIFORM_TO_COMPUTE,
        }
    }

    /// The first access to the acquired image: the submit waits for the image
    /// at its stage (barrier.rs, `acquire_wait_stage`).
    fn first_image_access(self) -> Access {
        match self {
            Draw::Fragment { .. } => Access::ColorAttachmentWrite,
            Draw::Compute(_) => Access::BlitWrite,
        }
    }
}

pub struct Frames {
    device: ash::Device,
    pool: vk::CommandPool,
    slots: Vec<Slot>,
    next: usize,
    /// `TWINRAY_TEST_OUT_OF_DATE` (hooks.rs): acquires that report out of date.
    forced_out_of_date: ForcedOutOfDate,
}

impl Frames {
    pub fn new(device: &Device) -> Result<Frames> {
        let d = &device.device;
        // RESET_COMMAND_BUFFER: each buffer is reset and re-recorded every frame.
        let info = vk::CommandPoolCreateInfo::default()
            .queue_family_index(device.queue_family)
            .flags(vk::CommandPoolCreateFlags::RESET_COMMAND_BUFFER);
        // SAFETY: a create on the live device; `this` (Frames) destroys the pool on drop, after
        // waiting for the GPU.
        let pool = unsafe { d.create_command_pool(&info, None) }
            .context("creating the frame command pool")?;
        let mut this = Frames {
            device: d.clone(),
            pool,
            slots: Vec::new(),
            next: 0,
            forced_out_of_date: ForcedOutOfDate::from_env()?,
        };
        let info = vk::CommandBufferAllocateInfo::default()
            .command_pool(pool)
            .level(vk::CommandBufferLevel::PRIMARY)
            .command_buffer_count(FRAMES_IN_FLIGHT as u32);
        // SAFETY: the pool was made just above and is owned by `this`; only this thread records
        // from it.
        let cmds = unsafe { d.allocate_command_buffers(&info) }
            .context("allocating the frame command buffers")?;
        for cmd in cmds {
            // SAFETY: a create on the live device; the slot pushed below owns it, and Frames::drop
            // destroys it after waiting for the GPU.
            let image_available =
                unsafe { d.create_semaphore(&vk::SemaphoreCreateInfo::default(), None) }
                    .context("creating an image-available semaphore")?;
            let signalled = vk::FenceCreateInfo::default().flags(vk::FenceCreateFlags::SIGNALED);
            // SAFETY: as for the semaphore.
            let in_flight = match unsafe { d.create_fence(&signalled, None) } {
                Ok(f) => f,
                Err(e) => {
                    // SAFETY: the semaphore was never used: no slot holds it yet.
                    unsafe { d.destroy_semaphore(image_available, None) };
                    return Err(e).context("creating an in-flight fence");
                }
            };
            this.slots.push(Slot {
                cmd,
                image_available,
                in_flight,
                timestamps: None,
                submitted: false,
            });
            let slot = this.slots.last_mut().expect("just pushed");
            slot.timestamps = Timestamps::new(device)?;
        }
        explain::numbered(16, "Frames in flight: VkCommandPool, then per frame a VkCommandBuffer, VkSemaphore, VkFence", || {
            format!(
                "{FRAMES_IN_FLIGHT} frames; pool flag RESET_COMMAND_BUFFER (re-recorded every frame);\n\
                 fences created SIGNALED so the first wait returns; image-available semaphores unsignalled"
            )
        });
        Ok(this)
    }

    /// One frame: wait for the slot, acquire an image, record, submit, present.
    pub fn draw(
        &mut self,
        device: &Device,
        loader: &khr::swapchain::Device,
        swapchain: &Swapchain,
        draw: Draw,
        frame: &GpuFrame,
    ) -> Result<FrameResult> {
        let d = &device.device;
        let slot = &mut self.slots[self.next];
        // SAFETY: the fence belongs to this device.
        unsafe { d.wait_for_fences(&[slot.in_flight], true, u64::MAX) }
            .context("waiting for a frame in flight")?;
        let gpu_ms = match (&slot.timestamps, slot.submitted) {
            (Some(t), true) => Some(t.read_ms()?),
            _ => None,
        };

        let acquired = if self.forced_out_of_date.this_acquire() {
            Err(vk::Result::ERROR_OUT_OF_DATE_KHR)
        } else {
            // SAFETY: the semaphore is unsignalled: its last signal was waited on by the slot's
            // last submit.
            unsafe {
                loader.acquire_next_image(
                    swapchain.swapchain,
                    u64::MAX,
                    slot.image_available,
                    vk::Fence::null(),
                )
            }
        };
        let (index, suboptimal) = match acquired {
            Ok(r) => r,
            Err(vk::Result::ERROR_OUT_OF_DATE_KHR) => return Ok(FrameResult::OutOfDate),
            Err(e) => return Err(e).context("acquiring a swapchain image"),
        };
        // Reset only now: had the acquire failed, a reset fence would never be signalled.
        // SAFETY: the fence is signalled (waited above), so no pending submission uses it.
        unsafe { d.reset_fences(&[slot.in_flight]) }.context("resetting a frame fence")?;

        record(device, slot, swapchain, index, draw, frame)?;

        let signals = [swapchain.render_finished[index as usize]];
        submit(device, slot, draw.first_image_access(), signals[0])?;
        slot.submitted = true;
        self.next = (self.next + 1) % FRAMES_IN_FLIGHT;

        let swapchains = [swapchain.swapchain];
        let indices = [index];
        let present = vk::PresentInfoKHR::default()
            .wait_semaphores(&signals)
            .swapchains(&swapchains)
            .image_indices(&indices);
        // SAFETY: `index` was acquired from this swapchain above and not yet presented; the submit
        // just made signals the semaphore the present waits on; the swapchain outlives the call
        // (borrowed).
        let presented = unsafe { loader.queue_present(device.queue, &present) };
        let suboptimal = suboptimal
            || match presented {
                Ok(s) => s,
                Err(vk::Result::ERROR_OUT_OF_DATE_KHR) => true,
                Err(e) => return Err(e).context("presenting a frame"),
            };
        Ok(FrameResult::Presented { gpu_ms, suboptimal })
    }
}

// vkCmdUpdateBuffer takes at most 65536 bytes, a multiple of 4: the `Frame`
// block is written that way every frame (and before a capture in window.rs).
const _: () = {
    let size = std::mem::size_of::<GpuFrame>();
    assert!(size % 4 == 0 && size <= 65536);
};

/// Submits the slot's frame: it waits for the acquired image at the stage of
/// `first` (the image's first access), signals `finished` for the present and
/// the slot's fence for the CPU. vkQueueSubmit2, with synchronization2, gives
/// each semaphore its own stage.
fn submit(device: &Device, slot: &Slot, first: Access, finished: vk::Semaphore) -> Result<()> {
    let d = &device.device;
    let cmds = [slot.cmd];
    let (waits, signals) = ([slot.image_available], [finished]);
    let submitted = match device.recording {
        Recording::Vulkan10 => {
            let wait_stages = [barrier::acquire_wait_stage_1_0(first)];
            let submit = vk::SubmitInfo::default()
                .wait_semaphores(&waits)
                .wait_dst_stage_mask(&wait_stages)
                .command_buffers(&cmds)
                .signal_semaphores(&signals);
            // SAFETY: the slot's buffer was recorded just before and its previous submission has
            // finished (its fence was waited on); the fence was reset; the wait semaphore has a
            // signal pending from this frame's acquire; the render-finished semaphore is that
            // image's, whose last signal the previous present of the image waited on; only this
            // thread uses the queue.
            unsafe { d.queue_submit(device.queue, &[submit], slot.in_flight) }
        }
        Recording::Synchronization2 => {
            let wait = [vk::SemaphoreSubmitInfo::default()
                .semaphore(waits[0])
                .stage_mask(barrier::acquire_wait_stage(first, device.recording))];
            let signal = [vk::SemaphoreSubmitInfo::default()
                .semaphore(signals[0])
                .stage_mask(barrier::SIGNAL_AFTER_ALL)];
            let buffers = [vk::CommandBufferSubmitInfo::default().command_buffer(slot.cmd)];
            let submit = vk::SubmitInfo2::default()
                .wait_semaphore_infos(&wait)
                .command_buffer_infos(&buffers)
                .signal_semaphore_infos(&signal);
            // SAFETY: as for vkQueueSubmit above; the device enabled synchronization2
            // (Device::new, for this recording).
            unsafe { d.queue_submit2(device.queue, &[submit], slot.in_flight) }
        }
    };
    submitted.context("submitting a frame")
}

/// The frame's commands, recorded afresh (see the module comment).
fn record(
    device: &Device,
    slot: &Slot,
    swapchain: &Swapchain,
    index: u32,
    draw: Draw,
    frame: &GpuFrame,
) -> Result<()> {
    let d = &device.device;
    let cmd = slot.cmd;
    // SAFETY: the pool was made with RESET_COMMAND_BUFFER, and the slot's fence has been waited on,
    // so the buffer is not pending.
    unsafe { d.reset_command_buffer(cmd, vk::CommandBufferResetFlags::empty()) }
        .context("resetting a command buffer")?;
    let begin =
        vk::CommandBufferBeginInfo::default().flags(vk::CommandBufferUsageFlags::ONE_TIME_SUBMIT);
    // SAFETY: the buffer was reset just above, so it is in the initial state.
    unsafe { d.begin_command_buffer(cmd, &begin) }.context("recording a frame")?;
    if let Some(t) = &slot.timestamps {
        t.record_reset(cmd);
        t.record(cmd, 0);
    }
    // One uniform buffer serves both frames in flight, so the write waits for
    // the previous frame's shaders to finish reading it (write after read: an
    // execution dependency is enough; both stages, as the previous frame may
    // have run the other path), and the tracer waits for the write.
    let uniform = [draw.uniform()];
    let after_reads = [(barrier::UNIFORM_AFTER_READS, On::Nothing)];
    let to_tracer = [(draw.uniform_to_tracer(), On::Buffers(&uniform))];
    // SAFETY: `cmd` began recording above; the uniform buffer belongs to the
    // scene resources in `draw`, which the window keeps until the GPU is idle;
    // `frame` fits vkCmdUpdateBuffer (asserted at compile time above).
    unsafe {
        pipeline_barrier::record(device, cmd, &after_reads);
        d.cmd_update_buffer(cmd, uniform[0], 0, bytemuck::bytes_of(frame));
        pipeline_barrier::record(device, cmd, &to_tracer);
    }
    match draw {
        Draw::Fragment { render_pass, scene } => {
            record_render_pass(d, cmd, swapchain, index, render_pass, scene)
        }
        Draw::Compute(compute) => compute.record(device, cmd, swapchain.images[index as usize]),
    }
    if let Some(t) = &slot.timestamps {
        t.record(cmd, 1);
    }
    // SAFETY: the buffer is recording (begun above), and every command above was recorded outside a
    // render pass or with the pass ended.
    unsafe { d.end_command_buffer(cmd) }.context("recording a frame")
}

/// The fragment path's part of the frame: the fullscreen triangle in the
/// render pass, whose layout transitions and dependencies take the acquired
/// image from UNDEFINED to PRESENT_SRC_KHR.
fn record_render_pass(
    d: &ash::Device,
    cmd: vk::CommandBuffer,
    swapchain: &Swapchain,
    index: u32,
    render_pass: vk::RenderPass,
    scene: &SceneResources,
) {
    let extent = swapchain.extent;
    let begin_pass = vk::RenderPassBeginInfo::default()
        .render_pass(render_pass)
        .framebuffer(swapchain.framebuffers[index as usize])
        .render_area(vk::Rect2D {
            offset: vk::Offset2D::default(),
            extent,
        });
    let (viewport, scissor) = crate::pipeline::whole(extent);
    // SAFETY: `cmd` is recording (record() began it); the render pass, the
    // framebuffer of image `index`, the pipeline and the set belong to the window,
    // its swapchain and `scene`, which the window replaces only after waiting
    // for the GPU; viewport and scissor are dynamic states of the windowed
    // pipeline (made without a fixed size).
    unsafe {
        d.cmd_begin_render_pass(cmd, &begin_pass, vk::SubpassContents::INLINE);
        d.cmd_set_viewport(cmd, 0, &[viewport]);
        d.cmd_set_scissor(cmd, 0, &[scissor]);
        d.cmd_bind_pipeline(
            cmd,
            vk::PipelineBindPoint::GRAPHICS,
            scene.pipeline.pipeline,
        );
        d.cmd_bind_descriptor_sets(
            cmd,
            vk::PipelineBindPoint::GRAPHICS,
            scene.pipeline.layout,
            0,
            &[scene.descriptors.set],
            &[],
        );
        d.cmd_draw(cmd, 3, 1, 0, 0);
        d.cmd_end_render_pass(cmd);
    }
}

impl Drop for Frames {
    fn drop(&mut self) {
        // SAFETY: after the wait no frame uses the semaphores, fences or command
        // buffers (the pool frees the buffers); all were made on this device. The
        // timestamp pools drop with the slots, after this.
        unsafe {
            let _ = self.device.device_wait_idle();
            for s in &self.slots {
                self.device.destroy_semaphore(s.image_available, None);
                self.device.destroy_fence(s.in_flight, None);
            }
            self.device.destroy_command_pool(self.pool, None);
        }
        explain::numbered(
            20,
            "Frames::drop: vkDeviceWaitIdle; per slot vkDestroySemaphore, vkDestroyFence; vkDestroyCommandPool",
            String::new,
        );
    }
}
