//! Descriptors: how the shader's `layout(set = 0, binding = N)` blocks find our buffers.
//!
//! Vulkan splits this in three. The *set layout* is the shape (binding 0 is a
//! uniform buffer; the storage buffers sit at bindings 1–4 and 6–8, as
//! `common/src/gpu/layout.rs`'s `binding::STORAGE` lists them; all are read by
//! the fragment stage; the compute path adds binding 5, a storage image, and
//! names the compute stage); it
//! exists on its own because the pipeline is compiled against it, before any
//! buffer is chosen. Sets are allocated from a *pool*, so the driver can manage
//! their memory in bulk. The *set* is then written once to point at the buffers.
//! Nothing changes between frames, so it is bound once, in the recorded commands.

use crate::barrier::{self, Access};
use crate::device::Device;
use crate::memory::Buffer;
use anyhow::{Context, Result};
use ash::vk;
use twinray_common::explain;
use twinray_common::gpu::layout::binding;

pub struct Descriptors {
    device: ash::Device,
    pub set_layout: vk::DescriptorSetLayout,
    pool: vk::DescriptorPool,
    pub set: vk::DescriptorSet,
}

impl Descriptors {
    /// `frame` is the uniform buffer; `storage` pairs each storage binding with its buffer.
    pub fn new(device: &Device, frame: &Buffer, storage: &[(u32, Buffer)]) -> Result<Descriptors> {
        Descriptors::for_stage(device, frame, storage, vk::ShaderStageFlags::FRAGMENT, None)
    }

