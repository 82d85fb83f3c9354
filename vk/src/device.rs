//! Choosing a GPU (the *physical device*) and opening it (the *logical device*)
//! with one queue.
//!
//! Vulkan separates the two because choosing is the app's job: a physical device
//! is only a description (name, type, limits, memory types, queue families) that
//! the app inspects. The logical device is the open connection every later object
//! is created on; it enables only the queues and features the app asks for, so
//! the driver sets up nothing else. Work reaches the GPU only through *queues*,
//! which come in families with different abilities: we need one that can draw and dispatch.

use crate::barrier::Recording;
use crate::instance::Instance;
use crate::surface::Surface;
use anyhow::{Context, Result};
use ash::{khr, vk};
use twinray_common::cli::{SceneMemory, VulkanKnobs};
use twinray_common::error::{bad_input, no_device};
use twinray_common::explain;
use twinray_common::limits::StorageLimit;
use twinray_common::plan::requests::{ComputeLimits, DeviceRequest};
use twinray_common::report::DeviceInfo;

pub struct Device {
    pub physical: vk::PhysicalDevice,
    pub properties: vk::PhysicalDeviceProperties,
    pub memory_properties: vk::PhysicalDeviceMemoryProperties,
    pub name: String,
    /// "driverName driverInfo" where Vulkan 1.2 can tell us, else the raw driverVersion.
    pub driver: String,
    pub queue_family: u32,
    /// The queue family's timestampValidBits: 0 means no timestamps on this queue.
    pub timestamp_valid_bits: u32,
    pub device: ash::Device,
    pub queue: vk::Queue,
    /// VK_KHR_pipeline_executable_properties, where offered: `--dump-shaders`
    /// reads what the driver compiled (statistics.rs).
    pub executable_properties: Option<khr::pipeline_executable_properties::Device>,
    /// Where the scene's buffers go on this device (`--vk-memory`).
    pub scene_memory: SceneMemory,
    /// fragmentStoresAndAtomics, enabled where offered: the fragment path's
    /// ray-counting frame writes a storage buffer (`--count-rays`).
    pub fragment_stores: bool,
    /// How barriers are recorded (`--vk-sync2`): barrier.rs.
    pub recording: Recording,
}

/// One physical device as the chooser sees it.
struct Candidate {
    physical: vk::PhysicalDevice,
    properties: vk::PhysicalDeviceProperties,
    name: String,
    /// The first queue family that can draw and dispatch (and present, for a window), with
    /// its timestampValidBits and flags.
    graphics_family: Option<(u32, u32, vk::QueueFlags)>,
}

