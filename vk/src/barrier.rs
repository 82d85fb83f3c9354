//! Barriers as named accesses. This module owns every pipeline stage, access
//! mask and image layout that twinray-vk's synchronisation uses: the pipeline
//! barriers, the render pass's subpass dependencies, the stage at which a
//! frame's submit waits for its swapchain image, and the stages of the
//! timestamps. Everywhere else a barrier is named by what came before and what
//! comes after it ([`Access`]), as kajiya's `barrier.rs` names them over
//! `vk_sync::AccessType`; the masks follow from the names in one table,
//! [`Access::masks`]. (vk-sync-fork, the maintained vk-sync, fits ash 0.38 but
//! records Vulkan 1.0 barriers only, and knows no semaphore waits or
//! subpass dependencies: too little for one table, so this module is its own.)
//!
//! One source for three readers: the code records the [`Barrier`]s of [`ALL`]
//! (pipeline_barrier.rs), `--explain` prints each barrier from the very
//! structures handed to the driver, and docs/vulkan-walkthrough.md's barrier table is
//! checked against [`ALL`] by tests/tests/barriers.rs.
//!
//! The same names make two recordings ([`Recording`]): Vulkan 1.0's
//! vkCmdPipelineBarrier, one pair of stage masks for the whole call and
//! `TRANSFER` for every copy, blit and buffer update; and synchronization2's
//! vkCmdPipelineBarrier2 (Vulkan 1.3, `--vk-sync2`), where each barrier carries
//! its own stages and `TRANSFER` splits into `COPY`, `BLIT` and `CLEAR`.

use ash::vk;
use std::collections::BTreeSet;
use std::sync::Mutex;
use twinray_common::explain;

/// One access to a buffer or image, by a command or by the host: the words a
/// barrier is written in.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Access {
    /// No access: the start of a resource's life, whose contents may go.
    Nothing,
    /// The swapchain image's acquire. The submit waits for its semaphore at
    /// the stage of the image's first access ([`acquire_wait_stage`]), and a
    /// barrier after it starts at that same stage, so that the barrier's
    /// layout transition chains onto the wait.
    Acquire,
    /// `vkCmdCopyBuffer` or `vkCmdCopyImageToBuffer` reading its source.
    CopyRead,
    /// `vkCmdCopyBuffer` or `vkCmdCopyImageToBuffer` writing its destination.
    CopyWrite,
    /// `vkCmdUpdateBuffer`, which the specification counts among the clear commands.
    UpdateBufferWrite,
    /// `vkCmdBlitImage` reading its source.
    BlitRead,
    /// `vkCmdBlitImage` writing its destination.
    BlitWrite,
    /// The fragment shader reading uniform and storage buffers.
    FragmentShaderRead,
    /// The fragment shader writing a storage buffer (the ray counts).
    FragmentShaderWrite,
    /// The compute shader reading uniform and storage buffers.
    ComputeShaderRead,
    /// The compute shader writing a storage image (`imageStore`) or buffer.
    ComputeShaderWrite,
    /// The render pass writing its colour attachment.
    ColorAttachmentWrite,
    /// The CPU reading mapped memory.
    HostRead,
    /// The presentation engine reading the swapchain image.
    Present,
}

/// Which barrier calls the names are recorded with.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Recording {
    /// Vulkan 1.0: vkCmdPipelineBarrier and vkQueueSubmit.
    Vulkan10,
    /// Vulkan 1.3's synchronization2: vkCmdPipelineBarrier2 and vkQueueSubmit2.
    Synchronization2,
}

/// The masks and layout one access stands for, in one recording.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Masks {
    pub stages: vk::PipelineStageFlags2,
    pub access: vk::AccessFlags2,
    /// The layout an image must be in; `None` for an access twinray makes
    /// to buffers only.
    pub layout: Option<vk::ImageLayout>,
}

impl Masks {
    /// The masks as Vulkan 1.0 writes them.
    pub fn narrowed(&self) -> (vk::PipelineStageFlags, vk::AccessFlags) {
        (narrow_stages(self.stages), narrow_access(self.access))
    }
}

/// All of a colour image with one mip level and one layer: every image twinray
/// makes (targets, storage images, swapchain images), every view of one, and
/// so every image barrier.
pub const COLOR_IMAGE: vk::ImageSubresourceRange = vk::ImageSubresourceRange {
    aspect_mask: vk::ImageAspectFlags::COLOR,
    base_mip_level: 0,
    level_count: 1,
    base_array_layer: 0,
    layer_count: 1,
};

