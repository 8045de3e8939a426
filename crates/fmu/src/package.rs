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
    /// Writing the archive failed.
    #[error("{path}: {why}")]
    Write {
        /// The file.
        path: String,
        /// What failed.
        why: String,
    },
}

/// Where the slave library is: `explicit` (`--library`), else the file named
/// by `$HYDROCYL_FMU_LIBRARY`, else `libhydrocyl_fmu.so` next to the running
/// executable or one folder up (cargo puts it in `target/<profile>/`, beside
/// `hydrocyl`; test binaries run from `target/<profile>/deps/`).
pub fn find_library(explicit: Option<&Path>) -> Result<PathBuf, FmuError> {
    let missing = |p: &Path, how: &str| {
        FmuError::Library(format!(
            "the FMU library {} ({how}) does not exist: build it with `cargo build -p hydrocyl-fmu` (same profile as hydrocyl) or name it with --library / ${LIBRARY_ENV}",
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

/// Writes the FMU of `rig` (already with its `--set` overrides) to `out`.
/// `model_name` names the rig (preset name or file stem). The archive is
/// written to a temporary file beside `out` and renamed into place, so a
/// failure leaves no file.
pub fn write_fmu(
    rig: &Value,
    model_name: &str,
    library: &Path,
    out: &Path,
) -> Result<(), FmuError> {
    let vars = Variables::of(rig)?;
    let lib = std::fs::read(library)
        .map_err(|e| FmuError::Library(format!("{}: {e}", library.display())))?;
    if !lib.starts_with(b"\x7fELF") || !contains(&lib, b"fmi2DoStep") {
        return Err(FmuError::Library(format!(
            "{} is not the hydrocyl FMU library (no ELF object exporting fmi2DoStep)",
            library.display()
        )));
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
    let xml = model_description(&vars, model_name, &description, &guid(&rig_text));
    let id = model_identifier(model_name);
    let files: [(String, &[u8]); 3] = [
        ("modelDescription.xml".into(), xml.as_bytes()),
        ("resources/rig.json".into(), rig_text.as_bytes()),
        (format!("binaries/linux64/{id}.so"), &lib),
    ];
    let err = |why: String| FmuError::Write {
        path: out.display().to_string(),
        why,
    };
    let name = out
        .file_name()
        .ok_or_else(|| err("not a file name".into()))?;
    let tmp = out.with_file_name(format!(
        ".{}.tmp{}",
        name.to_string_lossy(),
        std::process::id()
    ));
    let result = (|| -> Result<(), String> {
        let file = std::fs::File::create(&tmp).map_err(|e| e.to_string())?;
        let mut zip = zip::ZipWriter::new(file);
        let opts = zip::write::SimpleFileOptions::default()
            .compression_method(zip::CompressionMethod::Deflated)
            .unix_permissions(0o644);
        for (path, bytes) in &files {
            zip.start_file(path.as_str(), opts)
                .map_err(|e| e.to_string())?;
            zip.write_all(bytes).map_err(|e| e.to_string())?;
        }
        let file = zip.finish().map_err(|e| e.to_string())?;
        file.sync_all().map_err(|e| e.to_string())?;
        std::fs::rename(&tmp, out).map_err(|e| e.to_string())
    })();
    if let Err(why) = result {
        let _ = std::fs::remove_file(&tmp);
        return Err(err(why));
    }
    Ok(())
}

fn contains(hay: &[u8], needle: &[u8]) -> bool {
    hay.windows(needle.len()).any(|w| w == needle)
}
