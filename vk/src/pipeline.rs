//! The render pass and the graphics pipeline.
//!
//! The *render pass* declares the attachments a draw writes (one colour image),
//! what happens to them at the start and end (don't load, store) and which
//! layout the image ends in; it exists so the driver knows all of that before
//! recording, which lets tiled GPUs keep the image on-chip. Headless, the
//! attachment is our RGBA32F image and ends ready to be copied out; windowed,
//! it is a swapchain image and ends ready to be presented. (A classic render
//! pass rather than dynamic rendering: it is core in Vulkan 1.0, which every
//! driver here has, while dynamic rendering needs 1.3 or an extension.)
//!
//! The *pipeline* bakes every piece of GPU state into one object, compiled once
//! up front instead of at draw time: the two shaders (naga's SPIR-V), the
//! viewport, rasterisation, blending, and through the *pipeline layout* the
//! descriptor set layout its shaders read. Headless nothing is dynamic (the
//! size never changes); windowed, the viewport and scissor are *dynamic state*,
//! set while recording, so that a resize does not recompile the tracer.

use crate::barrier::{self, Access, Barrier};
use crate::device::Device;
use anyhow::{Context, Result};
use ash::vk;
use twinray_common::explain;
use twinray_common::shader::build::Shaders;

/// Float output, so the NaN count and the 8-bit rounding happen on the CPU,
/// identically for both APIs. Every Vulkan device can render to it.
pub const COLOR_FORMAT: vk::Format = vk::Format::R32G32B32A32_SFLOAT;

pub struct RenderPass {
    device: ash::Device,
    pub render_pass: vk::RenderPass,
}

impl RenderPass {
    /// The headless pass: RGBA32F, left in TRANSFER_SRC_OPTIMAL for the readback.
    pub fn offscreen(device: &Device) -> Result<RenderPass> {
        let out = Some(barrier::OFFSCREEN_PASS_OUT);
        RenderPass::new(device, COLOR_FORMAT, barrier::OFFSCREEN_PASS_IN, out)
    }

    /// The windowed pass: the swapchain's format, left in PRESENT_SRC_KHR.
    pub fn for_swapchain(device: &Device, format: vk::Format) -> Result<RenderPass> {
        // Presenting needs no dependency out: the submit's semaphore covers it.
        RenderPass::new(device, format, barrier::WINDOW_PASS_IN, None)
    }

    /// A pass whose dependency `incoming` orders its colour writes after what
    /// came before, and `outgoing` (headless) the next use after them; without
    /// one, the image is presented next.
    fn new(
        device: &Device,
        format: vk::Format,
        incoming: Barrier,
        outgoing: Option<Barrier>,
    ) -> Result<RenderPass> {
        let d = &device.device;
        let next = outgoing.map_or(Access::Present, |b| b.after[0]);
        let final_layout = barrier::layout_for(next);
        // The fullscreen triangle writes every pixel, so the old contents are
        // not loaded (DONT_CARE); a CLEAR took as long
        // (docs/findings/fragment-gap.md).
        let load = vk::AttachmentLoadOp::DONT_CARE;
        let attachment = vk::AttachmentDescription::default()
            .format(format)
            .samples(vk::SampleCountFlags::TYPE_1)
            .load_op(load)
            .store_op(vk::AttachmentStoreOp::STORE)
            .initial_layout(barrier::layout_for(Access::Nothing))
            .final_layout(final_layout);
        let color_ref = [vk::AttachmentReference {
            attachment: 0,
            layout: barrier::layout_for(Access::ColorAttachmentWrite),
        }];
        let subpass = vk::SubpassDescription::default()
            .pipeline_bind_point(vk::PipelineBindPoint::GRAPHICS)
            .color_attachments(&color_ref);
        // Into the pass: its writes wait for what came before in the same
        // image (headless: the previous frame's colour writes; windowed: the
        // acquire, which the submit waits for at the colour-output stage).
        let mut dependencies = vec![incoming.subpass_dependency(vk::SUBPASS_EXTERNAL, 0)];
        // Out of the headless pass: the readback copy waits for the writes to land.
        dependencies.extend(outgoing.map(|b| b.subpass_dependency(0, vk::SUBPASS_EXTERNAL)));
        let attachments = [attachment];
        let subpasses = [subpass];
        let info = vk::RenderPassCreateInfo::default()
            .attachments(&attachments)
            .subpasses(&subpasses)
            .dependencies(&dependencies);
        // SAFETY: the attachment, subpass and dependency arrays are locals that outlive the call,
        // and the subpass's attachment reference names attachment 0, which exists; the RenderPass
        // returned destroys the pass.
        let render_pass =
            unsafe { d.create_render_pass(&info, None) }.context("creating the render pass")?;
        explain::numbered(7, "VkRenderPass", || {
            format!(
                "1 colour attachment {format:?}, load {load:?} (every pixel is written), store STORE\n\
                 layout UNDEFINED -> COLOR_ATTACHMENT_OPTIMAL -> {final_layout:?}; {} subpass dependencies",
                dependencies.len()
            )
        });
        Ok(RenderPass {
            device: d.clone(),
            render_pass,
        })
    }
}

