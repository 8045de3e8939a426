//! The analytic circuit Jacobian against central finite differences of the
//! right-hand side, along runs of the presets and the example circuits.

use crate::rig;
use crate::signal::Signal;
use crate::Circuit;
use hydrocyl_integrators::{solve, Method, OdeSystem, Options};

/// The rigs whose every component has tangents (the list).
const COVERED: &[&str] = &[
    "leaney-moog",
    "wang-hybrid",
    "wang-valve-c10",
    "leaney-moog-closed-loop",
    "../../fixtures/rigs/wang-hybrid-closed-loop.json",
    "../../fixtures/rigs/wang-hybrid-improved.json",
    "../../fixtures/rigs/wang-hybrid-needle.json",
    "../../fixtures/rigs/wang-hybrid-servo-needle.json",
    "../../fixtures/rigs/wang-hybrid-solenoid.json",
    "../../fixtures/rigs/examples/meter-out-needle.json",
    "../../fixtures/rigs/examples/pump-closed-circuit.json",
    "../../fixtures/rigs/examples/two-cylinders-parallel.json",
];

/// A command that moves each rig both ways: a sine of the command's unit
/// (a normalised spool command, volts on the pump, metres of reference).
fn command(name: &str) -> Signal {
    let amplitude = if name.contains("closed-loop") {
        0.02 // a position reference [m]
    } else if name.contains("hybrid") || name.contains("pump") {
        4.0
    } else {
        0.4
    };
    Signal::Sine {
        amplitude,
        period_s: 0.8,
        bias: 0.0,
        phase_rad: 0.3,
    }
}

fn circuit(name: &str) -> Circuit {
    let v = rig::load(name).unwrap_or_else(|e| panic!("{name}: {e}"));
    let mut c = rig::circuit(&v, command(name)).unwrap_or_else(|e| panic!("{name}: {e}"));
    let x0 = c.initial_state();
    c.reset(0.0, &x0);
    c
}

/// States along a 1.2 s Rosenbrock run, every 20 ms.
fn trajectory(c: &mut Circuit) -> Vec<(f64, Vec<f64>)> {
    let x0 = c.initial_state();
    let t: Vec<f64> = (1..=60).map(|k| 0.02 * k as f64).collect();
    let opts = Options {
        rtol: 1e-7,
        atol: c.atol(1e-7),
        t_eval: Some(t),
        ..Options::default()
    };
    let sol = solve(Method::Rosenbrock, c, 0.0, &x0, 1.2, &opts).expect("run");
    (0..sol.t.len())
        .map(|k| (sol.t[k], sol.state(k).to_vec()))
        .collect()
}

/// Central difference of column `j` with step `h`.
fn column(c: &Circuit, t: f64, x: &[f64], j: usize, h: f64) -> Vec<f64> {
    let n = c.dim();
    let (mut up, mut dn) = (x.to_vec(), x.to_vec());
    up[j] += h;
    dn[j] -= h;
    let (mut fu, mut fd) = (vec![0.0; n], vec![0.0; n]);
    c.rhs(t, &up, &mut fu);
    c.rhs(t, &dn, &mut fd);
    fu.iter()
        .zip(&fd)
        .map(|(a, b)| (a - b) / (2.0 * h))
        .collect()
}

