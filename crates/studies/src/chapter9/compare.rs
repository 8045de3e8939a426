//! The comparison of the chapter-9 variants with the pilot-shifted drive:
//! every rig of [`super::RIGS`] at every speed and load, with the
//! parameters the study sets — the optimiser's needle opening per speed on
//! the needle variants, the servo law fitted to those openings on the servo
//! needle — and the rest as the rig files ship them.

use super::needle::{optimise, Optimum};
use super::run::{run_case, Case, Measured};
use super::servo::ServoLaw;
use super::{LOADS_KG, RIGS, SPEEDS_MM_S};
use hydrocyl_energy::EnergyError;
use hydrocyl_system::rig::{self, RigError};
use serde::Serialize;
use serde_json::Value;
use std::path::Path;

/// One row of the comparison.
#[derive(Clone, Debug, Serialize)]
pub struct Row {
    /// The rig's name.
    pub system: String,
    /// The case.
    pub case: Case,
    /// The `--set`s the study applied.
    pub sets: Vec<String>,
    /// What the run measured.
    pub measured: Measured,
}

/// Everything the study chose and measured.
#[derive(Clone, Debug, Serialize)]
pub struct Comparison {
    /// The needle optimum per speed of the pilot-shifted drive
    /// (`wang-hybrid-needle`).
    pub needle: Vec<Optimum>,
    /// The needle optimum per speed of the solenoid drive
    /// (`wang-hybrid-improved`).
    pub needle_solenoid: Vec<Optimum>,
    /// The servo needle's law fitted to `needle_solenoid` (the servo needle
    /// rig is the solenoid drive, whose optimal opening changes most with
    /// speed).
    pub servo: ServoLaw,
    /// The rows, in the order of [`RIGS`], speeds, loads.
    pub rows: Vec<Row>,
}

fn rig_err(name: &str) -> impl Fn(RigError) -> EnergyError + '_ {
    move |source| EnergyError::Rig {
        rig: name.into(),
        source,
    }
}

/// Loads rig `name` from the folder `rigs`.
pub fn load(rigs: &Path, name: &str) -> Result<Value, EnergyError> {
    rig::load(&rigs.join(format!("{name}.json")).display().to_string()).map_err(rig_err(name))
}

/// Runs the study on the rig files in `rigs` (`fixtures/rigs`).
pub fn compare(rigs: &Path) -> Result<Comparison, EnergyError> {
    let needle_rig = load(rigs, "wang-hybrid-needle")?;
    let improved_rig = load(rigs, "wang-hybrid-improved")?;
    let mut needle = Vec::new();
    let mut needle_solenoid = Vec::new();
    for s in SPEEDS_MM_S {
        needle.push(optimise(&needle_rig, s)?);
        needle_solenoid.push(optimise(&improved_rig, s)?);
    }
    let point = |o: &Optimum| (1e-3 * o.speed_mm_s, o.best.area_m2);
    let servo_rig = load(rigs, "wang-hybrid-servo-needle")?;
    let servo = ServoLaw::fit(
        &servo_rig,
        point(&needle_solenoid[0]),
        point(&needle_solenoid[1]),
    )
    .map_err(rig_err("wang-hybrid-servo-needle"))?;
    let mut rows = Vec::new();
    for name in RIGS {
        let base = load(rigs, name)?;
        for (i, speed_mm_s) in SPEEDS_MM_S.into_iter().enumerate() {
            let sets: Vec<String> = match name {
                "wang-hybrid-needle" => {
                    vec![format!("needle_valve.area={}", needle[i].best.area_m2)]
                }
                "wang-hybrid-improved" => {
                    vec![format!(
                        "needle_valve.area={}",
                        needle_solenoid[i].best.area_m2
                    )]
                }
                "wang-hybrid-servo-needle" => servo.sets().to_vec(),
                _ => vec![],
            };
            let mut v = base.clone();
            for s in &sets {
                rig::apply_set(&mut v, s).map_err(rig_err(name))?;
            }
            for load_kg in LOADS_KG {
                let case = Case {
                    speed_mm_s,
                    load_kg,
                };
                rows.push(Row {
                    system: name.into(),
                    case,
                    sets: sets.clone(),
                    measured: run_case(&v, &case)?,
                });
            }
        }
    }
    Ok(Comparison {
        needle,
        needle_solenoid,
        servo,
        rows,
    })
}