impl Drop for RenderPass {
    fn drop(&mut self) {
        // SAFETY: the pipelines and framebuffers made for it are gone (drop order).
        unsafe { self.device.destroy_render_pass(self.render_pass, None) };
    }
}

pub struct Pipeline {
    device: ash::Device,
    pub layout: vk::PipelineLayout,
    pub pipeline: vk::Pipeline,
}

/// A shader module is only needed while the pipeline is compiled.
pub(crate) struct Module(ash::Device, pub(crate) vk::ShaderModule);

impl Drop for Module {
    fn drop(&mut self) {
        // SAFETY: a pipeline keeps its own copy of the code, so the module may go as soon as the
        // pipelines made from it exist, even while they run.
        unsafe { self.0.destroy_shader_module(self.1, None) };
    }
}

pub(crate) fn module(d: &ash::Device, spirv: &[u32], stage: &str) -> Result<Module> {
    let info = vk::ShaderModuleCreateInfo::default().code(spirv);
    // SAFETY: `spirv` is naga's output, validated by naga before it was written, so it is well-
    // formed SPIR-V words (the slice outlives the call); the Module destroys it.
    let m = unsafe { d.create_shader_module(&info, None) }
        .with_context(|| format!("creating the {stage} shader module"))?;
    Ok(Module(d.clone(), m))
}

/// The pipeline layout both pipelines use: the one descriptor set, no push constants.
pub(crate) fn layout(
    d: &ash::Device,
    set_layout: vk::DescriptorSetLayout,
    what: &str,
) -> Result<vk::PipelineLayout> {
    let set_layouts = [set_layout];
    let info = vk::PipelineLayoutCreateInfo::default().set_layouts(&set_layouts);
    // SAFETY: `set_layout` is alive (owned by the caller's Descriptors, which outlive the
    // pipeline); the caller owns the layout and destroys it with its pipeline.
    unsafe { d.create_pipeline_layout(&info, None) }
        .with_context(|| format!("creating the {what} pipeline layout"))
}