/// Compares the analytic Jacobian with central differences at each state of
/// a run: entry `(i, j)` scaled by state `j`'s typical magnitude must agree to
/// `tol` of row `i`'s largest scaled entry. A column whose difference moves
/// between steps `h` and `2h` straddles a switching surface (a valve cracking,
/// the stick band) and is left out; returns (compared, left out).
fn compare(name: &str, tol: f64) -> (usize, usize) {
    let mut c = circuit(name);
    assert!(c.has_jacobian(), "{name} has no analytic Jacobian");
    let states = trajectory(&mut c);
    let n = c.n_states();
    let dim = c.dim();
    let scale = c.atol(1.0);
    let (mut compared, mut left) = (0, 0);
    let mut jac = vec![0.0; dim * dim];
    for (t, x) in &states {
        assert!(
            c.jacobian(*t, x, &mut jac),
            "{name}: no Jacobian at t = {t}"
        );
        let fd: Vec<Vec<f64>> = (0..n)
            .map(|j| {
                let h = 1e-6 * x[j].abs().max(scale[j]);
                let (a, b) = (column(&c, *t, x, j, h), column(&c, *t, x, j, 2.0 * h));
                let smooth = a.iter().zip(&b).enumerate().all(|(i, (a, b))| {
                    (a - b).abs() * scale[j]
                        <= 0.3 * tol * row_norm(&jac, i, dim, n, &scale).max(1e-300)
                });
                if smooth {
                    a
                } else {
                    Vec::new()
                }
            })
            .collect();
        for (j, col) in fd.iter().enumerate() {
            if col.is_empty() {
                // a switching surface within the stencil: the analytic
                // column is the one-sided slope of the branch the state is
                // on, so it matches the difference towards one side
                left += 1;
                let f0 = {
                    let mut f = vec![0.0; dim];
                    c.rhs(*t, x, &mut f);
                    f
                };
                // worst row's (error, row, difference) of the one-sided
                // difference with step `h` (signed)
                let side = |h: f64| {
                    let mut y = x.clone();
                    y[j] += h;
                    let mut f = vec![0.0; dim];
                    c.rhs(*t, &y, &mut f);
                    (0..n)
                        .map(|i| {
                            let d = (f[i] - f0[i]) / h;
                            let e = (jac[i * dim + j] - d).abs() * scale[j]
                                / row_norm(&jac, i, dim, n, &scale).max(1e-300);
                            (e, i, d)
                        })
                        .fold((0.0, 0, 0.0), |a, b| if b.0 > a.0 { b } else { a })
                };
                // one-sided differences are first order and the stencil must
                // stay on one side of the kink: the best of a few steps
                let base = x[j].abs().max(scale[j]);
                let (err, i, d) = [1e-5, 1e-6, 1e-7, 1e-8]
                    .iter()
                    .flat_map(|r| [side(r * base), side(-r * base)])
                    .fold(
                        (f64::INFINITY, 0, 0.0),
                        |a, b| if b.0 < a.0 { b } else { a },
                    );
                assert!(
                    err < 1e-3,
                    "{name}: t = {t}: column {} matches neither side ({err:e}): row {} analytic {} one-sided {d}",
                    c.state_names()[j],
                    c.state_names()[i],
                    jac[i * dim + j]
                );
                continue;
            }
            compared += 1;
            for i in 0..n {
                let norm = row_norm(&jac, i, dim, n, &scale);
                let err = (jac[i * dim + j] - col[i]).abs() * scale[j];
                assert!(
                    err <= tol * norm || err < 1e-300,
                    "{name}: t = {t}, ∂f{i}/∂x{j} ({} / {}) analytic {} vs FD {} (row scale {norm:e})",
                    c.state_names()[i],
                    c.state_names()[j],
                    jac[i * dim + j],
                    col[i]
                );
            }
        }
    }
    (compared, left)
}

fn row_norm(jac: &[f64], i: usize, dim: usize, n: usize, scale: &[f64]) -> f64 {
    (0..n)
        .map(|j| (jac[i * dim + j] * scale[j]).abs())
        .fold(0.0, f64::max)
}

#[test]
fn the_analytic_jacobian_equals_central_differences_along_runs() {
    for name in COVERED {
        let (compared, left) = compare(name, 1e-6);
        eprintln!("{name}: {compared} columns compared, {left} left out at switching surfaces");
        // the comparison must not be vacuous: at most one column in five
        // left to the one-sided check. A position loop holds its piston at
        // v = 0 for long, where the seal bound changes with the direction
        // (wang-hybrid-closed-loop: 50 of 540 along its run).
        assert!(
            left * 5 <= compared,
            "{name}: {left} of {} columns straddle a switching surface",
            compared + left
        );
    }
}

/// Rosenbrock with the analytic Jacobian follows the same trajectory as with
/// finite differences, to the integrator's tolerance, for fewer right-hand
/// side evaluations per step.
#[test]
fn rosenbrock_with_the_analytic_jacobian_follows_the_finite_difference_run() {
    let rtol = 1e-6;
    for name in COVERED {
        let mut runs = Vec::new();
        for analytic in [false, true] {
            let mut c = circuit(name);
            c.set_analytic_jacobian(analytic);
            assert_eq!(c.has_jacobian(), analytic);
            let x0 = c.initial_state();
            let t: Vec<f64> = (1..=40).map(|k| 0.05 * k as f64).collect();
            let opts = Options {
                rtol,
                atol: c.atol(rtol),
                t_eval: Some(t),
                ..Options::default()
            };
            let sol = solve(Method::Rosenbrock, &mut c, 0.0, &x0, 2.0, &opts).expect("run");
            runs.push((sol, c.atol(1.0)));
        }
        let ((fd, scale), (an, _)) = (&runs[0], &runs[1]);
        let per = |s: &hydrocyl_integrators::Solution| {
            s.stats.rhs_evals as f64 / (s.stats.steps + s.stats.rejected) as f64
        };
        eprintln!(
            "{name}: steps {} / {}, rhs per attempted step {:.2} (FD) / {:.2} (analytic)",
            fd.stats.steps,
            an.stats.steps,
            per(fd),
            per(an)
        );
        assert!(per(an) < per(fd), "{name}");
        let mut worst = 0.0_f64;
        for k in 0..fd.t.len() {
            for (j, (a, b)) in an.state(k).iter().zip(fd.state(k)).enumerate() {
                worst = worst.max((a - b).abs() / (a.abs().max(scale[j])));
            }
        }
        eprintln!("{name}: largest scaled difference {worst:.1e}");
        assert!(worst < 100.0 * rtol, "{name}: {worst:e}");
    }
}

