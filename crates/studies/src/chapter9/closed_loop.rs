//! The closed-loop drive: a position P controller on the servomotor
//! (`wang-hybrid-closed-loop`, a `position_controller` writing the pump
//! command). It is driven by the position reference of the open-loop
//! square's motion (a triangle of slope ±v, [`super::run::input`]), so
//! "the symmetric command" is a symmetric reference: the drift per period
//! is the controller's, and the stall is measured at the reference's
//! reversals. The gain is the rig file's; [`gains`] sweeps it.

use super::run::{run_case, Case, Measured};
use hydrocyl_energy::EnergyError;
use hydrocyl_system::rig;
use serde_json::Value;

/// Runs the closed-loop rig at each controller gain `kp` \[V/m\] on `case`.
pub fn gains(
    rig_value: &Value,
    case: &Case,
    kp: &[f64],
) -> Result<Vec<(f64, Measured)>, EnergyError> {
    kp.iter()
        .map(|&k| {
            let mut v = rig_value.clone();
            rig::apply_set(&mut v, &format!("controller.gain={k}")).map_err(|source| {
                EnergyError::Rig {
                    rig: "closed loop".into(),
                    source,
                }
            })?;
            Ok((k, run_case(&v, case)?))
        })
        .collect()
}
