//! The model the loop fits: a netlist rig (any circuit with a `cylinder` on a
//! `mass`), read and edited through its `<component>.<parameter>` paths.
//!
//! Each catalog effect is a set of *targets*: a component type and one of
//! its parameters ([`targets`]). On a rig, an effect's parameter reaches
//! every component of a target type that the rig has (`rig::parameters`
//! lists them); an effect applies when each of its parameters reaches at
//! least one component, and the report names the missing component type
//! otherwise. No rig kind is special-cased: the valve rig and the hybrid
//! rig are both just netlists.
//!
//! Three effects are edits of the friction *law* rather than one
//! parameter (`coulomb_asymmetry`, `stribeck`, `lugre_dynamics`): they act
//! on a friction component of type `friction_coulomb_viscous`,
//! `friction_stribeck` or `friction_lugre` (`friction_law.rs`). `sensor_lag`
//! is a measurement model on the simulated p1/p2 samples (no component).

use std::sync::Arc;

use hydrocyl_system::netlist::registry;
use hydrocyl_system::rig;
use hydrocyl_system::valve_rig::ValveRig;
use serde_json::{Map, Value};

use crate::catalog::EffectId;
pub use crate::catalog::{Scale, Target};

/// Every friction component type of the catalog (they all carry the
/// additive seal terms `seal.k_pressure`, `seal.h_acceleration`).
pub const FRICTION_TYPES: [&str; 6] = [
    "friction_coulomb_viscous",
    "friction_stribeck",
    "friction_karnopp",
    "friction_dahl",
    "friction_lugre",
    "friction_wang",
];

/// Friction types whose law the asymmetry, Stribeck and LuGre edits apply to.
pub const SWITCHABLE_FRICTION: [&str; 3] = [
    "friction_coulomb_viscous",
    "friction_stribeck",
    "friction_lugre",
];

/// The netlist targets of parameter `name` of effect `id`: the targets the
/// catalog declares for it ([`ParamSpec::targets`](crate::catalog::ParamSpec::targets);
/// none for the law edits and the measurement model, which [`Model`]
/// handles itself).
pub fn targets(id: EffectId, name: &str) -> Vec<Target> {
    id.params()
        .iter()
        .find(|p| p.name == name)
        .map_or_else(Vec::new, |p| p.targets.to_vec())
}

/// Whether effect `id` edits the friction law (not one parameter).
pub fn is_law_edit(id: EffectId) -> bool {
    matches!(
        id,
        EffectId::CoulombAsymmetry | EffectId::Stribeck | EffectId::LugreDynamics
    )
}

/// The component names of a rig, by the role the loop needs.
#[derive(Clone, Debug)]
pub struct Roles {
    /// The rig's name.
    pub name: String,
    /// The `cylinder` (or `generalised_cylinder`) the record measures.
    pub cylinder: String,
    /// Its type.
    pub cylinder_type: String,
    /// The `mass` on the cylinder's rod.
    pub load: String,
    /// The servo spool, if any (`servo_spool_*`).
    pub spool: Option<String>,
    /// The position controller, if any.
    pub controller: Option<String>,
    /// The friction component, if any.
    pub friction: Option<String>,
    /// The declared netlist (base of the `scale` targets).
    pub declared: Value,
}

/// A netlist rig being fitted, plus the measurement model's sensor lag.
#[derive(Clone, Debug)]
pub struct Model {
    /// The netlist (kind `netlist`).
    pub net: Value,
    /// First-order lag τ of the pressure sensors applied to the simulated
    /// p1/p2 samples \[s\] (catalog `sensor_lag`; 0 = ideal sensors).
    pub lag: f64,
    /// Component roles (shared by every copy).
    pub roles: Arc<Roles>,
    /// Where the record's first samples contradict a spool at the first
    /// command (a record that starts on a command step), the spool starts
    /// at the opening the initial velocity needs: this many metres of spool
    /// per m/s, applied by [`Model::set_v0`] so that the spool follows the
    /// fitted initial velocity. `None`: the spool starts at the first
    /// command (`sim::with_initial`).
    pub spool_per_velocity: Option<f64>,
}

fn components(net: &Value) -> Option<&Map<String, Value>> {
    net.get("components").and_then(Value::as_object)
}

fn type_of(net: &Value, comp: &str) -> Option<String> {
    components(net)?
        .get(comp)?
        .get("type")?
        .as_str()
        .map(str::to_string)
}

fn first_of(net: &Value, types: &[&str]) -> Option<String> {
    components(net)?.iter().find_map(|(n, c)| {
        let ty = c.get("type").and_then(Value::as_str)?;
        types.contains(&ty).then(|| n.clone())
    })
}

