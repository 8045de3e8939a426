//! Errors of the energy crate: each names the rig, scenario or file and what is wrong.

use hydrocyl_system::rig::RigError;
use thiserror::Error;

/// Why an energy computation failed.
#[derive(Debug, Error)]
pub enum EnergyError {
    /// The rig could not be built or simulated.
    #[error("rig `{rig}`: {source}")]
    Rig {
        /// The rig (preset name, file or variant name).
        rig: String,
        /// What the assembler or solver said.
        #[source]
        source: RigError,
    },
    /// A scenario parameter out of range.
    #[error("scenario `{scenario}`: {why}")]
    Scenario {
        /// The scenario's label.
        scenario: String,
        /// What is wrong.
        why: String,
    },
    /// A malformed variant rig file.
    #[error("variant rig `{path}`: {why}")]
    Variant {
        /// The file or variant name.
        path: String,
        /// What is wrong.
        why: String,
    },
    /// The run does not carry what the ledger needs.
    #[error("ledger: {0}")]
    Ledger(String),
}
