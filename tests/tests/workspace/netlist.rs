//! Circuits as data: the netlist presets reproduce the hand-built rigs, the
//! example circuits (which no rig kind could express) meet closed-form
//! steady states, and bad netlists are refused with the JSON path.

use super::{files, root};
use hydrocyl_ports::{Area, Density, Pressure};
use hydrocyl_system::rig;
use hydrocyl_system::run::{Run, RunOptions, Solver};
use hydrocyl_system::signal::Signal;
use hydrocyl_system::simulation::Simulation;
use hydrocyl_valves::check::CheckValve;
use hydrocyl_valves::orifice::Orifice;
use serde_json::Value;

fn load(rel: &str) -> Value {
    rig::load(root().join(rel).to_str().unwrap()).unwrap_or_else(|e| panic!("{rel}: {e}"))
}

/// The netlist files in `dir`.
fn netlists(dir: &std::path::Path) -> Vec<std::path::PathBuf> {
    files(dir, ".json")
        .into_iter()
        .filter(|f| {
            let v: Value = serde_json::from_str(&std::fs::read_to_string(f).unwrap()).unwrap();
            v["kind"] == "netlist"
        })
        .collect()
}

fn times(t_end: f64, dt: f64) -> Vec<f64> {
    let n = (t_end / dt).round() as usize;
    (0..=n).map(|k| k as f64 * dt).collect()
}

fn square() -> Signal {
    Signal::Square {
        amplitude: 0.2,
        period_s: 1.0,
        bias: 0.0,
    }
}

/// The netlist presets give the very runs of the typed rigs they are read
/// into: the hybrid rig's hand-built component list, and the valve rig read
/// back from its netlist — the same steps and every channel to the last bit.
#[test]
fn netlist_presets_reproduce_the_typed_rigs() {
    use hydrocyl_system::hybrid::WangHybrid;
    use hydrocyl_system::valve_rig::ValveRig;
    let t = times(2.0, 0.01);
    let opts = RunOptions {
        solver: Solver::Rosenbrock,
        ..RunOptions::default()
    };
    let hyb = Signal::Square {
        amplitude: 3.0,
        period_s: 1.0,
        bias: 0.5,
    };
    let net = rig::preset("wang-hybrid").unwrap();
    let typed = WangHybrid::from_value(&net).unwrap();
    assert_eq!(typed, WangHybrid::preset());
    let runs = [
        (
            "wang-hybrid",
            WangHybrid::preset()
                .simulate(hyb.clone(), &t, &opts)
                .unwrap(),
            rig::simulate(&net, hyb, &t, &opts).unwrap(),
        ),
        (
            "leaney-moog",
            ValveRig::leaney_moog()
                .simulate(square(), &t, &opts)
                .unwrap(),
            rig::simulate(&rig::preset("leaney-moog").unwrap(), square(), &t, &opts).unwrap(),
        ),
    ];
    for (name, a, b) in runs {
        assert_eq!(a.stats.steps, b.stats.steps, "{name}");
        assert_eq!(a.channels.len(), b.channels.len(), "{name}");
        for c in &a.channels {
            let other = b
                .channel(&c.name)
                .unwrap_or_else(|| panic!("{name}: no `{}` in the netlist run", c.name));
            assert_eq!(c.values, other, "{name}: channel `{}`", c.name);
        }
    }
}

/// A valve rig written as a netlist reads back as the same rig, in every
/// formulation, spool order, friction law and with lagging sensors; a netlist
/// of another circuit is refused by the typed view, naming what differs.
#[test]
fn valve_rigs_round_trip_through_their_netlists() {
    use hydrocyl_system::valve_rig::{Formulation, ValveRig};
    use hydrocyl_valves::servovalve::SpoolDynamics;
    let base = ValveRig::leaney_moog();
    let mut variants = vec![base.clone()];
    for f in [
        Formulation::GeneralisedAnalytical,
        Formulation::GeneralisedNumerical,
    ] {
        let mut r = base.clone();
        r.cylinder.formulation = f;
        variants.push(r);
    }
    let mut r = base.clone();
    r.valve.dynamics = SpoolDynamics::Second {
        natural_frequency_rad_per_s: 600.0,
        damping_ratio: 0.7,
    };
    r.sensors.pressure_lag_s = 0.002;
    r.initial.p1 = Some(3.0e6);
    r.initial.p2 = Some(4.0e6);
    variants.push(r);
    let c10 = rig::valve_rig_from(&rig::preset("wang-valve-c10").unwrap()).unwrap();
    variants.push(c10);
    for r in variants {
        let v = r.to_netlist().unwrap();
        let mut back = ValveRig::from_netlist(&v).unwrap();
        // written out, the steady initial pressures are explicit numbers
        if r.initial.p1.is_none() && r.cylinder.formulation == Formulation::Fundamental {
            back.initial.p1 = None;
            back.initial.p2 = None;
        }
        assert_eq!(back, r, "{:?}", r.cylinder.formulation);
    }
    let other = load("fixtures/rigs/examples/meter-out-needle.json");
    let err = ValveRig::from_netlist(&other).unwrap_err().to_string();
    assert!(err.contains("components.line_b"), "{err}");
}