    /// The same buffers for the shader `stage`, plus, for the compute path, the
    /// storage image view at binding 5 (in GENERAL layout, the one layout in
    /// which shaders may write an image).
    // Long function: one linear walk through the walkthrough's descriptor step (layout, pool, set, writes), in the order a learner reads it.
    pub fn for_stage(
        device: &Device,
        frame: &Buffer,
        storage: &[(u32, Buffer)],
        stage: vk::ShaderStageFlags,
        image: Option<vk::ImageView>,
    ) -> Result<Descriptors> {
        let d = &device.device;
        // --explain: the compute path's set is part of its own step.
        let step = if stage == vk::ShaderStageFlags::COMPUTE {
            21
        } else {
            6
        };
        let mut this = Descriptors {
            device: d.clone(),
            set_layout: vk::DescriptorSetLayout::null(),
            pool: vk::DescriptorPool::null(),
            set: vk::DescriptorSet::null(),
        };
        let all: Vec<(u32, vk::DescriptorType, &Buffer)> =
            std::iter::once((binding::FRAME, vk::DescriptorType::UNIFORM_BUFFER, frame))
                .chain(
                    storage
                        .iter()
                        .map(|(b, buf)| (*b, vk::DescriptorType::STORAGE_BUFFER, buf)),
                )
                .collect();

        let mut bindings: Vec<_> = all
            .iter()
            .map(|&(b, ty, _)| {
                vk::DescriptorSetLayoutBinding::default()
                    .binding(b)
                    .descriptor_type(ty)
                    .descriptor_count(1)
                    .stage_flags(stage)
            })
            .collect();
        if image.is_some() {
            bindings.push(
                vk::DescriptorSetLayoutBinding::default()
                    .binding(binding::IMAGE)
                    .descriptor_type(vk::DescriptorType::STORAGE_IMAGE)
                    .descriptor_count(1)
                    .stage_flags(stage),
            );
        }
        let info = vk::DescriptorSetLayoutCreateInfo::default().bindings(&bindings);
        // SAFETY: `bindings` outlives the call and names each binding once; `this` (which owns the
        // layout) destroys it on drop.
        this.set_layout = unsafe { d.create_descriptor_set_layout(&info, None) }
            .context("creating the descriptor set layout")?;
        explain::numbered(step, "VkDescriptorSetLayout", || {
            all.iter()
                .map(|(b, ty, _)| format!("binding {b}: {ty:?} x1, {stage:?} stage\n"))
                .chain(image.map(|_| {
                    format!(
                        "binding {}: STORAGE_IMAGE x1, {stage:?} stage\n",
                        binding::IMAGE
                    )
                }))
                .collect()
        });

        let mut sizes = vec![
            vk::DescriptorPoolSize {
                ty: vk::DescriptorType::UNIFORM_BUFFER,
                descriptor_count: 1,
            },
            vk::DescriptorPoolSize {
                ty: vk::DescriptorType::STORAGE_BUFFER,
                descriptor_count: storage.len() as u32,
            },
        ];
        if image.is_some() {
            sizes.push(vk::DescriptorPoolSize {
                ty: vk::DescriptorType::STORAGE_IMAGE,
                descriptor_count: 1,
            });
        }
        let info = vk::DescriptorPoolCreateInfo::default()
            .max_sets(1)
            .pool_sizes(&sizes);
        // SAFETY: a create on the live device from local sizes; `this` destroys the pool, which
        // frees its set.
        this.pool = unsafe { d.create_descriptor_pool(&info, None) }
            .context("creating the descriptor pool")?;
        // Printed from the sizes the pool was made with, so the compute path's
        // storage image is there too.
        explain::numbered(step, "VkDescriptorPool", || {
            let sizes: Vec<String> = sizes
                .iter()
                .map(|s| format!("{} {:?}", s.descriptor_count, s.ty))
                .collect();
            format!("max 1 set; {}", sizes.join(", "))
        });

        let layouts = [this.set_layout];
        let info = vk::DescriptorSetAllocateInfo::default()
            .descriptor_pool(this.pool)
            .set_layouts(&layouts);
        // SAFETY: the pool and layout were made above on `d`; the pool has room for exactly this
        // one set.
        this.set = unsafe { d.allocate_descriptor_sets(&info) }
            .context("allocating the descriptor set")?[0];

        let infos: Vec<[vk::DescriptorBufferInfo; 1]> = all
            .iter()
            .map(|(_, _, buf)| {
                [vk::DescriptorBufferInfo {
                    buffer: buf.buffer,
                    offset: 0,
                    range: buf.size,
                }]
            })
            .collect();
        let writes: Vec<_> = all
            .iter()
            .zip(&infos)
            .map(|(&(b, ty, _), info)| {
                vk::WriteDescriptorSet::default()
                    .dst_set(this.set)
                    .dst_binding(b)
                    .descriptor_type(ty)
                    .buffer_info(info)
            })
            .collect();
        // SAFETY: the set is new, so no command buffer uses it yet; each write's buffer is alive
        // (the caller owns it and keeps it past this set, see SceneResources) and its range is that
        // buffer's whole size; binding numbers and types match the layout made from the same `all`
        // list.
        unsafe { d.update_descriptor_sets(&writes, &[]) };
        if let Some(view) = image {
            this.write_image(view);
        }
        explain::numbered(
            step,
            "VkDescriptorSet (allocated, then vkUpdateDescriptorSets)",
            || {
                format!(
                    "{} writes: each binding points at its whole buffer",
                    writes.len() + usize::from(image.is_some())
                )
            },
        );
        Ok(this)
    }
}

impl Descriptors {
    /// Points binding 5 at a storage image view (GENERAL layout). The window
    /// calls it again when its storage image is made anew for a new size; the
    /// set must not be in use by a pending command buffer then.
    pub fn write_image(&self, view: vk::ImageView) {
        let info = [vk::DescriptorImageInfo {
            sampler: vk::Sampler::null(),
            image_view: view,
            image_layout: barrier::layout_for(Access::ComputeShaderWrite),
        }];
        let write = vk::WriteDescriptorSet::default()
            .dst_set(self.set)
            .dst_binding(binding::IMAGE)
            .descriptor_type(vk::DescriptorType::STORAGE_IMAGE)
            .image_info(&info);
        // SAFETY: the set and the view are alive; the callers wait for the GPU first.
        unsafe { self.device.update_descriptor_sets(&[write], &[]) };
    }
}

impl Drop for Descriptors {
    fn drop(&mut self) {
        // SAFETY: no command buffer using the set is pending (see Commands::drop).
        // Destroying the pool frees the set allocated from it.
        unsafe {
            self.device.destroy_descriptor_pool(self.pool, None);
            self.device
                .destroy_descriptor_set_layout(self.set_layout, None);
        }
    }
}
