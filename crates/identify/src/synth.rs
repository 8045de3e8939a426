//! Generated friction-bench records with planted effects: the test cases of
//! the loop (and the fixtures in `fixtures/measured/`).
//!
//! The drive moves the piston in smoothed strokes (velocity
//! `V(t) tanh(sin(2π f t)/0.15)`, with the stroke speed `V(t)` swept between
//! 20 and 100 mm/s so that speed-dependent terms are separable from Coulomb
//! friction); the chamber pressure is swept between 1 and 7 bar (so that the
//! pressure term is separable). The true model's force is computed from the
//! exact motion, then Gaussian sensor noise is added to position, pressure and
//! force. The record is what a rig would log: time, position, p2, force.

use std::collections::BTreeMap;

use crate::bench::{BenchFriction, BenchSignals, FrictionBench, KIND};
use crate::catalog::EffectId;
use crate::data::{ColumnMap, Record, Signal};
use crate::smooth::gaussian_noise;

/// Sensor noise standard deviations of generated records.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Noise {
    /// Position noise \[m\].
    pub position: f64,
    /// Pressure noise \[Pa\].
    pub pressure: f64,
    /// Force noise \[N\].
    pub force: f64,
}

impl Default for Noise {
    fn default() -> Self {
        Self {
            position: 2e-6,
            pressure: 2e3,
            force: 0.5,
        }
    }
}

/// Something planted in a generated record that the catalog does not have.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Foreign {
    /// Nothing.
    None,
    /// A spring along the stroke, `k x` \[N·m⁻¹\] (e.g. a cable or bellows).
    Spring(f64),
    /// A transport delay of the load-cell signal \[s\].
    ForceDelay(f64),
}

/// The declared model of the generated bench: a 50 mm bore, 2 kg piston,
/// Coulomb 20 N + viscous 300 N·s/m, pressure on the −x side.
pub fn base_rig() -> FrictionBench {
    let mut effects = BTreeMap::new();
    effects.insert(
        EffectId::Viscous,
        BTreeMap::from([("b".to_string(), 300.0)]),
    );
    FrictionBench {
        kind: KIND.into(),
        name: "synthetic-bench".into(),
        area1: 0.0,
        area2: std::f64::consts::PI * 0.025f64.powi(2),
        mass: 2.0,
        force_sign: 1.0,
        friction: BenchFriction {
            coulomb: 20.0,
            smoothing_velocity: 1e-3,
            effects,
        },
        refit: vec![],
        columns: ColumnMap::default(),
        paths: Default::default(),
        steady_state: false,
    }
}

/// A realistic magnitude of each force-balance effect for [`base_rig`].
pub fn planted(id: EffectId) -> BTreeMap<String, f64> {
    let kv = |k: &str, v: f64| (k.to_string(), v);
    match id {
        EffectId::CoulombAsymmetry => BTreeMap::from([kv("dFc", 10.0)]),
        EffectId::Stribeck => BTreeMap::from([kv("Fs", 45.0), kv("vs", 0.01), kv("alpha", 1.0)]),
        EffectId::Viscous => BTreeMap::from([kv("b", 300.0)]),
        EffectId::PressureViscous => BTreeMap::from([kv("K", 1e-9)]),
        EffectId::AccelerationFriction => BTreeMap::from([kv("H", 5e9)]),
        EffectId::LugreDynamics => BTreeMap::from([kv("sigma0", 2e5), kv("sigma1", 600.0)]),
        EffectId::ExternalForce => BTreeMap::from([kv("F0", 15.0)]),
        _ => BTreeMap::new(),
    }
}

/// How many times finer than the record the true model's inputs are sampled
/// when a record is generated: the bench's inputs hold each sample linearly
/// to the next, so LuGre's bristle sees the exact velocity to 1e-6 of it.
pub const OVERSAMPLE: usize = 8;

/// The true model's load-cell force on [`motion`] at `n` samples of `dt`:
/// the bench's netlist ([`FrictionBench::simulate`]) driven by the exact
/// motion sampled [`OVERSAMPLE`] times finer, read at the record's samples.
pub fn true_force(truth: &FrictionBench, n: usize, dt: f64) -> Vec<f64> {
    let k = OVERSAMPLE;
    let fine = motion((n - 1) * k + 1, dt / k as f64);
    let inputs = crate::bench::BenchInputs::of(&fine).expect("a generated motion is a valid input");
    let f = truth
        .simulate(&fine, &inputs)
        .expect("the true bench simulates on its generated motion");
    f.into_iter().step_by(k).collect()
}