/// The parameter paths of a netlist are `<component>.<parameter>` and
/// `<component>.initial.<state>`, listed with units, settable by `--set`:
/// `cylinder.initial.position` on every preset with a cylinder (the seal
/// benches' cylinder under test too), `load.mass` where there is a load,
/// and a bench's drive (which carries the moving mass) under the same scheme.
#[test]
fn one_parameter_path_scheme() {
    let mut cylinders = 0;
    for f in netlists(&root().join("fixtures/rigs")) {
        let mut v = load(f.strip_prefix(root()).unwrap().to_str().unwrap());
        let bench = v["components"]["drive"]["type"] == "imposed_motion";
        let ps = rig::parameters(&v);
        let has = |path: &str| ps.iter().any(|p| p.path == path);
        if bench {
            assert!(
                has("drive.mass") && has("drive.initial.position"),
                "{}",
                f.display()
            );
            rig::apply_set(&mut v, "drive.initial.position=-0.06").unwrap();
            rig::apply_set(&mut v, "drive.mass=2").unwrap();
        } else {
            assert!(
                ps.iter()
                    .any(|p| p.path == "load.mass" && p.unit == Some("kg")),
                "{}",
                f.display()
            );
            rig::apply_set(&mut v, "load.mass=50").unwrap();
        }
        let emps = f.file_name().is_some_and(|n| n == "emps.json");
        assert_eq!(
            has("cylinder.initial.position"),
            !emps,
            "every preset but emps (an electromechanical axis) has a cylinder: {}",
            f.display()
        );
        let start = if emps {
            -0.06
        } else {
            cylinders += 1;
            rig::apply_set(&mut v, "cylinder.initial.position=-0.05").unwrap();
            -0.05
        };
        let run = rig::simulate(
            &v,
            Signal::Constant { value: 0.0 },
            &[0.0, 0.001],
            &RunOptions::dp45(),
        )
        .unwrap();
        assert_eq!(
            run.channel("position").unwrap()[0],
            start,
            "{}",
            f.display()
        );
        if !bench {
            let err = rig::apply_set(&mut v, "load.mass_kg=50")
                .unwrap_err()
                .to_string();
            assert!(
                err.contains("load.mass_kg") && err.contains("mass, external_force"),
                "{err}"
            );
        }
    }
    assert!(cylinders >= 12, "{cylinders}");
}

fn steady_speed(run: &Run, channel: &str, from: f64, to: f64) -> f64 {
    let v = run.channel(channel).unwrap();
    let sel: Vec<f64> = run
        .time
        .iter()
        .zip(v)
        .filter(|(t, _)| **t >= from && **t <= to)
        .map(|(_, v)| *v)
        .collect();
    sel.iter().sum::<f64>() / sel.len() as f64
}

