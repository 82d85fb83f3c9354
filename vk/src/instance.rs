//! The loader and the instance, plus the optional validation layer.
//!
//! Vulkan is not a library the app links against but a *loader* (libvulkan.so.1)
//! that finds the installed drivers at run time; `ash::Entry` opens it. The
//! `VkInstance` is this application's connection to the loader: it is where the
//! app states the Vulkan version it targets and the layers and extensions it
//! wants, and it is the only way to list the GPUs.
//!
//! Drivers do almost no error checking (that is part of why Vulkan is fast), so
//! correctness checking is an opt-in *layer* between the app and the driver:
//! VK_LAYER_KHRONOS_validation, which reports through a VK_EXT_debug_utils
//! messenger, a callback we provide.

use anyhow::{Context, Result};
use ash::{ext::debug_utils, vk};
use std::ffi::{c_char, c_void, CStr};
use std::sync::atomic::{AtomicU64, Ordering};
use twinray_common::error::no_device;
use twinray_common::explain;

const VALIDATION_LAYER: &CStr = c"VK_LAYER_KHRONOS_validation";

/// Warnings and errors the layer reported. The app reads it after every Vulkan
/// object is destroyed, so mistakes in teardown count too.
pub static VALIDATION_MESSAGES: AtomicU64 = AtomicU64::new(0);

pub struct Instance {
    pub entry: ash::Entry,
    pub instance: ash::Instance,
    /// The Vulkan version this app asked the loader for.
    pub api_version: u32,
    messenger: Option<(debug_utils::Instance, vk::DebugUtilsMessengerEXT)>,
}

impl Instance {
    /// `validate` is `--validate`: the layer is then required, not optional;
    /// `best_effort` is `--vk-validation`: on where installed, a note where not.
    /// `window_extensions` are the surface extensions a window needs (none headless).
    /// `sync2` is `--vk-sync2`: Vulkan 1.3 is asked for, whose synchronization2
    /// records the barriers (barrier.rs).
    // Long function: the walkthrough's first step in order (layers, extensions, application info, create, debug messenger), one block each.
    pub fn new(
        validate: bool,
        best_effort: bool,
        window_extensions: &[*const c_char],
        sync2: bool,
    ) -> Result<Instance> {
        // SAFETY: dlopens the system's libvulkan.so.1 (its initialisers are the
        // loader's own); the Entry keeps it loaded while any of its function
        // pointers can be called, as the Instance holds the Entry.
        let entry = unsafe { ash::Entry::load() }.map_err(|_| {
            no_device(
                "no Vulkan loader found (libvulkan.so.1): install libvulkan1 and a Vulkan driver, e.g. mesa-vulkan-drivers",
            )
        })?;
        explain::numbered(
            1,
            "Loader: libvulkan.so.1 opened (ash::Entry::load)",
            || "the loader finds the installed drivers (ICDs) and layers at run time".into(),
        );

        // The layer checks every call, which costs CPU time on every submit, and a
        // timing run must not pay for it. So it is on only when asked for:
        // --validate (required) or --vk-validation / TWINRAY_VK_VALIDATION=1 (best effort).
        // SAFETY: a global query through the loader `entry` just opened, which lives in the
        // returned Instance.
        let layers = unsafe { entry.enumerate_instance_layer_properties() }
            .context("listing Vulkan layers")?;
        let installed = layers
            .iter()
            .any(|l| l.layer_name_as_c_str() == Ok(VALIDATION_LAYER));
        if validate && !installed {
            return Err(no_device(
                "--validate needs VK_LAYER_KHRONOS_validation, which is not installed: install vulkan-validationlayers",
            ));
        }
        if best_effort && !installed {
            eprintln!(
                "twinray-vk: --vk-validation (TWINRAY_VK_VALIDATION) is on but the validation layer is not installed; running without it"
            );
        }
        let validation = installed && (validate || best_effort);

        // Vulkan 1.2 is asked for only to read VkPhysicalDeviceDriverProperties (the
        // driver's name for the report), 1.3 only for --vk-sync2. A 1.0 loader
        // rejects any higher version.
        // SAFETY: a global query through the open loader.
        let loader_version = unsafe { entry.try_enumerate_instance_version() }
            .context("asking the loader for its Vulkan version")?
            .unwrap_or(vk::API_VERSION_1_0);
        let wanted = if sync2 {
            vk::API_VERSION_1_3
        } else {
            vk::API_VERSION_1_2
        };
        let api_version = loader_version.min(wanted);
        let app = vk::ApplicationInfo::default()
            .application_name(c"twinray-vk")
            .engine_name(c"twinray")
            .api_version(api_version);
        let layer_names = [VALIDATION_LAYER.as_ptr()];
        let mut extension_names = window_extensions.to_vec();
        if validation {
            extension_names.push(debug_utils::NAME.as_ptr());
        }
        let mut early_messenger = messenger_info();
        let mut info = vk::InstanceCreateInfo::default()
            .application_info(&app)
            .enabled_extension_names(&extension_names);
        if validation {
            // Chained here, the messenger also hears about vkCreateInstance and
            // vkDestroyInstance, when the real messenger does not exist yet or any more.
            info = info
                .enabled_layer_names(&layer_names)
                .push_next(&mut early_messenger);
        }
        // SAFETY: every pointer in `info` (application info, the 'static layer and extension names,
        // the chained messenger info whose callback is a plain function) outlives the call; the
        // layer is enabled only where it is installed. The Instance returned owns the result and
        // destroys it on drop, after every device object (app.rs orders the drops).
        let instance = unsafe { entry.create_instance(&info, None) }.map_err(|e| match e {
            vk::Result::ERROR_INCOMPATIBLE_DRIVER => {
                no_device("the Vulkan loader found no usable driver: install mesa-vulkan-drivers or a GPU driver")
            }
            e => anyhow::Error::new(e).context("creating the Vulkan instance"),
        })?;

        explain::numbered(1, "VkInstance (vkCreateInstance)", || {
            let v = |v: u32| {
                format!(
                    "{}.{}.{}",
                    vk::api_version_major(v),
                    vk::api_version_minor(v),
                    vk::api_version_patch(v)
                )
            };
            let names: Vec<String> = extension_names
                .iter()
                // SAFETY: every pointer comes from a 'static C string (ash or ash-window).
                .map(|&p| unsafe { CStr::from_ptr(p) }.to_string_lossy().into_owned())
                .collect();
            format!(
                "API version {} requested (loader supports {}; 1.2 only to read the driver's name, 1.3 for --vk-sync2)\n\
                 layers: {}\nextensions: {}",
                v(api_version),
                v(loader_version),
                if validation { "VK_LAYER_KHRONOS_validation" } else { "none (no --validate: timings don't pay for checks)" },
                if names.is_empty() { "none".to_string() } else { names.join(", ") },
            )
        });

        // From here on, `Drop` cleans up whatever was created, even on error.
        let mut this = Instance {
            entry,
            instance,
            api_version,
            messenger: None,
        };
        if validation {
            let functions = debug_utils::Instance::new(&this.entry, &this.instance);
            // SAFETY: the instance was created with VK_EXT_debug_utils enabled (validation is on),
            // so the functions exist; `this` destroys the messenger before the instance.
            let messenger =
                unsafe { functions.create_debug_utils_messenger(&messenger_info(), None) }
                    .context("creating the debug messenger")?;
            this.messenger = Some((functions, messenger));
            explain::numbered(2, "VkDebugUtilsMessengerEXT", || {
                "severity WARNING|ERROR, types GENERAL|VALIDATION|PERFORMANCE: every message is counted and fails --validate".into()
            });
        }
        Ok(this)
    }
}