/// The exact motion and pressure of a generated record: `n` samples at `dt`
/// (position by trapezoidal integration of the velocity, zero mean).
pub fn motion(n: usize, dt: f64) -> BenchSignals {
    use std::f64::consts::PI;
    let t: Vec<f64> = (0..n).map(|i| i as f64 * dt).collect();
    let f = 0.8;
    let vel = |t: f64| {
        let speed = 0.06 + 0.04 * (2.0 * PI * 0.11 * t).sin();
        speed * ((2.0 * PI * f * t).sin() / 0.15).tanh()
    };
    let v: Vec<f64> = t.iter().map(|&t| vel(t)).collect();
    let h = 1e-6;
    let a: Vec<f64> = t
        .iter()
        .map(|&t| (vel(t + h) - vel(t - h)) / (2.0 * h))
        .collect();
    let p2: Vec<f64> = t
        .iter()
        .map(|&t| 4e5 + 3e5 * (2.0 * PI * 0.13 * t + 0.5).sin())
        .collect();
    let mut x = vec![0.0; n];
    for i in 1..n {
        x[i] = x[i - 1] + 0.5 * (v[i] + v[i - 1]) * dt;
    }
    let mean = x.iter().sum::<f64>() / n as f64;
    x.iter_mut().for_each(|v| *v -= mean);
    BenchSignals {
        source: "synthetic".into(),
        x,
        v,
        a,
        p1: vec![0.0; n],
        p2,
        force: vec![0.0; n],
        t,
    }
}

/// Generates a record of `truth` on [`motion`] with sensor `noise`, plus an
/// out-of-catalog `foreign` term, seeded for reproducibility.
pub fn record(
    truth: &FrictionBench,
    n: usize,
    dt: f64,
    noise: Noise,
    foreign: Foreign,
    seed: u64,
) -> Record {
    let m = motion(n, dt);
    let mut force = true_force(truth, n, dt);
    let x = m.x.clone();
    match foreign {
        Foreign::None => {}
        Foreign::Spring(k) => {
            for (f, xi) in force.iter_mut().zip(&x) {
                *f += truth.force_sign * k * xi;
            }
        }
        Foreign::ForceDelay(tau) => {
            let f0 = force.clone();
            for (i, f) in force.iter_mut().enumerate() {
                *f = crate::data::interp_linear(&m.t, &f0, m.t[i] - tau);
            }
        }
    }
    let ex = gaussian_noise(n, seed);
    let ep = gaussian_noise(n, seed.wrapping_add(1));
    let ef = gaussian_noise(n, seed.wrapping_add(2));
    let pos: Vec<f64> = x
        .iter()
        .zip(&ex)
        .map(|(x, e)| x + noise.position * e)
        .collect();
    let p2: Vec<f64> =
        m.p2.iter()
            .zip(&ep)
            .map(|(p, e)| p + noise.pressure * e)
            .collect();
    let force: Vec<f64> = force
        .iter()
        .zip(&ef)
        .map(|(f, e)| f + noise.force * e)
        .collect();
    let mut signals = BTreeMap::new();
    signals.insert(Signal::Position, pos);
    signals.insert(Signal::P2, p2);
    signals.insert(Signal::Force, force);
    Record {
        source: "synthetic".into(),
        time: m.t,
        signals,
        ignored: vec![],
        units: Default::default(),
        lines: Vec::new(),
    }
}

/// The true rig of a planted case: [`base_rig`] with `effects` on at their
/// [`planted`] magnitude (acceleration friction needs pressure_viscous's K,
/// which is then on in the base too).
pub fn truth_with(effects: &[EffectId]) -> FrictionBench {
    let mut r = declared_for(effects);
    for &id in effects {
        r.friction.effects.insert(id, planted(id));
    }
    r
}

/// The declared rig of a planted case: the truth without the planted effects.
pub fn declared_for(effects: &[EffectId]) -> FrictionBench {
    let mut r = base_rig();
    if effects.contains(&EffectId::AccelerationFriction) {
        r.friction.effects.insert(
            EffectId::PressureViscous,
            planted(EffectId::PressureViscous),
        );
    }
    for id in effects {
        r.friction.effects.remove(id);
    }
    r
}

