//! Rig files as the CLI reads them: a preset or a file (duplicate keys
//! refused, [`rig::load`]), checked with every error naming the JSON path
//! and, for a file, its line — serde's type and enum errors included, which
//! the rig kinds report without a path.

use crate::error::CliError;
use hydrocyl_system::hybrid::WangHybrid;
use hydrocyl_system::rig::{self, RigError};
use hydrocyl_system::valve_rig::{self, ValveRig};
use serde_json::Value;

/// The JSON path of a deserialisation error of `value` read as `T`, with
/// serde's message, or `None` if it reads.
fn serde_path<T: serde::de::DeserializeOwned>(value: &Value) -> Option<(String, String)> {
    match serde_path_to_error::deserialize::<_, T>(value.clone()) {
        Ok(_) => None,
        Err(e) => Some((e.path().to_string(), e.into_inner().to_string())),
    }
}

/// A rig error with its JSON path found (a serde error of the older rig
/// kinds names none) and the line in `source` added.
pub fn locate(e: RigError, value: &Value, source: &str) -> CliError {
    let e = match e {
        RigError::Invalid { path, why } if path == "rig" => {
            let found = match value.get("kind").and_then(Value::as_str) {
                Some(valve_rig::KIND) => serde_path::<ValveRig>(value),
                Some(hydrocyl_system::hybrid::KIND) => serde_path::<WangHybrid>(value),
                _ => None,
            };
            match found {
                Some((p, why)) if p != "." => RigError::Invalid { path: p, why },
                _ => RigError::Invalid { path, why },
            }
        }
        other => other,
    };
    CliError::Input(rig::at_line(e, source).to_string())
}

/// Checks a rig value of a known kind (see [`locate`]).
pub fn check(value: &Value, source: &str) -> Result<(), CliError> {
    rig::check(value).map_err(|e| locate(e, value, source))
}
