//! The hooks the end-to-end tests drive a window with under Xvfb (not user
//! options): `TWINRAY_TEST_RESIZE=1` makes the app resize its own window on
//! every frame and minimize/restore it now and then; `TWINRAY_TEST_KEYS=2,p,+,-,r,1`
//! presses those keys' actions, one per frame. They are read only in a build
//! with the cargo feature `test-hooks` (tests/run.sh builds the apps with it);
//! any other build refuses them, so a test run against such a build fails
//! clearly instead of passing without having pressed anything.

use crate::error::bad_input;
use crate::window::keys::Action;

/// The actions of `TWINRAY_TEST_KEYS`, last first (popped from the end).
#[cfg(feature = "test-hooks")]
pub fn test_keys() -> anyhow::Result<Vec<Action>> {
    let Ok(list) = std::env::var("TWINRAY_TEST_KEYS") else {
        return Ok(Vec::new());
    };
    let mut actions: Vec<Action> = list
        .split(',')
        .filter(|k| !k.trim().is_empty())
        .map(|k| match k.trim() {
            "esc" => Ok(Action::Quit),
            c => crate::window::keys::action_for_char(c)
                .ok_or_else(|| bad_input(format!("TWINRAY_TEST_KEYS: '{c}' is no key of the app"))),
        })
        .collect::<anyhow::Result<_>>()?;
    actions.reverse(); // popped from the end
    Ok(actions)
}

/// Whether `TWINRAY_TEST_RESIZE=1` asks for the resize test.
#[cfg(feature = "test-hooks")]
pub fn resize_test() -> anyhow::Result<bool> {
    Ok(std::env::var("TWINRAY_TEST_RESIZE").is_ok_and(|v| v == "1"))
}

#[cfg(not(feature = "test-hooks"))]
pub fn test_keys() -> anyhow::Result<Vec<Action>> {
    refuse("TWINRAY_TEST_KEYS").map(|()| Vec::new())
}

#[cfg(not(feature = "test-hooks"))]
pub fn resize_test() -> anyhow::Result<bool> {
    refuse("TWINRAY_TEST_RESIZE").map(|()| false)
}

#[cfg(not(feature = "test-hooks"))]
fn refuse(name: &str) -> anyhow::Result<()> {
    match std::env::var_os(name) {
        None => Ok(()),
        Some(_) => Err(bad_input(format!(
            "{name} is a test hook, and this build has none: build the app with `--features test-hooks` (tests/run.sh does)"
        ))),
    }
}
