//! The `friction-bench` rig kind: a piston moved by an external drive through
//! a load cell, chamber pressure(s) measured, the force balance the only
//! balance.
//!
//! ```text
//!   drive ──▶ load cell (force F) ──▶ rod ─┬─ piston ─┬─▶ position x, + one way
//!                                          │ p1 A1 (+)│ p2 A2 (−)
//!                                          └ friction F_f(v, a, p1, p2, z)
//! ```
//!
//! Force balance (thesis eq 5.9 with the drive force added):
//! `m a = s F + p1 A1 − p2 A2 − F_f − F0`, so the model's prediction of the
//! measured force is `F̂ = s (m a + F_f + F0 − p1 A1 + p2 A2)` where `s = ±1`
//! says which way the load-cell force pushes. The motion is the input
//! (measured position, differentiated by the smoother) and the force is the
//! output: for a bench whose drive imposes the motion this is the only
//! well-posed simulation (the inverse model of the robotics IDIM practice).
//!
//! The friction law is the declared Coulomb level `Fc` plus the catalog's
//! force-balance effects, each on or off ([`BenchFriction`]):
//! * static: `F_f = g(v) tanh(v / v_t)`, `g(v) = Fc + (Fs − Fc) exp(−|v/vs|^α)`
//!   (the `stribeck` term, eq 5.1's g);
//! * `lugre_dynamics` (eq 5.1): `F_f = σ0 z + σ1 ż`,
//!   `ż = v − σ0 |v| z / g(v)` in place of the static curve;
//! * plus `viscous` `b v`, `pressure_viscous` `K (p1 − p2)² v` (eq 5.4),
//!   `acceleration_friction` `K H a` (eq 5.12), `coulomb_asymmetry`
//!   `(dFc/2) |tanh(v/v_t)|` (extending level `Fc + dFc/2`, retracting
//!   `Fc − dFc/2`) and `external_force` `F0`.
//!
//! The bench runs as its netlist ([`hydrocyl_system::netlist::migrate::bench`])
//! through the one run path ([`BenchRun`]): the record's velocity,
//! acceleration and pressures are the netlist's inputs (first-order hold
//! between samples), the load cell its output; the bristle ODE is
//! integrated by the run's solver.

use std::collections::BTreeMap;

use serde::{Deserialize, Serialize};
use thiserror::Error;

use crate::catalog::{Balance, EffectId};
use crate::data::ColumnMap;
use hydrocyl_system::netlist::migrate::bench as net;

/// Effects a friction bench can carry (the force balance's).
pub const BENCH_EFFECTS: [EffectId; 7] = [
    EffectId::CoulombAsymmetry,
    EffectId::Stribeck,
    EffectId::Viscous,
    EffectId::PressureViscous,
    EffectId::AccelerationFriction,
    EffectId::LugreDynamics,
    EffectId::ExternalForce,
];

/// A bad rig declaration.
#[derive(Debug, Error, Clone, PartialEq)]
pub enum RigError {
    /// An effect id not in the catalog.
    #[error("{place}: unknown effect '{id}'")]
    UnknownEffect {
        /// Where.
        place: String,
        /// The id.
        id: String,
    },
    /// An effect the rig kind has no balance for.
    #[error("{place}: effect '{id}' belongs to a balance a friction bench does not have")]
    NotApplicable {
        /// Where.
        place: String,
        /// The id.
        id: String,
    },
    /// A parameter missing, unknown, not finite or out of range.
    #[error("{place}: {reason}")]
    Parameter {
        /// Where (`effects.stribeck.vs`).
        place: String,
        /// What is wrong.
        reason: String,
    },
}

/// The bench's friction law: declared Coulomb level plus catalog effects.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BenchFriction {
    /// Coulomb level Fc \[N\].
    pub coulomb: f64,
    /// Smoothing velocity v_t of the static law's tanh \[m·s⁻¹\].
    pub smoothing_velocity: f64,
    /// The effects switched on, id → parameter name → value (SI).
    #[serde(default)]
    pub effects: BTreeMap<EffectId, BTreeMap<String, f64>>,
}