impl Device {
    /// `surface` is the window's, in windowed mode: the queue must also present
    /// to it, and the device must offer VK_KHR_swapchain. `knobs` may name the
    /// device and say where scene buffers go. `request` is what the run plan
    /// asks of the device: fragmentStoresAndAtomics, which the ray-counting
    /// frame needs on the fragment path (`count_rays`; the timed runs get the
    /// device they always had).
    // Long function: the walkthrough's device step read top to bottom (pick a GPU, a queue family, features, extensions, create); each block is one choice.
    pub fn new(
        instance: &Instance,
        surface: Option<&Surface>,
        knobs: &VulkanKnobs,
        request: &DeviceRequest,
    ) -> Result<Device> {
        let DeviceRequest { count_rays } = *request;
        let vk_instance = &instance.instance;
        // SAFETY: `instance` is alive for the whole call (borrowed) and is used from this thread
        // only.
        let physicals = unsafe { vk_instance.enumerate_physical_devices() }
            .context("listing Vulkan devices")?;
        if physicals.is_empty() {
            return Err(no_device(
                "no Vulkan device found: install mesa-vulkan-drivers (lavapipe, on the CPU) or a GPU driver",
            ));
        }
        let candidates: Vec<Candidate> = physicals
            .into_iter()
            .map(|physical| {
                // SAFETY: `physical` was just listed by this live instance; physical devices need
                // no destruction.
                let properties = unsafe { vk_instance.get_physical_device_properties(physical) };
                // SAFETY: as above: a query on a listed physical device of the live instance.
                let families =
                    unsafe { vk_instance.get_physical_device_queue_family_properties(physical) };
                let presents = |i: u32| surface.is_none_or(|s| s.supports(physical, i));
                // Both paths run on this one queue: the fragment path draws, the compute path dispatches.
                let abilities = vk::QueueFlags::GRAPHICS | vk::QueueFlags::COMPUTE;
                let graphics_family = (0u32..)
                    .zip(&families)
                    .find(|&(i, f)| f.queue_flags.contains(abilities) && presents(i))
                    .filter(|_| surface.is_none() || has_swapchain(vk_instance, physical))
                    .map(|(i, f)| (i, f.timestamp_valid_bits, f.queue_flags));
                let name = properties
                    .device_name_as_c_str()
                    .unwrap_or(c"?")
                    .to_string_lossy()
                    .into_owned();
                Candidate {
                    physical,
                    properties,
                    name,
                    graphics_family,
                }
            })
            .collect();
        let chosen = choose(&candidates, knobs.device())?;
        let (queue_family, timestamp_valid_bits, flags) =
            chosen.graphics_family.expect("choose() checks this");
        explain::numbered(3, "VkPhysicalDevice chosen", || {
            let mut s = String::new();
            for (i, c) in candidates.iter().enumerate() {
                let mark = if c.physical == chosen.physical {
                    "->"
                } else {
                    "  "
                };
                let usable = if c.graphics_family.is_some() {
                    ""
                } else {
                    " (cannot draw/present here)"
                };
                s += &format!(
                    "{mark} {i}: {} [{:?}]{usable}
",
                    c.name, c.properties.device_type
                );
            }
            let why = if knobs.device().is_some() {
                "--vk-device (TWINRAY_VK_DEVICE) picked it"
            } else {
                "the most capable kind present (discrete > integrated > virtual > CPU)"
            };
            s + &format!(
                "why: {why}
queue family {queue_family}: {flags:?}, timestampValidBits {timestamp_valid_bits}{}",
                if surface.is_some() {
                    ", presents to the surface"
                } else {
                    ""
                }
            )
        });

        // One queue is enough: every frame is submitted and waited for in turn.
        let priorities = [1.0];
        let queue_infos = [vk::DeviceQueueCreateInfo::default()
            .queue_family_index(queue_family)
            .queue_priorities(&priorities)];
        // A window needs the swapchain, a device extension; headless needs none.
        let mut extensions = if surface.is_some() {
            vec![khr::swapchain::NAME.as_ptr()]
        } else {
            vec![]
        };
        // Optional, for --dump-shaders only: what the driver made of the shader.
        let executable_info = has_extension(
            &instance.instance,
            chosen.physical,
            khr::pipeline_executable_properties::NAME,
        );
        if executable_info {
            extensions.push(khr::pipeline_executable_properties::NAME.as_ptr());
        }
        let mut executable_features =
            vk::PhysicalDevicePipelineExecutablePropertiesFeaturesKHR::default()
                .pipeline_executable_info(true);
        // SAFETY: a query on the chosen physical device of the live instance.
        let offered = unsafe { vk_instance.get_physical_device_features(chosen.physical) };
        let fragment_stores = offered.fragment_stores_and_atomics == vk::TRUE;
        let features = vk::PhysicalDeviceFeatures::default()
            .fragment_stores_and_atomics(fragment_stores && count_rays);
        let recording = recording(knobs, instance, &chosen.properties)?;
        let mut vulkan_1_3 = vk::PhysicalDeviceVulkan13Features::default().synchronization2(true);
        let mut info = vk::DeviceCreateInfo::default()
            .queue_create_infos(&queue_infos)
            .enabled_extension_names(&extensions)
            .enabled_features(&features);
        if executable_info {
            info = info.push_next(&mut executable_features);
        }
        if recording == Recording::Synchronization2 {
            info = info.push_next(&mut vulkan_1_3);
        }
        // SAFETY: `chosen.physical` belongs to the live instance; the queue info names a family
        // that exists (found in its list) with one priority; every extension name is a 'static C
        // string the device offers (swapchain only with a surface, which has_swapchain checked; the
        // other only where has_extension found it); the feature structs chained with it outlive the
        // call, synchronization2's only where `recording` found Vulkan 1.3. The Device owns the result and destroys it on drop, after everything made on it.
        let device = unsafe { vk_instance.create_device(chosen.physical, &info, None) }
            .with_context(|| format!("opening the Vulkan device '{}'", chosen.name))?;
        // SAFETY: queue 0 of `queue_family` is the one queue the create info asked for.
        let queue = unsafe { device.get_device_queue(queue_family, 0) };
        explain::numbered(
            4,
            "VkDevice + VkQueue (vkCreateDevice, vkGetDeviceQueue)",
            || {
                let ext = if surface.is_some() {
                    "VK_KHR_swapchain"
                } else {
                    "none"
                };
                let features = if fragment_stores && count_rays {
                    "fragmentStoresAndAtomics (--count-rays)"
                } else {
                    "no optional features"
                };
                let features = match recording {
                    Recording::Synchronization2 => {
                        format!("{features}; synchronization2 (--vk-sync2)")
                    }
                    Recording::Vulkan10 => features.to_string(),
                };
                format!("1 queue from family {queue_family}, priority 1.0; device extensions: {ext}; {features}")
            },
        );
        let executable_properties = executable_info
            .then(|| khr::pipeline_executable_properties::Device::new(&instance.instance, &device));
        // SAFETY: a query on the chosen physical device of the live instance.
        let memory_properties =
            unsafe { vk_instance.get_physical_device_memory_properties(chosen.physical) };
        Ok(Device {
            executable_properties,
            physical: chosen.physical,
            properties: chosen.properties,
            memory_properties,
            name: chosen.name.clone(),
            driver: driver_description(instance, chosen),
            queue_family,
            timestamp_valid_bits,
            device,
            queue,
            fragment_stores: fragment_stores && count_rays,
            scene_memory: knobs.memory,
            recording,
        })
    }