/// One generated fixture: name, planted catalog effects, foreign term, seed.
#[derive(Clone, Debug, PartialEq)]
pub struct FixtureCase {
    /// File stem in `fixtures/measured/`.
    pub name: String,
    /// Catalog effects planted (and left out of the declared rig).
    pub planted: Vec<EffectId>,
    /// Out-of-catalog term planted.
    pub foreign: Foreign,
    /// Noise seed.
    pub seed: u64,
}

/// The fixture cases: nothing missing, each force-balance effect alone, two
/// at once, and two out-of-catalog shapes.
pub fn fixture_cases() -> Vec<FixtureCase> {
    let mut v = vec![FixtureCase {
        name: "bench-none".into(),
        planted: vec![],
        foreign: Foreign::None,
        seed: 100,
    }];
    for (k, id) in crate::bench::BENCH_EFFECTS.iter().enumerate() {
        v.push(FixtureCase {
            name: format!("bench-{}", id.id()),
            planted: vec![*id],
            foreign: Foreign::None,
            seed: 101 + k as u64,
        });
    }
    v.push(FixtureCase {
        name: "bench-pressure_viscous+external_force".into(),
        planted: vec![EffectId::PressureViscous, EffectId::ExternalForce],
        foreign: Foreign::None,
        seed: 120,
    });
    v.push(FixtureCase {
        name: "bench-foreign-spring".into(),
        planted: vec![],
        foreign: Foreign::Spring(400.0),
        seed: 121,
    });
    v.push(FixtureCase {
        name: "bench-foreign-delay".into(),
        planted: vec![],
        foreign: Foreign::ForceDelay(0.01),
        seed: 122,
    });
    v
}

/// A realistic magnitude of each valve-rig effect on `leaney-moog`: its
/// first parameter (the one the tests check against its interval); see
/// [`valve_planted_all`] for every parameter planted. `None` for effects
/// the valve rig does not expose.
pub fn valve_planted(id: EffectId) -> Option<(&'static str, f64)> {
    valve_planted_all(id).first().copied()
}

/// Every parameter planted for effect `id` on `leaney-moog` (empty for
/// effects the valve rig does not expose), in the order to set them.
pub fn valve_planted_all(id: EffectId) -> Vec<(&'static str, f64)> {
    match id {
        EffectId::ValveNullBias => vec![("xb", 0.03 * 0.375e-3)],
        EffectId::FlowGainError => vec![("kw", 0.85)],
        EffectId::InternalLeakage => vec![("Cl", 1e-11)],
        EffectId::ExternalLeakage => vec![("Ce1", 1e-11)],
        // 2e9 Pa s/m^3: about 4 bar of droop at the 12 l/min the records draw at most
        EffectId::SupplyDroop => vec![("Rs", 2e9)],
        // a transducer with its line and anti-alias filter
        EffectId::SensorLag => vec![("tau", 5e-3)],
        EffectId::BulkModulus => vec![("B", 3.5e8)],
        EffectId::ExternalForce => vec![("F0", 800.0)],
        // declared Fc = 50 N: extending 70 N, retracting 30 N
        EffectId::CoulombAsymmetry => vec![("dFc", 40.0)],
        // a break-away level three times the Coulomb level, fading over ~20 mm/s
        EffectId::Stribeck => vec![("Fs", 150.0), ("vs", 0.02), ("alpha", 0.7)],
        // bristles with a 0.25 mm relaxation length at Fc = 50 N, damped
        EffectId::LugreDynamics => vec![("sigma0", 2e5), ("sigma1", 600.0)],
        _ => vec![],
    }
}

/// Noise seed of the generated valve-rig fixtures (`fixtures/measured/valve-*.csv`).
pub const VALVE_FIXTURE_SEED: u64 = 40;

/// The generated valve-rig fixtures: file stem and the planted effect
/// (`None`: nothing missing) — every effect [`valve_planted`] knows, each on
/// `leaney-moog` alone at its planted magnitude; the declared rig is the
/// preset itself.
pub fn valve_fixture_cases() -> Vec<(String, Option<EffectId>)> {
    let mut v = vec![("valve-none".to_string(), None)];
    for id in EffectId::ALL {
        if valve_planted(id).is_some() {
            v.push((format!("valve-{}", id.id()), Some(id)));
        }
    }
    v
}

