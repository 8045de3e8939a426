//! The bench's simulation on one record: the bench's netlist
//! ([`hydrocyl_system::netlist::migrate::bench`]: drive, measured-pressure
//! chambers, piston, `friction_bench` law) driven by the record's velocity,
//! acceleration and pressures, run through the one run path
//! ([`Simulation`]); the predicted load-cell force at every sample.

use super::{BenchSignals, FrictionBench};
use crate::catalog::EffectId;
use hydrocyl_system::netlist::{self, migrate::bench as net};
use hydrocyl_system::run::RunOptions;
use hydrocyl_system::signal::Signal;
use hydrocyl_system::simulation::Simulation;

/// The solver options of a bench run: DP45. A static law's force is
/// algebraic in the inputs and needs no tolerance (the default's 1e-6 only
/// steers the position state); LuGre's bristle state is integrated at 1e-10,
/// so that the force's dependence on σ0, σ1 is smooth to well below the
/// finite-difference steps of the fit (at 1e-6 the step-size choices show
/// through and the fit of σ0 stalls).
pub fn run_options(lugre: bool) -> RunOptions {
    let mut o = RunOptions::dp45();
    if lugre {
        o.rtol = 1e-10;
    }
    o
}

/// One record's inputs to the bench netlist, built once per record and
/// reused by every simulation on it ([`net::INPUTS`] order).
#[derive(Clone, Debug)]
pub struct BenchInputs {
    signals: Vec<(String, Signal)>,
}

impl BenchInputs {
    /// The record's velocity, acceleration and pressures as input signals.
    pub fn of(s: &BenchSignals) -> Result<Self, String> {
        let table = |y: &[f64]| {
            Signal::table(s.t.clone(), y.to_vec()).map_err(|e| format!("{}: {e}", s.source))
        };
        let signals = net::INPUTS
            .iter()
            .map(|n| n.to_string())
            .zip([table(&s.v)?, table(&s.a)?, table(&s.p1)?, table(&s.p2)?])
            .collect();
        Ok(BenchInputs { signals })
    }
}

impl FrictionBench {
    /// The bench's netlist ([`net::to_netlist`] of its declaration).
    pub fn netlist(&self) -> Result<serde_json::Value, String> {
        let v = serde_json::to_value(self).map_err(|e| e.to_string())?;
        net::to_netlist(&v).map_err(|e| e.to_string())
    }

    /// Simulates the bench on one record: the predicted load-cell force at
    /// every sample. The bristle state starts from the value that explains
    /// the first five samples' force (limited to the steady range).
    pub fn simulate_netlist(
        &self,
        s: &BenchSignals,
        inputs: &BenchInputs,
    ) -> Result<Vec<f64>, String> {
        self.run(s, inputs, false)
    }

    /// Simulates the bench with the bristle deflection starting at zero (at
    /// rest) instead of from the measured force: what `hydrocyl simulate`
    /// does for a record that has no force to start from.
    pub fn simulate_netlist_from_rest(
        &self,
        s: &BenchSignals,
        inputs: &BenchInputs,
    ) -> Result<Vec<f64>, String> {
        self.run(s, inputs, true)
    }

    /// The bristle deflection that explains the mean friction of the first
    /// five samples, limited to `|z0| <= g(v0)/σ0` \[m\] (0 without LuGre).
    fn initial_z(&self, s: &BenchSignals) -> f64 {
        let Some(p) = self.friction.effects.get(&EffectId::LugreDynamics) else {
            return 0.0;
        };
        let s0 = p.get("sigma0").copied().unwrap_or(0.0).max(1e-9);
        let f0 = self.eff(EffectId::ExternalForce, "F0");
        let k = s.t.len().min(5);
        // s F = m a + F_f + F0 − pA  →  F_f = s F − m a − F0 + pA
        let ff: f64 = (0..k)
            .map(|i| {
                self.force_sign * s.force[i] - self.mass * s.a[i] - f0 + s.p1[i] * self.area1
                    - s.p2[i] * self.area2
            })
            .sum::<f64>()
            / k.max(1) as f64;
        let zmax = self.g(s.v[0]) / s0;
        (ff / s0).clamp(-zmax, zmax)
    }

    /// g(v): the Coulomb level plus the Stribeck hump if on \[N\].
    fn g(&self, v: f64) -> f64 {
        match self.friction.effects.get(&EffectId::Stribeck) {
            Some(_) => {
                let fc = self.friction.coulomb;
                let vs = self.eff(EffectId::Stribeck, "vs").max(1e-12);
                let al = self.eff(EffectId::Stribeck, "alpha");
                let r = (v / vs).abs();
                let e = if al == 1.0 { r } else { r.powf(al) };
                fc + (self.eff(EffectId::Stribeck, "Fs") - fc) * (-e).exp()
            }
            None => self.friction.coulomb,
        }
    }

