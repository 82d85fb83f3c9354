//! Failure kinds and the exit codes of the command-line contract:
//! 0 success, 2 bad input, 3 no usable GPU/driver, 1 anything else.

use std::fmt;

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum FailureKind {
    /// A scene file, option or value the user gave is wrong (exit 2).
    BadInput,
    /// No usable GPU, driver or loader (exit 3).
    NoDevice,
}

impl FailureKind {
    pub fn exit_code(self) -> i32 {
        match self {
            FailureKind::BadInput => 2,
            FailureKind::NoDevice => 3,
        }
    }
}

/// An error that carries its exit code. The message is one sentence that names
/// the file, option or value at fault.
#[derive(Debug)]
pub struct Failure {
    pub kind: FailureKind,
    pub message: String,
}

impl fmt::Display for Failure {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.message)
    }
}

impl std::error::Error for Failure {}

/// Shorthand: `Err(bad_input(format!(..)))?`.
pub fn bad_input(message: impl Into<String>) -> anyhow::Error {
    Failure {
        kind: FailureKind::BadInput,
        message: message.into(),
    }
    .into()
}

pub fn no_device(message: impl Into<String>) -> anyhow::Error {
    Failure {
        kind: FailureKind::NoDevice,
        message: message.into(),
    }
    .into()
}

/// The exit code an error maps to: the first `Failure` in its chain decides.
pub fn exit_code_of(err: &anyhow::Error) -> i32 {
    err.chain()
        .find_map(|e| e.downcast_ref::<Failure>())
        .map(|f| f.kind.exit_code())
        .unwrap_or(1)
}

/// Prints the error as one line (`program: outer: inner`) and exits with its code.
/// For a `Failure` only its own sentence is printed: it already names what is wrong.
pub fn exit_with(program: &str, err: anyhow::Error) -> ! {
    let msg = match err.chain().find_map(|e| e.downcast_ref::<Failure>()) {
        Some(f) => f.message.clone(),
        None => err
            .chain()
            .map(|e| e.to_string())
            .collect::<Vec<_>>()
            .join(": "),
    };
    eprintln!("{program}: error: {msg}");
    std::process::exit(exit_code_of(&err));
}

/// A dependency's error text without the source location some crates put in
/// their Display (winit: "os error at /root/.cargo/registry/src/…/mod.rs:760: …"):
/// the user needs the reason, not where in a crate it was raised.
pub fn without_source_location(message: &str) -> String {
    match message.rfind(".rs:") {
        Some(i) => {
            let rest = &message[i + 4..];
            let rest = rest.trim_start_matches(|c: char| c.is_ascii_digit() || c == ':');
            rest.trim().trim_end_matches('.').to_string()
        }
        None => message.to_string(),
    }
}

#[cfg(test)]
mod tests {
    #[test]
    fn source_location_is_dropped() {
        let winit = "os error at /root/.cargo/registry/src/index.crates.io-1949cf8c6b5b557f/winit-0.30.12/src/platform_impl/linux/mod.rs:764: neither WAYLAND_DISPLAY nor WAYLAND_SOCKET nor DISPLAY is set.";
        assert_eq!(
            super::without_source_location(winit),
            "neither WAYLAND_DISPLAY nor WAYLAND_SOCKET nor DISPLAY is set"
        );
        assert_eq!(super::without_source_location("plain"), "plain");
    }
}
