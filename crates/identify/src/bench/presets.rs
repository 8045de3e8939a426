//! How a friction bench is read: the built-in presets (the bench netlists of
//! `fixtures/rigs/` with their identification sections, read as any rig
//! file is) and rig files — a netlist whose
//! identification section names the `friction-bench` model
//! ([`FrictionBench::from_rig`]), or an older `friction-bench` file read
//! as that netlist (`hydrocyl_system::rig::load` migrates it).

use std::collections::BTreeMap;

use super::{BenchFriction, FrictionBench, ParamRef, KIND};
use crate::catalog::EffectId;
use crate::data::{ColumnMap, Signal};

/// Names of the built-in friction-bench presets: netlist files in
/// `fixtures/rigs/` listed in `hydrocyl_system::rig::PRESETS`.
pub const PRESETS: [&str; 3] = ["tudelft-seal-25", "tudelft-seal-257", "emps"];

/// A built-in friction-bench preset, or `None`: the netlist preset of that
/// name read as its file is ([`FrictionBench::from_rig`]: the circuit's view
/// and the file's own `identify` section), so the name, the file and its
/// `--print-rig` are one bench.
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
    if !PRESETS.contains(&name) {
        return None;
    }
    // the preset file's own identification section (columns, refits, the
    // LuGre law's smoothing velocity): what its file and `--print-rig` read as
    FrictionBench::from_rig(&hydrocyl_system::rig::preset(name)?).ok()
}

/// The law's tanh smoothing velocity \[m/s\] of a rig file's bench whose
/// netlist law has none (LuGre, `friction_lugre`) and whose identification
/// section gives none (`identify.smoothing_velocity`).
pub const SMOOTHING_VELOCITY: f64 = 1e-3;

/// `true` when a rig value is a friction bench for identification: a
/// netlist whose `identify.model` is `friction-bench`, or an older
/// `friction-bench` file.
pub fn is_bench_rig(v: &serde_json::Value) -> bool {
    v.pointer("/identify/model").and_then(|m| m.as_str())
        == Some(hydrocyl_system::netlist::identify::IdentifyModel::FrictionBench.name())
        || v.get("kind").and_then(|k| k.as_str()) == Some(KIND)
}

impl FrictionBench {
    /// The bench of a rig value for identification: a netlist with the
    /// `friction-bench` identification section (its columns, refits and
    /// steady-state flag; the circuit's view by [`FrictionBench::from_netlist`]),
    /// or an older `friction-bench` file migrated to that netlist
    /// (`hydrocyl_system::netlist::migrate`). Errors name the JSON path.
    pub fn from_rig(v: &serde_json::Value) -> Result<Self, String> {
        use hydrocyl_system::netlist::{self, identify::IdentifyModel};
        let migrated;
        let net = match netlist::migrate::migrate(v).map_err(|e| e.to_string())? {
            Some(n) => {
                migrated = n;
                &migrated
            }
            None => v,
        };
        let s =
            netlist::read(net).map_err(|e| hydrocyl_system::rig::RigError::from(e).to_string())?;
        let Some(id) = s
            .identify
            .filter(|i| i.model == IdentifyModel::FrictionBench)
        else {
            return Err(format!(
                "`identify.model`: not a friction bench (a bench rig file's identification section names the model \"{}\")",
                IdentifyModel::FrictionBench.name()
            ));
        };
        let vt = id.smoothing_velocity.unwrap_or(SMOOTHING_VELOCITY);
        let mut b = FrictionBench::from_netlist(net, vt)?;
        for (role, header) in &id.columns {
            let sig = Signal::from_name(role)
                .ok_or_else(|| format!("`identify.columns.{role}`: not a measured-data signal"))?;
            b.columns.0.insert(sig, header.clone());
        }
        b.refit = id.refit;
        b.steady_state = id.steady_state;
        b.validate().map_err(|e| e.to_string())?;
        Ok(b)
    }

