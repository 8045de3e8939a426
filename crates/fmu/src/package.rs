//! Packaging: the `.fmu` archive of a rig (model description, the rig as
//! `resources/rig.json`, the slave library as
//! `binaries/linux64/<modelIdentifier>.so`), and where the library is found.

use crate::model_description::{guid, model_description, model_identifier};
use crate::variables::Variables;
use hydrocyl_system::rig::RigError;
use serde_json::Value;
use std::io::Write as _;
use std::path::{Path, PathBuf};
use thiserror::Error;

/// The environment variable naming the slave library (`libhydrocyl_fmu.so`).
pub const LIBRARY_ENV: &str = "HYDROCYL_FMU_LIBRARY";
/// The file name cargo gives the slave library on Linux.
pub const LIBRARY_FILE: &str = "libhydrocyl_fmu.so";

/// A failed export.
#[derive(Debug, Error)]
pub enum FmuError {
    /// The rig is bad.
    #[error(transparent)]
    Rig(#[from] RigError),
    /// The slave library is missing or is not one.
    #[error("{0}")]
    Library(String),
    /// Building the archive failed.
    #[error("the FMU archive: {0}")]
    Archive(String),
}

/// Where the slave library is: `explicit` (`--library`), else the file named
/// by `$HYDROCYL_FMU_LIBRARY`, else `libhydrocyl_fmu.so` next to the running
/// executable or one folder up (cargo puts it in `target/<profile>/`, beside
/// `hydrocyl`; test binaries run from `target/<profile>/deps/`).
pub fn find_library(explicit: Option<&Path>) -> Result<PathBuf, FmuError> {
    let missing = |p: &Path, how: &str| {
        let what = if p.is_dir() {
            "is a folder, not the library file (libhydrocyl_fmu.so)"
        } else {
            "does not exist"
        };
        FmuError::Library(format!(
            "the FMU library {} ({how}) {what}: build it with `cargo build -p hydrocyl-fmu` (same profile as hydrocyl) or name it with --library / ${LIBRARY_ENV}",
            p.display()
        ))
    };
    if let Some(p) = explicit {
        return if p.is_file() {
            Ok(p.to_path_buf())
        } else {
            Err(missing(p, "--library"))
        };
    }
    if let Some(p) = std::env::var_os(LIBRARY_ENV) {
        let p = PathBuf::from(p);
        return if p.is_file() {
            Ok(p)
        } else {
            Err(missing(&p, &format!("${LIBRARY_ENV}")))
        };
    }
    let exe = std::env::current_exe()
        .map_err(|e| FmuError::Library(format!("cannot locate the running executable: {e}")))?;
    let dir = exe.parent().unwrap_or(Path::new("."));
    let candidates = [dir.join(LIBRARY_FILE), dir.join("..").join(LIBRARY_FILE)];
    candidates
        .iter()
        .find(|p| p.is_file())
        .cloned()
        .ok_or_else(|| missing(&candidates[0], "next to the hydrocyl executable"))
}

/// The FMU archive (a zip: the model description, the rig, the slave
/// library) of `rig`, already with its `--set` overrides. `model_name` names
/// the rig (preset name or file stem). The caller writes it where it goes
/// (`hydrocyl fmu` through its outputs: a temporary file put in place).
pub fn fmu_archive(rig: &Value, model_name: &str, library: &Path) -> Result<Vec<u8>, FmuError> {
    let mut vars = Variables::of(rig)?;
    let lib = std::fs::read(library)
        .map_err(|e| FmuError::Library(format!("{}: {e}", library.display())))?;
    let refused = |why: &str| refusal(library, why);
    if !lib.starts_with(b"\x7fELF") || !contains(&lib, b"fmi2DoStep") {
        return Err(refused(
            "is not the hydrocyl FMU library (no ELF object exporting fmi2DoStep)",
        ));
    }
    let rig_text = serde_json::to_string_pretty(rig).map_err(|e| RigError::Invalid {
        path: "rig".into(),
        why: e.to_string(),
    })?;
    let description = rig
        .get("description")
        .and_then(Value::as_str)
        .map(str::to_string)
        .unwrap_or_else(|| format!("hydrocyl rig {model_name}"));
    // the library must make the same variables of this rig, value
    // reference for value reference: it computes the same GUID only then
    same_build(
        library,
        &guid(&rig_text, &vars),
        crate::ffi::library_guid(library, &rig_text),
    )?;
    // the dependencies declared hold for every value of the parameters
    vars.widen_feedthrough(rig);
    let xml = model_description(&vars, model_name, &description, &rig_text);
    let id = model_identifier(model_name);
    let files: [(String, &[u8]); 3] = [
        ("modelDescription.xml".into(), xml.as_bytes()),
        ("resources/rig.json".into(), rig_text.as_bytes()),
        (format!("binaries/linux64/{id}.so"), &lib),
    ];
    let zipped = (|| -> zip::result::ZipResult<Vec<u8>> {
        let mut zip = zip::ZipWriter::new(std::io::Cursor::new(Vec::new()));
        let opts = zip::write::SimpleFileOptions::default()
            .compression_method(zip::CompressionMethod::Deflated)
            .unix_permissions(0o644);
        for (path, bytes) in &files {
            zip.start_file(path.as_str(), opts)?;
            zip.write_all(bytes)?;
        }
        Ok(zip.finish()?.into_inner())
    })();
    zipped.map_err(|e| FmuError::Archive(e.to_string()))
}

/// A refused library: the message names it, says why and how to build the
/// right one.
fn refusal(library: &Path, why: &str) -> FmuError {
    FmuError::Library(format!(
        "the FMU library {} {why}: build both with `cargo build -p hydrocyl-fmu -p hydrocyl-cli` (same profile), or name the library of this build with --library / ${LIBRARY_ENV}",
        library.display()
    ))
}

/// Whether `library` is of this build for the rig: `theirs` is the GUID it
/// computes for the rig's text (or why it has none), `ours` the packager's.
fn same_build(library: &Path, ours: &str, theirs: Result<String, String>) -> Result<(), FmuError> {
    let why = match theirs {
        Ok(theirs) if theirs == ours => return Ok(()),
        Ok(theirs) => format!(
            "for this rig it computes the GUID {theirs}, this hydrocyl {ours}: it makes other variables of the rig, so value references would set the wrong parameters"
        ),
        Err(why) => why,
    };
    Err(refusal(
        library,
        &format!("is not from the same build as this hydrocyl ({why})"),
    ))
}

fn contains(hay: &[u8], needle: &[u8]) -> bool {
    hay.windows(needle.len()).any(|w| w == needle)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A library that computes another GUID for the rig (another build),
    /// or none, is refused with one line naming it, why and the remedy.
    #[test]
    fn a_library_computing_another_guid_is_refused() {
        let lib = Path::new("/x/libhydrocyl_fmu.so");
        let ours = "{00000000-0000-0000-0000-00000000000a}";
        assert!(same_build(lib, ours, Ok(ours.into())).is_ok());
        for (theirs, why) in [
            (
                Ok("{00000000-0000-0000-0000-00000000000b}".to_string()),
                "it makes other variables of the rig",
            ),
            (
                Err("it has no hydrocyl_fmu_guid: a build older than this hydrocyl's".into()),
                "no hydrocyl_fmu_guid",
            ),
        ] {
            let e = same_build(lib, ours, theirs).unwrap_err().to_string();
            assert!(
                e.starts_with("the FMU library /x/libhydrocyl_fmu.so is not from the same build")
                    && e.contains(why)
                    && e.contains("cargo build -p hydrocyl-fmu -p hydrocyl-cli")
                    && !e.contains('\n'),
                "{e}"
            );
        }
    }
}
