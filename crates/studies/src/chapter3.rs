//! The chapter-3 test cases of the `leaney-moog` rig (thesis section 3.3,
//! Figs 3-11, 3-13, 3-21 to 3-26, Table 3-5), shared by the tests, the
//! validation suite (`cargo xtask validate`) and the benchmarks.
//!
//! The thesis does not give the periods and durations of its tests; the
//! choices here are documented on each case.

use hydrocyl_system::rig::RigError;
use hydrocyl_system::run::{nrmse, Run, RunOptions};
use hydrocyl_system::signal::Signal;
use hydrocyl_system::valve_rig::{Formulation, ValveRig};

/// One test case: a rig, a command, output times and the thesis's Simulink
/// wall times (numerical X, analytical X, fundamental) \[s\], if it gives them.
#[derive(Clone, Debug)]
pub struct Case {
    /// Short name (`square`, `underlap-sine`, `sawtooth`, `underlap-sweep`).
    pub name: &'static str,
    /// What it is.
    pub description: String,
    /// The rig (formulation set per run).
    pub rig: ValveRig,
    /// The command.
    pub command: Signal,
    /// Output times \[s\].
    pub times: Vec<f64>,
    /// Table 3-5: numerical X, analytical X, fundamental \[s\].
    pub thesis_seconds: Option<[f64; 3]>,
}

fn times(t_end: f64, dt: f64) -> Vec<f64> {
    let n = (t_end / dt).round() as usize;
    (0..=n).map(|k| k as f64 * dt).collect()
}

/// Open-loop square wave giving ±90 mm/s (Figs 2-30, 3-11, 3-21) with the
/// bias of section 3.1.3 computed from the rig's steady state; period 2 s,
/// three periods (the piston moves 90 mm out and back each period).
pub fn square_wave() -> Result<Case, RigError> {
    let rig = ValveRig::leaney_moog();
    let (bias, amplitude) = rig.open_loop_square(0.09)?;
    Ok(Case {
        name: "square",
        description: format!(
            "square wave ±90 mm/s: u = {bias:.5} ± {amplitude:.5}, period 2 s, 6 s"
        ),
        rig,
        command: Signal::Square {
            amplitude,
            period_s: 2.0,
            bias,
        },
        times: times(6.0, 1e-3),
        thesis_seconds: Some([5.49, 1.07, 1.12]),
    })
}

/// Underlap widened to 20 % of the spool stroke (u0 = 0.075 mm, section
/// 3.3.2); a sine of ±60 % of the underlap about the spool position at which
/// the piston rests (so that the spool never leaves the underlap and the
/// piston does not creep to an end), period 2 s, 6 s.
pub fn underlap_sine() -> Result<Case, RigError> {
    let mut rig = ValveRig::leaney_moog();
    rig.valve.underlap_m = 0.075e-3;
    let xs0 = rig.spool_for_velocity(0.0)?;
    rig.initial.spool = xs0;
    let xm = rig.valve.stroke_m;
    Ok(Case {
        name: "underlap-sine",
        description: format!(
            "sine inside a 20 % underlap: x_s = {:.4} mm ± 0.045 mm (u0 = 0.075 mm), period 2 s, 6 s",
            xs0 * 1e3
        ),
        command: Signal::Sine {
            amplitude: 0.6 * rig.valve.underlap_m / xm,
            period_s: 2.0,
            bias: xs0 / xm,
            phase_rad: 0.0,
        },
        rig,
        times: times(6.0, 1e-3),
        thesis_seconds: Some([1647.17, 8.50, 8.35]),
    })
}

/// Sawtooth across null (section 3.3.3): u from −0.52 to +0.52 each 1.5 s
/// period, so that 2.31 % of the spool travel is inside the underlap as in
/// the thesis; 6 s. The drop at the end of each ramp reverses a piston
/// moving at ~0.3 m/s, and chamber 1 cavitates (reported).
pub fn sawtooth() -> Result<Case, RigError> {
    let rig = ValveRig::leaney_moog();
    Ok(Case {
        name: "sawtooth",
        description: "sawtooth across null: u from -0.52 to +0.52, period 1.5 s, 6 s".into(),
        rig,
        command: Signal::Sawtooth {
            amplitude: 0.52,
            period_s: 1.5,
            bias: 0.0,
        },
        times: times(6.0, 1e-3),
        thesis_seconds: Some([8.26, 1.23, 1.52]),
    })
}

