//! The Vulkan window's own test hook (not a user option):
//! `TWINRAY_TEST_OUT_OF_DATE=N` makes every Nth swapchain acquire report
//! `VK_ERROR_OUT_OF_DATE_KHR` without acquiring anything, as a window system
//! may when the window changed since the swapchain was made. lavapipe under
//! Xvfb reports a resize at the present, not at the acquire, so without this
//! the acquire's out-of-date path (and the walkthrough's exercise 3, which
//! breaks it) never runs there. Read only in a build with the cargo feature
//! `test-hooks`; any other build refuses it, as it refuses twinray-common's
//! window hooks, so a test cannot pass without having forced anything.

use anyhow::Result;
use twinray_common::error::bad_input;

const NAME: &str = "TWINRAY_TEST_OUT_OF_DATE";

/// Counts acquires and says which ones to fail.
#[derive(Default)]
pub struct ForcedOutOfDate {
    every: Option<u32>,
    acquires: u32,
}

impl ForcedOutOfDate {
    /// The hook as the environment sets it (off when unset).
    pub fn from_env() -> Result<ForcedOutOfDate> {
        let Some(value) = std::env::var_os(NAME) else {
            return Ok(ForcedOutOfDate::default());
        };
        if !cfg!(feature = "test-hooks") {
            return Err(bad_input(format!(
                "{NAME} is a test hook, and this build has none: build the app with `--features test-hooks` (tests/run.sh does)"
            )));
        }
        let text = value.to_string_lossy();
        let every = text.trim().parse::<u32>().ok().filter(|&n| n >= 1);
        match every {
            Some(n) => Ok(ForcedOutOfDate {
                every: Some(n),
                acquires: 0,
            }),
            None => Err(bad_input(format!(
                "{NAME}: '{text}' is not a whole number of acquires of at least 1"
            ))),
        }
    }

    /// Whether this acquire is to report out of date instead of running.
    pub fn this_acquire(&mut self) -> bool {
        let Some(every) = self.every else {
            return false;
        };
        self.acquires += 1;
        self.acquires % every == 0
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_third_acquire_is_forced() {
        let mut hook = ForcedOutOfDate {
            every: Some(3),
            acquires: 0,
        };
        let forced: Vec<bool> = (0..6).map(|_| hook.this_acquire()).collect();
        assert_eq!(forced, [false, false, true, false, false, true]);
        assert!(
            !ForcedOutOfDate::default().this_acquire(),
            "off unless asked for"
        );
    }
}