    /// The largest storage buffer this device binds: what every run plan is checked against.
    pub fn storage_limit(&self) -> StorageLimit {
        StorageLimit {
            bytes: self.properties.limits.max_storage_buffer_range as u64,
            name: "this device's maxStorageBufferRange limit",
            texel_buffer: 0,
        }
    }

    /// The compute limits under Vulkan's names.
    pub fn compute_limits(&self) -> ComputeLimits {
        let l = &self.properties.limits;
        ComputeLimits {
            group_size: [
                l.max_compute_work_group_size[0],
                l.max_compute_work_group_size[1],
            ],
            invocations: l.max_compute_work_group_invocations,
            group_count: [
                l.max_compute_work_group_count[0],
                l.max_compute_work_group_count[1],
            ],
            names: [
                "maxComputeWorkGroupSize",
                "maxComputeWorkGroupInvocations",
                "maxComputeWorkGroupCount",
            ],
        }
    }

    /// What the `--json` report says about this device.
    pub fn info(&self) -> DeviceInfo {
        DeviceInfo {
            device: self.name.clone(),
            driver: self.driver.clone(),
            api_version: self.api_version(),
        }
    }

    /// "Vulkan 1.3.230": the version the device (not the loader) supports.
    pub fn api_version(&self) -> String {
        let v = self.properties.api_version;
        format!(
            "Vulkan {}.{}.{}",
            vk::api_version_major(v),
            vk::api_version_minor(v),
            vk::api_version_patch(v)
        )
    }

    /// Image and framebuffer sizes are bounded per device; say which limit a size breaks.
    pub fn check_size(&self, width: u32, height: u32) -> Result<()> {
        let l = &self.properties.limits;
        let checks = [
            (width, l.max_image_dimension2_d, "maxImageDimension2D"),
            (height, l.max_image_dimension2_d, "maxImageDimension2D"),
            (width, l.max_framebuffer_width, "maxFramebufferWidth"),
            (height, l.max_framebuffer_height, "maxFramebufferHeight"),
            (
                width,
                l.max_viewport_dimensions[0],
                "maxViewportDimensions[0]",
            ),
            (
                height,
                l.max_viewport_dimensions[1],
                "maxViewportDimensions[1]",
            ),
        ];
        match checks.iter().find(|(value, limit, _)| value > limit) {
            Some((_, limit, name)) => Err(bad_input(format!(
                "--size {width}x{height} exceeds this device's limit of {limit} ({name})"
            ))),
            None => Ok(()),
        }
    }

