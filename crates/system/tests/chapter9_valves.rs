//! The chapter-9 valve components against closed forms: the solenoid
//! four-way valve (`solenoid_four_way`: the spool's first-order shift
//! `s = 1 − e^{−t/τ}`, each path's orifice flow through the power it
//! dissipates, the closed centre) and the servo needle valve
//! (`servo_needle_valve`: the opening law and its orifice flow).

use hydrocyl_system::rig;
use hydrocyl_system::run::RunOptions;
use hydrocyl_system::signal::Signal;
use serde_json::{json, Value};

const CD: f64 = 0.65;
const RHO: f64 = 900.0;

/// `Q = Cd A √(2 Δp / ρ)` for Δp well above the regularisation.
fn q(area: f64, dp: f64) -> f64 {
    CD * area * (2.0 * dp / RHO).sqrt()
}

fn source(p: f64) -> Value {
    json!({"type": "pressure_source", "pressure": p})
}

/// P1, P2, A, B and T held at fixed pressures around the valve.
fn solenoid_rig(p: [f64; 5], tau: f64) -> Value {
    json!({
        "kind": "netlist", "name": "solenoid-test", "description": "closed-form test",
        "components": {
            "command": {"type": "command_input"},
            "p1": source(p[0]), "p2": source(p[1]), "a": source(p[2]), "b": source(p[3]), "t": source(p[4]),
            "valve": {"type": "solenoid_four_way", "area_supply": 2e-6, "area_return": 3e-6,
                      "threshold": 0.1, "time_constant": tau,
                      "orifice": {"cd": CD, "density": RHO, "dp_transition": 1000.0}}
        },
        "connections": [
            ["u", "command.out", "valve.command"],
            ["n1", "p1.port", "valve.P1"], ["n2", "p2.port", "valve.P2"],
            ["na", "a.port", "valve.A"], ["nb", "b.port", "valve.B"], ["nt", "t.port", "valve.T"]
        ],
        "outputs": {"spool": "valve.spool"}
    })
}

#[test]
fn solenoid_spool_shifts_first_order_and_each_path_is_an_orifice() {
    let p = [60e5, 50e5, 20e5, 10e5, 0.0];
    let tau = 0.01;
    let t: Vec<f64> = (0..=50).map(|k| k as f64 * 1e-3).collect();
    for (u, sign) in [(2.0, 1.0), (-2.0, -1.0), (0.05, 0.0)] {
        let v = solenoid_rig(p, tau);
        let cmd = Signal::Constant { value: u };
        let run = rig::simulate(
            &v,
            cmd.clone(),
            &t,
            &RunOptions {
                rtol: 1e-9,
                ..RunOptions::default()
            },
        )
        .unwrap();
        let s = run.channel("spool").unwrap();
        let c = rig::circuit(&v, cmd).unwrap();
        let i = c.component_index("valve").unwrap();
        for (k, &tk) in t.iter().enumerate() {
            let want = sign * (1.0 - (-tk / tau).exp());
            assert!(
                (s[k] - want).abs() < 1e-6,
                "u {u} t {tk}: {} vs {want}",
                s[k]
            );
            // power dissipated = Σ Δp Q over the open paths at this spool
            let pw = c.power_terms(tk, run.state(k))[i].dissipated;
            let f = s[k].abs();
            let want_p = if sign > 0.0 {
                (p[0] - p[2]) * q(2e-6 * f, p[0] - p[2]) + (p[3] - p[4]) * q(3e-6 * f, p[3] - p[4])
            } else {
                (p[1] - p[3]) * q(2e-6 * f, p[1] - p[3]) + (p[2] - p[4]) * q(3e-6 * f, p[2] - p[4])
            };
            assert!(
                (pw - want_p).abs() <= 1e-9 * want_p.abs().max(1.0),
                "u {u} t {tk}: {pw} vs {want_p}"
            );
        }
        if sign == 0.0 {
            // below the threshold no solenoid is energised: closed centre
            assert!(s.iter().all(|&x| x == 0.0));
        }
    }
}

#[test]
fn servo_needle_opening_follows_the_command() {
    let (a0, amax, gp, gn) = (1e-6, 1e-5, 2e-6, 3e-6);
    let (p_in, p_out) = (8e5, 0.0);
    for (u, want_a) in [
        (1.0, a0 + gp),
        (-2.0, a0 + 2.0 * gn),
        (0.0, a0),
        (10.0, amax),
    ] {
        let v = json!({
            "kind": "netlist", "name": "servo-needle-test", "description": "closed-form test",
            "components": {
                "command": {"type": "command_input"},
                "inlet": source(p_in), "outlet": source(p_out),
                "needle": {"type": "servo_needle_valve", "area_min": a0, "area_max": amax,
                           "gain_positive": gp, "gain_negative": gn, "effective_factor": 0.8,
                           "orifice": {"cd": CD, "density": RHO, "dp_transition": 1000.0},
                           "reverse_check": {"cracking": 35000.0, "opening_range": 50000.0, "k_open": 9.19e-7}}
            },
            "connections": [
                ["u", "command.out", "needle.command"],
                ["i", "inlet.port", "needle.inlet"], ["o", "outlet.port", "needle.outlet"]
            ],
            "outputs": {"opening": "needle.opening"}
        });
        // no states: the circuit is evaluated directly
        let c = rig::circuit(&v, Signal::Constant { value: u }).unwrap();
        let probe = c
            .probes()
            .into_iter()
            .find(|p| p.name.ends_with("opening"))
            .unwrap();
        let mut a = [0.0];
        c.read_wires(0.01, &[], &[probe.wire], &mut a);
        assert!((a[0] - want_a).abs() < 1e-15, "u {u}: {} vs {want_a}", a[0]);
        let i = c.component_index("needle").unwrap();
        let pw = c.power_terms(0.01, &[])[i].dissipated;
        // the needle meters through 0.8 of its opening (eq 6.14)
        let want_p = p_in * q(0.8 * want_a, p_in - p_out);
        assert!(
            (pw - want_p).abs() < 1e-9 * want_p,
            "u {u}: {pw} vs {want_p}"
        );
    }
}
