//! GL error reporting: the KHR_debug callback and glGetError checks, both
//! feeding one count that becomes the report's `validation_messages`.

use glow::HasContext;
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::Arc;
use twinray_common::explain;

/// Errors seen so far. The callback may be called from any driver thread,
/// hence the shared atomic. One fault can count twice (callback and
/// glGetError): the count decides pass or fail, it is not a tally.
#[derive(Clone, Default)]
pub struct DebugLog {
    errors: Arc<AtomicU64>,
}

impl DebugLog {
    /// Installs the callback (core since 4.3, so always there on our 4.5
    /// context). Without a debug context drivers may report little, but what
    /// they do report still counts.
    pub fn install(gl: &mut glow::Context) -> DebugLog {
        let log = DebugLog::default();
        let errors = log.errors.clone();
        // SAFETY: the callback only touches the shared counter and stderr.
        unsafe {
            gl.enable(glow::DEBUG_OUTPUT);
            // Synchronous, so that a message is printed next to the call that caused it.
            gl.enable(glow::DEBUG_OUTPUT_SYNCHRONOUS);
            gl.debug_message_callback(move |_source, kind, id, severity, message| {
                // Performance and portability notes are not failures; only
                // errors (and anything the driver calls high severity) are.
                if kind == glow::DEBUG_TYPE_ERROR || severity == glow::DEBUG_SEVERITY_HIGH {
                    errors.fetch_add(1, Ordering::Relaxed);
                    eprintln!("twinray-gl: GL debug error {id:#x}: {message}");
                }
            });
        }
        explain::numbered(2, "KHR_debug: glDebugMessageCallback", || {
            "DEBUG_OUTPUT + DEBUG_OUTPUT_SYNCHRONOUS; errors and high-severity messages are counted"
                .into()
        });
        log
    }

    /// Drains glGetError; `stage` says where in the run the error surfaced,
    /// since glGetError cannot say which call set it.
    pub fn check(&self, gl: &glow::Context, stage: &str) {
        // Bounded: a lost context can return errors forever.
        for _ in 0..32 {
            // SAFETY: plain query on the current context.
            let e = unsafe { gl.get_error() };
            if e == glow::NO_ERROR {
                break;
            }
            self.errors.fetch_add(1, Ordering::Relaxed);
            eprintln!("twinray-gl: glGetError {e:#x} {stage}");
        }
    }

    pub fn errors(&self) -> u64 {
        self.errors.load(Ordering::Relaxed)
    }
}
