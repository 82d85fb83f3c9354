//! What the driver made of the tracer, for `--dump-shaders`: the pipeline
//! executable statistics of VK_KHR_pipeline_executable_properties (registers,
//! local memory, instruction counts: each driver names its own), where the
//! device offers the extension.
//!
//! Capturing is asked for per pipeline (`CAPTURE_STATISTICS`), so it is on
//! only for runs that dump: a timed run compiles exactly what it always did.
//! The pipelines are created deep in the setup, so the statistics are gathered
//! in one process-wide list, like the validation-message count.

use crate::device::Device;
use ash::vk;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Mutex;
use twinray_common::report::ShaderStats;

static CAPTURE: AtomicBool = AtomicBool::new(false);
static CAPTURED: Mutex<Vec<ShaderStats>> = Mutex::new(Vec::new());

/// From now on, pipelines ask the driver to keep their statistics.
pub fn enable() {
    CAPTURE.store(true, Ordering::SeqCst);
}

/// The create flags a pipeline needs for `capture`.
pub fn pipeline_flags(device: &Device) -> vk::PipelineCreateFlags {
    if CAPTURE.load(Ordering::SeqCst) && device.executable_properties.is_some() {
        vk::PipelineCreateFlags::CAPTURE_STATISTICS_KHR
    } else {
        vk::PipelineCreateFlags::empty()
    }
}

/// Reads and keeps the statistics of a pipeline made with `pipeline_flags`.
/// A driver that declines is no error: the dump says what was offered.
pub fn capture(device: &Device, pipeline: vk::Pipeline, what: &str) {
    if pipeline_flags(device).is_empty() {
        return;
    }
    let Some(ext) = &device.executable_properties else {
        return;
    };
    let info = vk::PipelineInfoKHR::default().pipeline(pipeline);
    // SAFETY: a live pipeline of this device, created with CAPTURE_STATISTICS.
    let Ok(executables) = (unsafe { ext.get_pipeline_executable_properties(&info) }) else {
        return;
    };
    let mut captured = CAPTURED.lock().unwrap_or_else(|e| e.into_inner());
    for (index, exe) in executables.iter().enumerate() {
        let exe_info = vk::PipelineExecutableInfoKHR::default()
            .pipeline(pipeline)
            .executable_index(index as u32);
        // SAFETY: the index comes from the driver's own list for this pipeline.
        let stats =
            unsafe { ext.get_pipeline_executable_statistics(&exe_info) }.unwrap_or_default();
        let statistics = stats
            .iter()
            .map(|s| {
                let name = s
                    .name_as_c_str()
                    .map(|c| c.to_string_lossy().into_owned())
                    .unwrap_or_default();
                // SAFETY: `format` says which member of the union the driver wrote.
                let value = unsafe {
                    match s.format {
                        vk::PipelineExecutableStatisticFormatKHR::BOOL32 => {
                            (s.value.b32 != 0).to_string()
                        }
                        vk::PipelineExecutableStatisticFormatKHR::INT64 => s.value.i64.to_string(),
                        vk::PipelineExecutableStatisticFormatKHR::UINT64 => s.value.u64.to_string(),
                        vk::PipelineExecutableStatisticFormatKHR::FLOAT64 => {
                            s.value.f64.to_string()
                        }
                        _ => "?".to_string(),
                    }
                };
                (name, value)
            })
            .collect();
        captured.push(ShaderStats {
            pipeline: what.to_string(),
            stage: exe
                .name_as_c_str()
                .map(|c| c.to_string_lossy().into_owned())
                .unwrap_or_default(),
            statistics,
        });
    }
}

/// Everything captured so far.
pub fn captured() -> Vec<ShaderStats> {
    CAPTURED.lock().unwrap_or_else(|e| e.into_inner()).clone()
}
