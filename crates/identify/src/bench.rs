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
//! The bristle state is integrated exactly over each sample step with the
//! velocity held at the step's mid value (z relaxes exponentially towards
//! `g(v) sgn(v) / σ0`), so σ0 of 1e7 N/m at 100 Hz is no stiffness problem.

use std::collections::BTreeMap;

use serde::{Deserialize, Serialize};
use thiserror::Error;

use crate::catalog::{Balance, EffectId};
use crate::data::{ColumnMap, Record, Signal};

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
    /// Parses `Fc`, `m` or `effect.param`.
    pub fn parse(s: &str) -> Option<ParamRef> {
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

/// The signals of one record the bench model runs on (all SI, per sample).
#[derive(Clone, Debug, PartialEq)]
pub struct BenchSignals {
    /// Record name.
    pub source: String,
    /// Time \[s\].
    pub t: Vec<f64>,
    /// Position (smoothed, or integrated from measured velocity) \[m\].
    pub x: Vec<f64>,
    /// Velocity (smoothed derivative of position, or measured) \[m·s⁻¹\].
    pub v: Vec<f64>,
    /// Acceleration \[m·s⁻²\].
    pub a: Vec<f64>,
    /// Chamber pressure p1 (zero if not measured) \[Pa\].
    pub p1: Vec<f64>,
    /// Chamber pressure p2 (zero if not measured) \[Pa\].
    pub p2: Vec<f64>,
    /// Measured load-cell force \[N\].
    pub force: Vec<f64>,
}

impl FrictionBench {
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
            let p = ParamRef::parse(r).ok_or_else(|| RigError::Parameter {
                place: "refit".into(),
                reason: format!("'{r}' is not Fc, m or effect.param"),
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

    /// `true` when effect `id` is on.
    pub fn has(&self, id: EffectId) -> bool {
        self.friction.effects.contains_key(&id)
    }

    fn eff(&self, id: EffectId, p: &str) -> f64 {
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

    /// The law's coefficients, looked up once per simulation.
    fn coeffs(&self) -> Coeffs {
        let fc = self.friction.coulomb;
        Coeffs {
            fc,
            vt: self.friction.smoothing_velocity,
            stribeck: self.has(EffectId::Stribeck).then(|| {
                (
                    self.eff(EffectId::Stribeck, "Fs"),
                    self.eff(EffectId::Stribeck, "vs").max(1e-12),
                    self.eff(EffectId::Stribeck, "alpha"),
                )
            }),
            lugre: self.has(EffectId::LugreDynamics).then(|| {
                (
                    self.eff(EffectId::LugreDynamics, "sigma0").max(1e-9),
                    self.eff(EffectId::LugreDynamics, "sigma1"),
                )
            }),
            b: self.eff(EffectId::Viscous, "b"),
            k: self.eff(EffectId::PressureViscous, "K"),
            h: self.eff(EffectId::AccelerationFriction, "H"),
            dfc: self.eff(EffectId::CoulombAsymmetry, "dFc"),
        }
    }

    /// Simulates the bench on one record: the predicted load-cell force at
    /// every sample. The bristle state starts from the value that explains
    /// the first five samples' force (limited to the steady range).
    pub fn simulate(&self, s: &BenchSignals) -> Vec<f64> {
        self.simulate_from(s, false)
    }

    /// Simulates the bench with the bristle deflection starting at zero (at
    /// rest) instead of from the measured force: what `hydrocyl simulate`
    /// does for a record that has no force to start from.
    pub fn simulate_from_rest(&self, s: &BenchSignals) -> Vec<f64> {
        self.simulate_from(s, true)
    }

    fn simulate_from(&self, s: &BenchSignals, at_rest: bool) -> Vec<f64> {
        let c = self.coeffs();
        let n = s.t.len();
        let mut out = vec![0.0; n];
        let f0 = self.eff(EffectId::ExternalForce, "F0");
        let sg = self.force_sign;
        let pres = |i: usize| s.p1[i] * self.area1 - s.p2[i] * self.area2;
        let mut z = 0.0;
        if let (Some((s0, _)), false) = (c.lugre, at_rest) {
            // s F = m a + F_f + F0 − pA  →  F_f = s F − m a − F0 + pA.
            let k = n.min(5);
            let ff: f64 = (0..k)
                .map(|i| sg * s.force[i] - self.mass * s.a[i] - f0 + pres(i))
                .sum::<f64>()
                / k as f64;
            let zmax = c.g(s.v[0]) / s0;
            z = (ff / s0).clamp(-zmax, zmax);
        }
        for (i, o) in out.iter_mut().enumerate() {
            let ff = c.friction(s.v[i], s.a[i], s.p1[i], s.p2[i], z);
            *o = sg * (self.mass * s.a[i] + ff + f0 - pres(i));
            if let (Some((s0, _)), true) = (c.lugre, i + 1 < n) {
                let h = s.t[i + 1] - s.t[i];
                let vm = 0.5 * (s.v[i] + s.v[i + 1]);
                let g = c.g(vm).max(1e-9);
                let rate = s0 * vm.abs() / g;
                if rate * h > 1e-12 {
                    let zs = vm / rate;
                    z = zs + (z - zs) * (-rate * h).exp();
                } else {
                    z += vm * h;
                }
            }
        }
        out
    }
}

/// Names of the built-in friction-bench presets: netlist files in
/// `fixtures/rigs/` listed in `hydrocyl_system::rig::PRESETS`.
pub const PRESETS: [&str; 3] = ["tudelft-seal-25", "tudelft-seal-257", "emps"];

/// What identification needs of a bench preset beyond its circuit: where
/// the signals are in the measured files, which parameters to refit, and the
/// smoothing velocity of the static law where the netlist's law has none.
struct Identification {
    name: &'static str,
    columns: &'static [(Signal, &'static str)],
    refit: &'static [&'static str],
    smoothing_velocity: f64,
}

const TUDELFT_COLUMNS: &[(Signal, &str)] = &[
    (Signal::Time, "time_ms [ms]"),
    (Signal::Position, "position_mm [mm]"),
    (Signal::P2, "pressure_bar_gauge [bar]"),
    (Signal::Force, "force_N [N]"),
];
const TUDELFT_REFIT: &[&str] = &["Fc", "lugre_dynamics.sigma0", "viscous.b"];

const IDENTIFICATION: [Identification; 3] = [
    Identification {
        name: "tudelft-seal-25",
        columns: TUDELFT_COLUMNS,
        refit: TUDELFT_REFIT,
        smoothing_velocity: 1e-4,
    },
    Identification {
        name: "tudelft-seal-257",
        columns: TUDELFT_COLUMNS,
        refit: TUDELFT_REFIT,
        smoothing_velocity: 1e-4,
    },
    Identification {
        name: "emps",
        columns: &[
            (Signal::Time, "t_s"),
            (Signal::Position, "qm_motor_position_m"),
            (Signal::Force, "force_N(=gtau*vir)"),
        ],
        refit: &["Fc", "m", "viscous.b"],
        smoothing_velocity: 1e-3,
    },
];

/// A built-in friction-bench preset, or `None`: the identification view
/// ([`FrictionBench::from_netlist`]) of the netlist preset of that name.
///
/// * `tudelft-seal-25` / `tudelft-seal-257`: the TU Delft pneumatic seal
///   rig (Zillen 2021), bore 25 mm / 25.7 mm, one chamber at constant gauge
///   pressure pushing the piston towards −x, drive through a load cell
///   pushing +x (so `F = p A + F_f + m a`); declared as LuGre (eq 5.1) with
///   viscous σ2 and *no pressure term*, Fc, σ0 and b refitted. The moving
///   mass (0.1 kg) is assumed: the provenance does not give it, and at
///   these accelerations (< 0.1 m/s²) m a is below 0.01 N.
/// * `emps`: the EMPS electromechanical axis (Janot et al. 2019): motor
///   force `gtau · vir` pushes +x, no pressures; declared Coulomb + viscous
///   with Fc, b and the moving mass m refitted.
pub fn preset(name: &str) -> Option<FrictionBench> {
    let id = IDENTIFICATION.iter().find(|i| i.name == name)?;
    let v = hydrocyl_system::rig::preset(name)?;
    let mut rig = FrictionBench::from_netlist(&v, id.smoothing_velocity).ok()?;
    rig.name = name.into();
    for (sig, col) in id.columns {
        rig.columns.0.insert(*sig, (*col).into());
    }
    rig.refit = id.refit.iter().map(|r| r.to_string()).collect();
    Some(rig)
}

impl FrictionBench {
    /// The identification view of a friction-bench netlist: one
    /// `imposed_motion` drive (mass, load-cell sign), at most one `piston`
    /// (areas) and one friction law on the rod, `friction_coulomb_viscous`
    /// or `friction_lugre` with equal extending and retracting sets (a
    /// stiction level above the Coulomb level is the `stribeck` effect).
    /// `smoothing_velocity` is the static law's tanh velocity where the
    /// netlist's law has none (LuGre). Another circuit is refused by path.
    pub fn from_netlist(v: &serde_json::Value, smoothing_velocity: f64) -> Result<Self, String> {
        let s = hydrocyl_system::netlist::read(v)
            .map_err(|e| hydrocyl_system::rig::RigError::from(e).to_string())?;
        let of = |ty: &str| -> Vec<&hydrocyl_system::netlist::registry::Instance> {
            s.instances
                .iter()
                .filter(|i| i.ty.name.starts_with(ty))
                .collect()
        };
        let one = |ty: &str| match of(ty).as_slice() {
            [i] => Ok(*i),
            l => Err(format!(
                "components: a friction bench has one `{ty}` component, found {}",
                l.len()
            )),
        };
        let drive = one("imposed_motion")?;
        let law = one("friction_")?;
        let (area1, area2) = match of("piston").as_slice() {
            [] => (0.0, 0.0),
            [p] => (p.get("area_1"), p.get("area_2")),
            _ => return Err("components: a friction bench has at most one `piston`".into()),
        };
        if let Some(extra) = s.instances.iter().find(|i| {
            !["imposed_motion", "piston", "pressure_source"].contains(&i.ty.name)
                && !std::ptr::eq(*i, law)
        }) {
            return Err(format!(
                "components.{}: a `{}` is not part of a friction bench (imposed_motion, piston, pressure_source, one friction law)",
                extra.name, extra.ty.name
            ));
        }
        let here = |p: &str| format!("components.{}.{p}", law.name);
        let mut effects = BTreeMap::new();
        let mut on = |id: EffectId, params: &[(&str, f64)]| {
            effects.insert(
                id,
                params.iter().map(|(k, v)| (k.to_string(), *v)).collect(),
            );
        };
        let (coulomb, vt) = match law.ty.name {
            "friction_coulomb_viscous" => {
                on(EffectId::Viscous, &[("b", law.get("viscous"))]);
                (law.get("coulomb"), law.get("smoothing_velocity"))
            }
            "friction_lugre" => {
                for p in [
                    "curve.coulomb",
                    "curve.stiction",
                    "curve.stribeck_velocity",
                    "curve.stribeck_exponent",
                    "sigma2",
                ] {
                    let (e, r) = (format!("extending.{p}"), format!("retracting.{p}"));
                    if law.get(&e) != law.get(&r) {
                        return Err(format!(
                            "{}: the bench's law has one set for both directions ({} ≠ {})",
                            here(&e),
                            law.get(&e),
                            law.get(&r)
                        ));
                    }
                }
                let fc = law.get("extending.curve.coulomb");
                let fs = law.get("extending.curve.stiction");
                if fs != fc {
                    on(
                        EffectId::Stribeck,
                        &[
                            ("Fs", fs),
                            ("vs", law.get("extending.curve.stribeck_velocity")),
                            ("alpha", law.get("extending.curve.stribeck_exponent")),
                        ],
                    );
                }
                on(
                    EffectId::LugreDynamics,
                    &[("sigma0", law.get("sigma0")), ("sigma1", law.get("sigma1"))],
                );
                on(EffectId::Viscous, &[("b", law.get("extending.sigma2"))]);
                (fc, smoothing_velocity)
            }
            other => {
                return Err(format!(
                    "components.{}.type: `{other}` has no friction-bench view (friction_coulomb_viscous or friction_lugre)",
                    law.name
                ))
            }
        };
        let k = law.opt("seal.k_pressure").unwrap_or(0.0);
        let h = law.opt("seal.h_acceleration").unwrap_or(0.0);
        if k > 0.0 {
            on(EffectId::PressureViscous, &[("K", k)]);
        }
        if h != 0.0 {
            on(EffectId::AccelerationFriction, &[("H", h)]);
        }
        let rig = FrictionBench {
            kind: KIND.into(),
            name: s.name.clone(),
            area1,
            area2,
            mass: drive.get("mass"),
            force_sign: drive.get("force_sign"),
            friction: BenchFriction {
                coulomb,
                smoothing_velocity: vt,
                effects,
            },
            steady_state: false,
            refit: Vec::new(),
            columns: ColumnMap::default(),
        };
        rig.validate().map_err(|e| e.to_string())?;
        Ok(rig)
    }
}

/// The friction law's coefficients in plain fields (the hot loop's view).
struct Coeffs {
    fc: f64,
    vt: f64,
    stribeck: Option<(f64, f64, f64)>,
    lugre: Option<(f64, f64)>,
    b: f64,
    k: f64,
    h: f64,
    dfc: f64,
}

impl Coeffs {
    /// g(v): Coulomb level plus the Stribeck hump if on \[N\].
    fn g(&self, v: f64) -> f64 {
        match self.stribeck {
            Some((fs, vs, al)) => {
                let r = (v / vs).abs();
                let e = if al == 1.0 { r } else { r.powf(al) };
                self.fc + (fs - self.fc) * (-e).exp()
            }
            None => self.fc,
        }
    }

    /// Friction force at one instant \[N\].
    fn friction(&self, v: f64, a: f64, p1: f64, p2: f64, z: f64) -> f64 {
        let th = (v / self.vt).tanh();
        let mut f = match self.lugre {
            Some((s0, s1)) => {
                let g = self.g(v).max(1e-9);
                let zdot = v - s0 * v.abs() * z / g;
                s0 * z + s1 * zdot
            }
            None => self.g(v) * th,
        };
        f += self.b * v;
        f += self.k * (p1 - p2).powi(2) * v;
        f += self.k * self.h * a;
        f += 0.5 * self.dfc * th.abs();
        f
    }
}

/// Prepares a record for the bench: smoothed velocity and acceleration from
/// position (or measured velocity), pressures (zero where absent), force.
pub fn bench_signals(
    rec: &Record,
    half_window: Option<usize>,
    steady_state: bool,
) -> Result<(BenchSignals, crate::smooth::SmootherInfo), crate::data::DataError> {
    let force = rec.require(Signal::Force)?.to_vec();
    let t = rec.time.clone();
    let zeros = vec![0.0; t.len()];
    let p1 = rec
        .get(Signal::P1)
        .map_or_else(|| zeros.clone(), |p| p.to_vec());
    let p2 = rec
        .get(Signal::P2)
        .map_or_else(|| zeros.clone(), |p| p.to_vec());
    if steady_state {
        let v = rec.require(Signal::Velocity)?.to_vec();
        let info = crate::smooth::SmootherInfo {
            method: "none (steady-state samples: measured velocity, zero acceleration)".into(),
            order: 0,
            half_window: 0,
            window_s: 0.0,
            criterion: "steady".into(),
            residual_rms: 0.0,
        };
        return Ok((
            BenchSignals {
                source: rec.source.clone(),
                x: zeros.clone(),
                a: zeros,
                t,
                v,
                p1,
                p2,
                force,
            },
            info,
        ));
    }
    let (x, v, a, info) = if let Some(x) = rec.get(Signal::Position) {
        let s = match half_window {
            Some(h) => crate::smooth::smooth_with(&t, x, h, 3),
            None => crate::smooth::smooth_gcv(&t, x, 3, 400),
        };
        (s.value, s.d1, s.d2, s.info)
    } else {
        let vel = rec.require(Signal::Velocity)?;
        let s = match half_window {
            Some(h) => crate::smooth::smooth_with(&t, vel, h, 3),
            None => crate::smooth::smooth_gcv(&t, vel, 3, 400),
        };
        let mut x = vec![0.0; t.len()];
        for i in 1..t.len() {
            x[i] = x[i - 1] + 0.5 * (s.value[i] + s.value[i - 1]) * (t[i] - t[i - 1]);
        }
        (x, s.value, s.d1, s.info)
    };
    Ok((
        BenchSignals {
            source: rec.source.clone(),
            t,
            x,
            v,
            a,
            p1,
            p2,
            force,
        },
        info,
    ))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn rig() -> FrictionBench {
        FrictionBench {
            kind: KIND.into(),
            name: "t".into(),
            area1: 4.9e-4,
            area2: 0.0,
            mass: 0.5,
            force_sign: 1.0,
            friction: BenchFriction {
                coulomb: 5.0,
                smoothing_velocity: 1e-4,
                effects: BTreeMap::new(),
            },
            refit: vec![],
            columns: ColumnMap::default(),
            steady_state: false,
        }
    }

    fn signals(v: impl Fn(f64) -> f64, n: usize, dt: f64) -> BenchSignals {
        let t: Vec<f64> = (0..n).map(|i| i as f64 * dt).collect();
        let vv: Vec<f64> = t.iter().map(|&t| v(t)).collect();
        BenchSignals {
            source: "x".into(),
            a: vec![0.0; n],
            p1: vec![3e5; n],
            p2: vec![0.0; n],
            force: vec![0.0; n],
            x: vec![0.0; n],
            v: vv,
            t,
        }
    }

    #[test]
    fn lugre_reaches_the_static_curve_at_constant_velocity() {
        // At constant velocity the bristle settles and LuGre's force equals
        // the static law g(v) (eq 5.7); the balance adds s(F_f − p A).
        let mut r = rig();
        let mut lug = BTreeMap::new();
        lug.insert("sigma0".to_string(), 1e6);
        lug.insert("sigma1".to_string(), 50.0);
        r.friction.effects.insert(EffectId::LugreDynamics, lug);
        let s = signals(|_| 0.01, 500, 1e-3);
        let f = r.simulate(&s);
        let expect = 5.0 - 3e5 * 4.9e-4;
        assert!((f[499] - expect).abs() < 1e-6, "{} vs {expect}", f[499]);
        // Static model gives the same steady value.
        r.friction.effects.clear();
        let g = r.simulate(&s);
        assert!((g[499] - expect).abs() < 1e-6);
    }

    #[test]
    fn lugre_presliding_follows_the_closed_form() {
        // Monotone motion from z = 0 with σ1 = 0: dz/dx = 1 − σ0 z / Fc, so
        // F = σ0 z = Fc (1 − exp(−σ0 x / Fc)) — a spring for x ≪ Fc/σ0,
        // saturating at Fc. Checked at several travels.
        let mut r = rig();
        r.area1 = 0.0;
        let mut lug = BTreeMap::new();
        lug.insert("sigma0".to_string(), 1e6);
        lug.insert("sigma1".to_string(), 0.0);
        r.friction.effects.insert(EffectId::LugreDynamics, lug);
        let dt = 1e-4;
        let v0 = 1e-4;
        let s = signals(|_| v0, 2000, dt);
        let f = r.simulate(&s);
        for i in [10, 100, 400, 1999] {
            let x = v0 * dt * i as f64;
            let closed = 5.0 * (1.0 - (-1e6 * x / 5.0).exp());
            assert!(
                (f[i] - closed).abs() < 1e-3 * 5.0,
                "i={i}: {} vs {closed}",
                f[i]
            );
        }
        // Small travel: spring of stiffness σ0.
        assert!((f[10] / (v0 * dt * 10.0) / 1e6 - 1.0).abs() < 0.05);
    }

    /// The presets' identification view is the declaration the bench had
    /// before its circuit became a netlist, field for field (so `diagnose`
    /// and `cargo xtask validate` fit the same model from the same start).
    #[test]
    fn presets_are_the_netlists_seen_as_benches() {
        let effects = |e: &[(EffectId, &[(&str, f64)])]| -> BTreeMap<_, _> {
            e.iter()
                .map(|(id, p)| (*id, p.iter().map(|(k, v)| (k.to_string(), *v)).collect()))
                .collect()
        };
        for (name, bore) in [("tudelft-seal-25", 0.025f64), ("tudelft-seal-257", 0.0257)] {
            let r = preset(name).unwrap();
            assert_eq!(r.area1, 0.0);
            assert_eq!(r.area2, std::f64::consts::PI * (0.5 * bore).powi(2));
            assert_eq!((r.mass, r.force_sign), (0.1, 1.0));
            assert_eq!(r.friction.coulomb, 5.0);
            assert_eq!(r.friction.smoothing_velocity, 1e-4);
            assert_eq!(
                r.friction.effects,
                effects(&[
                    (EffectId::LugreDynamics, &[("sigma0", 1e5), ("sigma1", 0.0)]),
                    (EffectId::Viscous, &[("b", 0.0)]),
                ])
            );
            assert_eq!(r.refit, ["Fc", "lugre_dynamics.sigma0", "viscous.b"]);
            assert_eq!(r.columns.0[&Signal::Time], "time_ms [ms]");
        }
        let r = preset("emps").unwrap();
        assert_eq!(
            (r.area1, r.area2, r.mass, r.force_sign),
            (0.0, 0.0, 50.0, 1.0)
        );
        assert_eq!(
            (r.friction.coulomb, r.friction.smoothing_velocity),
            (10.0, 1e-3)
        );
        assert_eq!(
            r.friction.effects,
            effects(&[(EffectId::Viscous, &[("b", 100.0)])])
        );
        assert_eq!(r.refit, ["Fc", "m", "viscous.b"]);
        assert!(preset("leaney-moog").is_none());
    }

    /// The netlist run of a bench preset (`rig::simulate`, imposed velocity)
    /// and the bench's inverse model on the same motion give the same
    /// load-cell force: LuGre's bristle from rest on a velocity that ramps
    /// up, holds, reverses (the model integrates it exactly per sample, the
    /// netlist with DP45 at rtol 1e-9).
    #[test]
    fn netlist_run_equals_the_inverse_model() {
        use hydrocyl_system::{rig, run::RunOptions, signal::Signal as Cmd};
        for name in PRESETS {
            let bench = preset(name).unwrap();
            let dt = 1e-3;
            let t: Vec<f64> = (0..3000).map(|i| i as f64 * dt).collect();
            let v: Vec<f64> = t
                .iter()
                .map(|&t| 0.02 * (t / 0.5).min(1.0) * (std::f64::consts::PI * t / 1.5).cos())
                .collect();
            let mut opts = RunOptions::dp45();
            opts.rtol = 1e-9;
            let mut value = rig::preset(name).unwrap();
            // the record's chamber pressure is the preset's constant
            let p = if bench.area2 > 0.0 { 3e5 } else { 0.0 };
            if p > 0.0 {
                rig::apply_set(&mut value, "chamber.pressure=3e5").unwrap();
            }
            let run = rig::simulate(&value, Cmd::table(t.clone(), v.clone()).unwrap(), &t, &opts)
                .unwrap();
            let f = run.channel("force").unwrap();
            // the model's signals: acceleration as the netlist sees it (the
            // slope of the interval that starts at the sample)
            let mut a: Vec<f64> = v.windows(2).map(|w| (w[1] - w[0]) / dt).collect();
            a.push(0.0);
            let s = BenchSignals {
                source: "x".into(),
                x: vec![0.0; t.len()],
                p1: vec![0.0; t.len()],
                p2: vec![p; t.len()],
                force: vec![0.0; t.len()],
                v,
                a,
                t,
            };
            let model = bench.simulate_from_rest(&s);
            let scale = model.iter().fold(0.0f64, |m, f| m.max(f.abs()));
            let worst = f
                .iter()
                .zip(&model)
                .map(|(x, y)| (x - y).abs())
                .fold(0.0, f64::max);
            assert!(worst < 1e-6 * scale, "{name}: worst {worst} N of {scale} N");
        }
    }

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
}