/// 1.0's flags are 2's low 32 bits, with the same meaning: the 1.0 recording
/// narrows them (every 1.0 mask of this table exists in 1.0).
fn narrow_stages(s: vk::PipelineStageFlags2) -> vk::PipelineStageFlags {
    vk::PipelineStageFlags::from_raw(s.as_raw() as u32)
}

fn narrow_access(a: vk::AccessFlags2) -> vk::AccessFlags {
    vk::AccessFlags::from_raw(a.as_raw() as u32)
}

impl Access {
    /// Every access, in the page's table's order.
    pub const EVERY: [Access; 14] = [
        Access::Nothing,
        Access::Acquire,
        Access::CopyRead,
        Access::CopyWrite,
        Access::UpdateBufferWrite,
        Access::BlitRead,
        Access::BlitWrite,
        Access::FragmentShaderRead,
        Access::FragmentShaderWrite,
        Access::ComputeShaderRead,
        Access::ComputeShaderWrite,
        Access::ColorAttachmentWrite,
        Access::HostRead,
        Access::Present,
    ];

    /// Whether the access writes: only writes need making available, so only
    /// they put access bits in a barrier's source mask.
    pub fn writes(self) -> bool {
        matches!(
            self,
            Access::CopyWrite
                | Access::UpdateBufferWrite
                | Access::BlitWrite
                | Access::FragmentShaderWrite
                | Access::ComputeShaderWrite
                | Access::ColorAttachmentWrite
        )
    }

    /// The table: the stage that performs the access, its access bits and the
    /// layout an image must be in for it. `Acquire` has no stage of its own
    /// (see [`Access::Acquire`]); the transfer commands differ only in
    /// synchronization2.
    pub fn masks(self, recording: Recording) -> Masks {
        use vk::AccessFlags2 as A;
        use vk::ImageLayout as L;
        use vk::PipelineStageFlags2 as S;
        let sync2 = recording == Recording::Synchronization2;
        let transfer = |stage2| if sync2 { stage2 } else { S::TRANSFER };
        // 1.0's SHADER_READ is 2's sampled and storage reads; twinray's shaders
        // read storage buffers only.
        let shader_read = A::UNIFORM_READ
            | if sync2 {
                A::SHADER_STORAGE_READ
            } else {
                A::SHADER_READ
            };
        let shader_write = if sync2 {
            A::SHADER_STORAGE_WRITE
        } else {
            A::SHADER_WRITE
        };
        // 1.0 has no NONE stage: an empty source is TOP_OF_PIPE, an empty destination BOTTOM_OF_PIPE.
        let (none_before, none_after) = if sync2 {
            (S::NONE, S::NONE)
        } else {
            (S::TOP_OF_PIPE, S::BOTTOM_OF_PIPE)
        };
        let (stages, access, layout) = match self {
            Access::Nothing => (none_before, A::NONE, Some(L::UNDEFINED)),
            Access::Acquire => (S::NONE, A::NONE, Some(L::UNDEFINED)),
            Access::CopyRead => (
                transfer(S::COPY),
                A::TRANSFER_READ,
                Some(L::TRANSFER_SRC_OPTIMAL),
            ),
            Access::CopyWrite => (
                transfer(S::COPY),
                A::TRANSFER_WRITE,
                Some(L::TRANSFER_DST_OPTIMAL),
            ),
            // The specification runs vkCmdUpdateBuffer in the CLEAR stage; the
            // validation layer of Debian 12 (1.3.239) still checks it at COPY,
            // where it ran before. Both are named until that layer is gone.
            Access::UpdateBufferWrite => (transfer(S::CLEAR | S::COPY), A::TRANSFER_WRITE, None),
            Access::BlitRead => (
                transfer(S::BLIT),
                A::TRANSFER_READ,
                Some(L::TRANSFER_SRC_OPTIMAL),
            ),
            Access::BlitWrite => (
                transfer(S::BLIT),
                A::TRANSFER_WRITE,
                Some(L::TRANSFER_DST_OPTIMAL),
            ),
            Access::FragmentShaderRead => (S::FRAGMENT_SHADER, shader_read, None),
            Access::FragmentShaderWrite => (S::FRAGMENT_SHADER, shader_write, None),
            Access::ComputeShaderRead => (S::COMPUTE_SHADER, shader_read, None),
            Access::ComputeShaderWrite => (S::COMPUTE_SHADER, shader_write, Some(L::GENERAL)),
            Access::ColorAttachmentWrite => (
                S::COLOR_ATTACHMENT_OUTPUT,
                A::COLOR_ATTACHMENT_WRITE,
                Some(L::COLOR_ATTACHMENT_OPTIMAL),
            ),
            Access::HostRead => (S::HOST, A::HOST_READ, None),
            Access::Present => (none_after, A::NONE, Some(L::PRESENT_SRC_KHR)),
        };
        Masks {
            stages,
            access,
            layout,
        }
    }
}

