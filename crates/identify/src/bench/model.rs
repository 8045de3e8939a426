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
use hydrocyl_system::AnyWire;

/// The solver options of a bench run with LuGre's bristle on a record whose
/// largest sample interval is `h` \[s\], `rate = σ0 max|v| / min g` the
/// bristle's fastest relaxation rate on the record \[1/s\]:
///
/// * fixed-step RK4 at `h / m`, `m` the least whole number with
///   `rate h / m <= 1`, while `m <= 8`: the fit differences the force with
///   respect to σ0 and σ1, so the force must be smooth in them, which an
///   adaptive step's choices are not (DP45 at rtol 1e-6 gives a σ0
///   derivative wrong by 1000× its size; at rtol 1e-10 it is smooth but 7×
///   the cost of RK4 at the record's step). At `rate h / m <= 1` RK4 is well
///   inside its stability bound (2.78);
/// * stiffer (a bristle relaxing in under an eighth of a sample interval),
///   the L-stable Rodas4 at rtol 1e-8 with steps of at most `h`, whose cost
///   does not grow with σ0.
///
/// On the planted-LuGre fixture (500 Hz) the RK4 force is within 2e-2 N of
/// DP45 at rtol 1e-12 (the noise is 0.5 N) and its σ0 derivative within 1 %
/// (`solver_choice_on_the_lugre_fixture`).
pub fn run_options(rate: f64, h: f64) -> RunOptions {
    use hydrocyl_system::run::Solver;
    let m = (rate * h).ceil().max(1.0);
    if m <= 8.0 {
        RunOptions {
            solver: Solver::Rk4,
            rk4_step: h / m,
            ..RunOptions::default()
        }
    } else {
        RunOptions {
            solver: Solver::Rosenbrock,
            rtol: 1e-8,
            h_max: h,
            ..RunOptions::default()
        }
    }
}

/// One record's inputs to the bench netlist, built once per record and
/// reused by every simulation on it ([`net::INPUTS`] order).
#[derive(Clone, Debug)]
pub struct BenchInputs {
    signals: Vec<(String, Signal)>,
    v_max: f64,
    h_max: f64,
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
        Ok(BenchInputs {
            signals,
            v_max: s.v.iter().fold(0.0, |m, v| m.max(v.abs())),
            h_max: s.t.windows(2).fold(0.0, |m, w| m.max(w[1] - w[0])),
        })
    }
}

impl FrictionBench {
    /// The bench's netlist with its identification section
    /// ([`net::to_netlist`] of its declaration): what a bench rig file holds
    /// (`make_fixtures` writes it, [`FrictionBench::from_rig`] reads it back).
    pub fn netlist(&self) -> Result<serde_json::Value, String> {
        let v = serde_json::to_value(self).map_err(|e| e.to_string())?;
        net::to_netlist(&v).map_err(|e| e.to_string())
    }

    /// Simulates the bench on one record: the predicted load-cell force at
    /// every sample, the bench's netlist assembled for this call
    /// ([`BenchRun`]; a fit keeps one and reuses it). The bristle state
    /// starts from the value that explains the first five samples' force
    /// (limited to the steady range).
    pub fn simulate(&self, s: &BenchSignals, inputs: &BenchInputs) -> Result<Vec<f64>, String> {
        BenchRun::new(self, inputs)?.force(self, s, false)
    }

    /// Simulates the bench with the bristle deflection starting at zero (at
    /// rest) instead of from the measured force: what `hydrocyl simulate`
    /// does for a record that has no force to start from.
    pub fn simulate_from_rest(
        &self,
        s: &BenchSignals,
        inputs: &BenchInputs,
    ) -> Result<Vec<f64>, String> {
        BenchRun::new(self, inputs)?.force(self, s, true)
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

    /// The fitted parameters as netlist paths and values: `friction.coulomb`,
    /// `drive.mass` and every parameter of each effect that is on
    /// ([`ParamRef::path`]).
    fn path_values(&self) -> impl Iterator<Item = (String, f64)> + '_ {
        self.all_params()
            .into_iter()
            .map(|p| (p.path(), self.get(&p)))
    }
}

/// The bench's netlist assembled once on one record's inputs and run as
/// often as wanted with the parameters of a [`FrictionBench`] set on the
/// built circuit by their netlist paths (no reassembly): the one run path
/// ([`Simulation`]) as a fit uses it.
///
/// * A static law has no state the force depends on (the drive's position
///   feeds no force): the load cell is read at the sample times with no
///   integration ([`Simulation::sample_state_free`], which checks that).
/// * LuGre's bristle is integrated ([`Simulation::run_wires`], reading only
///   the load cell) with [`run_options`] (fixed-step RK4 at the record's step or a fraction of it).
///
/// When the effects switched on change (a bristle or a Stribeck hump added
/// or removed), the circuit is assembled again.
pub struct BenchRun {
    inputs: BenchInputs,
    /// The record's largest |v| \[m/s\] and largest sample interval \[s\].
    v_max: f64,
    h_max: f64,
    effects: Vec<EffectId>,
    sim: Simulation,
    force: AnyWire,
    z: Option<usize>,
}

impl BenchRun {
    /// Assembles `bench`'s netlist on `inputs`.
    pub fn new(bench: &FrictionBench, inputs: &BenchInputs) -> Result<Self, String> {
        let v = bench.netlist()?;
        let schematic = netlist::schematic(&v).map_err(|e| e.to_string())?;
        let circuit =
            netlist::assemble_inputs(&schematic, &inputs.signals).map_err(|e| e.to_string())?;
        let force = circuit
            .probes()
            .into_iter()
            .find(|p| p.name == "force")
            .ok_or("the bench netlist has no `force` output")?
            .wire;
        let z = circuit
            .state_names()
            .iter()
            .position(|n| *n == format!("{}.z", net::FRICTION));
        Ok(BenchRun {
            inputs: inputs.clone(),
            v_max: inputs.v_max,
            h_max: inputs.h_max,
            effects: bench.friction.effects.keys().copied().collect(),
            sim: Simulation::of_circuit(circuit),
            force,
            z,
        })
    }

