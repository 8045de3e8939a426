//! `hydrocyl fmu`: export a rig as an FMI 2.0 Co-Simulation FMU (linux64).
//!
//! ```text
//! hydrocyl fmu --rig leaney-moog --out drive.fmu [--set load.mass=50] [--library PATH]
//! hydrocyl fmu --list-presets
//! ```
//!
//! The FMU holds `modelDescription.xml`, the rig after `--set` as
//! `resources/rig.json`, and the slave library `libhydrocyl_fmu.so` (crate
//! `hydrocyl-fmu`) as `binaries/linux64/<modelIdentifier>.so`. The library
//! is found by `--library`, else `$HYDROCYL_FMU_LIBRARY`, else next to the
//! `hydrocyl` executable (where `cargo build -p hydrocyl-fmu` puts it).
//! It must be the library of this build: the packager loads it and
//! refuses it (exit 2, nothing written) unless it computes the packager's
//! GUID for the rig, i.e. makes the same variables of it (a library built
//! from other sources would map value references to other parameters);
//! see `docs/fmu.md`.

use crate::error::CliError;
use crate::output::Outputs;
use hydrocyl_fmu::package::{find_library, fmu_archive};
use hydrocyl_system::rig;
use std::path::{Path, PathBuf};

/// Arguments of `hydrocyl fmu`.
#[derive(clap::Args)]
pub struct Args {
    /// A preset name (leaney-moog, ...) or a rig JSON file.
    #[arg(long, required = true, conflicts_with = "list_presets")]
    rig: Option<String>,
    /// The FMU file to write.
    #[arg(long, required = true, conflicts_with = "list_presets")]
    out: Option<PathBuf>,
    /// Override a rig parameter by its path before export, e.g. `--set
    /// load.mass=50` (repeatable; `hydrocyl simulate --print-rig` lists
    /// every path); it becomes the parameter's start value.
    #[arg(long = "set", value_name = "PATH=VALUE")]
    set: Vec<String>,
    /// The slave library (`libhydrocyl_fmu.so`) of this build; default:
    /// $HYDROCYL_FMU_LIBRARY, else next to this executable.
    #[arg(long)]
    library: Option<PathBuf>,
    /// Print the preset names (one per line) and exit.
    #[arg(long, exclusive = true)]
    list_presets: bool,
}

/// Runs `hydrocyl fmu`.
pub fn run(args: Args) -> Result<(), CliError> {
    if args.list_presets {
        let names: String = rig::PRESETS
            .iter()
            .map(|p| format!("{}\n", p.name))
            .collect();
        return crate::console::print(&names);
    }
    let (Some(rig_arg), Some(out)) = (args.rig, args.out) else {
        return Err(CliError::Input("--rig and --out are required".into()));
    };
    let input = |e: &dyn std::fmt::Display| CliError::Input(e.to_string());
    // the rig first: its errors are the user's to fix, whatever the library
    let mut value = rig::load(&rig_arg).map_err(|e| input(&e))?;
    rig::apply_sets(&mut value, &args.set).map_err(|e| input(&e))?;
    // errors name the file and line of their JSON path
    rig::check(&value)
        .map_err(|e| input(&crate::rigfile::at_line_or_set(e, &rig_arg, &args.set)))?;
    // a unit slip runs (and exports): warned of, as `simulate` warns of it
    if let Ok(s) = hydrocyl_system::netlist::read(&value) {
        for w in hydrocyl_system::netlist::implausible(&s) {
            crate::console::hold_warning(w);
        }
    }
    let library = find_library(args.library.as_deref()).map_err(|e| input(&e))?;
    // the FMU must not be written over an input: the rig file or the library
    let rig_file = (!rig::is_preset(&rig_arg)).then(|| PathBuf::from(&rig_arg));
    let mut inputs: Vec<(&str, &Path)> = vec![("--library", library.as_path())];
    if let Some(f) = &rig_file {
        inputs.push(("--rig", f.as_path()));
    }
    let mut outputs = Outputs::new(&inputs);
    let file = outputs.file("--out", &out)?;
    let name = if rig::is_preset(&rig_arg) {
        rig_arg.clone()
    } else {
        Path::new(&rig_arg)
            .file_stem()
            .map(|s| s.to_string_lossy().into_owned())
            .unwrap_or_else(|| "rig".into())
    };
    let archive = fmu_archive(&value, &name, &library).map_err(|e| input(&e))?;
    outputs.write(file, &archive)?;
    // an FMU is flushed to the disk before it is put in place, as before
    outputs.commit(true)?;
    crate::console::note(format_args!(
        "hydrocyl: wrote {} (rig {name}, library {})",
        out.display(),
        library.display()
    ));
    crate::console::print_held(false);
    Ok(())
}
