//! The bench's simulation on one record: the bench's netlist
//! ([`hydrocyl_system::netlist::migrate::bench`]: drive, measured-pressure
//! chambers, piston, `friction_bench` law) driven by the record's velocity,
//! acceleration and pressures, run through the one run path
//! ([`Simulation`]); the predicted load-cell force at every sample.

use super::{BenchSignals, FrictionBench, ParamRef};
use crate::catalog::EffectId;
use hydrocyl_system::netlist::{self, migrate::bench as net};
use hydrocyl_system::run::{Channel, ProbeSet, Run, RunOptions, SimError, Solver};
use hydrocyl_system::signal::Signal;
use hydrocyl_system::simulation::Simulation;
use hydrocyl_system::AnyWire;

/// The solver options of a bench run with LuGre's bristle on a record
/// whose longest sample interval is `h` \[s\]: the exponential
/// Rosenbrock–Euler step ([`Solver::Exponential`]), one step per sample
/// interval, landing on every sample.
///
/// With the record's velocity held linearly between samples, the step takes
/// the velocity at the interval's middle and relaxes the bristle exactly
/// towards `v / rate` at that velocity's rate `σ0 |v| / g(v)`, however stiff
/// (the exponential midpoint rule of the bristle, second order in `h`); its
/// cost is one circuit evaluation and one tangent pass a sample, and the
/// force is a smooth function of σ0 and σ1 (no step-size control), which
/// the fit's finite differences need (DP45 at rtol 1e-6 gives a σ0
/// derivative wrong by 1000× its size).
pub fn run_options(h: f64) -> RunOptions {
    RunOptions {
        solver: Solver::Exponential,
        rk4_step: h,
        ..RunOptions::default()
    }
}

/// One record's inputs to the bench netlist, built once per record and
/// reused by every simulation on it ([`net::INPUTS`] order).
#[derive(Clone, Debug)]
pub struct BenchInputs {
    signals: Vec<(String, Signal)>,
    h_max: f64,
}

impl BenchInputs {
    /// The record's velocity, acceleration and pressures as input signals.
    pub fn of(s: &BenchSignals) -> Result<Self, String> {
        // one copy of the times, shared by every input's table
        let t: std::sync::Arc<[f64]> = s.t.as_slice().into();
        let table = |y: &[f64]| {
            Signal::shared_table(t.clone(), y.into()).map_err(|e| format!("{}: {e}", s.source))
        };
        let signals = net::INPUTS
            .iter()
            .map(|n| n.to_string())
            .zip([table(&s.v)?, table(&s.a)?, table(&s.p1)?, table(&s.p2)?])
            .collect();
        Ok(BenchInputs {
            signals,
            h_max: s.t.windows(2).fold(0.0, |m, w| m.max(w[1] - w[0])),
        })
    }
}