/// The registry's default of a target's parameter (a parameter left at its
/// default is absent from the file).
fn default_of(tg: &Target) -> Option<f64> {
    match registry::lookup(tg.ty)?.param(tg.param)?.default {
        registry::Default::Value(x) => Some(x),
        _ => None,
    }
}

/// Reads `param` (dotted) of component `comp`.
fn read(net: &Value, comp: &str, param: &str) -> Option<f64> {
    let mut v = components(net)?.get(comp)?;
    for seg in param.split('.') {
        v = v.get(seg)?;
    }
    v.as_f64()
}

/// Writes `param` (dotted) of component `comp`, creating the objects on
/// the way (a parameter left at its default is absent from the file).
pub(super) fn write(net: &mut Value, comp: &str, param: &str, x: Value) {
    let Some(mut v) = net.get_mut("components").and_then(|c| c.get_mut(comp)) else {
        return;
    };
    let segs: Vec<&str> = param.split('.').collect();
    for seg in &segs[..segs.len() - 1] {
        if !v.get(*seg).is_some_and(Value::is_object) {
            v[*seg] = Value::Object(Map::new());
        }
        v = &mut v[*seg];
    }
    v[*segs.last().unwrap_or(&"")] = x;
}

impl Model {
    /// A model of netlist `net`: it must read (`rig::check`) and have a
    /// `cylinder` (or `generalised_cylinder`) and a `mass`.
    pub fn new(net: &Value) -> Result<Self, String> {
        rig::check(net).map_err(|e| e.to_string())?;
        let (cylinder, load) = (
            first_of(net, &["cylinder", "generalised_cylinder"]),
            first_of(net, &["mass"]),
        );
        let (Some(cylinder), Some(load)) = (cylinder, load) else {
            return Err(
                "diagnose needs a `cylinder` (or `generalised_cylinder`) and a `mass` in the netlist"
                    .into(),
            );
        };
        let roles = Roles {
            name: net
                .get("name")
                .and_then(Value::as_str)
                .unwrap_or("rig")
                .to_string(),
            cylinder_type: type_of(net, &cylinder).unwrap_or_default(),
            cylinder,
            load,
            spool: first_of(
                net,
                &["servo_spool_first_order", "servo_spool_second_order"],
            ),
            controller: first_of(net, &["position_controller"]),
            friction: first_of(net, &FRICTION_TYPES),
            declared: net.clone(),
        };
        Ok(Self {
            net: net.clone(),
            lag: 0.0,
            roles: Arc::new(roles),
            spool_per_velocity: None,
        })
    }

    /// The components a target reaches on this rig: those of its type (the
    /// registry says the type has the parameter; a test checks every target).
    pub fn reached(&self, tg: &Target) -> Vec<String> {
        let has = registry::lookup(tg.ty).is_some_and(|t| t.param(tg.param).is_some());
        let Some(cs) = components(&self.net).filter(|_| has) else {
            return Vec::new();
        };
        cs.iter()
            .filter(|(_, c)| c.get("type").and_then(Value::as_str) == Some(tg.ty))
            .map(|(n, _)| n.clone())
            .collect()
    }

    /// `Ok` when effect `id` applies to this rig, else why not (the
    /// component type it needs is missing).
    pub fn applies(&self, id: EffectId) -> Result<(), String> {
        if id == EffectId::SensorLag {
            return Ok(());
        }
        if is_law_edit(id) {
            let ty = self.friction_type();
            return match ty.as_deref() {
                Some(t) if SWITCHABLE_FRICTION.contains(&t) => Ok(()),
                Some(t) => Err(format!(
                    "edits the friction law, and the rig's `{t}` is not one it edits ({})",
                    SWITCHABLE_FRICTION.join(", ")
                )),
                None => Err("needs a friction component (the rig has none)".into()),
            };
        }
        // the effects sized by the pressure the circuit holds
        match id {
            EffectId::PressureViscous if self.seal_dp() <= 0.0 => {
                return Err(format!(
                    "the seal term K (p1 − p2)² v has no pressure to be sized at: {} and the friction has no `seal.dp_max`",
                    NO_PRESSURE
                ));
            }
            EffectId::SupplyDroop if self.supply() <= 0.0 => {
                return Err(format!("no supply to droop: {NO_PRESSURE}"));
            }
            _ => {}
        }
        for q in id.params() {
            let tg = targets(id, q.name);
            if !tg.iter().any(|tg| !self.reached(tg).is_empty()) {
                let mut types: Vec<&str> = tg.iter().map(|t| t.ty).collect();
                types.dedup();
                return Err(format!(
                    "needs a component of type {} (the rig has none)",
                    types
                        .iter()
                        .map(|t| format!("`{t}`"))
                        .collect::<Vec<_>>()
                        .join(" or ")
                ));
            }
        }
        Ok(())
    }

