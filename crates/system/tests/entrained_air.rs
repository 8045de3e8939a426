//! The entrained-air fluid model (`hydrocyl_actuator::fluid`) in circuits:
//! closed forms (filling an evacuated volume at constant inflow, Boyle's law
//! in a shut chamber), mass conservation, the floor at absolute zero, energy,
//! the limit of no air, and the analytic Jacobian against differences.

use hydrocyl_integrators::OdeSystem;
use hydrocyl_system::circuit::LEDGER_TERMS;
use hydrocyl_system::rig;
use hydrocyl_system::run::{Run, RunOptions, Solver};
use hydrocyl_system::signal::Signal;
use hydrocyl_system::simulation::Simulation;
use hydrocyl_system::Circuit;
use serde_json::{json, Value};

const PA: f64 = 101_325.0;
/// A rigid liquid: only the air is compressible (the closed forms below).
const RIGID: f64 = 1e20;

/// Pump (`K` = 1e-5 m³/s/V, ω_n = 2000 rad/s, ζ = 1) between the tank and a
/// volume of 0.1 L holding air fraction `alpha`, starting at gauge `p0`.
fn pumped_volume(alpha: f64, b: f64, p0: f64) -> Value {
    json!({
        "kind": "netlist",
        "name": "pumped-volume",
        "components": {
            "command": { "type": "command_input" },
            "pump": { "type": "pump_identified", "gain": 1e-5, "natural_frequency": 2000.0, "damping": 1.0 },
            "vol": { "type": "volume", "volume": 1e-4, "bulk_modulus": b, "air_fraction": alpha,
                     "initial": { "pressure": p0 } },
            "tank": { "type": "pressure_source", "pressure": 0.0 }
        },
        "connections": [["command.out", "pump.command"], ["pump.a", "vol.port"], ["pump.b", "tank.port"]]
    })
}

/// Rosenbrock at rtol 1e-10, no step bound, the energy ledger on or off.
fn options(ledger: bool) -> RunOptions {
    RunOptions {
        solver: Solver::Rosenbrock,
        rtol: 1e-10,
        h_max: f64::INFINITY,
        max_steps: 1_000_000,
        ledger,
        ..RunOptions::default()
    }
}

fn simulation(v: &Value, command: Signal) -> Simulation {
    Simulation::new(v, command)
        .expect("circuit")
        .options(options(false))
}

fn build(v: &Value, u: f64) -> Simulation {
    simulation(v, Signal::Constant { value: u })
}

/// A run from t = 0 sampled at `t_eval` (after 0): `state(k)` and `t[k]`
/// are at `t_eval[k]`.
struct Sol {
    run: Run,
    t: Vec<f64>,
}

impl Sol {
    fn state(&self, k: usize) -> &[f64] {
        self.run.state(k + 1)
    }
}

fn run(sim: &mut Simulation, t_eval: Vec<f64>) -> Sol {
    let mut t = vec![0.0];
    t.extend_from_slice(&t_eval);
    let run = sim.run(&t).expect("solve");
    Sol { run, t: t_eval }
}

fn state_of(c: &Circuit, comp: &str, k: usize) -> usize {
    c.state_range(c.component_index(comp).expect(comp)).start + k
}

/// Rigid liquid, isothermal air: the content `V/v(p)`, `v = (1 − α) + α p_a/P`,
/// changes by `Q/v`, so `v(t) = v0 e^(−Q t/V)` for a constant inflow `Q`
/// (the pump's 2nd-order start delays the flow by 2ζ/ω_n): the pressure
/// follows `P = α p_a / (v − (1 − α))` and the evacuated volume reaches gauge
/// 0 at `t = (V/Q) ln v0`.
#[test]
fn an_evacuated_volume_fills_in_the_closed_form_time() {
    let (alpha, v, q) = (0.01, 1e-4, 1e-5);
    let p0 = -1.0e5; // 1325 Pa absolute
    let v0 = (1.0 - alpha) + alpha * PA / (p0 + PA);
    let delay = 2.0 * 1.0 / 2000.0;
    let t_fill = v / q * v0.ln() + delay;
    let mut sim = build(&pumped_volume(alpha, RIGID, p0), q / 1e-5);
    let times: Vec<f64> = vec![0.5, 1.0, 2.0, 4.0, t_fill];
    let sol = run(&mut sim, times.clone());
    let ip = state_of(sim.circuit(), "vol", 0);
    for (k, &t) in times.iter().enumerate() {
        let vt = v0 * (-q * (t - delay) / v).exp();
        let want = alpha * PA / (vt - (1.0 - alpha)) - PA;
        let got = sol.state(k)[ip];
        // a relative 5e-7 of the content: P = α p_a/(v − (1 − α)) amplifies an
        // error in v by v/(v − 1 + α), up to 100 near gauge 0
        let amplify = vt / (vt - (1.0 - alpha));
        assert!(
            (got - want).abs() < 5e-7 * amplify * (want + PA),
            "t = {t}: p {got} vs {want}"
        );
    }
    let at_fill = sol.state(times.len() - 1)[ip];
    // 5 Pa is 5 µs of the 5.6 s fill at 1e6 Pa/s
    assert!(
        at_fill.abs() < 5.0,
        "gauge {at_fill} Pa at the fill time {t_fill} s"
    );
}

