//! `twinray-vk`: parse the shared command line, run, map any failure to the
//! contract's exit code (2 bad input, 3 no usable GPU/driver, 1 anything else).

use twinray_common::cli::{parse_or_exit, VulkanCli};
use twinray_common::error::exit_with;
use twinray_vk::app::run;

fn main() {
    // First thing: `setup_ms` in the report is measured from here to the first submit.
    let process_start = std::time::Instant::now();
    let cli: VulkanCli = parse_or_exit();
    if let Err(e) = run(cli.render, &cli.knobs, process_start) {
        exit_with("twinray-vk", e)
    }
}