    /// Blocks until the GPU has finished everything submitted so far: before
    /// objects a frame may still use are replaced or destroyed.
    pub fn wait_idle(&self) -> ash::prelude::VkResult<()> {
        // SAFETY: the device is alive (self owns it) and twinray submits to its
        // one queue from this thread only, the external synchronisation that
        // vkDeviceWaitIdle asks for.
        unsafe { self.device.device_wait_idle() }
    }

    /// Records commands into a throwaway command buffer, runs them and waits.
    /// For setup and readback copies only; the timed frames use commands.rs.
    pub fn run_once(&self, what: &str, record: impl FnOnce(vk::CommandBuffer)) -> Result<()> {
        let d = &self.device;
        let info = vk::CommandPoolCreateInfo::default()
            .queue_family_index(self.queue_family)
            .flags(vk::CommandPoolCreateFlags::TRANSIENT);
        // SAFETY: a create on this live device; the pool is destroyed below on every path.
        let pool = unsafe { d.create_command_pool(&info, None) }
            .with_context(|| format!("creating a command pool for {what}"))?;
        let result = (|| -> ash::prelude::VkResult<()> {
            let alloc = vk::CommandBufferAllocateInfo::default()
                .command_pool(pool)
                .command_buffer_count(1);
            // SAFETY: `pool` is alive until the end of run_once and is used by this thread only.
            let cmd = unsafe { d.allocate_command_buffers(&alloc) }?[0];
            let begin = vk::CommandBufferBeginInfo::default()
                .flags(vk::CommandBufferUsageFlags::ONE_TIME_SUBMIT);
            // SAFETY: the buffer was just allocated, so it is in the initial state.
            unsafe { d.begin_command_buffer(cmd, &begin) }?;
            record(cmd);
            // SAFETY: the buffer is recording; `record` only records into it.
            unsafe { d.end_command_buffer(cmd) }?;
            let cmds = [cmd];
            let submit = vk::SubmitInfo::default().command_buffers(&cmds);
            // SAFETY: the buffer is recorded and submitted once (ONE_TIME_SUBMIT); every object it
            // names is the caller's, borrowed for the whole of run_once, so alive until the wait
            // below; only this thread uses the queue.
            unsafe { d.queue_submit(self.queue, &[submit], vk::Fence::null()) }?;
            // Setup only, so waiting for the whole queue is simpler than a fence.
            // SAFETY: a wait on the queue of this live device.
            unsafe { d.queue_wait_idle(self.queue) }
        })();
        // Destroying the pool frees its command buffer too.
        // SAFETY: the queue is idle (waited above) or nothing was submitted, so the buffer is not
        // pending.
        unsafe { d.destroy_command_pool(pool, None) };
        result.with_context(|| format!("running the commands for {what}"))
    }
}

/// Whether the device can make swapchains at all.
fn has_swapchain(instance: &ash::Instance, physical: vk::PhysicalDevice) -> bool {
    has_extension(instance, physical, khr::swapchain::NAME)
}

fn has_extension(
    instance: &ash::Instance,
    physical: vk::PhysicalDevice,
    name: &std::ffi::CStr,
) -> bool {
    // SAFETY: a valid physical device of this instance.
    let exts =
        unsafe { instance.enumerate_device_extension_properties(physical) }.unwrap_or_default();
    exts.iter().any(|e| e.extension_name_as_c_str() == Ok(name))
}