/// What a barrier guards: which kind of memory barrier it is recorded as.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Guards {
    /// Buffers: one buffer memory barrier each.
    Buffers,
    /// An image: one image memory barrier, with a layout transition.
    Image,
    /// An image whose old contents may go: the transition starts from `UNDEFINED`.
    ImageDiscarded,
    /// Nothing to flush (every access before it reads): an execution dependency only.
    Execution,
    /// A render pass's subpass dependency, declared when the pass is made.
    Subpass,
}

/// One barrier twinray records, by name: what came before, what comes after.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Barrier {
    /// What it is for, as `--explain` and the page's table call it.
    pub name: &'static str,
    /// The walkthrough step that teaches it.
    pub step: u32,
    pub before: &'static [Access],
    pub after: &'static [Access],
    pub guards: Guards,
}

use Access::*;

const fn barrier(
    name: &'static str,
    step: u32,
    before: &'static [Access],
    after: &'static [Access],
    guards: Guards,
) -> Barrier {
    Barrier {
        name,
        step,
        before,
        after,
        guards,
    }
}

/// The scene's copies, before any shader of a later submission reads the buffers.
pub const SCENE_UPLOAD: Barrier = barrier(
    "scene upload",
    5,
    &[CopyWrite],
    &[FragmentShaderRead, ComputeShaderRead],
    Guards::Buffers,
);
/// Into the headless render pass: this frame's colour writes after the last frame's.
pub const OFFSCREEN_PASS_IN: Barrier = barrier(
    "offscreen render pass in",
    7,
    &[ColorAttachmentWrite],
    &[ColorAttachmentWrite],
    Guards::Subpass,
);
/// Into the windowed render pass: the colour writes after the acquire.
pub const WINDOW_PASS_IN: Barrier = barrier(
    "window render pass in",
    7,
    &[Acquire],
    &[ColorAttachmentWrite],
    Guards::Subpass,
);
/// Out of the headless render pass: the readback copy reads what it wrote.
pub const OFFSCREEN_PASS_OUT: Barrier = barrier(
    "offscreen render pass out",
    7,
    &[ColorAttachmentWrite],
    &[CopyRead],
    Guards::Subpass,
);
/// The readback buffer, before the CPU maps it.
pub const READBACK: Barrier = barrier("readback", 9, &[CopyWrite], &[HostRead], Guards::Buffers);
/// The ray counts, before the CPU maps them.
pub const RAY_COUNTS: Barrier = barrier(
    "ray counts",
    11,
    &[FragmentShaderWrite, ComputeShaderWrite],
    &[HostRead],
    Guards::Buffers,
);
/// The frame's uniform write after the previous frame's reads (either path's).
pub const UNIFORM_AFTER_READS: Barrier = barrier(
    "uniform write after reads",
    15,
    &[FragmentShaderRead, ComputeShaderRead],
    &[UpdateBufferWrite],
    Guards::Execution,
);
/// The fragment shader reads the uniform block just written.
pub const UNIFORM_TO_FRAGMENT: Barrier = barrier(
    "uniform to fragment shader",
    15,
    &[UpdateBufferWrite],
    &[FragmentShaderRead],
    Guards::Buffers,
);
/// The window's screenshot: the uniform block written before a headless frame of either path.
pub const UNIFORM_TO_CAPTURE: Barrier = barrier(
    "uniform to capture",
    19,
    &[UpdateBufferWrite],
    &[FragmentShaderRead, ComputeShaderRead],
    Guards::Buffers,
);
/// The storage image, once, from nothing to the layout shaders write in.
pub const STORAGE_IMAGE_SETUP: Barrier = barrier(
    "storage image setup",
    21,
    &[Nothing],
    &[ComputeShaderWrite],
    Guards::ImageDiscarded,
);
/// A headless frame's imageStores after the previous frame's (write after write).
pub const FRAME_AFTER_FRAME: Barrier = barrier(
    "frame after frame",
    21,
    &[ComputeShaderWrite],
    &[ComputeShaderWrite],
    Guards::Image,
);
/// The headless readback copy reads what the last dispatch wrote.
pub const STORAGE_IMAGE_TO_COPY: Barrier = barrier(
    "storage image to copy",
    21,
    &[ComputeShaderWrite],
    &[CopyRead],
    Guards::Image,
);
/// The compute shader reads the uniform block just written (window).
pub const UNIFORM_TO_COMPUTE: Barrier = barrier(
    "uniform to compute shader",
    22,
    &[UpdateBufferWrite],
    &[ComputeShaderRead],
    Guards::Buffers,
);
/// The window's storage image: this frame's writes after the last frame's blit read it.
pub const STORAGE_IMAGE_AFTER_BLIT: Barrier = barrier(
    "storage image after blit",
    22,
    &[BlitRead],
    &[ComputeShaderWrite],
    Guards::ImageDiscarded,
);
/// The blit reads what the dispatch wrote.
pub const STORAGE_IMAGE_TO_BLIT: Barrier = barrier(
    "storage image to blit",
    22,
    &[ComputeShaderWrite],
    &[BlitRead],
    Guards::Image,
);
/// The acquired swapchain image, its old contents dropped, to be blitted into.
pub const SWAPCHAIN_TO_BLIT: Barrier = barrier(
    "swapchain image to blit",
    22,
    &[Acquire],
    &[BlitWrite],
    Guards::ImageDiscarded,
);
/// The swapchain image, blitted into, handed to presentation.
pub const SWAPCHAIN_TO_PRESENT: Barrier = barrier(
    "swapchain image to present",
    22,
    &[BlitWrite],
    &[Present],
    Guards::Image,
);