/// A friction-bench rig.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FrictionBench {
    /// Rig kind; must be `friction-bench`.
    #[serde(default = "bench_kind")]
    pub kind: String,
    /// Rig name.
    pub name: String,
    /// Area on which p1 pushes in + direction \[m²\].
    #[serde(default)]
    pub area1: f64,
    /// Area on which p2 pushes in − direction \[m²\].
    #[serde(default)]
    pub area2: f64,
    /// Moving mass \[kg\].
    pub mass: f64,
    /// +1 when a positive load-cell force pushes the piston in + direction, −1 otherwise.
    pub force_sign: f64,
    /// The friction law.
    pub friction: BenchFriction,
    /// Each sample is a steady state (a table of velocity vs force): the
    /// measured velocity is used as it is and the acceleration is zero.
    #[serde(default)]
    pub steady_state: bool,
    /// Declared parameters refitted before tracing (`Fc`, `m`, or `effect.param`).
    #[serde(default)]
    pub refit: Vec<String>,
    /// Where the signals are in files whose headers are not the format's.
    #[serde(default)]
    pub columns: ColumnMap,
    /// The `--set` paths of the parameters in the rig's own netlist where
    /// they are not [`ParamRef::path`] (a law other than `friction_bench`,
    /// components named otherwise): each parameter's paths, two for a law
    /// with one set per direction (`friction_lugre`); none for an effect
    /// the rig's law does not have. Filled by [`FrictionBench::from_netlist`].
    #[serde(skip)]
    pub paths: BTreeMap<ParamRef, Vec<String>>,
}

fn bench_kind() -> String {
    KIND.to_string()
}

/// The rig-file `kind` of a friction bench.
pub const KIND: &str = "friction-bench";

/// A parameter of the bench model: a base one (`Fc`, `m`) or an effect's.
#[derive(Clone, Debug, PartialEq, Eq, PartialOrd, Ord)]
pub enum ParamRef {
    /// The Coulomb level Fc \[N\].
    Coulomb,
    /// The moving mass m \[kg\].
    Mass,
    /// Parameter `name` of effect `id`.
    Effect(EffectId, String),
}

impl ParamRef {
    /// Parses a netlist path of the bench (`friction.coulomb`,
    /// `drive.mass`, `friction.viscous`: [`ParamRef::path`]) or the catalog
    /// name `Fc`, `m` or `effect.param` (`viscous.b`) of older rig files.
    pub fn parse(s: &str) -> Option<ParamRef> {
        if let Some(p) = ParamRef::from_path(s) {
            return Some(p);
        }
        match s {
            "Fc" => Some(ParamRef::Coulomb),
            "m" => Some(ParamRef::Mass),
            _ => {
                let (e, p) = s.split_once('.')?;
                let id = EffectId::from_id(e)?;
                id.params().iter().find(|q| q.name == p)?;
                Some(ParamRef::Effect(id, p.to_string()))
            }
        }
    }

    /// Its path in the bench's netlist (`<component>.<parameter>`, the one
    /// parameter scheme): `friction.coulomb`, `drive.mass`, and each catalog
    /// effect's parameter under the `friction_bench` name the migration's
    /// table gives it ([`net::EFFECT_PARAMS`]: `viscous.b` is
    /// `friction.viscous`).
    pub fn path(&self) -> String {
        match self {
            ParamRef::Coulomb => format!("{}.coulomb", net::FRICTION),
            ParamRef::Mass => format!("{}.mass", net::DRIVE),
            ParamRef::Effect(id, p) => {
                let target = net::EFFECT_PARAMS
                    .iter()
                    .find(|(e, q, _)| *e == id.id() && q == p)
                    .map(|(_, _, t)| *t)
                    .expect("every bench effect parameter is in the migration's table");
                format!("{}.{target}", net::FRICTION)
            }
        }
    }