/// Pumped out for 20 s (twice its content at atmosphere), the volume's
/// pressure falls towards absolute zero as `v = v0 e^(Q t/V)` but never
/// below it; the constant-B liquid has no floor.
#[test]
fn no_outflow_takes_a_volume_below_absolute_zero() {
    let (alpha, v, q) = (0.01, 1e-4, 1e-5);
    let times: Vec<f64> = (1..=40).map(|k| 0.5 * k as f64).collect();
    let mut sim = build(&pumped_volume(alpha, RIGID, 0.0), -1.0);
    let sol = run(&mut sim, times.clone());
    let ip = state_of(sim.circuit(), "vol", 0);
    for (k, &t) in times.iter().enumerate() {
        let p = sol.state(k)[ip];
        assert!(p > -PA, "t = {t}: {p} Pa gauge is below absolute zero");
        let vt = (q * (t - 1e-3) / v).exp();
        // the gas law's P_eff; the state is P = P_eff − s²/P_eff (the floor's hyperbola)
        let p_eff = alpha * PA / (vt - (1.0 - alpha));
        let s2 = hydrocyl_actuator::fluid::ABSOLUTE_FLOOR_SCALE.powi(2);
        let want = p_eff - s2 / p_eff;
        assert!(
            ((p + PA) / want - 1.0).abs() < 1e-6,
            "t = {t}: P {} vs {want}",
            p + PA
        );
    }
    assert_eq!(sol.run.cavitation_entries(), 0, "air: never below vacuum");
    // the constant-B liquid has no floor: it goes far below absolute zero,
    // and the volume reports it (one entry below absolute vacuum)
    let mut sim = build(&pumped_volume(0.0, 7e8, 0.0), -1.0);
    let sol = run(&mut sim, vec![0.05]);
    assert!(sol.state(0)[state_of(sim.circuit(), "vol", 0)] < -10.0 * PA);
    assert_eq!(sol.run.cavitation_entries(), 1, "{:?}", sol.run.diagnostics);
}

/// Energy into the volume (the pump's `(p_a − p_b) Q`) equals the compression
/// power the volume books, and that integral equals the stored energy
/// recomputed from the end state (`V ∫ p/B_eff dp`).
#[test]
fn the_ledger_closes_and_the_stored_energy_is_the_compression_work() {
    let v = pumped_volume(0.005, 7e8, -0.9e5);
    let mut sim = build(&v, 1.0).options(options(true));
    let sol = run(&mut sim, vec![3.0]);
    let c = sim.circuit();
    let last = sol.state(0);
    let o = c.ledger_offset();
    let pump = c.component_index("pump").unwrap();
    let vol = c.component_index("vol").unwrap();
    let source = last[o + LEDGER_TERMS * pump];
    let storage = last[o + LEDGER_TERMS * vol + 2];
    assert!(
        (source - storage).abs() < 1e-8 * source.abs(),
        "{source} vs {storage}"
    );
    let p = last[state_of(c, "vol", 0)];
    assert!(p > 1e6, "filled to {p} Pa");
    let air = hydrocyl_actuator::EntrainedAir::isothermal(0.005);
    let stored = air.stored_energy(7e8, p, 1e-4) - air.stored_energy(7e8, -0.9e5, 1e-4);
    assert!(
        (stored / storage - 1.0).abs() < 1e-6,
        "{stored} vs {storage}"
    );
}

/// A cylinder with both ports shut and a 20 kg mass thrown at 0.3 m/s: the
/// air in each chamber obeys Boyle's law, `P (V − m(1 − α)) = α m p_a` for
/// its content `m`, at every sample, and kinetic plus gas energy is
/// conserved (no friction): `½ M v² + Σ m ε(p)`, `ε = α p_a (ln(P/p_a) + p_a/P − 1)`.
#[test]
fn a_shut_chamber_is_a_boyle_gas_spring() {
    let alpha = 0.02;
    let (a1, a2, l) = (8.042e-4, 5.5e-4, 0.16);
    let net = json!({
        "kind": "netlist",
        "name": "shut-cylinder",
        "components": {
            "cylinder": { "type": "cylinder", "area_1": a1, "area_2": a2, "stroke": 0.3,
                "chamber_length_1": l, "chamber_length_2": l, "bulk_modulus": RIGID,
                "air_fraction": alpha,
                "initial": { "position": 0.0, "velocity": 0.3, "p1": 0.0, "p2": 0.0 } },
            "load": { "type": "mass", "mass": 20.0 },
            "gauge_1": { "type": "pressure_sensor", "time_constant": 1e-3 },
            "gauge_2": { "type": "pressure_sensor", "time_constant": 1e-3 }
        },
        "connections": [["cylinder.rod", "load.rod"], ["cylinder.A", "gauge_1.port"], ["cylinder.B", "gauge_2.port"]]
    });
    let mut sim = build(&net, 0.0);
    let times: Vec<f64> = (1..=50).map(|k| 2e-3 * k as f64).collect();
    let sol = run(&mut sim, times.clone());
    let c = sim.circuit();
    let (ip1, ip2) = (state_of(c, "cylinder", 0), state_of(c, "cylinder", 1));
    let (ix, iv) = (state_of(c, "load", 0), state_of(c, "load", 1));
    let (m1, m2) = (a1 * l, a2 * l);
    let eps = |p: f64| alpha * PA * (((p + PA) / PA).ln() + PA / (p + PA) - 1.0);
    let energy = |x: &[f64]| 0.5 * 20.0 * x[iv] * x[iv] + m1 * eps(x[ip1]) + m2 * eps(x[ip2]);
    let e0 = 0.5 * 20.0 * 0.3 * 0.3;
    let mut moved = 0.0f64;
    for (k, &t) in times.iter().enumerate() {
        let x = sol.state(k);
        let (v1, v2) = (a1 * (l + x[ix]), a2 * (l - x[ix]));
        moved = moved.max(x[ix].abs());
        for (p, vol, m) in [(x[ip1], v1, m1), (x[ip2], v2, m2)] {
            let want = alpha * m * PA / (vol - m * (1.0 - alpha));
            assert!(
                ((p + PA) / want - 1.0).abs() < 1e-6,
                "t = {t}: P {} vs {want}",
                p + PA
            );
        }
        assert!(
            (energy(x) / e0 - 1.0).abs() < 1e-6,
            "t = {t}: {} vs {e0}",
            energy(x)
        );
    }
    assert!(moved > 2e-3, "the piston moved {moved} m");
}

