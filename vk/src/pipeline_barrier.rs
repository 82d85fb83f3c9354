//! Recording named barriers: each [`Barrier`] of barrier.rs, with the buffers
//! or image it guards, becomes one barrier call in the device's recording.
//! Vulkan 1.0's vkCmdPipelineBarrier takes one pair of stage masks for the
//! whole call; synchronization2's vkCmdPipelineBarrier2 gives each barrier its
//! own. Either way the masks are the names' (barrier.rs) and nothing here
//! chooses one; `--explain` prints each call from the structures it was given.

use crate::barrier::{explain_once, show, Barrier, Guards, Recording, COLOR_IMAGE};
use crate::device::Device;
use ash::vk;
use twinray_common::explain;

/// What one barrier guards: buffers, an image, or nothing (an execution dependency).
pub enum On<'a> {
    Buffers(&'a [vk::Buffer]),
    Image(vk::Image),
    Nothing,
}

/// A buffer barrier (with its stages set, where it has them) completed with
/// the `(src, dst)` access masks, over the whole `buffer`, with no queue
/// transfer. Vulkan 1.0's and synchronization2's structures differ in type
/// but not in these fields, hence a macro.
macro_rules! whole_buffer {
    ($base:expr, $access:expr, $buffer:expr) => {{
        let (src, dst) = $access;
        $base
            .src_access_mask(src)
            .dst_access_mask(dst)
            .src_queue_family_index(vk::QUEUE_FAMILY_IGNORED)
            .dst_queue_family_index(vk::QUEUE_FAMILY_IGNORED)
            .buffer($buffer)
            .size(vk::WHOLE_SIZE)
    }};
}

/// As `whole_buffer!`, for the colour `image` moving between the `(old, new)`
/// layouts.
macro_rules! colour_image {
    ($base:expr, $access:expr, $image:expr, $layouts:expr) => {{
        let ((src, dst), (old, new)) = ($access, $layouts);
        $base
            .src_access_mask(src)
            .dst_access_mask(dst)
            .old_layout(old)
            .new_layout(new)
            .src_queue_family_index(vk::QUEUE_FAMILY_IGNORED)
            .dst_queue_family_index(vk::QUEUE_FAMILY_IGNORED)
            .image($image)
            .subresource_range(COLOR_IMAGE)
    }};
}

/// Records `barriers` (each with what it guards) as one barrier call, in the
/// device's recording, and prints each with `--explain` the first time it is
/// recorded, from the structures the call was given.
///
/// # Safety
/// `cmd` was allocated from `device` and is recording, outside a render pass,
/// and every buffer and image named is alive until the commands have run.
pub unsafe fn record(device: &Device, cmd: vk::CommandBuffer, barriers: &[(Barrier, On)]) {
    // What a barrier guards is part of its name: the table says "buffers", the
    // call must hand it buffers.
    for (b, on) in barriers {
        let fits = matches!(
            (b.guards, on),
            (Guards::Buffers, On::Buffers(_))
                | (Guards::Image | Guards::ImageDiscarded, On::Image(_))
                | (Guards::Execution, On::Nothing)
        );
        assert!(fits, "the {} barrier guards {:?}", b.name, b.guards);
    }
    if barriers.is_empty() {
        return;
    }
    match device.recording {
        // SAFETY: forwarded from the caller.
        Recording::Vulkan10 => unsafe { record_1_0(&device.device, cmd, barriers) },
        // SAFETY: forwarded from the caller; the device enabled synchronization2
        // (Device::new does, for this recording).
        Recording::Synchronization2 => unsafe { record_2(&device.device, cmd, barriers) },
    }
}

/// One vkCmdPipelineBarrier: the stage masks of all the barriers together.
///
/// # Safety
/// As for [`record`].
unsafe fn record_1_0(d: &ash::Device, cmd: vk::CommandBuffer, barriers: &[(Barrier, On)]) {
    // The union of every barrier's stages, starting from the first's.
    let [(mut src, _), (mut dst, _)] = barriers[0].0.masks_1_0();
    let (mut buffers, mut images) = (Vec::new(), Vec::new());
    for (b, on) in barriers {
        let [(src_stages, src_access), (dst_stages, dst_access)] = b.masks_1_0();
        src |= src_stages;
        dst |= dst_stages;
        match on {
            On::Buffers(list) => buffers.extend(list.iter().map(|&buffer| {
                let base = vk::BufferMemoryBarrier::default();
                whole_buffer!(base, (src_access, dst_access), buffer)
            })),
            On::Image(image) => {
                let base = vk::ImageMemoryBarrier::default();
                images.push(colour_image!(
                    base,
                    (src_access, dst_access),
                    *image,
                    b.layouts()
                ))
            }
            // An execution dependency: the stage masks alone.
            On::Nothing => {}
        }
    }
    // SAFETY: forwarded from the caller.
    unsafe {
        d.cmd_pipeline_barrier(
            cmd,
            src,
            dst,
            vk::DependencyFlags::empty(),
            &[],
            &buffers,
            &images,
        )
    };
    if explain::is_on() {
        let mut lines = vec![format!("stages {src:?} -> {dst:?}")];
        lines.extend(buffers.iter().map(|b| {
            format!(
                "buffer access {} -> {}",
                show(b.src_access_mask),
                show(b.dst_access_mask)
            )
        }));
        lines.extend(images.iter().map(|i| {
            format!(
                "image access {} -> {}, layout {:?} -> {:?}",
                show(i.src_access_mask),
                show(i.dst_access_mask),
                i.old_layout,
                i.new_layout
            )
        }));
        explain_call("vkCmdPipelineBarrier", barriers, &lines);
    }
}