impl FrictionBench {
    /// The bench's netlist with its identification section
    /// ([`net::to_netlist`] of its declaration): what a bench rig file holds
    /// (`make_fixtures` writes it, [`FrictionBench::from_rig`] reads it back).
    pub fn netlist(&self) -> Result<serde_json::Value, String> {
        // the refits as the bench circuit's paths (a preset names them by
        // its own netlist's, `friction.extending.curve.coulomb`)
        let mut b = self.clone();
        b.refit = self.refit_params().iter().map(ParamRef::path).collect();
        let v = serde_json::to_value(&b).map_err(|e| e.to_string())?;
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

    /// The bench's output channels on record `s` as a run at the record's
    /// times ([`BenchRun::channels`]): the channels of the bench's circuit
    /// named in `only` (every one for `None`: `position`, `velocity`, `p1`,
    /// `p2`, `force`, `friction_force`), chosen and ordered as any run's
    /// ([`ProbeSet::selected`], whose error names a channel the circuit
    /// lacks); the bristle from rest when `at_rest`, else from the record's
    /// first forces.
    pub fn simulate_channels(
        &self,
        s: &BenchSignals,
        inputs: &BenchInputs,
        at_rest: bool,
        only: Option<&[String]>,
    ) -> Result<Run, String> {
        BenchRun::new(self, inputs)?.channels(self, s, at_rest, only)
    }

    /// Checks a channel selection (what [`FrictionBench::simulate_channels`]
    /// takes) against the bench's circuit, its inputs held, before any
    /// record is read: [`ProbeSet::selected`]'s error for a name the circuit
    /// has no output of.
    pub fn check_channels(&self, only: Option<&[String]>) -> Result<(), String> {
        let v = self.netlist()?;
        let schematic = netlist::schematic(&v).map_err(|e| e.to_string())?;
        let held: Vec<(String, Signal)> = net::INPUTS
            .iter()
            .map(|n| (n.to_string(), Signal::Constant { value: 0.0 }))
            .collect();
        let circuit = netlist::assemble_inputs(&schematic, &held).map_err(|e| e.to_string())?;
        ProbeSet::selected(&circuit, only)
            .map(|_| ())
            .map_err(selection_error)
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
/// * A static law has no state the force depends on (the drive's and the
///   piston's positions feed no force): the load cell is read at the sample times with no
///   integration ([`Simulation::sample_state_free`], which checks that).
/// * LuGre's bristle is integrated ([`Simulation::run_wires`], reading only
///   the load cell) with [`run_options`]: the exponential Rosenbrock–Euler
///   step on the circuit's analytic tangents, one step per sample.
///
/// When the effects switched on change (a bristle or a Stribeck hump added
/// or removed), the circuit is assembled again.
pub struct BenchRun {
    inputs: BenchInputs,
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
        self.reassemble_for(bench)?;
        let wires = [self.force];
        Ok(self.read(bench, s, at_rest, &wires)?.swap_remove(0))
    }

    /// Assembles the circuit again when the effects switched on in `bench`
    /// are not those it was built for (a bristle or a hump added or removed).
    fn reassemble_for(&mut self, bench: &FrictionBench) -> Result<(), String> {
        if !bench
            .friction
            .effects
            .keys()
            .copied()
            .eq(self.effects.iter().copied())
        {
            *self = BenchRun::new(bench, &self.inputs)?;
        }
        Ok(())
    }

    /// The channels of the bench's circuit named in `only` (every one for
    /// `None`) on record `s`, as a run at the record's times: chosen and
    /// ordered by [`ProbeSet::selected`] (its error for a name the circuit
    /// has no output of), each with its unit and probe. The position is
    /// the record's (`s.x`): the run integrates no position (a static law
    /// reads the load cell with no integration; the drive of a LuGre run
    /// starts at 0); the velocity and pressures are the record's too, as
    /// the circuit's inputs at the sample times.
    pub fn channels(
        &mut self,
        bench: &FrictionBench,
        s: &BenchSignals,
        at_rest: bool,
        only: Option<&[String]>,
    ) -> Result<Run, String> {
        self.reassemble_for(bench)?;
        let chosen = ProbeSet::selected(self.sim.circuit(), only).map_err(selection_error)?;
        let all = self.sim.circuit().probes();
        let probes: Vec<_> = chosen
            .names()
            .filter_map(|n| all.iter().find(|p| p.name == n))
            .collect();
        let position = format!("{}.position", net::CYLINDER);
        let wires: Vec<AnyWire> = probes
            .iter()
            .filter(|p| p.path != position)
            .map(|p| p.wire)
            .collect();
        let mut values = self.read(bench, s, at_rest, &wires)?.into_iter();
        let channels = probes
            .into_iter()
            .map(|p| {
                let values = if p.path == position {
                    s.x.clone()
                } else {
                    values.next().ok_or("a channel without its wire")?
                };
                Ok(Channel {
                    name: p.name.clone(),
                    unit: p.unit,
                    probe: p.path.clone(),
                    values,
                })
            })
            .collect::<Result<_, String>>()?;
        Ok(Run {
            time: s.t.clone(),
            channels,
            ..Run::default()
        })
    }

    /// `wires` of the circuit (assembled for `bench`'s effects) with
    /// `bench`'s parameters on record `s`.
    fn read(
        &mut self,
        bench: &FrictionBench,
        s: &BenchSignals,
        at_rest: bool,
        wires: &[AnyWire],
    ) -> Result<Vec<Vec<f64>>, String> {
        for (path, value) in bench.path_values() {
            self.sim
                .set_parameter(&path, value)
                .map_err(|e| e.to_string())?;
        }
        let err = |e: hydrocyl_system::rig::RigError| format!("{}: {e}", s.source);
        match self.z {
            Some(k) => {
                let mut x0 = self.sim.circuit().initial_state();
                x0[k] = if at_rest { 0.0 } else { bench.initial_z(s) };
                self.sim.set_initial_state(x0);
                self.sim.set_options(run_options(self.inputs.h_max));
                self.sim.run_wires(&s.t, wires).map_err(err)
            }
            None => self.sim.sample_state_free(&s.t, wires).map_err(err),
        }
    }
}

/// A selection's error as its reason (`channel `x`: the circuit has no such
/// output (it has …)`), without the run-settings prefix.
fn selection_error(e: SimError) -> String {
    match e {
        SimError::Settings(why) => why,
        e => e.to_string(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bench::{BenchFriction, ParamRef, KIND};
    use crate::data::{ColumnMap, Record};
    use std::collections::BTreeMap;
    use std::path::Path;

    fn fixtures() -> std::path::PathBuf {
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../../fixtures/measured")
    }

    /// The static law's load-cell force written out (the module doc's
    /// balance), an independent reference for the netlist run.
    fn closed_form(b: &FrictionBench, s: &BenchSignals) -> Vec<f64> {
        let e = |id, p| b.eff(id, p);
        (0..s.t.len())
            .map(|i| {
                let (v, a) = (s.v[i], s.a[i]);
                let th = (v / b.friction.smoothing_velocity).tanh();
                let k = e(EffectId::PressureViscous, "K");
                let ff = b.g(v) * th
                    + e(EffectId::Viscous, "b") * v
                    + k * (s.p1[i] - s.p2[i]).powi(2) * v
                    + k * e(EffectId::AccelerationFriction, "H") * a
                    + 0.5 * e(EffectId::CoulombAsymmetry, "dFc") * th.abs()
                    + e(EffectId::ExternalForce, "F0");
                b.force_sign * (b.mass * a + ff - s.p1[i] * b.area1 + s.p2[i] * b.area2)
            })
            .collect()
    }

    /// The LuGre run on the circuit with DP45 at `rtol` (the reference the
    /// exponential step is measured against), bristle from the record.
    fn tight(r: &FrictionBench, s: &BenchSignals, inputs: &BenchInputs, rtol: f64) -> Vec<f64> {
        let mut net = BenchRun::new(r, inputs).unwrap();
        let mut x0 = net.sim.circuit().initial_state();
        x0[net.z.unwrap()] = r.initial_z(s);
        net.sim.set_initial_state(x0);
        let mut o = RunOptions::dp45();
        o.rtol = rtol;
        net.sim.set_options(o);
        net.sim
            .run_wires(&s.t, &[net.force])
            .unwrap()
            .swap_remove(0)
    }

    fn worst(a: &[f64], b: &[f64]) -> f64 {
        a.iter()
            .zip(b)
            .map(|(x, y)| (x - y).abs())
            .fold(0.0, f64::max)
    }

    /// Every friction-bench fixture, migrated to its netlist and run through
    /// `Simulation`, predicts the load-cell force of the written-out static
    /// balance to 1e-9 of the force's range, on its own record, alone and
    /// with every static catalog effect switched on; with LuGre's bristle
    /// on top, the exponential step at the record's samples is within 1e-3
    /// of the force's range (rms) of DP45 at rtol 1e-10 on the same circuit.
    #[test]
    fn every_bench_fixture_simulates_as_the_closed_form() {
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
                all.set(&ParamRef::Effect(id, p.into()), v);
            }
            for r in [&rig, &all] {
                if r.has(EffectId::LugreDynamics) {
                    continue; // the planted-LuGre fixture's rig: below
                }
                let new = r.simulate(&s, &inputs).unwrap();
                let old = closed_form(r, &s);
                let scale = old.iter().fold(0.0f64, |m, f| m.max(f.abs()));
                let w = worst(&new, &old);
                assert!(w <= 1e-9 * scale, "{stem}: worst {w} N of {scale} N");
            }
            if !rig.steady_state {
                let mut lugre = all.clone();
                for (p, v) in [("sigma0", 4e5), ("sigma1", 30.0)] {
                    lugre.set(&ParamRef::Effect(EffectId::LugreDynamics, p.into()), v);
                }
                let new = lugre.simulate(&s, &inputs).unwrap();
                let old = tight(&lugre, &s, &inputs, 1e-10);
                let scale = old.iter().fold(0.0f64, |m, f| m.max(f.abs()));
                let rms = (new
                    .iter()
                    .zip(&old)
                    .map(|(a, b)| (a - b).powi(2))
                    .sum::<f64>()
                    / new.len() as f64)
                    .sqrt();
                eprintln!("{stem} LuGre: rms {rms:.3e} N of {scale:.3e} N");
                assert!(
                    rms <= 1e-3 * scale,
                    "{stem} LuGre: rms {rms} N of {scale} N"
                );
            }
            seen += 1;
        }
        assert!(seen >= 11, "{seen} bench fixtures");
    }

    fn rig() -> FrictionBench {
        FrictionBench {
            kind: KIND.into(),
            name: "t".into(),
            area1: 0.0,
            area2: 4.9e-4,
            mass: 0.5,
            force_sign: 1.0,
            friction: BenchFriction {
                coulomb: 5.0,
                smoothing_velocity: 1e-4,
                effects: BTreeMap::new(),
            },
            refit: vec![],
            columns: ColumnMap::default(),
            paths: Default::default(),
            steady_state: false,
        }
    }

    fn signals(v: impl Fn(f64) -> f64, n: usize, dt: f64) -> BenchSignals {
        let t: Vec<f64> = (0..n).map(|i| i as f64 * dt).collect();
        BenchSignals {
            source: "x".into(),
            a: vec![0.0; n],
            p1: vec![0.0; n],
            p2: vec![3e5; n],
            force: vec![0.0; n],
            x: vec![0.0; n],
            v: t.iter().map(|&t| v(t)).collect(),
            t,
        }
    }

    fn lugre(r: &mut FrictionBench, s0: f64, s1: f64) {
        r.set(
            &ParamRef::Effect(EffectId::LugreDynamics, "sigma0".into()),
            s0,
        );
        r.set(
            &ParamRef::Effect(EffectId::LugreDynamics, "sigma1".into()),
            s1,
        );
    }

    /// Monotone motion from z = 0 with σ1 = 0: `dz/dx = 1 − σ0 z / Fc`, so
    /// `F_f = σ0 z = Fc (1 − exp(−σ0 x / Fc))` (a spring of stiffness σ0
    /// for x ≪ Fc/σ0, saturating at Fc) plus the chamber's `p A2`. The
    /// exponential step at a constant velocity is exact: 1e-9 of Fc at
    /// every sample, the bristle's rate·h from 0.02 to 2000.
    #[test]
    fn lugre_presliding_follows_the_closed_form() {
        for s0 in [1e4, 1e6, 1e9] {
            let mut r = rig();
            lugre(&mut r, s0, 0.0);
            let (dt, v0) = (1e-4, 1e-4);
            let s = signals(|_| v0, 2000, dt);
            let f = r
                .simulate_from_rest(&s, &BenchInputs::of(&s).unwrap())
                .unwrap();
            for (i, fi) in f.iter().enumerate() {
                let x = v0 * dt * i as f64;
                let closed = 5.0 * -(-s0 * x / 5.0).exp_m1() + 3e5 * 4.9e-4;
                assert!(
                    (fi - closed).abs() < 1e-9 * 5.0,
                    "σ0 {s0}, i {i}: {fi} vs {closed}"
                );
            }
        }
    }

    /// At a constant velocity the bristle settles and LuGre's force is the
    /// static law's, g(v) (eq 5.7): a static rig's force on the same record.
    #[test]
    fn lugre_reaches_the_static_curve_at_constant_velocity() {
        let mut r = rig();
        let s = signals(|_| 0.01, 500, 1e-3);
        let inputs = BenchInputs::of(&s).unwrap();
        let stat = r.simulate(&s, &inputs).unwrap();
        lugre(&mut r, 1e6, 50.0);
        let dynamic = r.simulate_from_rest(&s, &inputs).unwrap();
        let expect = 5.0 + 3e5 * 4.9e-4;
        assert!((stat[499] - expect).abs() < 1e-6);
        assert!((dynamic[499] - expect).abs() < 1e-6, "{}", dynamic[499]);
    }

    /// The bench's LuGre run ([`run_options`]) on the planted-LuGre
    /// fixture's record (500 Hz, σ0 = 2e5, σ1 = 600) against DP45 at rtol
    /// 1e-12 on the same circuit: its force is within 0.05 N rms (the
    /// record's noise is 0.5 N) and 1 N at worst (at a reversal, where |v|
    /// has a kink inside a sample interval: the midpoint rule's order drops
    /// there; two steps a sample cut it 4× or more); the force's change for
    /// a 1e-6 relative step in σ0 (what the fit differences) is the
    /// reference's to 3 % rms, and the same to 1e-3 with a 10× larger step
    /// (a smooth map: no step-size control).
    #[test]
    fn the_exponential_step_on_the_lugre_fixture() {
        let dir = fixtures();
        let text = std::fs::read_to_string(dir.join("bench-none.rig.json")).unwrap();
        let mut rig = FrictionBench::from_rig(&serde_json::from_str(&text).unwrap()).unwrap();
        lugre(&mut rig, 2e5, 600.0);
        let rec = Record::read_mapped(&dir.join("bench-lugre_dynamics.csv"), &rig.columns).unwrap();
        let (s, _) = super::super::bench_signals(&rec, None, false).unwrap();
        let inputs = BenchInputs::of(&s).unwrap();
        let mut stepped = rig.clone();
        let s0 = ParamRef::Effect(EffectId::LugreDynamics, "sigma0".into());
        stepped.set(&s0, 2e5 * (1.0 + 1e-6));
        let mut run = BenchRun::new(&rig, &inputs).unwrap();
        let (f, g) = (
            run.force(&rig, &s, false).unwrap(),
            run.force(&stepped, &s, false).unwrap(),
        );
        let (fr, gr) = (
            tight(&rig, &s, &inputs, 1e-12),
            tight(&stepped, &s, &inputs, 1e-12),
        );
        let rms = |a: &[f64], b: &[f64]| {
            (a.iter().zip(b).map(|(x, y)| (x - y).powi(2)).sum::<f64>() / a.len() as f64).sqrt()
        };
        let (w, e) = (worst(&f, &fr), rms(&f, &fr));
        eprintln!("one step a sample: worst {w:.3e} N, rms {e:.3e} N");
        assert!(e < 0.05 && w < 1.0, "worst {w} N, rms {e} N");
        // two steps a sample: the reversals' kink of |v| inside an interval
        // (where the worst error is) shrinks by 4× or more
        let mut fine = BenchRun::new(&rig, &inputs).unwrap();
        let mut x0 = fine.sim.circuit().initial_state();
        x0[fine.z.unwrap()] = rig.initial_z(&s);
        fine.sim.set_initial_state(x0);
        fine.sim.set_options(run_options(inputs.h_max / 2.0));
        let f2 = fine
            .sim
            .run_wires(&s.t, &[fine.force])
            .unwrap()
            .swap_remove(0);
        let (w2, e2) = (worst(&f2, &fr), rms(&f2, &fr));
        eprintln!("two steps a sample: worst {w2:.3e} N, rms {e2:.3e} N");
        assert!(w2 < w / 4.0 && e2 < e / 4.0, "worst {w2} N, rms {e2} N");
        // the σ0 derivative: the reference's to 3 % (rms over the record;
        // 2.1 % seen, the discrete model's own derivative differing from the
        // continuous one's at the reversals),
        // and smooth (the same with a 10× larger difference step)
        let d: Vec<f64> = g.iter().zip(&f).map(|(a, b)| (a - b) / 1e-6).collect();
        let dr: Vec<f64> = gr.iter().zip(&fr).map(|(a, b)| (a - b) / 1e-6).collect();
        let zero = vec![0.0; d.len()];
        let (derr, dscale) = (rms(&d, &dr), rms(&dr, &zero));
        let mut coarse = rig.clone();
        coarse.set(&s0, 2e5 * (1.0 + 1e-5));
        let d10: Vec<f64> = run
            .force(&coarse, &s, false)
            .unwrap()
            .iter()
            .zip(&f)
            .map(|(a, b)| (a - b) / 1e-5)
            .collect();
        let smooth = rms(&d10, &d);
        eprintln!("σ0 derivative: off the reference by {derr:.3e} (rms) of {dscale:.3e}; 1e-5 vs 1e-6 step {smooth:.3e}");
        assert!(
            derr < 3e-2 * dscale,
            "σ0 derivative off by {derr} of {dscale}"
        );
        assert!(
            smooth < 1e-3 * dscale,
            "σ0 derivative not smooth: {smooth} of {dscale}"
        );
    }
}