/// `wanted` (`--vk-device`: an index or part of a name) wins; otherwise the kind of
/// device most likely to be fast: discrete, integrated, virtual, then CPU.
fn choose<'a>(candidates: &'a [Candidate], wanted: Option<&str>) -> Result<&'a Candidate> {
    if let Some(wanted) = wanted {
        let needle = wanted.to_lowercase();
        // A number is an index, never part of a name ("1" is in "LLVM 15.0.6").
        let found = match needle.parse::<usize>() {
            Ok(i) => candidates.get(i),
            Err(_) => candidates
                .iter()
                .find(|c| c.name.to_lowercase().contains(&needle)),
        };
        let list: Vec<String> = candidates
            .iter()
            .enumerate()
            .map(|(i, c)| format!("{i}: {}", c.name))
            .collect();
        let c = found.ok_or_else(|| {
            bad_input(format!(
                "--vk-device (TWINRAY_VK_DEVICE) '{wanted}' matches no Vulkan device; the devices are {}",
                list.join(", ")
            ))
        })?;
        if c.graphics_family.is_none() {
            return Err(bad_input(format!(
                "--vk-device (TWINRAY_VK_DEVICE) '{wanted}' picks '{}', which cannot draw here (no graphics queue, or none that presents to the window)",
                c.name
            )));
        }
        return Ok(c);
    }
    let rank = |t: vk::PhysicalDeviceType| match t {
        vk::PhysicalDeviceType::DISCRETE_GPU => 0,
        vk::PhysicalDeviceType::INTEGRATED_GPU => 1,
        vk::PhysicalDeviceType::VIRTUAL_GPU => 2,
        vk::PhysicalDeviceType::CPU => 3,
        _ => 4,
    };
    let drawable = candidates.iter().filter(|c| c.graphics_family.is_some());
    drawable.min_by_key(|c| rank(c.properties.device_type)).ok_or_else(|| {
        no_device("no Vulkan device can draw (no graphics queue): install mesa-vulkan-drivers or a GPU driver")
    })
}

/// The driver's own name ("llvmpipe Mesa 22.3.6 ...") needs Vulkan 1.2 on both
/// the instance and the device; before that there is only a vendor-coded number.
fn driver_description(instance: &Instance, c: &Candidate) -> String {
    if instance.api_version < vk::API_VERSION_1_2 || c.properties.api_version < vk::API_VERSION_1_2
    {
        return format!("driverVersion {:#x}", c.properties.driver_version);
    }
    let mut driver = vk::PhysicalDeviceDriverProperties::default();
    let mut props2 = vk::PhysicalDeviceProperties2::default().push_next(&mut driver);
    // SAFETY: `c.physical` belongs to the live instance, which (like the device)
    // is at least Vulkan 1.2, checked above, so vkGetPhysicalDeviceProperties2
    // and the driver-properties struct exist; `driver` outlives the call.
    unsafe {
        instance
            .instance
            .get_physical_device_properties2(c.physical, &mut props2)
    };
    let text = |s: Result<&std::ffi::CStr, _>| s.unwrap_or(c"?").to_string_lossy().into_owned();
    format!(
        "{} {}",
        text(driver.driver_name_as_c_str()),
        text(driver.driver_info_as_c_str())
    )
}

impl Drop for Device {
    fn drop(&mut self) {
        // SAFETY: every object made on this device was dropped before it (see app.rs).
        unsafe { self.device.destroy_device(None) };
        explain::numbered(20, "Device::drop: vkDestroyDevice", String::new);
    }
}

/// The barrier calls a run records with: synchronization2 with `--vk-sync2`,
/// which needs Vulkan 1.3 of the loader and the device (where it is core, so
/// every 1.3 device offers the feature).
fn recording(
    knobs: &VulkanKnobs,
    instance: &Instance,
    properties: &vk::PhysicalDeviceProperties,
) -> Result<Recording> {
    if !knobs.sync2 {
        return Ok(Recording::Vulkan10);
    }
    let version = instance.api_version.min(properties.api_version);
    if version < vk::API_VERSION_1_3 {
        return Err(bad_input(format!(
            "--vk-sync2 needs Vulkan 1.3, and this loader and device offer {}.{}: leave it out to record Vulkan 1.0 barriers",
            vk::api_version_major(version),
            vk::api_version_minor(version)
        )));
    }
    Ok(Recording::Synchronization2)
}