/// Every barrier twinray-vk records, in the page's order: what its table holds.
pub const ALL: [Barrier; 17] = [
    SCENE_UPLOAD,
    OFFSCREEN_PASS_IN,
    WINDOW_PASS_IN,
    OFFSCREEN_PASS_OUT,
    READBACK,
    RAY_COUNTS,
    UNIFORM_AFTER_READS,
    UNIFORM_TO_FRAGMENT,
    UNIFORM_TO_CAPTURE,
    STORAGE_IMAGE_SETUP,
    FRAME_AFTER_FRAME,
    STORAGE_IMAGE_TO_COPY,
    UNIFORM_TO_COMPUTE,
    STORAGE_IMAGE_AFTER_BLIT,
    STORAGE_IMAGE_TO_BLIT,
    SWAPCHAIN_TO_BLIT,
    SWAPCHAIN_TO_PRESENT,
];

/// Flags as `--explain` prints them: ash's names, and `NONE` for none (ash prints nothing).
pub fn show(flags: impl std::fmt::Debug + PartialEq + Default) -> String {
    if flags == Default::default() {
        "NONE".into()
    } else {
        format!("{flags:?}")
    }
}

/// `FragmentShaderRead | ComputeShaderRead`: accesses as the page writes them.
pub fn names(accesses: &[Access]) -> String {
    let names: Vec<String> = accesses.iter().map(|a| format!("{a:?}")).collect();
    names.join(" | ")
}

impl Barrier {
    /// `CopyWrite → HostRead`.
    pub fn words(&self) -> String {
        format!("{} → {}", names(self.before), names(self.after))
    }

    /// The stages that wait, and the access bits made visible to them.
    pub fn destination(&self, recording: Recording) -> (vk::PipelineStageFlags2, vk::AccessFlags2) {
        self.after.iter().fold(Default::default(), |(s, a), x| {
            let m = x.masks(recording);
            (s | m.stages, a | m.access)
        })
    }