impl Pipeline {
    pub fn new(
        device: &Device,
        set_layout: vk::DescriptorSetLayout,
        shaders: &Shaders,
        render_pass: vk::RenderPass,
        fixed_size: Option<(u32, u32)>,
    ) -> Result<Pipeline> {
        let d = &device.device;
        let mut this = Pipeline {
            device: d.clone(),
            layout: vk::PipelineLayout::null(),
            pipeline: vk::Pipeline::null(),
        };

        this.layout = layout(d, set_layout, "graphics")?;
        explain::numbered(8, "VkPipelineLayout", || {
            "1 descriptor set layout (set 0), no push constants".into()
        });

        let vertex = module(d, &shaders.vertex.spirv, "vertex")?;
        let fragment = module(d, &shaders.fragment.spirv, "fragment")?;
        explain::numbered(8, "VkShaderModule x2 (naga SPIR-V)", || {
            format!(
                "vertex {} words, fragment {} words; variant {}",
                shaders.vertex.spirv.len(),
                shaders.fragment.spirv.len(),
                shaders.variant.label()
            )
        });
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
        let assembly = vk::PipelineInputAssemblyStateCreateInfo::default()
            .topology(vk::PrimitiveTopology::TRIANGLE_LIST);
        // A normal viewport (positive height): Vulkan's row 0 is the top, and the
        // shader builds rays with +y down, so rows go to the PNG unflipped.
        let (width, height) = fixed_size.unwrap_or((1, 1));
        let (viewport, scissor) = whole(vk::Extent2D { width, height });
        let (viewports, scissors) = ([viewport], [scissor]);
        let viewport = vk::PipelineViewportStateCreateInfo::default()
            .viewports(&viewports)
            .scissors(&scissors);
        // Windowed, the size changes with the window: set while recording instead.
        let dynamic_states = [vk::DynamicState::VIEWPORT, vk::DynamicState::SCISSOR];
        let dynamic =
            vk::PipelineDynamicStateCreateInfo::default().dynamic_states(if fixed_size.is_some() {
                &[]
            } else {
                &dynamic_states
            });
        // No culling: the one triangle must be drawn whichever way it winds.
        let raster = vk::PipelineRasterizationStateCreateInfo::default()
            .polygon_mode(vk::PolygonMode::FILL)
            .cull_mode(vk::CullModeFlags::NONE)
            .line_width(1.0);
        let multisample = vk::PipelineMultisampleStateCreateInfo::default()
            .rasterization_samples(vk::SampleCountFlags::TYPE_1);
        let blend_attachments = [vk::PipelineColorBlendAttachmentState::default()
            .color_write_mask(vk::ColorComponentFlags::RGBA)];
        let blend =
            vk::PipelineColorBlendStateCreateInfo::default().attachments(&blend_attachments);
        let info = vk::GraphicsPipelineCreateInfo::default()
            .flags(crate::statistics::pipeline_flags(device))
            .stages(&stages)
            .vertex_input_state(&vertex_input)
            .input_assembly_state(&assembly)
            .viewport_state(&viewport)
            .rasterization_state(&raster)
            .multisample_state(&multisample)
            .color_blend_state(&blend)
            .dynamic_state(&dynamic)
            .layout(this.layout)
            .render_pass(render_pass)
            .subpass(0);
        // SAFETY: every state struct and the shader stages' modules and entry-point names are
        // locals alive until after the call; the modules hold naga's validated SPIR-V whose
        // bindings are those of the set layout; `render_pass` is alive (the caller's) and has
        // subpass 0 with the one colour attachment the blend state describes.
        let pipelines =
            unsafe { d.create_graphics_pipelines(vk::PipelineCache::null(), &[info], None) }
                .map_err(|(_, e)| e)
                .context("creating the graphics pipeline")?;
        this.pipeline = pipelines[0];
        crate::statistics::capture(device, this.pipeline, "graphics");
        explain::numbered(
            8,
            "VkPipeline (vkCreateGraphicsPipelines: the driver compiles the tracer here)",
            || {
                let size = match fixed_size {
                    Some((w, h)) => format!("fixed viewport + scissor {w}x{h}"),
                    None => "dynamic viewport + scissor (resizes don't recompile)".into(),
                };
                format!(
                    "TRIANGLE_LIST, no vertex input (3 vertices from gl_VertexIndex); {size}\n\
                     FILL, cull NONE, 1 sample, no blending, write RGBA; subpass 0"
                )
            },
        );
        Ok(this) // the shader modules are dropped here: the pipeline has its own copy.
    }
}

/// The viewport and scissor that cover the whole `extent`.
pub fn whole(extent: vk::Extent2D) -> (vk::Viewport, vk::Rect2D) {
    let viewport = vk::Viewport {
        x: 0.0,
        y: 0.0,
        width: extent.width as f32,
        height: extent.height as f32,
        min_depth: 0.0,
        max_depth: 1.0,
    };
    let scissor = vk::Rect2D {
        offset: vk::Offset2D::default(),
        extent,
    };
    (viewport, scissor)
}

impl Drop for Pipeline {
    fn drop(&mut self) {
        // SAFETY: no command buffer using them is pending (see Commands::drop).
        unsafe {
            self.device.destroy_pipeline(self.pipeline, None);
            self.device.destroy_pipeline_layout(self.layout, None);
        }
    }
}
