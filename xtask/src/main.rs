//! hydrocyl's developer tasks (`cargo xtask <task>`):
//!
//! * `validate` — the validation suite on the built-in presets, hydrocyl against the thesis;
//!   exits non-zero when a check fails.
//! * `xfactor` — Tables 3-3 and 3-4 recomputed, with the exact root-branch split.
//! * `energy` — the chapter-8 efficiency matrix.
//! * `bench` — speed ratios against reference runs in the same run.
//!
//! Every section prints only what it measured in this run.

mod bench;
mod bench_solve;
mod energy;
mod report;
mod validate;
mod xfactor;

use clap::{Parser, Subcommand};

#[derive(Parser)]
#[command(name = "xtask", about = "hydrocyl developer tasks")]
struct Cli {
    #[command(subcommand)]
    task: Task,
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
    /// Speed ratios against reference runs on this machine, in the same run.
    Bench,
}

fn main() {
    let cli = Cli::parse();
    let ok = match cli.task {
        Task::Validate { only } => validate::run(only.as_deref()),
        Task::Xfactor => xfactor::run(),
        Task::Energy => energy::run(),
        Task::Bench => bench::run(),
    };
    if !ok {
        std::process::exit(1);
    }
}