/// The command of generated valve-rig records: two sines (1 Hz, 0.3 and
/// 3.3 Hz, 0.1 of full spool demand).
pub fn valve_command(t: f64) -> f64 {
    use std::f64::consts::PI;
    0.3 * (2.0 * PI * t).sin() + 0.1 * (2.0 * PI * 3.3 * t).sin()
}

/// Generates a valve-rig record: `truth` simulated on [`valve_command`] for
/// `n` samples at `dt` (integrated at rtol 1e-8), position noise 20 µm and
/// pressure noise 20 kPa.
pub fn valve_record(
    truth: &hydrocyl_system::valve_rig::ValveRig,
    n: usize,
    dt: f64,
    seed: u64,
) -> Result<Record, String> {
    valve_record_delayed(truth, n, dt, seed, 0.0)
}

/// As [`valve_record`], but the rig receives the command `delay` seconds
/// late (a transport delay the catalog does not have); the record holds the
/// command as sent.
pub fn valve_record_delayed(
    truth: &hydrocyl_system::valve_rig::ValveRig,
    n: usize,
    dt: f64,
    seed: u64,
    delay: f64,
) -> Result<Record, String> {
    valve_record_with(truth, n, dt, seed, delay, &valve_command)
}

/// A command with rests: [`valve_command`] for 0.6 s of every second, then
/// `hold` (the spool demand at which the declared rig stands still) for
/// 0.4 s. A record that only moves cannot tell a Coulomb asymmetry from a
/// constant force (both are a constant force while moving); at rest the
/// asymmetry vanishes and the constant force does not.
pub fn valve_command_with_rests(t: f64, hold: f64) -> f64 {
    if t.rem_euclid(1.0) < 0.6 {
        hold + valve_command(t)
    } else {
        hold
    }
}

/// As [`valve_record_delayed`] on any `command` (normalised spool demand as
/// a function of time).
pub fn valve_record_with(
    truth: &hydrocyl_system::valve_rig::ValveRig,
    n: usize,
    dt: f64,
    seed: u64,
    delay: f64,
    command: &dyn Fn(f64) -> f64,
) -> Result<Record, String> {
    let t: Vec<f64> = (0..n).map(|i| i as f64 * dt).collect();
    let u: Vec<f64> = t.iter().map(|&t| command(t)).collect();
    let late: Vec<f64> = t.iter().map(|&t| command((t - delay).max(0.0))).collect();
    let cmd = hydrocyl_system::signal::Signal::shared_table(t.as_slice().into(), late.into())
        .map_err(|e| e.to_string())?;
    let run = truth
        .simulate(
            cmd,
            &t,
            &hydrocyl_system::run::RunOptions {
                rtol: 1e-8,
                ..hydrocyl_system::run::RunOptions::dp45()
            },
        )
        .map_err(|e| e.to_string())?;
    let ch = |name: &str| -> Result<Vec<f64>, String> {
        run.channel(name)
            .map(<[f64]>::to_vec)
            .ok_or_else(|| format!("no channel {name}"))
    };
    let mut signals = BTreeMap::new();
    let noisy = |v: Vec<f64>, s: f64, k: u64| -> Vec<f64> {
        let e = gaussian_noise(v.len(), seed.wrapping_add(k));
        v.iter().zip(&e).map(|(a, e)| a + s * e).collect()
    };
    signals.insert(Signal::Command, u);
    signals.insert(Signal::Position, noisy(ch("position")?, 2e-5, 0));
    signals.insert(Signal::P1, noisy(ch("p1")?, 2e4, 1));
    signals.insert(Signal::P2, noisy(ch("p2")?, 2e4, 2));
    Ok(Record {
        source: "synthetic-valve".into(),
        time: t,
        signals,
        ignored: vec![],
        units: Default::default(),
        lines: Vec::new(),
    })
}

/// The reference of generated closed-loop records \[m\]: steps of ±40 mm
/// every second, ramped over 50 ms, on a slow 10 mm sine: with Kp = 10 /m
/// the command reaches about 0.8 after each step and the piston settles in
/// between.
pub fn valve_reference(t: f64) -> f64 {
    use std::f64::consts::PI;
    let k = t.floor();
    let level = |k: f64| {
        if (k as i64).rem_euclid(2) == 0 {
            0.04
        } else {
            -0.04
        }
    };
    let frac = ((t - k) / 0.05).min(1.0);
    let prev = if k >= 1.0 { level(k - 1.0) } else { 0.0 };
    prev + (level(k) - prev) * frac + 0.01 * (2.0 * PI * 0.3 * t).sin()
}