    /// The identification view of a friction-bench netlist: one
    /// `imposed_motion` drive (mass, load-cell sign), at most one `piston`
    /// (areas) and one friction law on the rod, `friction_coulomb_viscous`
    /// or `friction_lugre` with equal extending and retracting sets (a
    /// stiction level above the Coulomb level is the `stribeck` effect),
    /// or `friction_bench`; which of the law's parameters is which catalog
    /// parameter is the netlist's friction-bench view
    /// (`hydrocyl_system::netlist::identify::bench_law_params`); an
    /// effect is on where its switch says so ([`FrictionBench::effect_switches`]:
    /// its first parameter given off its default).
    /// `smoothing_velocity` is the static law's tanh velocity where the
    /// netlist's law has none (LuGre). Another circuit is refused by path.
    pub fn from_netlist(v: &serde_json::Value, smoothing_velocity: f64) -> Result<Self, String> {
        use hydrocyl_system::netlist::identify::bench_law_params;
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
            ![
                "imposed_motion",
                "piston",
                "pressure_source",
                "signal_pressure_source",
                "command_input",
            ]
            .contains(&i.ty.name)
                && !std::ptr::eq(*i, law)
        }) {
            return Err(format!(
                "components.{}: a `{}` is not part of a friction bench (imposed_motion, piston, pressure_source, one friction law)",
                extra.name, extra.ty.name
            ));
        }
        let here = |p: &str| format!("components.{}.{p}", law.name);
        // the law's parameters that are a catalog parameter (`Fc`,
        // `viscous.b`, ...): the netlist's friction-bench view
        // (`bench_law_params`), two for a law with one set per direction,
        // none for an effect the law does not have
        let view = |catalog: &str| bench_law_params(law.ty.name, catalog, true);
        let Some(coulomb) = view("Fc").and_then(|ps| ps.first().map(|q| law.get(q))) else {
            return Err(format!(
                "components.{}.type: `{}` has no friction-bench view (friction_coulomb_viscous, friction_lugre or friction_bench)",
                law.name, law.ty.name
            ));
        };
        let law_params = |catalog: &str| view(catalog).unwrap_or_default();
        let effect_params = |id: EffectId| -> Vec<(&'static str, Vec<&'static str>)> {
            id.params()
                .iter()
                .map(|q| (q.name, law_params(&format!("{}.{}", id.id(), q.name))))
                .collect()
        };
        // one set for both directions: each catalog parameter's law
        // parameters hold one value
        let mut catalog = vec![law_params("Fc")];
        for id in super::BENCH_EFFECTS {
            catalog.extend(effect_params(id).into_iter().map(|(_, ps)| ps));
        }
        for ps in &catalog {
            if let Some(q) = ps.iter().find(|q| law.get(q) != law.get(ps[0])) {
                return Err(format!(
                    "{}: the bench's law has one set for both directions ({} ≠ {})",
                    here(ps[0]),
                    law.get(ps[0]),
                    law.get(q)
                ));
            }
        }
        // an effect is declared where its switch says so (the one rule,
        // `FrictionBench::effect_switches`: its first parameter given off
        // the type's default; a LuGre hump's stiction level not its Coulomb
        // level), with the values its law parameters hold
        let mut effects = BTreeMap::new();
        for switch in FrictionBench::effect_switches(law.ty.name) {
            if switch.is_on(law.opt(switch.on), coulomb) {
                let names = switch.effect.params().iter().map(|q| q.name.to_string());
                let values = switch.params(law.ty.name).into_iter().map(|q| law.get(q));
                effects.insert(switch.effect, names.zip(values).collect());
            }
        }
        // the static law's tanh velocity: the law's own, or where it has
        // none (LuGre) the one given
        let vt = match law.ty.param("smoothing_velocity") {
            Some(_) => law.get("smoothing_velocity"),
            None => smoothing_velocity,
        };
        let mut rig = FrictionBench {
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
            paths: BTreeMap::new(),
        };
        // where each parameter is in this netlist (its `--set` paths),
        // kept where that is not the bench circuit's path: the law's
        // parameters as the netlist's friction-bench view names them
        let stribeck = rig.has(EffectId::Stribeck);
        let law_paths = |p: &ParamRef| -> Vec<String> {
            if *p == ParamRef::Mass {
                return vec![format!("{}.mass", drive.name)];
            }
            bench_law_params(law.ty.name, &p.label(), stribeck)
                .expect("the law's type has a friction-bench view (its Coulomb level was read)")
                .iter()
                .map(|q| format!("{}.{q}", law.name))
                .collect()
        };
        let mut all = vec![ParamRef::Coulomb, ParamRef::Mass];
        for id in super::BENCH_EFFECTS {
            all.extend(
                id.params()
                    .iter()
                    .map(|q| ParamRef::Effect(id, q.name.to_string())),
            );
        }
        for p in all {
            let ps = law_paths(&p);
            if ps != [p.path()] {
                rig.paths.insert(p, ps);
            }
        }
        rig.validate().map_err(|e| e.to_string())?;
        Ok(rig)
    }
}

#[cfg(test)]
mod tests;
