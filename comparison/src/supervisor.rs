//! The one way the orchestrator runs a child app, for every step of
//! `compare`, `accuracy` and `ulp` and for `render`: it waits on the child
//! while watching the process's stop flag (`interrupt`). When SIGINT, SIGTERM
//! or SIGHUP arrives, the child gets the same signal (a signal sent to this
//! process alone never reaches it otherwise), then SIGKILL if it has not ended
//! within `GRACE`, so that a hung app cannot hold the orchestrator: the step
//! sees `Interrupted` within about a second and the report is written. Once a
//! signal has come no child is started at all.

use crate::interrupt::Stop;
use anyhow::Context;
use std::io::Read;
use std::process::{Child, Command, ExitStatus, Output, Stdio};
use std::time::{Duration, Instant};

/// How long a signalled child may take to end before it is killed: long
/// enough for an app to remove its temporary files, short enough that the
/// orchestrator's own exit stays within a second or two.
const GRACE: Duration = Duration::from_millis(500);

/// How often the child and the stop flag are looked at.
const POLL: Duration = Duration::from_millis(10);

/// A run that a stopping signal ended (or kept from starting): not a failure
/// of the app, and never recorded as one.
#[derive(Debug)]
pub struct Interrupted {
    pub signal: &'static str,
}

impl std::fmt::Display for Interrupted {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "interrupted by {}", self.signal)
    }
}

impl std::error::Error for Interrupted {}

/// Whether `e` (or what it wraps) is an interruption rather than a failure.
pub fn is_interrupted(e: &anyhow::Error) -> bool {
    e.chain().any(|c| c.downcast_ref::<Interrupted>().is_some())
}

fn interrupted(stop: &Stop) -> anyhow::Error {
    Interrupted {
        signal: stop.signal().map_or("a signal", |(name, _)| name),
    }
    .into()
}

/// Runs `cmd` to its end with stdout and stderr captured, as
/// `Command::output` does, unless a stopping signal comes first; with the
/// child's process id, which `sweep` records to show that every run had a
/// process of its own.
pub fn output_with_pid(mut cmd: Command, what: &str) -> anyhow::Result<(Output, u32)> {
    if let Some(stop) = Stop::current().filter(|s| s.stopped()) {
        return Err(interrupted(stop));
    }
    let mut child = cmd
        .stdin(Stdio::null())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .with_context(|| format!("starting {what}"))?;
    let pid = child.id();
    // Read while the child runs: a full pipe would otherwise block it forever.
    let drain = |pipe: Option<Box<dyn Read + Send>>| {
        std::thread::spawn(move || {
            let mut bytes = Vec::new();
            if let Some(mut p) = pipe {
                let _ = p.read_to_end(&mut bytes);
            }
            bytes
        })
    };
    let stdout = drain(
        child
            .stdout
            .take()
            .map(|p| Box::new(p) as Box<dyn Read + Send>),
    );
    let stderr = drain(
        child
            .stderr
            .take()
            .map(|p| Box::new(p) as Box<dyn Read + Send>),
    );
    let collect = |h: std::thread::JoinHandle<Vec<u8>>| h.join().unwrap_or_default();
    match wait(&mut child, what)? {
        Waited::Exited(status) => Ok((
            Output {
                status,
                stdout: collect(stdout),
                stderr: collect(stderr),
            },
            pid,
        )),
        // The readers are not waited for: a process the app started may
        // still hold the pipes, and they end by themselves when it lets go.
        Waited::Stopped(e) => Err(e),
    }
}

/// Runs `cmd` with the terminal's stdout and stderr, as `Command::status` does,
/// unless a stopping signal comes first (`render`, which shows the app's own output).
pub fn status(mut cmd: Command, what: &str) -> anyhow::Result<ExitStatus> {
    if let Some(stop) = Stop::current().filter(|s| s.stopped()) {
        return Err(interrupted(stop));
    }
    let mut child = cmd.spawn().with_context(|| format!("starting {what}"))?;
    match wait(&mut child, what)? {
        Waited::Exited(status) => Ok(status),
        Waited::Stopped(e) => Err(e),
    }
}

enum Waited {
    Exited(ExitStatus),
    Stopped(anyhow::Error),
}

/// Waits for `child`, passing a stopping signal on to it and killing it when
/// it outlives `GRACE`. A child that fails while the flag is up is reported
/// as stopped: the signal (a terminal's Ctrl-C reaches the whole process
/// group) is why it ended. One that succeeded finished its run: kept.
fn wait(child: &mut Child, what: &str) -> anyhow::Result<Waited> {
    let waiting = |e| anyhow::Error::new(e).context(format!("waiting for {what}"));
    let mut signalled: Option<Instant> = None;
    loop {
        if let Some(status) = child.try_wait().map_err(waiting)? {
            return Ok(match Stop::current().filter(|s| s.stopped()) {
                Some(stop) if !status.success() => Waited::Stopped(interrupted(stop)),
                _ => Waited::Exited(status),
            });
        }
        if let Some(stop) = Stop::current().filter(|s| s.stopped()) {
            match signalled {
                None => {
                    send(child, stop.number().unwrap_or(libc::SIGTERM));
                    signalled = Some(Instant::now());
                }
                Some(at) if at.elapsed() > GRACE => {
                    let _ = child.kill();
                    let _ = child.wait();
                    return Ok(Waited::Stopped(interrupted(stop)));
                }
                Some(_) => {}
            }
        }
        std::thread::sleep(POLL);
    }
}

/// Sends `signal` to the child, which has not been reaped (so its pid is still its own).
fn send(child: &Child, signal: i32) {
    let Ok(pid) = libc::pid_t::try_from(child.id()) else {
        return;
    };
    // SAFETY: kill takes no pointers; `pid` is our unreaped child, so it
    // cannot name another process.
    unsafe {
        libc::kill(pid, signal);
    }
}