    /// The parameter at a netlist path of the bench ([`ParamRef::path`]'s
    /// inverse), or `None`.
    pub fn from_path(path: &str) -> Option<ParamRef> {
        let (comp, name) = path.split_once('.')?;
        match (comp, name) {
            (net::DRIVE, "mass") => Some(ParamRef::Mass),
            (net::FRICTION, "coulomb") => Some(ParamRef::Coulomb),
            (net::FRICTION, target) => net::EFFECT_PARAMS
                .iter()
                .find(|(_, _, t)| *t == target)
                .and_then(|(e, p, _)| Some(ParamRef::Effect(EffectId::from_id(e)?, p.to_string()))),
            _ => None,
        }
    }

    /// Its name in reports.
    pub fn label(&self) -> String {
        match self {
            ParamRef::Coulomb => "Fc".into(),
            ParamRef::Mass => "m".into(),
            ParamRef::Effect(id, p) => format!("{}.{p}", id.id()),
        }
    }

    /// Bounds of a fit.
    pub fn bounds(&self) -> (f64, f64) {
        match self {
            ParamRef::Coulomb => (0.0, f64::INFINITY),
            ParamRef::Mass => (0.0, f64::INFINITY),
            ParamRef::Effect(id, p) => id
                .params()
                .iter()
                .find(|q| q.name == p)
                .map_or((f64::NEG_INFINITY, f64::INFINITY), |q| (q.lower, q.upper)),
        }
    }
}

impl FrictionBench {
    /// Checks that record `rec` holds the pressures the model needs: a
    /// chamber area over zero makes its pressure an input of the bench
    /// (without the column it would run at 0 Pa, and the pressure force it
    /// lacks be "explained" as an effect). The error names the file and
    /// the missing column (in the rig's column map, if it maps one).
    pub fn require_inputs(&self, rec: &crate::data::Record) -> Result<(), crate::data::DataError> {
        use crate::data::Signal;
        for (sig, area, name) in [
            (Signal::P1, self.area1, "area1"),
            (Signal::P2, self.area2, "area2"),
        ] {
            if area > 0.0 && rec.get(sig).is_none() {
                let column = self
                    .columns
                    .0
                    .get(&sig)
                    .cloned()
                    .unwrap_or_else(|| sig.name().to_string());
                return Err(crate::data::DataError::MissingInput {
                    file: rec.source.clone(),
                    column,
                    why: format!(
                        "the rig's {name} is {area:.4e} m², so its model is driven by the chamber pressure {sig} (without it, it would run at 0 Pa)"
                    ),
                });
            }
        }
        Ok(())
    }

