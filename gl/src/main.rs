//! `twinray-gl`: parses the shared command line and maps errors to the
//! contract's exit codes; everything else is in the library.

use std::time::Instant;
use twinray_common::cli::{parse_or_exit, OpenGlCli};
use twinray_common::error::exit_with;
use twinray_gl::run;

fn main() {
    // First thing: setup_ms counts from here.
    let started = Instant::now();
    let cli: OpenGlCli = parse_or_exit();
    if let Err(e) = run(cli.render, &cli.knobs, started) {
        exit_with("twinray-gl", e)
    }
}
