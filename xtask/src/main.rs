//! hydrocyl's developer tasks (`cargo xtask <task>`):
//!
//! * `validate` — the validation suite on the built-in presets, hydrocyl against the thesis;
//!   exits non-zero when a check fails.
//! * `xfactor` — Tables 3-3 and 3-4 recomputed, with the exact root-branch split.
//! * `energy` — the chapter-8 efficiency matrix.
//! * `commands` — writes `fixtures/commands/`, the thesis's experiments as
//!   command files for `hydrocyl simulate`.
//! * `bench` — speed ratios against reference runs in the same run.
//! * `test` — `cargo test --workspace`, then the Python package's pytest suite
//!   on a wheel built by maturin into a virtual environment.
//!
//! Every section prints only what it measured in this run.

mod bench;
mod bench_csv;
mod bench_record;
mod bench_solve;
mod commands;
mod energy;
mod energy_ch9;
mod energy_relief;
mod progress;
mod report;
mod test;
mod validate;
mod xfactor;

use clap::{Parser, Subcommand};

#[derive(Parser)]
#[command(name = "xtask", about = "hydrocyl developer tasks")]
struct Cli {
    #[command(subcommand)]
    task: Task,
    /// Draw progress bars (energy, validate) even when stderr is not a terminal.
    #[arg(long, global = true)]
    progress: bool,
}

#[derive(Subcommand)]
enum Task {
    /// Run the validation suite on the built-in presets and compare with the thesis.
    Validate {
        /// Run only the sections whose name contains this text.
        #[arg(long)]
        only: Option<String>,
    },
    /// Recompute the thesis's X-factor tables (3-3, 3-4) and the exact root-branch split.
    Xfactor,
    /// The chapter-8 energy-efficiency matrix of the valve and hybrid drives.
    Energy,
    /// Write fixtures/commands/: the command files of the chapter-3, 7 and 8
    /// experiments (from the studies' signal definitions) and their README.
    Commands,
    /// Speed ratios against reference runs on this machine, in the same run,
    /// timed on the release build (the one users run: `cargo xtask bench`
    /// builds and runs it; `--dev` times the dev build instead).
    Bench {
        /// Time this build (the dev profile: opt-level 2, debug assertions)
        /// instead of the release one.
        #[arg(long)]
        dev: bool,
        /// Run only the sections whose name contains this text (e.g. `csv`,
        /// `process`, `cost`).
        #[arg(long)]
        only: Option<String>,
        /// Write the whole-process row's command files into this folder and
        /// keep them (for profiling `hydrocyl simulate` on them).
        #[arg(long)]
        keep_files: Option<std::path::PathBuf>,
    },
    /// Every test: `cargo test --workspace`, then the Python package (wheel
    /// built by maturin into target/py-venv, pytest).
    Test {
        /// Only the Python package's tests.
        #[arg(long, conflicts_with = "rust_only")]
        python_only: bool,
        /// Only `cargo test --workspace`.
        #[arg(long)]
        rust_only: bool,
        /// Build the wheel with the release profile (as users get it).
        #[arg(long)]
        release: bool,
        /// Recreate the virtual environment.
        #[arg(long)]
        fresh: bool,
        /// Arguments passed on to pytest (after `--`).
        #[arg(last = true)]
        pytest_args: Vec<String>,
    },
}

fn main() {
    let cli = Cli::parse();
    progress::force(cli.progress);
    let ok = match cli.task {
        Task::Validate { only } => validate::run(only.as_deref()),
        Task::Xfactor => xfactor::run(),
        Task::Energy => energy::run(),
        Task::Commands => commands::run(),
        Task::Bench {
            dev,
            only,
            keep_files,
        } => {
            if cfg!(debug_assertions) && !dev {
                bench::in_release()
            } else {
                bench::run(only.as_deref(), keep_files.as_deref())
            }
        }
        Task::Test {
            python_only,
            rust_only,
            release,
            fresh,
            pytest_args,
        } => test::run_all(&test::Options {
            python_only,
            rust_only,
            release,
            fresh,
            pytest_args,
        }),
    };
    if !ok {
        std::process::exit(1);
    }
}