    /// Checks the declaration: every effect applicable, every parameter
    /// present, finite and within its catalog bounds.
    pub fn validate(&self) -> Result<(), RigError> {
        let pos = |name: &str, v: f64, allow_zero: bool| -> Result<(), RigError> {
            if !v.is_finite() || v < 0.0 || (!allow_zero && v == 0.0) {
                return Err(RigError::Parameter {
                    place: name.to_string(),
                    reason: format!(
                        "must be finite and {}, got {v}",
                        if allow_zero { ">= 0" } else { "> 0" }
                    ),
                });
            }
            Ok(())
        };
        if self.kind != KIND {
            return Err(RigError::Parameter {
                place: "kind".into(),
                reason: format!("'{}' is not '{KIND}'", self.kind),
            });
        }
        pos("area1", self.area1, true)?;
        pos("area2", self.area2, true)?;
        pos("mass", self.mass, true)?;
        pos("friction.coulomb", self.friction.coulomb, true)?;
        pos(
            "friction.smoothing_velocity",
            self.friction.smoothing_velocity,
            false,
        )?;
        if self.force_sign != 1.0 && self.force_sign != -1.0 {
            return Err(RigError::Parameter {
                place: "force_sign".into(),
                reason: format!("must be 1 or -1, got {}", self.force_sign),
            });
        }
        for (id, params) in &self.friction.effects {
            let place = format!("friction.effects.{}", id.id());
            if id.balance() != Balance::Force {
                return Err(RigError::NotApplicable {
                    place,
                    id: id.id().into(),
                });
            }
            for spec in id.params() {
                let v = params
                    .get(spec.name)
                    .copied()
                    .ok_or_else(|| RigError::Parameter {
                        place: place.clone(),
                        reason: format!("parameter '{}' [{}] missing", spec.name, spec.unit),
                    })?;
                if !v.is_finite() || v < spec.lower || v > spec.upper {
                    return Err(RigError::Parameter {
                        place: format!("{place}.{}", spec.name),
                        reason: format!(
                            "{v} outside [{}, {}] {}",
                            spec.lower, spec.upper, spec.unit
                        ),
                    });
                }
            }
            for k in params.keys() {
                if !id.params().iter().any(|p| p.name == k) {
                    return Err(RigError::Parameter {
                        place: place.clone(),
                        reason: format!("unknown parameter '{k}'"),
                    });
                }
            }
        }
        for r in &self.refit {
            let p = self.param(r).ok_or_else(|| RigError::Parameter {
                place: "refit".into(),
                reason: format!(
                    "'{r}' is not a bench parameter (`friction.coulomb`, `drive.mass`, `friction.<parameter>`, or Fc, m, effect.param)"
                ),
            })?;
            if let ParamRef::Effect(id, _) = &p {
                if !self.friction.effects.contains_key(id) {
                    return Err(RigError::Parameter {
                        place: "refit".into(),
                        reason: format!("'{r}': effect '{}' is not on", id.id()),
                    });
                }
            }
        }
        Ok(())
    }

    /// Parses and validates a rig file's JSON.
    pub fn from_json(text: &str) -> Result<FrictionBench, String> {
        let rig: FrictionBench = serde_json::from_str(text).map_err(|e| e.to_string())?;
        rig.validate().map_err(|e| e.to_string())?;
        Ok(rig)
    }

    /// The parameter a refit entry names: a `--set` path of the rig's
    /// netlist ([`FrictionBench::set_paths`]), else [`ParamRef::parse`].
    pub fn param(&self, s: &str) -> Option<ParamRef> {
        self.paths
            .iter()
            .find(|(_, ps)| ps.iter().any(|q| q == s))
            .map(|(p, _)| p.clone())
            .or_else(|| ParamRef::parse(s))
    }

    /// The `--set` paths of parameter `p` in the rig's netlist (so a fitted
    /// value can be fed back with `--set <path>=<value>`): [`ParamRef::path`]
    /// unless the rig's netlist holds it elsewhere (two paths for a law with
    /// one set per direction, none for an effect its law does not have).
    pub fn set_paths(&self, p: &ParamRef) -> Vec<String> {
        self.paths.get(p).cloned().unwrap_or_else(|| vec![p.path()])
    }

    /// Its name in reports: its first `--set` path on this rig, or its
    /// catalog name ([`ParamRef::label`]) where the rig's netlist has none.
    pub fn name_of(&self, p: &ParamRef) -> String {
        self.set_paths(p)
            .into_iter()
            .next()
            .unwrap_or_else(|| p.label())
    }

    /// The parameters the rig's `refit` names ([`FrictionBench::param`]),
    /// each once, in the order first named.
    pub fn refit_params(&self) -> Vec<ParamRef> {
        let mut out: Vec<ParamRef> = Vec::new();
        for p in self.refit.iter().filter_map(|s| self.param(s)) {
            if !out.contains(&p) {
                out.push(p);
            }
        }
        out
    }

    /// `true` when effect `id` is on.
    pub fn has(&self, id: EffectId) -> bool {
        self.friction.effects.contains_key(&id)
    }

