//! `twinray`: the orchestrator. It never links Vulkan or OpenGL: it runs the
//! apps as child processes (one API per process) and reads their JSON, renders
//! the f64 reference itself, and compares images.
//!
//! The modules follow the subcommands: `apps` runs the two apps (and serves
//! `render`); `compare` is `twinray compare`'s plan and steps, `report` its
//! report.md and plots; `accuracy` is `twinray accuracy` with its own report;
//! `diff` is `twinray diff`; `csv` writes every CSV file; `failures` and
//! `interrupt` are how a long run ends when some run failed or a signal came,
//! `supervisor` how every child app is run and, on a signal, stopped;
//! `summary` is `twinray summary`, the verdict table over compare folders;
//! `sweep` is `twinray sweep`, a plan file's runs with their jsonl and table;
//! `ulp` is `twinray ulp`, the GPU's f32 arithmetic measured; `unsettled` is
//! `render --unsettled`, the reference's mask of pixels f32 cannot settle.

mod accuracy;
mod apps;
mod compare;
mod csv;
mod diff;
mod failures;
mod interrupt;
mod report;
mod summary;
mod supervisor;
mod sweep;
mod ulp;
mod unsettled;

use clap::{CommandFactory, FromArgMatches, Parser, Subcommand};
use twinray_common::cli::{named_in_env, RenderArgs};
use twinray_common::error::exit_with;

#[derive(Parser)]
#[command(
    name = "twinray",
    about = "One GLSL ray tracer, two front doors: Vulkan vs OpenGL, checked against an f64 reference"
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
    /// The folder holding twinray-vk and twinray-gl [default: this executable's folder].
    #[arg(
        long,
        global = true,
        env = "TWINRAY_BIN_DIR",
        value_name = "DIR",
        value_parser = named_in_env(apps::parse_bin_dir)
    )]
    bin_dir: Option<std::path::PathBuf>,
}

#[derive(Subcommand)]
enum Command {
    /// Render one scene with one API (or the CPU reference); the app options pass through.
    Render {
        /// vulkan, opengl or reference.
        #[arg(long, value_enum)]
        api: apps::Api,
        #[command(flatten)]
        args: RenderArgs,
        /// Reference only: also write a mask (white) of the pixels f32 cannot settle, whose f64 colour moves by more than 8/255 when the primary ray turns by 4 f32 ULPs (for `twinray diff --exclude`).
        #[arg(long, value_name = "MASK.png")]
        unsettled: Option<std::path::PathBuf>,
        /// With --api reference: the f64 truth the hard cases are measured
        /// against (the truth numerics, whatever the scene's own).
        #[arg(long, hide = true)]
        truth: bool,
    },
    /// Side-by-side Vulkan vs OpenGL on the study's three experiments: results.csv, report.md, plots.
    Compare(compare::CompareArgs),
    /// The laboratory's runner: a plan's builds × apps × option sets, each in a fresh process per round, in alternating order: sweep.jsonl and sweep.md.
    Sweep(sweep::SweepArgs),
    /// Speed against error: sweeps of depth, offset, triangle and sphere tests against the f64 truth, and the hard cases.
    Accuracy(accuracy::AccuracyArgs),
    /// The GPU's f32 arithmetic: each operation the tracer uses, per API and path, against f64 (ULP error).
    Ulp(ulp::UlpArgs),
    /// The study's verdict in one table (Markdown) from the results.csv of `twinray compare` folders, e.g. comparison/results/*/compare*.
    Summary {
        /// Folders that `twinray compare` wrote (or their results.csv files).
        #[arg(required = true, value_name = "DIR")]
        dirs: Vec<std::path::PathBuf>,
    },
    /// Compare two PNGs: RMSE, PSNR, max abs error, share of pixels above 1/255 and 8/255.
    Diff {
        a: std::path::PathBuf,
        b: std::path::PathBuf,
        /// Print the metrics as one JSON object.
        #[arg(long)]
        json: bool,
        /// Also write a PNG that shows A dimmed to grey and every pixel off by more than 1/255 in red.
        #[arg(long)]
        heatmap: Option<std::path::PathBuf>,
        /// Leave out the pixels a mask names (any channel above 127), e.g. `render --api reference --unsettled`'s.
        #[arg(long, value_name = "MASK.png")]
        exclude: Option<std::path::PathBuf>,
    },
    /// The app options of each run every hard case must pass besides the
    /// default, one run a line (for the tolerance measurement script).
    #[command(hide = true)]
    HardRuns,
}

fn main() {
    let cmd = Cli::command();
    let parsed = cmd.clone().try_get_matches().and_then(|m| {
        // Before any work: no output of any command may name one of its inputs.
        if let Err(e) = twinray_common::cli::files::check_command(&cmd, &m) {
            exit_with("twinray", e);
        }
        Cli::from_arg_matches(&m)
    });
    let cli = match parsed {
        Ok(c) => c,
        Err(e) => {
            let code = if e.use_stderr() { 2 } else { 0 };
            let _ = e.print();
            std::process::exit(code);
        }
    };
    apps::set_bin_dir(cli.bin_dir);
    let result = match cli.command {
        Command::Render {
            api,
            args,
            unsettled,
            truth,
        } => unsettled::render(api, &args, truth, unsettled.as_deref()),
        Command::Diff {
            a,
            b,
            json,
            heatmap,
            exclude,
        } => diff::run(&a, &b, json, heatmap.as_deref(), exclude.as_deref()),
        Command::Compare(args) => compare::run(&args),
        Command::Sweep(args) => sweep::run(&args),
        Command::Summary { dirs } => summary::run(&dirs),
        Command::Accuracy(args) => accuracy::run(&args),
        Command::Ulp(args) => ulp::run(&args),
        Command::HardRuns => {
            for run in twinray_common::scene::hard::RUNS {
                println!("{}", run.join(" "));
            }
            Ok(())
        }
    };
    if let Err(e) = result {
        // A signal before anything finished (during the device probe): no
        // report to write, but the exit code still says which signal it was.
        if supervisor::is_interrupted(&e) {
            if let Some((name, code)) = interrupt::Stop::current().and_then(interrupt::Stop::signal)
            {
                eprintln!("twinray: interrupted by {name} before any run finished");
                std::process::exit(code);
            }
        }
        exit_with("twinray", e);
    }
}

#[cfg(test)]
mod tests {
    #[test]
    fn no_output_of_any_command_may_name_one_of_its_inputs() {
        use clap::CommandFactory;
        let dir = std::env::temp_dir().join(format!("twinray-pairs-{}", std::process::id()));
        let failures = twinray_common::cli::files::every_pair_refused(&super::Cli::command(), &dir);
        let _ = std::fs::remove_dir_all(&dir);
        assert!(failures.is_empty(), "{}", failures.join("\n"));
    }
}
