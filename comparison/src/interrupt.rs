//! The signals that stop a long comparison: SIGINT (Ctrl-C), SIGTERM (a job
//! scheduler, `kill`, a container's stop) and SIGHUP (a closed terminal). Each
//! only raises a flag that every step polls between runs, so the runs that
//! finished are kept and the report is written; the exit code then says which
//! signal it was, the way a shell reports a process the signal killed
//! (128 + its number: 130, 143, 129). The flag is the process's one: the
//! supervisor that runs every child app (`supervisor`) reads it to pass the
//! signal on to the running child, however deep in a step that child was started.

use anyhow::Context;
use signal_hook::consts::{SIGHUP, SIGINT, SIGTERM};
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::sync::{Arc, OnceLock};

const SIGNALS: [(i32, &str); 3] = [(SIGINT, "SIGINT"), (SIGTERM, "SIGTERM"), (SIGHUP, "SIGHUP")];

/// The process's one `Stop`, once a command installed it.
static STOP: OnceLock<Stop> = OnceLock::new();

/// Whether a stopping signal arrived, and which (the last, if several did).
/// Every clone reads the same flags.
#[derive(Clone)]
pub struct Stop {
    flag: Arc<AtomicBool>,
    signal: Arc<AtomicUsize>,
}

impl Stop {
    /// Takes SIGINT, SIGTERM and SIGHUP over from their default (ending the
    /// process at once, losing every finished point).
    pub fn install() -> anyhow::Result<Stop> {
        if let Some(stop) = STOP.get() {
            return Ok(stop.clone());
        }
        let stop = Stop {
            flag: Arc::new(AtomicBool::new(false)),
            signal: Arc::new(AtomicUsize::new(0)),
        };
        for (signal, name) in SIGNALS {
            // The number first: whoever sees the flag raised finds it set.
            signal_hook::flag::register_usize(signal, stop.signal.clone(), signal as usize)
                .and_then(|_| signal_hook::flag::register(signal, stop.flag.clone()))
                .with_context(|| format!("installing the {name} handler"))?;
        }
        Ok(STOP.get_or_init(|| stop).clone())
    }

    /// The installed `Stop`, if a command installed one.
    pub fn current() -> Option<&'static Stop> {
        STOP.get()
    }

    /// The signal's number, once one arrived.
    pub fn number(&self) -> Option<i32> {
        self.stopped()
            .then(|| self.signal.load(Ordering::SeqCst) as i32)
    }

    /// The flag the steps poll.
    pub fn flag(&self) -> &AtomicBool {
        &self.flag
    }

    pub fn stopped(&self) -> bool {
        self.flag.load(Ordering::SeqCst)
    }

    /// The signal's name and the exit code it gives, once one arrived.
    pub fn signal(&self) -> Option<(&'static str, i32)> {
        if !self.stopped() {
            return None;
        }
        let n = self.signal.load(Ordering::SeqCst) as i32;
        let name = SIGNALS
            .iter()
            .find(|(s, _)| *s == n)
            .map_or("a signal", |(_, name)| name);
        Some((name, 128 + n))
    }
}