/// Bisection for the root of a function that changes sign on `[lo, hi]`.
fn root_of(f: impl Fn(f64) -> f64, mut lo: f64, mut hi: f64) -> f64 {
    let flo = f(lo);
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if (f(mid) > 0.0) == (flo > 0.0) {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    0.5 * (lo + hi)
}

/// Δp across an orifice of coefficient `k = Cd A √(2/ρ)` passing `q`.
fn dp(q: f64, k: f64) -> f64 {
    (q / k).powi(2)
}

fn k_of(cd: f64, area: f64, rho: f64) -> f64 {
    cd * area * (2.0 / rho).sqrt()
}

/// leaney-moog's valve fully open; `(A1, A2, Ps, k_valve, F(v))`.
fn valve_drive(v: &Value) -> (f64, f64, f64, f64, impl Fn(f64) -> f64) {
    let c = &v["components"];
    let (a1, a2) = (
        c["cylinder"]["area_1"].as_f64().unwrap(),
        c["cylinder"]["area_2"].as_f64().unwrap(),
    );
    let ps = c["supply"]["pressure"].as_f64().unwrap();
    let w = std::f64::consts::PI * c["valve"]["spool_diameter"].as_f64().unwrap();
    let open = c["spool"]["stroke"].as_f64().unwrap() + c["valve"]["underlap"].as_f64().unwrap();
    let k_valve = k_of(
        c["valve"]["orifice"]["cd"].as_f64().unwrap(),
        w * open,
        870.0,
    );
    let fr = c["friction"].clone();
    let friction = move |v: f64| {
        fr["coulomb"].as_f64().unwrap() * (v / fr["smoothing_velocity"].as_f64().unwrap()).tanh()
            + fr["viscous"].as_f64().unwrap() * v
    };
    (a1, a2, ps, k_valve, friction)
}

/// (a) A meter-out needle valve sets the extending speed: with the spool
/// fully open, `p1 = Ps − Δp_PA(A1 v)`, `p2 = Δp_BT(A2 v) + Δp_needle(A2 v)`
/// and `p1 A1 − p2 A2 = F(v)` give one speed, which the run settles to.
#[test]
fn meter_out_needle_sets_the_extending_speed() {
    let v = load("fixtures/rigs/examples/meter-out-needle.json");
    let (a1, a2, ps, kv, friction) = valve_drive(&v);
    let kn = k_of(0.65, 0.5e-6, 870.0);
    let expected = root_of(
        |s| {
            let p1 = ps - dp(a1 * s, kv);
            let p2 = dp(a2 * s, kv) + dp(a2 * s, kn);
            p1 * a1 - p2 * a2 - friction(s)
        },
        0.0,
        1.0,
    );
    let t = times(3.0, 0.005);
    let run = rig::simulate(&v, Signal::Constant { value: 1.0 }, &t, &RunOptions::dp45()).unwrap();
    let got = steady_speed(&run, "velocity", 2.0, 3.0);
    assert!(
        (got - expected).abs() < 2e-3 * expected,
        "steady extending speed {got} m/s, closed form {expected} m/s"
    );
    // without the needle the same drive extends faster: the needle sets it
    let free = root_of(
        |s| (ps - dp(a1 * s, kv)) * a1 - dp(a2 * s, kv) * a2 - friction(s),
        0.0,
        2.0,
    );
    assert!(free > 1.5 * expected, "{free} vs {expected}");
    // retracting, the rod side fills through the bypass check
    let back = rig::simulate(
        &v,
        Signal::Constant { value: -1.0 },
        &times(0.5, 0.005),
        &RunOptions::dp45(),
    )
    .unwrap();
    assert!(back
        .channel("bypass_flow")
        .unwrap()
        .iter()
        .any(|q| *q > 1e-5));
}

/// (b) Two identical cylinders in parallel on one valve move together, each
/// at the speed the closed form gives for the shared valve flow, about half
/// a single cylinder's; the outputs are named per cylinder.
#[test]
fn two_cylinders_in_parallel_share_the_valve_flow() {
    let v = load("fixtures/rigs/examples/two-cylinders-parallel.json");
    let c = &v["components"];
    let (a1, a2) = (
        c["cylinder_1"]["area_1"].as_f64().unwrap(),
        c["cylinder_1"]["area_2"].as_f64().unwrap(),
    );
    let ps = c["supply"]["pressure"].as_f64().unwrap();
    let w = std::f64::consts::PI * c["valve"]["spool_diameter"].as_f64().unwrap();
    let u = 0.3;
    let open =
        u * c["spool"]["stroke"].as_f64().unwrap() + c["valve"]["underlap"].as_f64().unwrap();
    let kv = k_of(0.625, w * open, 870.0);
    let kh = k_of(0.65, 1.0e-5, 870.0);
    let fr = &c["friction_1"];
    let friction = |v: f64| {
        fr["coulomb"].as_f64().unwrap() * (v / fr["smoothing_velocity"].as_f64().unwrap()).tanh()
            + fr["viscous"].as_f64().unwrap() * v
    };
    let speed = |n: f64, hoses: bool| {
        root_of(
            |s| {
                let h = if hoses { 1.0 } else { 0.0 };
                let p1 = ps - dp(n * a1 * s, kv) - h * dp(a1 * s, kh);
                let p2 = dp(n * a2 * s, kv) + h * dp(a2 * s, kh);
                p1 * a1 - p2 * a2 - friction(s)
            },
            0.0,
            2.0,
        )
    };
    let expected = speed(2.0, true);
    let t = times(1.2, 0.005);
    let opts = RunOptions {
        solver: Solver::Rosenbrock,
        rtol: 1e-7,
        ..RunOptions::default()
    };
    let run = rig::simulate(&v, Signal::Constant { value: u }, &t, &opts).unwrap();
    let v1 = steady_speed(&run, "load_1.velocity", 0.8, 1.2);
    let v2 = steady_speed(&run, "load_2.velocity", 0.8, 1.2);
    assert!((v1 - v2).abs() < 1e-9, "{v1} vs {v2}");
    assert!(
        (v1 - expected).abs() < 2e-3 * expected,
        "each {v1} m/s, closed form {expected} m/s"
    );
    let ratio = v1 / speed(1.0, false);
    assert!((0.45..0.55).contains(&ratio), "{ratio}");
}

/// (c) A pump-controlled closed circuit without the pilot-operated valve:
/// extending, the pump's steady flow `K u` less the flushing orifice's bleed
/// fills the cap side, `A1 v = K u − Q_flush(p1)`; the rod side's deficit
/// `K u − A2 v` comes from the tank through its anti-cavitation check, which
/// sets p2 below the tank; and `p1 A1 − p2 A2 = F(v)`.
#[test]
fn pump_closed_circuit_meets_its_steady_state() {
    let v = load("fixtures/rigs/examples/pump-closed-circuit.json");
    let c = &v["components"];
    let (a1, a2) = (
        c["cylinder"]["area_1"].as_f64().unwrap(),
        c["cylinder"]["area_2"].as_f64().unwrap(),
    );
    let q_pump = c["pump"]["gain"].as_f64().unwrap() * 2.0;
    let check: CheckValve = serde_json::from_value(serde_json::json!({
        "cracking": c["check_b"]["cracking"], "opening_range": c["check_b"]["opening_range"], "k_open": c["check_b"]["k_open"]
    }))
    .unwrap();
    let flush = Orifice::new(0.65, Density::new(900.0));
    let fr = &c["friction"];
    let friction = |v: f64| {
        fr["coulomb"].as_f64().unwrap() * (v / fr["smoothing_velocity"].as_f64().unwrap()).tanh()
            + fr["viscous"].as_f64().unwrap() * v
    };
    let p2_of = |s: f64| {
        let deficit = q_pump - a2 * s;
        root_of(
            |p2| check.flow(Pressure::ZERO, Pressure::new(p2)).si() - deficit,
            -1.0e6,
            0.0,
        )
    };
    let expected = root_of(
        |s| {
            let p1 = (friction(s) + p2_of(s) * a2) / a1;
            q_pump
                - flush
                    .flow(Area::new(0.3e-6), Pressure::new(p1), Pressure::ZERO)
                    .si()
                - a1 * s
        },
        1e-6,
        q_pump / a1,
    );
    let t = times(3.0, 0.005);
    let run = rig::simulate(&v, Signal::Constant { value: 2.0 }, &t, &RunOptions::dp45()).unwrap();
    let got = steady_speed(&run, "velocity", 2.0, 3.0);
    assert!(
        (got - expected).abs() < 2e-3 * expected,
        "{got} vs closed form {expected}"
    );
    let p2 = steady_speed(&run, "p2", 2.0, 3.0);
    assert!(
        p2 < 0.0 && (p2 - p2_of(expected)).abs() < 0.02 * p2.abs(),
        "{p2}"
    );
}

/// A bad-netlist case: what, the edit that breaks it, the words the message must hold.
type Case<'a> = (&'a str, &'a dyn Fn(&mut Value), &'a [&'a str]);

/// Bad netlists: one line naming the JSON path and what is wrong.
#[test]
fn bad_netlists_are_refused_by_path() {
    let base = load("fixtures/rigs/leaney-moog.json");
    let cases: &[Case] = &[
        (
            "unknown type",
            &|v| v["components"]["valve"]["type"] = "four_way".into(),
            &["components.valve.type", "unknown component type `four_way`"],
        ),
        (
            "unknown port",
            &|v| v["connections"][4][1] = "cylinder.C".into(),
            &["connections[4][1]", "no port `C`", "A, B, rod"],
        ),
        (
            // named at the element that brings the hydraulic node in, not
            // where that node was first used (`connections[4]`)
            "domain mismatch",
            &|v| v["connections"][6][1] = "valve.A".into(),
            &[
                "rig `connections[6][1]`:",
                "`valve.A` is hydraulic but `cylinder.rod` is mechanical",
                "share a domain",
            ],
        ),
        (
            "two owners",
            &|v| v["connections"][2][1] = "tank.port".into(),
            &[
                "rig `connections[2][1]`:",
                "owned by both",
                "supply.port",
                "tank.port",
            ],
        ),
        (
            // the second owner comes in a later connection than the node's
            // first: named there
            "two owners, the second in a later connection",
            &|v| v["connections"][4][2] = "supply.port".into(),
            &[
                "rig `connections[4][2]`:",
                "owned by both cylinder.A and supply.port",
            ],
        ),
        (
            "dangling port",
            &|v| {
                v["connections"].as_array_mut().unwrap().remove(3);
            },
            &["components.tank", "port `port`", "not connected"],
        ),
        (
            // an orifice between the supply and the valve: the node between
            // two resistive ports has no owner
            "no owner",
            &|v| {
                v["components"]["restrictor"] = serde_json::json!(
                    {"type": "orifice", "area": 1.0e-6, "cd": 0.65, "density": 870.0}
                );
                v["connections"][2] = serde_json::json!(["supply.port", "restrictor.a"]);
                v["connections"]
                    .as_array_mut()
                    .unwrap()
                    .push(serde_json::json!(["restrictor.b", "valve.P"]));
            },
            &[
                "rig `connections[7]`:",
                "the hydraulic node of restrictor.b, valve.P has no owner",
                "algebraic_node",
            ],
        ),
        (
            "out of range",
            &|v| v["components"]["valve"]["orifice"]["cd"] = 1.5.into(),
            &["components.valve.orifice.cd", "(0, 1]"],
        ),
        (
            "unknown parameter",
            &|v| v["components"]["load"]["mass_kg"] = 1.0.into(),
            &["components.load.mass_kg", "no parameter"],
        ),
        (
            "missing parameter",
            &|v| {
                v["components"]["load"]
                    .as_object_mut()
                    .unwrap()
                    .remove("mass");
            },
            &["components.load.mass", "missing"],
        ),
        (
            "a string for a number",
            &|v| v["components"]["load"]["mass"] = "100".into(),
            &["components.load.mass", "a number"],
        ),
        (
            "unknown component in a connection",
            &|v| v["connections"][0][0] = "cmd.out".into(),
            &["connections[0][0]", "no component named `cmd`"],
        ),
        (
            "unknown output",
            &|v| v["outputs"]["p3"] = "cylinder.p3".into(),
            &["outputs.p3", "no output `p3`"],
        ),
        (
            // the piston cannot pass the cylinder's head (stroke 0.52 m)
            "an end stop beyond the stroke",
            &|v| v["components"]["load"]["stop_max"] = 0.5.into(),
            &[
                "components.load.stop_max",
                "beyond the end of the stroke of components.cylinder",
                "0.26 m",
            ],
        ),
        (
            // a second cylinder on the rod whose initial position contradicts
            // the first's
            "two cylinders on one rod starting apart",
            &|v| {
                add_damper(v, 0.52, Some(0.1));
                v["components"]["cylinder"]["initial"]["position"] = 0.0.into();
            },
            &[
                "components.damper.initial.position",
                "differs from components.cylinder.initial.position",
                "give it on one of them",
            ],
        ),
        (
            // the shorter stroke limits the rod, and is the one named
            "an end stop beyond the shorter of two strokes",
            &|v| {
                add_damper(v, 0.3, None);
                v["components"]["load"]["stop_max"] = 0.2.into();
            },
            &[
                "components.load.stop_max",
                "beyond the end of the stroke of components.damper (0.15 m",
            ],
        ),
    ];
    assert_refused(&base, cases);
}

/// A second cylinder `damper` of `stroke` on the rod of `v` (a copy of its
/// `cylinder`), its chambers drained to tank through orifices, starting at
/// `position` if given.
fn add_damper(v: &mut Value, stroke: f64, position: Option<f64>) {
    let mut damper = v["components"]["cylinder"].clone();
    damper["stroke"] = stroke.into();
    damper["initial"] = serde_json::json!({"p1": 0.0, "p2": 0.0});
    if let Some(x) = position {
        damper["initial"]["position"] = x.into();
    }
    v["components"]["damper"] = damper;
    let drain = serde_json::json!(
        {"type": "orifice", "area": 2.0e-6, "cd": 0.65, "density": 870.0}
    );
    v["components"]["drain_a"] = drain.clone();
    v["components"]["drain_b"] = drain;
    let connections = v["connections"].as_array_mut().unwrap();
    for c in connections.iter_mut() {
        let joins = |port: &str| c.as_array().unwrap().iter().any(|e| e == port);
        if joins("cylinder.rod") {
            c.as_array_mut().unwrap().push("damper.rod".into());
        } else if joins("tank.port") {
            c.as_array_mut().unwrap().push("drain_a.b".into());
            c.as_array_mut().unwrap().push("drain_b.b".into());
        }
    }
    connections.push(serde_json::json!(["damper.A", "drain_a.a"]));
    connections.push(serde_json::json!(["damper.B", "drain_b.a"]));
}

/// Each case's edit of `base` is refused with a one-line error holding its words.
fn assert_refused(base: &serde_json::Value, cases: &[Case]) {
    for (what, edit, words) in cases {
        let mut v = base.clone();
        edit(&mut v);
        let err = rig::check(&v)
            .and_then(|_| {
                rig::simulate(&v, square(), &[0.0, 0.01], &RunOptions::dp45()).map(|_| ())
            })
            .expect_err(what)
            .to_string();
        assert!(!err.contains('\n'), "{what}: {err}");
        for w in *words {
            assert!(err.contains(w), "{what}: `{err}` lacks `{w}`");
        }
    }
}

/// A duplicate key in a rig file is refused with its path and line.
#[test]
fn a_duplicate_key_is_refused_with_its_line() {
    let dir = tempfile::tempdir().unwrap();
    let f = dir.path().join("dup.json");
    let text = std::fs::read_to_string(root().join("fixtures/rigs/leaney-moog.json"))
        .unwrap()
        .replacen("\"mass\": 100.0", "\"mass\": 100.0, \"mass\": 50.0", 1);
    std::fs::write(&f, text).unwrap();
    let err = rig::load(f.to_str().unwrap()).unwrap_err().to_string();
    // the shape of every other error: the path alone, then the line and file
    assert!(
        err.starts_with("rig `components.load.mass`: duplicate key")
            && err.ends_with(&format!(" of {})", f.display()))
            && err.contains("(line "),
        "{err}"
    );
}

/// The error of a rig file as the CLI and the Python package print it: read
/// (`rig::load`), checked, assembled, and located (`rig::at_line`).
fn file_error(path: &std::path::Path) -> String {
    let p = path.to_str().unwrap();
    let e = rig::load(p)
        .and_then(|v| rig::check(&v).map(|_| v))
        .and_then(|v| rig::circuit(&v, square()).map(|_| ()))
        .expect_err(p);
    rig::at_line(e, p).to_string()
}

/// Netlist errors in a rig file name the exact JSON path and its line: an
/// algebraic loop (found when the circuit is assembled) at the first
/// component on the cycle, a domain mismatch and a second owner at the
/// connection element that brings them in (a later connection than the
/// node's first), a node with no owner at its connection.
#[test]
fn netlist_errors_name_the_json_path_and_line() {
    // (fixture, edits, the edited text whose first line the error names,
    // the path, words of the message)
    type FileCase<'a> = (&'a str, &'a [(&'a str, &'a str)], &'a str, &'a str, &'a str);
    let cases: &[FileCase] = &[
        (
            "fixtures/rigs/leaney-moog-closed-loop.json",
            &[
                (
                    "\"reference\": {\n      \"type\": \"command_input\"\n    },",
                    "\"ctl2\": {\"type\": \"position_controller\", \"gain\": 10.0}, \"reference\": {\"type\": \"command_input\"},",
                ),
                (
                    "\"reference.out\",\n      \"controller.reference\"",
                    "\"ctl2.command\",\n      \"controller.reference\"",
                ),
                (
                    "\"controller.command\",\n      \"spool.command\"",
                    // the loop in one unit (a set-point [m]); the input drives the spool
                    "\"controller.command\",\n      \"ctl2.reference\"\n    ],\n    [\n      \"reference.out\",\n      \"spool.command\"",
                ),
                (
                    "\"controller.rod\"\n",
                    "\"controller.rod\",\n      \"ctl2.rod\"\n",
                ),
                ("\"reference\": \"reference.command\",\n", ""),
            ],
            "\"ctl2\": {",
            "components.ctl2",
            "algebraic loop between components ctl2, controller: put a volume or a mass between them",
        ),
        (
            "fixtures/rigs/leaney-moog.json",
            &[(
                "\"cylinder.rod\",\n      \"load.rod\"",
                "\"cylinder.rod\",\n      \"valve.A\"",
            )],
            "\"valve.A\",\n      \"friction.rod\"",
            "connections[6][1]",
            "`valve.A` is hydraulic but `cylinder.rod` is mechanical: connected ports share a domain",
        ),
        (
            "fixtures/rigs/leaney-moog.json",
            &[(
                "\"cylinder.A\",\n      \"friction.A\"",
                "\"cylinder.A\",\n      \"supply.port\"",
            )],
            "\"supply.port\"\n",
            "connections[4][2]",
            "the hydraulic node is owned by both cylinder.A and supply.port: a node has exactly one owner",
        ),
        (
            "fixtures/rigs/leaney-moog.json",
            &[
                (
                    "\"supply.port\",\n      \"valve.P\"",
                    "\"supply.port\",\n      \"restrictor.a\"\n    ],\n    [\n      \"restrictor.b\",\n      \"valve.P\"",
                ),
                (
                    "\"components\": {",
                    "\"components\": {\n    \"restrictor\": {\"type\": \"orifice\", \"area\": 1.0e-6, \"cd\": 0.65, \"density\": 870.0},",
                ),
            ],
            "[\n      \"restrictor.b\"",
            "connections[3]",
            "the hydraulic node of restrictor.b, valve.P has no owner",
        ),
    ];
    let dir = tempfile::tempdir().unwrap();
    for (k, (fixture, edits, at, path, why)) in cases.iter().enumerate() {
        let mut text = std::fs::read_to_string(root().join(fixture)).unwrap();
        for (a, b) in *edits {
            assert!(text.contains(a), "{fixture} has no `{a}`");
            text = text.replacen(a, b, 1);
        }
        let line = text[..text.find(at).expect(at)].matches('\n').count() + 1;
        let f = dir.path().join(format!("bad{k}.json"));
        std::fs::write(&f, &text).unwrap();
        let err = file_error(&f);
        let head = format!("rig `{path}`: {why}");
        let tail = format!("(line {line} of {})", f.display());
        assert!(
            err.starts_with(&head) && err.ends_with(&tail) && !err.contains('\n'),
            "`{err}`: expected `{head} … {tail}`"
        );
    }
}

/// The probes each component type declares are the ones its components
/// publish: every netlist fixture, run without an `outputs` list, gives one
/// column per declared probe, named `<component>.<probe>`.
#[test]
fn declared_probes_are_the_published_ones() {
    use hydrocyl_system::netlist::registry;
    let mut dirs = netlists(&root().join("fixtures/rigs"));
    dirs.extend(netlists(&root().join("fixtures/rigs/examples")));
    for f in dirs {
        let mut v = load(f.strip_prefix(root()).unwrap().to_str().unwrap());
        v.as_object_mut().unwrap().remove("outputs");
        let run = rig::simulate(
            &v,
            Signal::Constant { value: 0.0 },
            &[0.0, 1e-4],
            &RunOptions::dp45(),
        )
        .unwrap_or_else(|e| panic!("{}: {e}", f.display()));
        let mut want: Vec<String> = Vec::new();
        for (name, c) in v["components"].as_object().unwrap() {
            let t = registry::lookup(c["type"].as_str().unwrap()).unwrap();
            want.extend(t.probes.iter().map(|(p, _)| format!("{name}.{p}")));
        }
        let mut got: Vec<String> = run.channels.iter().map(|c| c.name.clone()).collect();
        want.sort();
        got.sort();
        assert_eq!(got, want, "{}", f.display());
    }
}

/// docs/components.md is the registry's catalog (regenerate it with
/// `hydrocyl components > docs/components.md` after the header).
#[test]
fn the_component_docs_are_the_registry() {
    let doc = std::fs::read_to_string(root().join("docs/components.md")).unwrap();
    let catalog = hydrocyl_system::netlist::registry::catalog_markdown();
    assert!(
        doc.ends_with(&catalog),
        "docs/components.md is out of date: regenerate its catalog with `hydrocyl components`"
    );
}

/// Every netlist gets an energy ledger that closes without bookkeeping of
/// its own: each component's power terms, integrated with the run, balance
/// — energy in = dissipated + stored + delivered to the load. The
/// generalised one-pressure cylinder is the exception: its single load
/// pressure stands for two chambers, and its power terms leave ~0.2 % of
/// the energy in unaccounted (measured here, not a target; the energy
/// studies use the two-chamber form).
#[test]
fn every_netlist_ledger_closes() {
    use hydrocyl_system::circuit::LEDGER_TERMS;
    let mut all = netlists(&root().join("fixtures/rigs"));
    all.extend(netlists(&root().join("fixtures/rigs/examples")));
    for f in all {
        let v = load(f.strip_prefix(root()).unwrap().to_str().unwrap());
        let pump = v["components"]["pump"].is_object();
        let cmd = Signal::Square {
            amplitude: if pump { 2.0 } else { 0.5 },
            period_s: 0.5,
            bias: 0.0,
        };
        let opts = RunOptions {
            solver: Solver::Rosenbrock,
            rtol: 1e-8,
            ledger: true,
            ..RunOptions::default()
        };
        let mut sim = Simulation::new(&v, cmd).unwrap().options(opts);
        let run = sim
            .run(&times(1.0, 0.01))
            .unwrap_or_else(|e| panic!("{}: {e}", f.display()));
        let c = sim.circuit();
        let last = run.state(run.time.len() - 1);
        let off = c.ledger_offset();
        let (mut e_in, mut residual) = (0.0, 0.0);
        for i in 0..c.components().count() {
            let k = off + LEDGER_TERMS * i;
            e_in += last[k];
            residual += last[k] - last[k + 1] - last[k + 2] - last[k + 3];
        }
        assert!(e_in > 0.0, "{}", f.display());
        let generalised = v["components"]
            .as_object()
            .unwrap()
            .values()
            .any(|c| c["type"] == "generalised_cylinder");
        // an algebraic node's pressure is solved to 1e-14 of the pressure
        // scale, so its inflows sum to zero only to that (times the members'
        // flow slopes): the node books that mismatch times its pressure
        let algebraic = v["components"]
            .as_object()
            .unwrap()
            .values()
            .any(|c| c["type"] == "algebraic_node");
        let tol = if generalised {
            5e-3
        } else if algebraic {
            1e-8
        } else {
            1e-9
        };
        assert!(
            residual.abs() < tol * e_in,
            "{}: ledger residual {residual} J of {e_in} J in",
            f.display()
        );
    }
}

/// An algebraic node (two resistive components in series, no volume) is
/// legal; the wiring mistakes around one are refused naming the JSON path:
/// a node between resistive components with no algebraic node (no owner),
/// an algebraic node on a node a volume owns (two owners), and one with a
/// single neighbour (nothing to balance).
#[test]
fn algebraic_node_errors_name_the_json_path() {
    let base = load("fixtures/rigs/wang-hybrid.json");
    let group = |v: &serde_json::Value| {
        v["connections"]
            .as_array()
            .unwrap()
            .iter()
            .position(|c| c[0] == "return_port")
            .unwrap()
    };
    let cases: &[Case] = &[
        (
            "no owner",
            &|v| {
                let g = group(v);
                v["connections"][g].as_array_mut().unwrap().remove(1);
                v["components"]
                    .as_object_mut()
                    .unwrap()
                    .remove("return_port");
            },
            &[
                "connections[6]",
                "needle_valve.inlet",
                "no owner",
                "algebraic_node",
            ],
        ),
        (
            "two owners",
            &|v| {
                let g = group(v);
                v["connections"][g]
                    .as_array_mut()
                    .unwrap()
                    .push("hose.port".into());
                v["components"]["hose"] = serde_json::json!(
                    {"type": "volume", "volume": 1e-6, "bulk_modulus": 1e9}
                );
            },
            &[
                "connections[6]",
                "owned by both",
                "return_port.node",
                "hose.port",
            ],
        ),
        (
            "one neighbour",
            &|v| {
                let g = group(v);
                let c = v["connections"][g].as_array_mut().unwrap();
                c.retain(|e| e != "needle_valve.inlet");
                let t = v["connections"]
                    .as_array()
                    .unwrap()
                    .iter()
                    .position(|c| c[0] == "tank")
                    .unwrap();
                let c = v["connections"][t].as_array_mut().unwrap();
                c.push("needle_valve.inlet".into());
            },
            &["components.return_port", "at least two"],
        ),
    ];
    assert_refused(&base, cases);
}

/// The hybrid drive's chapter-9 variants (netlists `wang-hybrid-*.json`,
/// open loop) load through `rig::load` (any working directory), check, and
/// run through the one run path; the solenoid variants have the
/// `solenoid_four_way` valve and neither relief valves 1 and 2 nor the pilot
/// valve.
#[test]
fn variant_files_run_through_the_rig_facade() {
    let dir = root().join("fixtures/rigs");
    let t = times(0.5, 0.01);
    let cmd = || {
        Signal::table(
            t.clone(),
            t.iter()
                .map(|&x| if x < 0.25 { 2.0 } else { -2.0 })
                .collect(),
        )
        .unwrap()
    };
    let mut found = 0;
    for f in files(&dir, ".json") {
        let v = rig::load(f.to_str().unwrap()).unwrap();
        let stem = f.file_stem().unwrap().to_string_lossy().to_string();
        if !stem.starts_with("wang-hybrid-") || stem.ends_with("closed-loop") {
            continue;
        }
        found += 1;
        rig::check(&v).unwrap_or_else(|e| panic!("{}: {e}", f.display()));
        let c = rig::circuit(&v, cmd()).unwrap();
        let names: Vec<&str> = c.components().map(|c| c.name()).collect();
        if v["components"]["four_way"]["type"] == "solenoid_four_way" {
            assert!(
                !names.contains(&"relief_1") && !names.contains(&"pilot_valve"),
                "{names:?}"
            );
        }
        let run = rig::simulate(&v, cmd(), &t, &RunOptions::default())
            .unwrap_or_else(|e| panic!("{}: {e}", f.display()));
        assert!(run
            .channel("position")
            .unwrap()
            .iter()
            .all(|x| x.is_finite()));
    }
    assert_eq!(found, 4);
}

/// A parameter spelled flat in the file (`"orifice.cd": 0.625` instead of
/// `"orifice": {"cd": 0.625}`) stays given once: `--print-rig`'s netlist
/// reads back, and `--set` changes it where it is.
#[test]
fn a_flat_spelled_parameter_prints_and_sets_where_it_is() {
    let mut v = load("fixtures/rigs/leaney-moog.json");
    let valve = v["components"]["valve"].as_object_mut().unwrap();
    let cd = valve["orifice"]
        .as_object_mut()
        .unwrap()
        .remove("cd")
        .unwrap();
    valve.insert("orifice.cd".into(), cd);
    rig::check(&v).unwrap();
    let shown = hydrocyl_system::netlist::expanded(&v).unwrap();
    rig::check(&shown).unwrap();
    assert_eq!(shown["components"]["valve"]["orifice.cd"], 0.625);
    assert!(shown["components"]["valve"]["orifice"].get("cd").is_none());
    rig::apply_set(&mut v, "valve.orifice.cd=0.6").unwrap();
    rig::check(&v).unwrap();
    assert_eq!(v["components"]["valve"]["orifice.cd"], 0.6);
    let p = rig::parameters(&v);
    let cd = p.iter().find(|p| p.path == "valve.orifice.cd").unwrap();
    assert_eq!(cd.value, Some(0.6));
}

/// A chamber pressure is known by the probe it reads, whatever its column
/// is called: a second cylinder drained through orifices, its `p1` shown as
/// `pd1`, is pulled far below vacuum by the first, and the run says so
/// (`Run::deep_cavitation`, `Run::min_chamber_pressure`) naming the damper.
#[test]
fn a_renamed_chamber_pressure_is_still_a_chamber_pressure() {
    let mut v = load("fixtures/rigs/leaney-moog.json");
    add_damper(&mut v, 0.52, None);
    v["outputs"]["pd1"] = "damper.p1".into();
    let t: Vec<f64> = (0..=300).map(|k| k as f64 * 1e-3).collect();
    let run = rig::simulate(
        &v,
        Signal::Constant { value: 0.5 },
        &t,
        &RunOptions::default(),
    )
    .unwrap();
    let pd1 = run.channels.iter().find(|c| c.name == "pd1").unwrap();
    assert_eq!(pd1.probe, "damper.p1");
    assert!(
        run.min_chamber_pressure() < -1e6,
        "{}",
        run.min_chamber_pressure()
    );
    assert_eq!(run.unphysical(), None);
    let d = run.deep_cavitation().expect("a chamber far below vacuum");
    assert_eq!(d.lowest.cylinder, "damper");
    assert!(
        d.what().starts_with("pd1 of `damper` fell below"),
        "{}",
        d.what()
    );
}