/// The limit of no air: α = 1e-9 follows the constant-B run to the first
/// order in α (B/B_eff − 1 ≈ α B/P ≈ 7e-6 at atmosphere), on the valve rig
/// (70 bar supply: no chamber near vacuum, where the two models part by
/// design).
#[test]
fn a_vanishing_air_fraction_is_the_liquid_model() {
    let net = |alpha: f64| {
        let mut v = rig::load("leaney-moog").unwrap();
        v["components"]["cylinder"]["air_fraction"] = json!(alpha);
        v
    };
    let sine = Signal::Sine {
        amplitude: 0.4,
        period_s: 0.4,
        bias: 0.0,
        phase_rad: 0.3,
    };
    let times: Vec<f64> = (1..=40).map(|k| 0.01 * k as f64).collect();
    let mut runs = Vec::new();
    for alpha in [0.0, 1e-9] {
        let mut sim = simulation(&net(alpha), sine.clone());
        let sol = run(&mut sim, times.clone());
        let c = sim.circuit();
        let (ix, ip) = (state_of(c, "load", 0), state_of(c, "cylinder", 0));
        let lowest = (0..times.len())
            .map(|k| sol.state(k)[ip])
            .fold(f64::INFINITY, f64::min);
        assert!(lowest > 0.0, "p1 fell to {lowest}");
        runs.push(
            (0..times.len())
                .map(|k| sol.state(k)[ix])
                .collect::<Vec<f64>>(),
        );
    }
    let span = runs[0].iter().fold(0.0f64, |m, x| m.max(x.abs()));
    let worst = runs[0]
        .iter()
        .zip(&runs[1])
        .fold(0.0f64, |m, (a, b)| m.max((a - b).abs()));
    assert!(span > 1e-3, "the piston moved {span} m");
    assert!(
        worst < 1e-5 * span,
        "α = 1e-9 differs by {worst} m of {span} m"
    );
}

/// The analytic Jacobian of volumes and chambers with air equals central
/// differences of the right-hand side, near atmosphere and near the floor.
#[test]
fn the_analytic_jacobian_with_air_equals_differences() {
    for (net, u) in [
        (pumped_volume(0.005, 7e8, -0.95e5), 1.0),
        (pumped_volume(0.01, 7e8, 2e5), -1.0),
    ] {
        let mut sim = build(&net, u);
        assert!(sim.circuit().has_jacobian());
        let sol = run(&mut sim, vec![0.005, 0.01, 0.02]);
        let c = sim.circuit();
        let n = c.dim();
        let mut jac = vec![0.0; n * n];
        for k in 0..3 {
            let x = sol.state(k).to_vec();
            assert!(c.jacobian(sol.t[k], &x, &mut jac));
            for j in 0..c.n_states() {
                let h = 1e-6 * x[j].abs().max(1.0);
                let (mut up, mut dn) = (x.clone(), x.clone());
                up[j] += h;
                dn[j] -= h;
                let (mut fu, mut fd) = (vec![0.0; n], vec![0.0; n]);
                c.rhs(sol.t[k], &up, &mut fu);
                c.rhs(sol.t[k], &dn, &mut fd);
                for i in 0..c.n_states() {
                    let d = (fu[i] - fd[i]) / (2.0 * h);
                    let a = jac[i * n + j];
                    assert!(
                        (d - a).abs() <= 1e-5 * d.abs().max(a.abs()).max(1e-9),
                        "∂f{i}/∂x{j} at t = {}: analytic {a} vs {d}",
                        sol.t[k]
                    );
                }
            }
        }
    }
}