/// One vkCmdPipelineBarrier2: each barrier with its own stages.
///
/// # Safety
/// As for [`record`], on a device with synchronization2 enabled.
unsafe fn record_2(d: &ash::Device, cmd: vk::CommandBuffer, barriers: &[(Barrier, On)]) {
    let r = Recording::Synchronization2;
    let (mut memory, mut buffers, mut images) = (Vec::new(), Vec::new(), Vec::new());
    for (b, on) in barriers {
        let ((src_stages, src_access), (dst_stages, dst_access)) = (b.source(r), b.destination(r));
        match on {
            On::Buffers(list) => buffers.extend(list.iter().map(|&buffer| {
                let staged = vk::BufferMemoryBarrier2::default()
                    .src_stage_mask(src_stages)
                    .dst_stage_mask(dst_stages);
                whole_buffer!(staged, (src_access, dst_access), buffer)
            })),
            On::Image(image) => {
                let staged = vk::ImageMemoryBarrier2::default()
                    .src_stage_mask(src_stages)
                    .dst_stage_mask(dst_stages);
                images.push(colour_image!(
                    staged,
                    (src_access, dst_access),
                    *image,
                    b.layouts()
                ))
            }
            // Stages live in the barriers now: an execution dependency is a
            // memory barrier with stages and no access bits.
            On::Nothing => memory.push(
                vk::MemoryBarrier2::default()
                    .src_stage_mask(src_stages)
                    .dst_stage_mask(dst_stages),
            ),
        }
    }
    let info = vk::DependencyInfo::default()
        .memory_barriers(&memory)
        .buffer_memory_barriers(&buffers)
        .image_memory_barriers(&images);
    // SAFETY: forwarded from the caller; the arrays outlive the call.
    unsafe { d.cmd_pipeline_barrier2(cmd, &info) };
    if explain::is_on() {
        let mut lines: Vec<String> = memory
            .iter()
            .map(|m| {
                format!(
                    "memory {}/{} -> {}/{}",
                    show(m.src_stage_mask),
                    show(m.src_access_mask),
                    show(m.dst_stage_mask),
                    show(m.dst_access_mask)
                )
            })
            .collect();
        lines.extend(buffers.iter().map(|b| {
            format!(
                "buffer {}/{} -> {}/{}",
                show(b.src_stage_mask),
                show(b.src_access_mask),
                show(b.dst_stage_mask),
                show(b.dst_access_mask)
            )
        }));
        lines.extend(images.iter().map(|i| {
            format!(
                "image {}/{} -> {}/{}, layout {:?} -> {:?}",
                show(i.src_stage_mask),
                show(i.src_access_mask),
                show(i.dst_stage_mask),
                show(i.dst_access_mask),
                i.old_layout,
                i.new_layout
            )
        }));
        explain_call("vkCmdPipelineBarrier2", barriers, &lines);
    }
}

/// `[n] vkCmdPipelineBarrier: a + b`, the named accesses, then what was recorded.
fn explain_call(call: &str, barriers: &[(Barrier, On)], recorded: &[String]) {
    let title: Vec<&str> = barriers.iter().map(|(b, _)| b.name).collect();
    let mut details: Vec<String> = barriers
        .iter()
        .map(|(b, on)| {
            let what = match on {
                On::Buffers(list) => format!("{} buffer(s)", list.len()),
                On::Image(_) => "image".into(),
                On::Nothing => "execution only".into(),
            };
            format!("{}: {} ({what})", b.name, b.words())
        })
        .collect();
    // The upload's six buffer barriers are one line, "6 x ...".
    let mut counted: Vec<(usize, &String)> = Vec::new();
    for line in recorded {
        match counted.last_mut() {
            Some((n, last)) if *last == line => *n += 1,
            _ => counted.push((1, line)),
        }
    }
    details.extend(counted.iter().map(|(n, line)| match n {
        1 => line.to_string(),
        n => format!("{n} x {line}"),
    }));
    let step = barriers.iter().map(|(b, _)| b.step).max().unwrap_or(0);
    explain_once(
        step,
        &format!("{call}: {}", title.join(" + ")),
        &details.join("\n"),
    );
}