    pub(crate) fn eff(&self, id: EffectId, p: &str) -> f64 {
        self.friction
            .effects
            .get(&id)
            .and_then(|m| m.get(p))
            .copied()
            .unwrap_or(0.0)
    }

    /// The value of a parameter (0 for an effect that is off).
    pub fn get(&self, p: &ParamRef) -> f64 {
        match p {
            ParamRef::Coulomb => self.friction.coulomb,
            ParamRef::Mass => self.mass,
            ParamRef::Effect(id, name) => self.eff(*id, name),
        }
    }

    /// Sets a parameter (switching its effect on if it was off).
    pub fn set(&mut self, p: &ParamRef, v: f64) {
        match p {
            ParamRef::Coulomb => self.friction.coulomb = v,
            ParamRef::Mass => self.mass = v,
            ParamRef::Effect(id, name) => {
                self.friction
                    .effects
                    .entry(*id)
                    .or_default()
                    .insert(name.clone(), v);
            }
        }
    }

    /// The parameters of every effect that is on, plus `Fc` and `m`.
    pub fn all_params(&self) -> Vec<ParamRef> {
        let mut v = vec![ParamRef::Coulomb, ParamRef::Mass];
        for id in self.friction.effects.keys() {
            for p in id.params() {
                v.push(ParamRef::Effect(*id, p.name.to_string()));
            }
        }
        v
    }
}

mod model;
mod presets;
mod signals;
mod switch;

pub use model::{run_options, BenchInputs, BenchRun};
pub use presets::{is_bench_rig, preset, PRESETS, SMOOTHING_VELOCITY};
pub use signals::{bench_signals, BenchSignals};
pub use switch::EffectSwitch;

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rig_json_is_checked() {
        let ok = r#"{"name":"b","mass":1,"force_sign":1,
            "friction":{"coulomb":3,"smoothing_velocity":1e-3,
              "effects":{"viscous":{"b":10}}}}"#;
        assert!(FrictionBench::from_json(ok).is_ok());
        let e = FrictionBench::from_json(&ok.replace("viscous", "warp_drive")).unwrap_err();
        assert!(e.contains("warp_drive"), "{e}");
        let e = FrictionBench::from_json(&ok.replace(r#"{"b":10}"#, r#"{}"#)).unwrap_err();
        assert!(e.contains("'b'") && e.contains("missing"), "{e}");
        let e = FrictionBench::from_json(&ok.replace(
            r#""viscous":{"b":10}"#,
            r#""internal_leakage":{"Cl":1e-12}"#,
        ))
        .unwrap_err();
        assert!(e.contains("does not have"), "{e}");
        let e = FrictionBench::from_json(&ok.replace(r#""mass":1"#, r#""mass":-1"#)).unwrap_err();
        assert!(e.contains("mass"), "{e}");
    }

    /// Every fitted parameter has a netlist path of the bench's circuit (one
    /// of `rig::parameters` of its netlist), and the path reads back as the
    /// same parameter; the catalog names of older files still parse.
    #[test]
    fn fit_targets_are_netlist_paths() {
        let mut all = crate::synth::base_rig();
        for id in BENCH_EFFECTS {
            all.friction.effects.insert(id, crate::synth::planted(id));
        }
        let paths: Vec<String> = hydrocyl_system::netlist::parameters(&all.netlist().unwrap())
            .unwrap()
            .into_iter()
            .map(|p| p.path)
            .collect();
        let params = all.all_params();
        assert_eq!(params.len(), 2 + 10);
        for p in params {
            assert!(paths.contains(&p.path()), "{} not in {paths:?}", p.path());
            assert_eq!(ParamRef::parse(&p.path()), Some(p.clone()));
            assert_eq!(ParamRef::parse(&p.label()), Some(p));
        }
        assert_eq!(
            ParamRef::parse("friction.viscous"),
            ParamRef::parse("viscous.b")
        );
        assert_eq!(ParamRef::parse("friction.warp"), None);
    }
}