    /// The `<component>.<parameter>` paths effect `id` writes on this rig.
    pub fn paths_of(&self, id: EffectId) -> Vec<String> {
        let mut out = Vec::new();
        for q in id.params() {
            for tg in &targets(id, q.name) {
                for c in self.reached(tg) {
                    out.push(format!("{c}.{}", tg.param));
                }
            }
        }
        if is_law_edit(id) {
            if let Some(f) = &self.roles.friction {
                out.push(format!("{f} (law)"));
            }
        }
        out
    }

    /// The friction component's type (it changes with the law edits).
    pub fn friction_type(&self) -> Option<String> {
        self.roles
            .friction
            .as_ref()
            .and_then(|f| type_of(&self.net, f))
    }

    /// The first component an effect parameter's targets reach, with its
    /// target (the component the parameter is read from).
    fn first_reached(&self, id: EffectId, name: &str) -> Option<(Target, String)> {
        targets(id, name)
            .into_iter()
            .find_map(|tg| self.reached(&tg).into_iter().next().map(|c| (tg, c)))
    }

    /// Reads a parameter target: the first component it reaches.
    pub(super) fn read_target(&self, id: EffectId, name: &str) -> Option<f64> {
        let (tg, c) = self.first_reached(id, name)?;
        let v = read(&self.net, &c, tg.param).or_else(|| default_of(&tg))?;
        match tg.scale {
            Scale::Factor => Some(v / read(&self.roles.declared, &c, tg.param)?),
            Scale::Absolute | Scale::Ratio => Some(v),
        }
    }

    /// Writes a parameter target on every component it reaches.
    pub(super) fn write_target(&mut self, id: EffectId, name: &str, x: f64) {
        let declared = |c: &str, tg: &Target| {
            read(&self.roles.declared, c, tg.param).or_else(|| default_of(tg))
        };
        // a `Ratio` target's reference: the first component's declared value
        let reference = self
            .first_reached(id, name)
            .and_then(|(tg, c)| declared(&c, &tg))
            .filter(|r| *r != 0.0 && r.is_finite());
        let mut writes = Vec::new();
        for tg in &targets(id, name) {
            for c in self.reached(tg) {
                let v = match (tg.scale, reference) {
                    (Scale::Absolute, _) | (Scale::Ratio, None) => x,
                    (Scale::Factor, _) => {
                        read(&self.roles.declared, &c, tg.param).unwrap_or(1.0) * x
                    }
                    (Scale::Ratio, Some(r)) => declared(&c, tg).map_or(x, |d| x * (d / r)),
                };
                writes.push((c, tg.param, v));
            }
        }
        for (c, param, v) in writes {
            write(&mut self.net, &c, param, Value::from(v));
        }
    }

    /// A parameter of component `comp` (default-filled paths only where the
    /// file has it; `None` where absent).
    pub fn param(&self, comp: &str, param: &str) -> Option<f64> {
        read(&self.net, comp, param)
    }

    /// Sets a parameter of component `comp` (`Value::Null` clears an
    /// initial state back to the rig's default).
    pub fn set_param(&mut self, comp: &str, param: &str, x: Value) {
        write(&mut self.net, comp, param, x);
    }

    /// The channels of `names` (the record's compared channels: `position`,
    /// `velocity`, `p1`, `p2`, `command`) the circuit has no output for,
    /// with the probe that would give each (`position` → `<mass>.position`):
    /// a netlist whose `outputs` leave them out (or that lists none, so
    /// that every probe is named `component.probe`) cannot be compared.
    pub fn missing_outputs(&self, names: &[&str]) -> Vec<(String, String)> {
        let Ok(c) = rig::circuit(
            &self.net,
            hydrocyl_system::signal::Signal::Constant { value: 0.0 },
        ) else {
            return Vec::new();
        };
        let have: Vec<String> = c.probes().into_iter().map(|p| p.name).collect();
        let r = &self.roles;
        names
            .iter()
            .filter(|n| !have.iter().any(|h| h == *n))
            .map(|&n| {
                let owner = match n {
                    "position" | "velocity" => r.load.as_str(),
                    "command" => r.controller.as_deref().unwrap_or("command"),
                    _ => r.cylinder.as_str(),
                };
                (n.to_string(), format!("{owner}.{n}"))
            })
            .collect()
    }