/// Warnings and errors only: "info" and "verbose" are chatter, not mistakes.
fn messenger_info() -> vk::DebugUtilsMessengerCreateInfoEXT<'static> {
    vk::DebugUtilsMessengerCreateInfoEXT::default()
        .message_severity(
            vk::DebugUtilsMessageSeverityFlagsEXT::WARNING
                | vk::DebugUtilsMessageSeverityFlagsEXT::ERROR,
        )
        .message_type(
            vk::DebugUtilsMessageTypeFlagsEXT::GENERAL
                | vk::DebugUtilsMessageTypeFlagsEXT::VALIDATION
                | vk::DebugUtilsMessageTypeFlagsEXT::PERFORMANCE,
        )
        .pfn_user_callback(Some(on_message))
}

/// Called by the layer, on whichever thread made the faulty call.
unsafe extern "system" fn on_message(
    severity: vk::DebugUtilsMessageSeverityFlagsEXT,
    kind: vk::DebugUtilsMessageTypeFlagsEXT,
    data: *const vk::DebugUtilsMessengerCallbackDataEXT<'_>,
    _user_data: *mut c_void,
) -> vk::Bool32 {
    VALIDATION_MESSAGES.fetch_add(1, Ordering::Relaxed);
    // SAFETY: the layer passes a valid struct (or null) for the duration of the call.
    let text = unsafe { data.as_ref().and_then(|d| d.message_as_c_str()) };
    let text = text.map(CStr::to_string_lossy).unwrap_or_default();
    eprintln!("twinray-vk: validation {severity:?} {kind:?}: {text}");
    // FALSE = let the call go ahead; we count and carry on to see every message.
    vk::FALSE
}

impl Drop for Instance {
    fn drop(&mut self) {
        // SAFETY: every device object was dropped before the instance (see app.rs).
        unsafe {
            if let Some((functions, messenger)) = self.messenger.take() {
                functions.destroy_debug_utils_messenger(messenger, None);
            }
            self.instance.destroy_instance(None);
        }
        explain::numbered(
            20,
            "Instance::drop: vkDestroyDebugUtilsMessengerEXT (with --validate), vkDestroyInstance",
            String::new,
        );
    }
}