    fn run(
        &self,
        s: &BenchSignals,
        inputs: &BenchInputs,
        at_rest: bool,
    ) -> Result<Vec<f64>, String> {
        let mut v = self.netlist()?;
        if !at_rest && self.has(EffectId::LugreDynamics) {
            v["components"][net::FRICTION]["initial"] =
                serde_json::json!({ "z": self.initial_z(s) });
        }
        let schematic = netlist::schematic(&v).map_err(|e| e.to_string())?;
        let circuit =
            netlist::assemble_inputs(&schematic, &inputs.signals).map_err(|e| e.to_string())?;
        let run = Simulation::of_circuit(circuit)
            .options(run_options(self.has(EffectId::LugreDynamics)))
            .run(&s.t)
            .map_err(|e| format!("{}: {e}", s.source))?;
        run.channel("force")
            .map(<[f64]>::to_vec)
            .ok_or_else(|| "the bench netlist has no `force` output".into())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::data::Record;
    use std::path::Path;

    fn fixtures() -> std::path::PathBuf {
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../../fixtures/measured")
    }

    /// Every friction-bench fixture, migrated to its netlist and run through
    /// `Simulation`, predicts the load-cell force of the bench's inverse
    /// model ([`super::super::inverse`]) to 1e-9 of the force's range, on
    /// its own record; and
    /// again with every catalog effect switched on (LuGre's bristle aside,
    /// which the netlist integrates as an ODE: checked to 1e-3, the old
    /// model's own per-sample discretisation).
    #[test]
    fn every_bench_fixture_simulates_as_the_inverse_model() {
        let mut seen = 0;
        for entry in std::fs::read_dir(fixtures()).unwrap() {
            let path = entry.unwrap().path();
            let name = path.file_name().unwrap().to_string_lossy().to_string();
            let Some(stem) = name.strip_suffix(".rig.json") else {
                continue;
            };
            let text = std::fs::read_to_string(&path).unwrap();
            if !text.contains(super::super::KIND) {
                continue;
            }
            let rig = FrictionBench::from_json(&text).unwrap();
            let csv = path.with_file_name(format!("{stem}.csv"));
            if !csv.exists() {
                continue; // mr-damper: its record is not in the repository
            }
            let rec = Record::read_mapped(&csv, &rig.columns).unwrap();
            let (s, _) = super::super::bench_signals(&rec, None, rig.steady_state).unwrap();
            let inputs = BenchInputs::of(&s).unwrap();
            let mut all = rig.clone();
            for (id, p, v) in [
                (EffectId::CoulombAsymmetry, "dFc", 3.0),
                (EffectId::Stribeck, "Fs", 1.4 * rig.friction.coulomb),
                (EffectId::Stribeck, "vs", 3e-3),
                (EffectId::Stribeck, "alpha", 1.3),
                (EffectId::PressureViscous, "K", 2e-9),
                (EffectId::AccelerationFriction, "H", 1e7),
                (EffectId::ExternalForce, "F0", -4.0),
            ] {
                all.set(&super::super::ParamRef::Effect(id, p.into()), v);
            }
            for (r, tol) in [(&rig, 1e-9), (&all, 1e-9)] {
                let new = r.simulate_netlist(&s, &inputs).unwrap();
                let old = r.simulate(&s);
                let scale = old.iter().fold(0.0f64, |m, f| m.max(f.abs()));
                let worst = new
                    .iter()
                    .zip(&old)
                    .map(|(a, b)| (a - b).abs())
                    .fold(0.0, f64::max);
                assert!(worst <= tol * scale, "{stem}: worst {worst} N of {scale} N");
            }
            if !rig.steady_state {
                let mut lugre = all.clone();
                for (p, v) in [("sigma0", 4e5), ("sigma1", 30.0)] {
                    lugre.set(
                        &super::super::ParamRef::Effect(EffectId::LugreDynamics, p.into()),
                        v,
                    );
                }
                let new = lugre.simulate_netlist(&s, &inputs).unwrap();
                let old = lugre.simulate(&s);
                let scale = old.iter().fold(0.0f64, |m, f| m.max(f.abs()));
                let rms = (new
                    .iter()
                    .zip(&old)
                    .map(|(a, b)| (a - b).powi(2))
                    .sum::<f64>()
                    / new.len() as f64)
                    .sqrt();
                assert!(
                    rms <= 1e-3 * scale,
                    "{stem} LuGre: rms {rms} N of {scale} N"
                );
            }
            seen += 1;
        }
        assert!(seen >= 11, "{seen} bench fixtures");
    }
}