    /// The predicted load-cell force of `bench` on record `s` (whose inputs
    /// this run was built on), the bristle from rest when `at_rest`, else
    /// from the record's first forces.
    pub fn force(
        &mut self,
        bench: &FrictionBench,
        s: &BenchSignals,
        at_rest: bool,
    ) -> Result<Vec<f64>, String> {
        if !bench
            .friction
            .effects
            .keys()
            .copied()
            .eq(self.effects.iter().copied())
        {
            *self = BenchRun::new(bench, &self.inputs)?;
        }
        for (path, value) in bench.path_values() {
            self.sim
                .set_parameter(&path, value)
                .map_err(|e| e.to_string())?;
        }
        let err = |e: hydrocyl_system::rig::RigError| format!("{}: {e}", s.source);
        let mut out = match self.z {
            Some(k) => {
                let mut x0 = self.sim.circuit().initial_state();
                x0[k] = if at_rest { 0.0 } else { bench.initial_z(s) };
                self.sim.set_initial_state(x0);
                let s0 = bench.eff(EffectId::LugreDynamics, "sigma0");
                let g_min = match bench.has(EffectId::Stribeck) {
                    true => bench
                        .friction
                        .coulomb
                        .min(bench.eff(EffectId::Stribeck, "Fs")),
                    false => bench.friction.coulomb,
                }
                .max(1e-9);
                self.sim
                    .set_options(run_options(s0 * self.v_max / g_min, self.h_max));
                self.sim.run_wires(&s.t, &[self.force]).map_err(err)?
            }
            None => self
                .sim
                .sample_state_free(&s.t, &[self.force])
                .map_err(err)?,
        };
        Ok(out.swap_remove(0))
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
            let v: serde_json::Value =
                serde_json::from_str(&std::fs::read_to_string(&path).unwrap()).unwrap();
            if !super::super::is_bench_rig(&v) {
                continue;
            }
            let rig = FrictionBench::from_rig(&v).unwrap();
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
                let new = r.simulate(&s, &inputs).unwrap();
                let old = r.reference(&s);
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
                let new = lugre.simulate(&s, &inputs).unwrap();
                let old = lugre.reference(&s);
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

#[cfg(test)]
mod solver_choice {
    use super::*;
    use crate::bench::ParamRef;
    use crate::data::Record;

    /// The bench's LuGre run ([`run_options`]) on the planted-LuGre
    /// fixture's record (500 Hz, σ0 = 2e5, σ1 = 600): its force is within
    /// 2e-2 N of DP45 at rtol 1e-12 (the record's noise is 0.5 N), and the
    /// force's change for a 1e-6 relative step in σ0 (what the fit
    /// differences) is the reference's to 1 %.
    #[test]
    fn solver_choice_on_the_lugre_fixture() {
        let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../fixtures/measured");
        let text = std::fs::read_to_string(dir.join("bench-none.rig.json")).unwrap();
        let mut rig = FrictionBench::from_rig(&serde_json::from_str(&text).unwrap()).unwrap();
        let s0 = ParamRef::Effect(EffectId::LugreDynamics, "sigma0".into());
        rig.set(&s0, 2e5);
        rig.set(
            &ParamRef::Effect(EffectId::LugreDynamics, "sigma1".into()),
            600.0,
        );
        let rec = Record::read_mapped(&dir.join("bench-lugre_dynamics.csv"), &rig.columns).unwrap();
        let (s, _) = super::super::bench_signals(&rec, None, false).unwrap();
        let inputs = BenchInputs::of(&s).unwrap();
        let mut stepped = rig.clone();
        stepped.set(&s0, 2e5 * (1.0 + 1e-6));
        let mut run = BenchRun::new(&rig, &inputs).unwrap();
        let (f, g) = (
            run.force(&rig, &s, false).unwrap(),
            run.force(&stepped, &s, false).unwrap(),
        );
        // the reference: DP45 at rtol 1e-12 on the same circuit
        let reference = |r: &FrictionBench| {
            let mut net = BenchRun::new(r, &inputs).unwrap();
            let mut x0 = net.sim.circuit().initial_state();
            x0[net.z.unwrap()] = r.initial_z(&s);
            net.sim.set_initial_state(x0);
            let mut o = RunOptions::dp45();
            o.rtol = 1e-12;
            net.sim.set_options(o);
            net.sim
                .run_wires(&s.t, &[net.force])
                .unwrap()
                .swap_remove(0)
        };
        let (fr, gr) = (reference(&rig), reference(&stepped));
        let worst = f
            .iter()
            .zip(&fr)
            .map(|(a, b)| (a - b).abs())
            .fold(0.0, f64::max);
        assert!(worst < 2e-2, "force off the reference by {worst} N");
        let d: Vec<f64> = g.iter().zip(&f).map(|(a, b)| a - b).collect();
        let dr: Vec<f64> = gr.iter().zip(&fr).map(|(a, b)| a - b).collect();
        let scale = dr.iter().fold(0.0f64, |m, x| m.max(x.abs()));
        let derr = d
            .iter()
            .zip(&dr)
            .map(|(a, b)| (a - b).abs())
            .fold(0.0, f64::max);
        assert!(
            scale > 0.0 && derr < 1e-2 * scale,
            "σ0 step: {derr} of {scale}"
        );
    }
}
