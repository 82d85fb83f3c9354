//! The frame's command buffer and its fence.
//!
//! Vulkan does nothing when the app "draws": commands are *recorded* into a
//! command buffer (allocated from a *pool*, which owns their memory), and the
//! GPU runs them only when the buffer is *submitted* to a queue. A *fence* is
//! how the CPU learns that a submission has finished.
//!
//! Every frame here is identical, so the buffer is recorded once and resubmitted.
//! That is deliberate, for a fair comparison with OpenGL: the per-frame CPU cost
//! measured is exactly submit + wait, the same loop the original study timed,
//! not the cost of re-recording (which real apps often do, and OpenGL cannot skip).

use crate::descriptors::Descriptors;
use crate::device::Device;
use crate::pipeline::Pipeline;
use crate::target::Target;
use crate::timestamps::Timestamps;
use anyhow::{Context, Result};
use ash::vk;
use twinray_common::explain;

pub struct Commands {
    device: ash::Device,
    queue: vk::Queue,
    pool: vk::CommandPool,
    cmd: vk::CommandBuffer,
    fence: vk::Fence,
}

impl Commands {
    /// The fragment path's frame: timestamps around one render pass that draws
    /// the fullscreen triangle.
    pub fn record(
        device: &Device,
        render_pass: vk::RenderPass,
        pipeline: &Pipeline,
        descriptors: &Descriptors,
        target: &Target,
        timestamps: Option<&Timestamps>,
    ) -> Result<Commands> {
        let extent = vk::Extent2D {
            width: target.width,
            height: target.height,
        };
        let (_, scissor) = crate::pipeline::whole(extent);
        let this = Commands::record_with(device, |d, cmd| {
            if let Some(t) = timestamps {
                t.record_reset(cmd);
                t.record(cmd, 0);
            }
            let begin = vk::RenderPassBeginInfo::default()
                .render_pass(render_pass)
                .framebuffer(target.framebuffer)
                .render_area(scissor);
            // SAFETY: every handle is alive and `cmd` is recording.
            unsafe {
                d.cmd_begin_render_pass(cmd, &begin, vk::SubpassContents::INLINE);
                d.cmd_bind_pipeline(cmd, vk::PipelineBindPoint::GRAPHICS, pipeline.pipeline);
                d.cmd_bind_descriptor_sets(
                    cmd,
                    vk::PipelineBindPoint::GRAPHICS,
                    pipeline.layout,
                    0,
                    &[descriptors.set],
                    &[],
                );
                // No vertex buffer: the vertex shader makes the fullscreen
                // triangle from the vertex index.
                d.cmd_draw(cmd, 3, 1, 0, 0);
                d.cmd_end_render_pass(cmd);
            }
            if let Some(t) = timestamps {
                t.record(cmd, 1);
            }
        })?;
        explain::numbered(
            11,
            "Command buffer recorded once (resubmitted every frame)",
            || {
                let ts = if timestamps.is_some() {
                    "reset queries, timestamp TOP_OF_PIPE, "
                } else {
                    ""
                };
                format!("{ts}begin render pass {}x{}, bind pipeline, bind descriptor set 0, draw 3 vertices, end pass{}",
                target.width, target.height, if timestamps.is_some() { ", timestamp BOTTOM_OF_PIPE" } else { "" })
            },
        );
        Ok(this)
    }