    /// The cylinder's stroke \[m\].
    pub fn stroke(&self) -> f64 {
        self.param(&self.roles.cylinder, "stroke")
            .unwrap_or(f64::NAN)
    }

    /// The spool stroke \[m\] (0 without a servo spool).
    pub fn spool_stroke(&self) -> f64 {
        self.roles
            .spool
            .as_ref()
            .and_then(|s| self.param(s, "stroke"))
            .unwrap_or(0.0)
    }

    /// The moving mass \[kg\].
    pub fn mass(&self) -> f64 {
        self.param(&self.roles.load, "mass").unwrap_or(0.0)
    }

    /// The initial piston position \[m\] (0 where the rig leaves it).
    pub fn x0(&self) -> f64 {
        self.param(&self.roles.cylinder, "initial.position")
            .unwrap_or(0.0)
    }

    /// The initial piston velocity \[m/s\].
    pub fn v0(&self) -> f64 {
        self.param(&self.roles.cylinder, "initial.velocity")
            .unwrap_or(0.0)
    }

    /// Sets the initial piston position \[m\].
    pub fn set_x0(&mut self, x: f64) {
        let c = self.roles.cylinder.clone();
        self.set_param(&c, "initial.position", Value::from(x));
    }

    /// Sets the initial piston velocity \[m/s\].
    pub fn set_v0(&mut self, v: f64) {
        let c = self.roles.cylinder.clone();
        self.set_param(&c, "initial.velocity", Value::from(v));
        if let (Some(k), Some(s)) = (self.spool_per_velocity, self.roles.spool.clone()) {
            let xm = self.spool_stroke();
            self.set_param(&s, "initial.position", Value::from((k * v).clamp(-xm, xm)));
        }
    }

    /// The highest pressure the circuit holds above its lowest source
    /// (supply over tank; where no source is above tank, the highest relief
    /// valve's cracking pressure) \[Pa\].
    pub fn supply(&self) -> f64 {
        let Some(cs) = components(&self.net) else {
            return 0.0;
        };
        let of = |ty: &str, p: &str| -> Vec<f64> {
            cs.values()
                .filter(|c| c.get("type").and_then(Value::as_str) == Some(ty))
                .filter_map(|c| c.get(p).and_then(Value::as_f64))
                .collect()
        };
        let sources = of("pressure_source", "pressure");
        let lo = sources.iter().copied().fold(f64::INFINITY, f64::min);
        let hi = sources.iter().copied().fold(f64::NEG_INFINITY, f64::max);
        let lo = if lo.is_finite() { lo } else { 0.0 };
        if hi > lo {
            return hi - lo;
        }
        of("relief_valve", "cracking")
            .into_iter()
            .fold(0.0, f64::max)
    }

    /// The pressure difference the seal term `pressure_viscous` is sized at \[Pa\]: half the supply
    /// ([`Model::supply`]), or the friction component's bound `seal.dp_max`
    /// where that is lower; the bound alone where the circuit holds no
    /// pressure above tank; 0 (the effect does not apply) where neither is
    /// there.
    pub fn seal_dp(&self) -> f64 {
        let half = 0.5 * self.supply();
        let bound = self
            .roles
            .friction
            .as_deref()
            .and_then(|f| self.param(f, "seal.dp_max"))
            .filter(|b| *b > 0.0);
        match bound {
            Some(b) if half > 0.0 => half.min(b),
            Some(b) => b,
            None => half.max(0.0),
        }
    }
}

/// Why a circuit has no supply pressure (the reason of the effects sized by it).
const NO_PRESSURE: &str =
    "the circuit holds no pressure above tank (no pressure source above the lowest one, no relief valve)";

impl Model {
    /// The model of a `valve-cylinder` rig value: its netlist, with the
    /// sensor lag taken out of the circuit into the measurement model.
    pub fn from_valve_rig(rig: &ValveRig) -> Result<Self, String> {
        let mut r = rig.clone();
        let lag = r.sensors.pressure_lag_s;
        r.sensors.pressure_lag_s = 0.0;
        let net = r.to_netlist().map_err(|e| e.to_string())?;
        let mut m = Self::new(&net)?;
        m.lag = lag;
        Ok(m)
    }

    /// This model as a `valve-cylinder` rig value, where the netlist is that
    /// circuit (the sensor lag back in the rig's sensors).
    pub fn to_valve_rig(&self) -> Result<ValveRig, String> {
        let mut r = ValveRig::from_netlist(&self.net).map_err(|e| e.to_string())?;
        r.sensors.pressure_lag_s = self.lag;
        Ok(r)
    }
}