/// Generates a closed-loop record of a rig with a controller: `truth`
/// simulated on `reference` \[m\] for `n` samples at `dt` (rtol 1e-8),
/// position noise 20 µm and pressure noise 20 kPa; the recorded `command`
/// is the controller's law applied to the reference and the *measured*
/// (noisy) position, as a real controller computes it (a PI controller's
/// integral summed over the samples, held while the output is clipped and
/// the error pushes it further out).
pub fn valve_record_closed_loop(
    truth: &hydrocyl_system::valve_rig::ValveRig,
    n: usize,
    dt: f64,
    seed: u64,
    reference: &dyn Fn(f64) -> f64,
) -> Result<Record, String> {
    let c = truth
        .controller
        .ok_or("the truth rig has no controller: a closed-loop record needs one")?;
    let mut rec = valve_record_with(truth, n, dt, seed, 0.0, reference)?;
    rec.source = "synthetic-valve-closed-loop".into();
    let r = rec
        .signals
        .remove(&Signal::Command)
        .ok_or("no input column")?;
    let x = rec.signals.get(&Signal::Position).ok_or("no position")?;
    let law = hydrocyl_system::components::PositionLaw {
        gain: c.gain_per_m,
        integral_time: c.integral_time_s,
        bias: c.bias,
        output_min: c.output_min,
        output_max: c.output_max,
    };
    let mut integral = 0.0;
    let mut u = Vec::with_capacity(r.len());
    // trapezoidal integral of the error between samples
    let e: Vec<f64> = r.iter().zip(x).map(|(r, x)| r - x).collect();
    for k in 0..e.len() {
        u.push(law.output(e[k], integral));
        if let (Some(t1), Some(e1)) = (rec.time.get(k + 1), e.get(k + 1)) {
            let rate = law.integral_rate(0.5 * (e[k] + e1), integral);
            integral += (t1 - rec.time[k]) * rate;
        }
    }
    rec.signals.insert(Signal::Command, u);
    rec.signals.insert(Signal::Reference, r);
    Ok(rec)
}

/// Generates a record of any netlist rig `truth` driven by `command` (the
/// run's input) for `n` samples at `dt` (rtol 1e-8, the default solver):
/// columns `command`, `position` (noise 20 µm), `p1` and `p2` (noise
/// 20 kPa), noise seeded by `seed`.
pub fn netlist_record(
    truth: &serde_json::Value,
    n: usize,
    dt: f64,
    seed: u64,
    command: &dyn Fn(f64) -> f64,
) -> Result<Record, String> {
    let t: Vec<f64> = (0..n).map(|i| i as f64 * dt).collect();
    let u: Vec<f64> = t.iter().map(|&t| command(t)).collect();
    let cmd =
        hydrocyl_system::signal::Signal::shared_table(t.as_slice().into(), u.as_slice().into())
            .map_err(|e| e.to_string())?;
    let run = hydrocyl_system::rig::simulate(
        truth,
        cmd,
        &t,
        &hydrocyl_system::run::RunOptions {
            rtol: 1e-8,
            ..hydrocyl_system::run::RunOptions::default()
        },
    )
    .map_err(|e| e.to_string())?;
    let ch = |name: &str| -> Result<Vec<f64>, String> {
        run.channel(name)
            .map(<[f64]>::to_vec)
            .ok_or_else(|| format!("no channel {name}"))
    };
    let noisy = |v: Vec<f64>, s: f64, k: u64| -> Vec<f64> {
        let e = gaussian_noise(v.len(), seed.wrapping_add(k));
        v.iter().zip(&e).map(|(a, e)| a + s * e).collect()
    };
    let mut signals = BTreeMap::new();
    signals.insert(Signal::Command, u);
    signals.insert(Signal::Position, noisy(ch("position")?, 2e-5, 0));
    signals.insert(Signal::P1, noisy(ch("p1")?, 2e4, 1));
    signals.insert(Signal::P2, noisy(ch("p2")?, 2e4, 2));
    Ok(Record {
        source: "synthetic-netlist".into(),
        time: t,
        signals,
        ignored: vec![],
        units: Default::default(),
        lines: Vec::new(),
    })
}