/// Fig 3-13: the spool swept across the underlap from +u0 to −u0 at constant
/// speed: held at +u0 for 1 s (the piston settles to its extending speed),
/// ramped to −u0 over `sweep_s`, held 1 s.
pub fn underlap_sweep(sweep_s: f64) -> Result<Case, RigError> {
    let mut rig = ValveRig::leaney_moog();
    let u = rig.valve.underlap_m / rig.valve.stroke_m;
    rig.initial.spool = rig.valve.underlap_m;
    Ok(Case {
        name: "underlap-sweep",
        description: format!("spool swept from +u0 to -u0 in {sweep_s} s (Fig 3-13)"),
        rig,
        command: Signal::Ramp {
            from: u,
            to: -u,
            t0_s: 1.0,
            t1_s: 1.0 + sweep_s,
        },
        times: times(2.0 + sweep_s, 1e-3),
        thesis_seconds: None,
    })
}

/// The three formulations run on one case, and the NRMSE between them.
#[derive(Clone, Debug)]
pub struct Comparison {
    /// Runs in [`Formulation::ALL`] order (numerical X, analytical X, fundamental).
    pub runs: Vec<(Formulation, Run)>,
}

/// Channels compared between formulations.
pub const COMPARED: [&str; 4] = ["velocity", "p1", "p2", "p_le"];

impl Comparison {
    /// Runs the case with each formulation.
    pub fn run(case: &Case, opts: &RunOptions) -> Result<Self, RigError> {
        let mut runs = Vec::new();
        for f in Formulation::ALL {
            let mut rig = case.rig.clone();
            rig.cylinder.formulation = f;
            runs.push((f, rig.simulate(case.command.clone(), &case.times, opts)?));
        }
        Ok(Self { runs })
    }

    /// A channel of run `k`; `p_le` is derived from p1, p2 where not probed.
    pub fn channel(&self, k: usize, name: &str, rig: &ValveRig) -> Vec<f64> {
        let r = &self.runs[k].1;
        if let Some(v) = r.channel(name) {
            return v.to_vec();
        }
        let (a1, a2) = (rig.cylinder.area_1_m2, rig.cylinder.area_2_m2);
        let ae = 0.5 * (a1 + a2);
        match (name, r.channel("p1"), r.channel("p2")) {
            ("p_le", Some(p1), Some(p2)) => p1
                .iter()
                .zip(p2)
                .map(|(x, y)| (x * a1 - y * a2) / ae)
                .collect(),
            _ => vec![f64::NAN; r.time.len()],
        }
    }

    /// NRMSE of channel `name` of run `a` against run `b` (reference).
    pub fn nrmse(&self, a: usize, b: usize, name: &str, rig: &ValveRig) -> f64 {
        nrmse(&self.channel(a, name, rig), &self.channel(b, name, rig))
    }
}

/// Drive into the extended stop and out again: u = 0.2 for 2.5 s (the piston
/// reaches +0.26 m after ~2 s and is held there while chamber 2 drains to
/// tank), then u = −0.3 for 1 s. Exercises the stop events and the orifice
/// law near zero pressure drop (the open edges P→A and B→T at p1 → Ps,
/// p2 → 0), where the regularisation acts.
pub fn end_stop() -> Case {
    Case {
        name: "end-stop",
        description: "into the extended stop and back: u = 0.2 for 2.5 s, then -0.3".into(),
        rig: ValveRig::leaney_moog(),
        command: Signal::Step {
            time_s: 2.5,
            before: 0.2,
            after: -0.3,
        },
        times: times(3.5, 1e-3),
        thesis_seconds: None,
    }
}
