//! The render pass and the graphics pipeline.
//!
//! The *render pass* declares the attachments a draw writes (one RGBA32F colour
//! image), what happens to them at the start and end (don't load, store) and
//! which layout the image ends in; it exists so the driver knows all of that
//! before recording, which lets tiled GPUs keep the image on-chip.
//!
//! The *pipeline* bakes every piece of GPU state into one object, compiled once
//! up front instead of at draw time: the two shaders (naga's SPIR-V), the fixed
//! viewport, rasterisation, blending, and through the *pipeline layout* the
//! descriptor set layout its shaders read. Nothing is left dynamic: the image
//! size never changes during a run.

use crate::device::Device;
use anyhow::{Context, Result};
use ash::vk;
use twinray_common::shader::Shaders;

/// Float output, so the NaN count and the 8-bit rounding happen on the CPU,
/// identically for both APIs. Every Vulkan device can render to it.
pub const COLOR_FORMAT: vk::Format = vk::Format::R32G32B32A32_SFLOAT;

pub struct Pipeline {
    device: ash::Device,
    pub render_pass: vk::RenderPass,
    pub layout: vk::PipelineLayout,
    pub pipeline: vk::Pipeline,
}

/// A shader module is only needed while the pipeline is compiled.
struct Module(ash::Device, vk::ShaderModule);

impl Drop for Module {
    fn drop(&mut self) {
        unsafe { self.0.destroy_shader_module(self.1, None) };
    }
}

fn module(d: &ash::Device, spirv: &[u32], stage: &str) -> Result<Module> {
    let info = vk::ShaderModuleCreateInfo::default().code(spirv);
    let m = unsafe { d.create_shader_module(&info, None) }
        .with_context(|| format!("creating the {stage} shader module"))?;
    Ok(Module(d.clone(), m))
}