    /// The stages waited for, and the access bits made available: writes only
    /// (a read leaves nothing to flush). `Acquire` starts where the access
    /// after it does, so that the barrier chains onto the semaphore wait.
    pub fn source(&self, recording: Recording) -> (vk::PipelineStageFlags2, vk::AccessFlags2) {
        self.before.iter().fold(Default::default(), |(s, a), x| {
            let m = x.masks(recording);
            let stages = if *x == Acquire {
                self.destination(recording).0
            } else {
                m.stages
            };
            let access = if x.writes() {
                m.access
            } else {
                vk::AccessFlags2::NONE
            };
            (s | stages, a | access)
        })
    }

    /// The masks as Vulkan 1.0 writes them: the source's stages and access,
    /// then the destination's.
    pub fn masks_1_0(&self) -> [(vk::PipelineStageFlags, vk::AccessFlags); 2] {
        let r = Recording::Vulkan10;
        [self.source(r), self.destination(r)].map(|(s, a)| (narrow_stages(s), narrow_access(a)))
    }

    /// The image's old and new layouts.
    pub fn layouts(&self) -> (vk::ImageLayout, vk::ImageLayout) {
        let layout = |a: &[Access]| layout_for(a[0]);
        let old = if self.guards == Guards::ImageDiscarded {
            vk::ImageLayout::UNDEFINED
        } else {
            layout(self.before)
        };
        (old, layout(self.after))
    }

    /// The render pass's dependency from `src` to `dst` subpass, in 1.0's masks.
    pub fn subpass_dependency(&self, src: u32, dst: u32) -> vk::SubpassDependency {
        let [(src_stages, src_access), (dst_stages, dst_access)] = self.masks_1_0();
        let dependency = vk::SubpassDependency::default()
            .src_subpass(src)
            .dst_subpass(dst)
            .src_stage_mask(src_stages)
            .src_access_mask(src_access)
            .dst_stage_mask(dst_stages)
            .dst_access_mask(dst_access);
        explain_once(
            self.step,
            &format!("VkSubpassDependency: {}", self.name),
            &format!(
                "{}\nstages {} -> {}; access {} -> {}",
                self.words(),
                show(dependency.src_stage_mask),
                show(dependency.dst_stage_mask),
                show(dependency.src_access_mask),
                show(dependency.dst_access_mask)
            ),
        );
        dependency
    }
}

/// The layout a render pass leaves its attachment in for what comes next.
/// Also the layout of an image barrier's side, and of the commands' image arguments.
pub fn layout_for(next: Access) -> vk::ImageLayout {
    next.masks(Recording::Vulkan10)
        .layout
        .unwrap_or_else(|| panic!("{next:?} is a buffer access; no image layout goes with it"))
}

/// The stage at which a frame's submit waits for the acquired image: that of
/// the image's first access (the render pass's colour writes, or the compute
/// path's blit). A barrier from [`Access::Acquire`] starts there too.
pub fn acquire_wait_stage(first: Access, recording: Recording) -> vk::PipelineStageFlags2 {
    first.masks(recording).stages
}

/// [`acquire_wait_stage`] for vkQueueSubmit's array of wait stages.
pub fn acquire_wait_stage_1_0(first: Access) -> vk::PipelineStageFlags {
    narrow_stages(acquire_wait_stage(first, Recording::Vulkan10))
}

/// Where a timestamp is written: before any command after it starts, or
/// after every command before it has finished.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Timestamp {
    Start,
    End,
}

impl Timestamp {
    pub fn stage(self) -> vk::PipelineStageFlags {
        match self {
            Timestamp::Start => vk::PipelineStageFlags::TOP_OF_PIPE,
            Timestamp::End => vk::PipelineStageFlags::BOTTOM_OF_PIPE,
        }
    }
}

/// The stage a frame's render-finished semaphore is signalled at: after every
/// command of the submit (synchronization2 names it; 1.0 signals after all).
pub const SIGNAL_AFTER_ALL: vk::PipelineStageFlags2 = vk::PipelineStageFlags2::ALL_COMMANDS;

/// Prints a barrier once: frames re-record theirs every frame.
pub(crate) fn explain_once(step: u32, title: &str, details: &str) {
    static SEEN: Mutex<BTreeSet<String>> = Mutex::new(BTreeSet::new());
    if !explain::is_on() {
        return;
    }
    let key = format!("{title}\n{details}");
    if SEEN.lock().unwrap_or_else(|e| e.into_inner()).insert(key) {
        explain::numbered(step, title, || details.to_string());
    }
}