    /// The pool, the one command buffer and the fence, with the frame's
    /// commands written by `record` (the draw above, or the compute path's
    /// dispatch). No ONE_TIME_SUBMIT flag: the buffer is resubmitted every frame.
    pub fn record_with(
        device: &Device,
        record: impl FnOnce(&ash::Device, vk::CommandBuffer),
    ) -> Result<Commands> {
        let d = &device.device;
        let mut this = Commands {
            device: d.clone(),
            queue: device.queue,
            pool: vk::CommandPool::null(),
            cmd: vk::CommandBuffer::null(),
            fence: vk::Fence::null(),
        };
        let info = vk::CommandPoolCreateInfo::default().queue_family_index(device.queue_family);
        // SAFETY: `d` is the open device this Commands keeps a clone of; the create info is a local
        // that outlives the call.
        this.pool =
            unsafe { d.create_command_pool(&info, None) }.context("creating the command pool")?;
        let info = vk::CommandBufferAllocateInfo::default()
            .command_pool(this.pool)
            .level(vk::CommandBufferLevel::PRIMARY)
            .command_buffer_count(1);
        // SAFETY: the pool was created just above on `d` and is owned by `this`, which frees it on
        // drop.
        this.cmd = unsafe { d.allocate_command_buffers(&info) }
            .context("allocating the command buffer")?[0];
        // Unsignalled: the first wait is for the first frame.
        // SAFETY: a plain create on the live device `d`; `this` destroys the fence.
        this.fence = unsafe { d.create_fence(&vk::FenceCreateInfo::default(), None) }
            .context("creating the fence")?;
        explain::numbered(11, "VkCommandPool + VkCommandBuffer + VkFence", || {
            format!(
                "pool on queue family {}; 1 PRIMARY buffer; fence created unsignalled",
                device.queue_family
            )
        });
        // SAFETY: the buffer was just allocated, so it is in the initial state and nothing else
        // records into it; `record` then writes commands into it before it ends.
        unsafe { d.begin_command_buffer(this.cmd, &vk::CommandBufferBeginInfo::default()) }
            .context("recording the frame")?;
        record(d, this.cmd);
        // SAFETY: the buffer is recording (begun above).
        unsafe { d.end_command_buffer(this.cmd) }.context("recording the frame")?;
        Ok(this)
    }

    /// Hands the frame to the GPU; the fence signals when it is done.
    pub fn submit(&self) -> Result<()> {
        let cmds = [self.cmd];
        let submit = vk::SubmitInfo::default().command_buffers(&cmds);
        // SAFETY: the buffer is fully recorded and is not pending: every submit is followed by
        // `wait` and `reset_fence` before the next (app.rs's frame loop), so the fence is
        // unsignalled here, as vkQueueSubmit requires. Only this thread uses the queue.
        unsafe { self.device.queue_submit(self.queue, &[submit], self.fence) }
            .context("submitting a frame")
    }

    /// Blocks until the GPU has finished the frame. A fence waits for exactly
    /// this submission; `idle` instead waits as the 2018 study did
    /// (vkQueueWaitIdle + vkDeviceWaitIdle), kept to measure whether that costs.
    pub fn wait(&self, idle: bool) -> Result<()> {
        if idle {
            // SAFETY: a wait on the queue this Commands submits to; only this thread uses it.
            unsafe { self.device.queue_wait_idle(self.queue) }
                .context("waiting for the queue to idle")?;
            // SAFETY: a wait on the live device; no other thread submits to it.
            unsafe { self.device.device_wait_idle() }.context("waiting for the device to idle")?;
        }
        // SAFETY: the fence is alive (owned by self) and was submitted with the frame, so the wait
        // ends.
        unsafe { self.device.wait_for_fences(&[self.fence], true, u64::MAX) }
            .context("waiting for a frame")
    }

    /// A fence stays signalled until reset; the next submit needs it unsignalled.
    pub fn reset_fence(&self) -> Result<()> {
        // SAFETY: the fence is signalled and its submission has finished (`wait` returned), so no
        // pending queue operation uses it.
        unsafe { self.device.reset_fences(&[self.fence]) }.context("resetting the fence")
    }
}

impl Drop for Commands {
    fn drop(&mut self) {
        // This is the last object created, so it is dropped first. When the app
        // unwinds from an error the GPU may still be running a frame: wait for it
        // before anything the frame uses is destroyed.
        // SAFETY: after the wait no submission uses the fence or the command
        // buffer; the pool frees the buffer with it; both were made on `device`.
        unsafe {
            let _ = self.device.device_wait_idle();
            self.device.destroy_fence(self.fence, None);
            self.device.destroy_command_pool(self.pool, None);
        }
    }
}