impl Pipeline {
    pub fn new(
        device: &Device,
        set_layout: vk::DescriptorSetLayout,
        shaders: &Shaders,
        width: u32,
        height: u32,
    ) -> Result<Pipeline> {
        let d = &device.device;
        let mut this = Pipeline {
            device: d.clone(),
            render_pass: vk::RenderPass::null(),
            layout: vk::PipelineLayout::null(),
            pipeline: vk::Pipeline::null(),
        };

        // The fullscreen triangle writes every pixel, so the old contents are not
        // loaded. The pass ends in TRANSFER_SRC_OPTIMAL, ready for the readback copy.
        let attachment = vk::AttachmentDescription::default()
            .format(COLOR_FORMAT)
            .samples(vk::SampleCountFlags::TYPE_1)
            .load_op(vk::AttachmentLoadOp::DONT_CARE)
            .store_op(vk::AttachmentStoreOp::STORE)
            .initial_layout(vk::ImageLayout::UNDEFINED)
            .final_layout(vk::ImageLayout::TRANSFER_SRC_OPTIMAL);
        let color_ref = [vk::AttachmentReference { attachment: 0, layout: vk::ImageLayout::COLOR_ATTACHMENT_OPTIMAL }];
        let subpass = vk::SubpassDescription::default()
            .pipeline_bind_point(vk::PipelineBindPoint::GRAPHICS)
            .color_attachments(&color_ref);
        // Two dependencies with the world outside the pass: a frame's writes wait
        // for the previous frame's (same image), and the readback copy waits for
        // the last frame's writes to land.
        let dependencies = [
            vk::SubpassDependency::default()
                .src_subpass(vk::SUBPASS_EXTERNAL)
                .dst_subpass(0)
                .src_stage_mask(vk::PipelineStageFlags::COLOR_ATTACHMENT_OUTPUT)
                .dst_stage_mask(vk::PipelineStageFlags::COLOR_ATTACHMENT_OUTPUT)
                .dst_access_mask(vk::AccessFlags::COLOR_ATTACHMENT_WRITE),
            vk::SubpassDependency::default()
                .src_subpass(0)
                .dst_subpass(vk::SUBPASS_EXTERNAL)
                .src_stage_mask(vk::PipelineStageFlags::COLOR_ATTACHMENT_OUTPUT)
                .src_access_mask(vk::AccessFlags::COLOR_ATTACHMENT_WRITE)
                .dst_stage_mask(vk::PipelineStageFlags::TRANSFER)
                .dst_access_mask(vk::AccessFlags::TRANSFER_READ),
        ];
        let attachments = [attachment];
        let subpasses = [subpass];
        let info = vk::RenderPassCreateInfo::default()
            .attachments(&attachments)
            .subpasses(&subpasses)
            .dependencies(&dependencies);
        this.render_pass = unsafe { d.create_render_pass(&info, None) }.context("creating the render pass")?;

        let set_layouts = [set_layout];
        let info = vk::PipelineLayoutCreateInfo::default().set_layouts(&set_layouts);
        this.layout = unsafe { d.create_pipeline_layout(&info, None) }.context("creating the pipeline layout")?;

        let vertex = module(d, &shaders.vertex_spirv, "vertex")?;
        let fragment = module(d, &shaders.fragment_spirv, "fragment")?;
        let stages = [
            vk::PipelineShaderStageCreateInfo::default()
                .stage(vk::ShaderStageFlags::VERTEX)
                .module(vertex.1)
                .name(c"main"),
            vk::PipelineShaderStageCreateInfo::default()
                .stage(vk::ShaderStageFlags::FRAGMENT)
                .module(fragment.1)
                .name(c"main"),
        ];
        // No vertex buffers: the vertex shader makes the triangle from gl_VertexIndex.
        let vertex_input = vk::PipelineVertexInputStateCreateInfo::default();
        let assembly =
            vk::PipelineInputAssemblyStateCreateInfo::default().topology(vk::PrimitiveTopology::TRIANGLE_LIST);
        // A normal viewport (positive height): Vulkan's row 0 is the top, and the
        // shader builds rays with +y down, so rows go to the PNG unflipped.
        let viewports = [vk::Viewport {
            x: 0.0,
            y: 0.0,
            width: width as f32,
            height: height as f32,
            min_depth: 0.0,
            max_depth: 1.0,
        }];
        let scissors = [vk::Rect2D { offset: vk::Offset2D::default(), extent: vk::Extent2D { width, height } }];
        let viewport = vk::PipelineViewportStateCreateInfo::default().viewports(&viewports).scissors(&scissors);
        // No culling: the one triangle must be drawn whichever way it winds.
        let raster = vk::PipelineRasterizationStateCreateInfo::default()
            .polygon_mode(vk::PolygonMode::FILL)
            .cull_mode(vk::CullModeFlags::NONE)
            .line_width(1.0);
        let multisample =
            vk::PipelineMultisampleStateCreateInfo::default().rasterization_samples(vk::SampleCountFlags::TYPE_1);
        let blend_attachments =
            [vk::PipelineColorBlendAttachmentState::default().color_write_mask(vk::ColorComponentFlags::RGBA)];
        let blend = vk::PipelineColorBlendStateCreateInfo::default().attachments(&blend_attachments);
        let info = vk::GraphicsPipelineCreateInfo::default()
            .stages(&stages)
            .vertex_input_state(&vertex_input)
            .input_assembly_state(&assembly)
            .viewport_state(&viewport)
            .rasterization_state(&raster)
            .multisample_state(&multisample)
            .color_blend_state(&blend)
            .layout(this.layout)
            .render_pass(this.render_pass)
            .subpass(0);
        let pipelines = unsafe { d.create_graphics_pipelines(vk::PipelineCache::null(), &[info], None) }
            .map_err(|(_, e)| e)
            .context("creating the graphics pipeline")?;
        this.pipeline = pipelines[0];
        Ok(this) // the shader modules are dropped here: the pipeline has its own copy.
    }
}

impl Drop for Pipeline {
    fn drop(&mut self) {
        // SAFETY: no command buffer using them is pending (see Commands::drop).
        unsafe {
            self.device.destroy_pipeline(self.pipeline, None);
            self.device.destroy_pipeline_layout(self.layout, None);
            self.device.destroy_render_pass(self.render_pass, None);
        }
    }
}