/// A user component without tangents: a laminar leak `q = k p` out of a node.
struct Leak {
    node: crate::HydraulicNode,
    k: f64,
}

impl crate::Component for Leak {
    fn name(&self) -> &str {
        "leak"
    }
    fn bind(&mut self, net: &mut crate::Netlist) -> Result<(), crate::BuildError> {
        self.node = net.hydraulic("v");
        Ok(())
    }
    fn evaluate(&self, _t: f64, _x: &[f64], w: &mut crate::Wires) {
        let q = self.k * w.get(self.node.pressure).si();
        w.add(self.node.inflow, hydrocyl_ports::VolumeFlow::new(-q));
    }
}

#[test]
fn a_component_without_tangents_falls_back_to_finite_differences() {
    let (v, b, k, p0) = (1e-4, 1.5e9, 1e-12, 1e7);
    let mut c = Circuit::build(vec![
        Box::new(crate::components::Volume::new("vol", "v", v, b, p0, None)),
        Box::new(Leak {
            node: crate::HydraulicNode::UNBOUND,
            k,
        }),
    ])
    .unwrap();
    assert!(!c.has_jacobian());
    let x0 = c.initial_state();
    let mut jac = vec![0.0; 1];
    assert!(!c.jacobian(0.0, &x0, &mut jac));
    let opts = Options {
        rtol: 1e-8,
        atol: c.atol(1e-8),
        ..Options::default()
    };
    let sol = solve(Method::Rosenbrock, &mut c, 0.0, &x0, 0.1, &opts).unwrap();
    // p = p0 exp(−B k t / V)
    let exact = p0 * (-b * k * 0.1 / v).exp();
    let p = sol.last().unwrap()[0];
    assert!((p - exact).abs() < 1e-6 * exact, "{p} {exact}");
    assert!(sol.stats.rhs_evals > 0);
}

/// Which rig files have an analytic Jacobian: every preset the issue names,
/// and the list printed for the note.
#[test]
fn the_named_rigs_have_an_analytic_jacobian() {
    let mut files: Vec<String> = std::fs::read_dir("../../fixtures/rigs")
        .unwrap()
        .chain(std::fs::read_dir("../../fixtures/rigs/examples").unwrap())
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "json"))
        .map(|p| p.display().to_string())
        .collect();
    files.sort();
    for f in &files {
        let Ok(v) = rig::load(f) else { continue };
        let Ok(c) = rig::circuit(&v, command(f)) else {
            continue;
        };
        let without: Vec<&str> = c
            .components()
            .filter(|k| !k.has_tangents())
            .map(|k| k.name())
            .collect();
        eprintln!("{f}: analytic {} {without:?}", c.has_jacobian());
    }
    for name in COVERED {
        assert!(circuit(name).has_jacobian(), "{name}");
    }
}

/// The friction bench's tangents (`friction_bench` with every term and
/// LuGre's bristle, `piston`, `signal_pressure_source`, `imposed_motion`)
/// against central differences:
/// * the law on a free `mass` whose piston's chambers are `volume`s (so the
///   velocity and the pressures are states and every partial of the law
///   enters the Jacobian), at states on both sides of v = 0, with and
///   without the Stribeck hump;
/// * the bench netlist as a fit runs it (imposed motion, measured
///   pressures): its Jacobian, and the load cell's tangent row with respect
///   to the bristle.
#[test]
fn the_friction_bench_tangents_equal_central_differences() {
    use crate::netlist::{assemble_inputs, schematic};
    use serde_json::json;
    for stiction in [None, Some(32.0)] {
        let mut law = json!({
            "type": "friction_bench", "coulomb": 20.0, "smoothing_velocity": 2e-3,
            "viscous": 150.0, "asymmetry": 3.0, "external_force": 4.0,
            "sigma0": 4e4, "sigma1": 30.0,
            "seal": { "k_pressure": 2e-10, "h_acceleration": 1e8 },
            "stribeck_velocity": 8e-3, "stribeck_exponent": 1.4
        });
        if let Some(fs) = stiction {
            law["stiction"] = json!(fs);
        }
        let v = json!({
            "kind": "netlist", "name": "t",
            "components": {
                "load": { "type": "mass", "mass": 3.0, "initial": { "position": 0.0, "velocity": 0.0 } },
                "c1": { "type": "volume", "volume": 2e-5, "bulk_modulus": 1.2e9 },
                "c2": { "type": "volume", "volume": 1e-5, "bulk_modulus": 1.2e9 },
                "piston": { "type": "piston", "area_1": 1e-3, "area_2": 6e-4 },
                "friction": law
            },
            "connections": [
                ["load.rod", "piston.rod", "friction.rod"],
                ["c1.port", "piston.A", "friction.A"],
                ["c2.port", "piston.B", "friction.B"]
            ]
        });
        let c = crate::netlist::circuit(&v, Signal::Constant { value: 0.0 }).unwrap();
        assert!(c.has_jacobian());
        let names = c.state_names();
        let idx = |n: &str| {
            names
                .iter()
                .position(|s| s == n)
                .unwrap_or_else(|| panic!("{n} not in {names:?}"))
        };
        let (iv, iz, ip1, ip2) = (idx("load.v"), idx("friction.z"), idx("c1.p"), idx("c2.p"));
        let dim = c.dim();
        let scale = c.atol(1.0);
        for (vel, z, p1, p2) in [
            (0.013, 2e-4, 4e5, 1.5e5),
            (-0.006, -3e-4, 2e5, 6e5),
            (0.0004, 1e-5, 3e5, 3e5),
            (-0.05, 4e-4, 8e5, 1e5),
        ] {
            let mut x = c.initial_state();
            x[iv] = vel;
            x[iz] = z;
            x[ip1] = p1;
            x[ip2] = p2;
            let mut jac = vec![0.0; dim * dim];
            assert!(c.jacobian(0.1, &x, &mut jac));
            for j in [iv, iz, ip1, ip2] {
                let h = 1e-6 * x[j].abs().max(scale[j]);
                let col = column(&c, 0.1, &x, j, h);
                for i in 0..c.n_states() {
                    let err = (jac[i * dim + j] - col[i]).abs();
                    assert!(
                        err <= 1e-6 * jac[i * dim + j].abs().max(col[i].abs()) + 1e-9,
                        "Fs {stiction:?}, v {vel}: ∂{}/∂{} analytic {} vs FD {}",
                        names[i],
                        names[j],
                        jac[i * dim + j],
                        col[i]
                    );
                }
            }
        }
    }
    // the bench netlist as a fit runs it: the load cell's row in z
    let v = crate::netlist::migrate::bench::to_netlist(&json!({
        "kind": "friction-bench", "name": "b", "area1": 1e-3, "area2": 4e-4,
        "mass": 2.0, "force_sign": -1.0,
        "friction": { "coulomb": 20.0, "smoothing_velocity": 1e-3, "effects": {
            "stribeck": { "Fs": 30.0, "vs": 0.01, "alpha": 1.0 },
            "lugre_dynamics": { "sigma0": 1e5, "sigma1": 80.0 },
            "pressure_viscous": { "K": 1e-9 },
            "acceleration_friction": { "H": 2e7 }
        } }
    }))
    .unwrap();
    let s = schematic(&v).unwrap();
    let sig = |x: f64| Signal::Constant { value: x };
    let inputs: Vec<_> = crate::netlist::migrate::bench::INPUTS
        .iter()
        .map(|n| n.to_string())
        .zip([sig(0.02), sig(0.3), sig(5e5), sig(1e5)])
        .collect();
    let c = assemble_inputs(&s, &inputs).unwrap();
    assert!(c.has_jacobian());
    let force = c
        .probes()
        .into_iter()
        .find(|p| p.name == "force")
        .unwrap()
        .wire;
    let iz = c
        .state_names()
        .iter()
        .position(|n| n == "friction.z")
        .unwrap();
    let mut x = c.initial_state();
    x[iz] = 1e-4;
    let dim = c.dim();
    let mut jac = vec![0.0; dim * dim];
    assert!(c.jacobian(0.0, &x, &mut jac));
    let col = column(&c, 0.0, &x, iz, 1e-10);
    assert!((jac[iz * dim + iz] - col[iz]).abs() <= 1e-7 * col[iz].abs());
    let read = |z: f64| {
        let mut y = x.clone();
        y[iz] = z;
        let mut out = [0.0];
        c.read_wires(0.0, &y, &[force], &mut out);
        out[0]
    };
    let fd = (read(1e-4 + 1e-10) - read(1e-4 - 1e-10)) / 2e-10;
    let analytic = c.tangents.borrow().row(force.0)[iz];
    assert!(
        (analytic - fd).abs() <= 1e-6 * fd.abs(),
        "∂force/∂z analytic {analytic} vs FD {fd}"
    );
}
