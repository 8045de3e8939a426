//! The series solve's tests: the evaluation order, the member Newton solve
//! and its fallbacks, on circuits with two resistive members.

use super::*;
use crate::components::{FixedOrifice, PressureSource, Volume};
use crate::wires::Wire;
use crate::Circuit;
use hydrocyl_integrators::{solve, Method, Options};
use hydrocyl_ports::{Area, Density};
use hydrocyl_valves::orifice::Orifice;

#[test]
fn a_loop_error_names_the_cycle_and_not_what_hangs_off_it() {
    // 0 ⇄ 1 is the cycle; 2 reads 0, 3 reads 2: neither is on it
    let deps: [&[usize]; 4] = [&[1], &[0], &[0], &[2]];
    let left = kahn(&[0, 1, 2, 3], |i| deps[i].iter().copied()).unwrap_err();
    assert_eq!(left, vec![0, 1]);
    // a chain without a cycle orders
    let chain: [&[usize]; 3] = [&[], &[0], &[1]];
    assert_eq!(
        kahn(&[2, 1, 0], |i| chain[i].iter().copied()),
        Ok(vec![0, 1, 2])
    );
}

fn orifice() -> Orifice {
    Orifice::new(0.65, Density::new(870.0))
}

/// supply ──[A1]── m (algebraic) ──[A2]── `to`
fn two_in_series(to: Box<dyn Component>) -> Vec<Box<dyn Component>> {
    vec![
        Box::new(PressureSource::new(
            "supply",
            "P",
            Pressure::from_bar(70.0),
            None,
        )),
        Box::new(FixedOrifice::new(
            "o1",
            "P",
            "M",
            Area::from_mm2(0.2),
            orifice(),
        )),
        Box::new(FixedOrifice::new(
            "o2",
            "M",
            "L",
            Area::from_mm2(0.1),
            orifice(),
        )),
        Box::new(AlgebraicNode::new("m", "M", Some("pm"))),
        to,
    ]
}

fn diag(c: &Circuit, k: &str) -> f64 {
    c.diagnostics().iter().find(|(n, _)| n == k).unwrap().1
}

#[test]
fn two_orifices_in_series_pass_the_series_area_flow() {
    let c = Circuit::build(two_in_series(Box::new(PressureSource::new(
        "tank",
        "L",
        Pressure::ZERO,
        None,
    ))))
    .unwrap();
    let w = c.wires_at(0.0, &[]);
    // 1/A² = 1/A1² + 1/A2²: Q = Cd A √(2 Ps/ρ), p_m = Ps A²/A2²
    let (a1, a2) = (0.2e-6_f64, 0.1e-6_f64);
    let a = 1.0 / (1.0 / (a1 * a1) + 1.0 / (a2 * a2)).sqrt();
    let q = 0.65 * a * (2.0 * 7.0e6 / 870.0_f64).sqrt();
    let q_tank = w.get(c.find_wire("hyd:L:q").unwrap());
    assert!((q_tank - q).abs() < 1e-10 * q, "{q_tank} {q}");
    let pm = w.get(c.find_wire("hyd:M:p").unwrap());
    let pm_exact = 7.0e6 * (a * a) / (a2 * a2);
    assert!((pm - pm_exact).abs() < 1e-9 * pm_exact, "{pm} {pm_exact}");
    assert_eq!(c.probes().iter().filter(|p| p.name == "pm").count(), 1);
    // Newton on the orifices' slopes, no fallback
    assert_eq!(diag(&c, "m.solve_fallbacks"), 0.0);
}

#[test]
fn a_volume_fills_through_two_orifices_in_series() {
    // the algebraic node inside an ODE: the volume reaches supply pressure
    let mut c = Circuit::build(two_in_series(Box::new(Volume::new(
        "vol", "L", 1e-5, 7e8, 0.0, None,
    ))))
    .unwrap();
    let x0 = c.initial_state();
    c.reset(0.0, &x0);
    let opts = Options {
        atol: c.atol(1e-8),
        rtol: 1e-8,
        ..Options::default()
    };
    let sol = solve(Method::DormandPrince45, &mut c, 0.0, &x0, 1.0, &opts).unwrap();
    let p = sol.last().unwrap()[0];
    assert!((p - 7.0e6).abs() < 1e3, "{p}");
    // two fixed orifices declare their laws: each solve evaluates the
    // members once, at the root found on the laws
    assert!(diag(&c, "m.solves") > 100.0);
    assert_eq!(diag(&c, "m.solve_evaluations"), diag(&c, "m.solves"));
    assert_eq!(diag(&c, "m.solve_fallbacks"), 0.0);
}

/// An orifice member that breaks the members' contract: it counts its
/// evaluations in a wire of its own (a value written from its previous
/// value).
#[derive(Debug)]
struct CountingOrifice {
    orifice: FixedOrifice,
    count: Wire<f64>,
}

impl Component for CountingOrifice {
    fn name(&self) -> &str {
        "counting"
    }
    fn bind(&mut self, net: &mut Netlist) -> Result<(), BuildError> {
        self.orifice.bind(net)?;
        self.count = net.private("count");
        Ok(())
    }
    fn evaluate(&self, t: f64, x: &[f64], w: &mut Wires) {
        self.orifice.evaluate(t, x, w);
        let n = w.get(self.count);
        w.set(self.count, n + 1.0);
    }
    fn inflow_slope(&self, t: f64, x: &[f64], w: &Wires, node: Wire<Pressure>) -> Option<f64> {
        self.orifice.inflow_slope(t, x, w, node)
    }
}

#[test]
#[cfg(debug_assertions)]
#[should_panic(expected = "differently after other trials")]
fn debug_builds_catch_a_member_writing_from_its_previous_value() {
    let mut parts = two_in_series(Box::new(PressureSource::new(
        "tank",
        "L",
        Pressure::ZERO,
        None,
    )));
    parts[2] = Box::new(CountingOrifice {
        orifice: FixedOrifice::new("o2", "M", "L", Area::from_mm2(0.1), orifice()),
        count: Wire::UNBOUND,
    });
    let c = Circuit::build(parts).unwrap();
    c.wires_at(0.0, &[]);
}

#[test]
fn a_node_without_an_owner_is_still_an_error() {
    let mut parts = two_in_series(Box::new(PressureSource::new(
        "tank",
        "L",
        Pressure::ZERO,
        None,
    )));
    parts.remove(3); // the AlgebraicNode
    let e = Circuit::build(parts).unwrap_err();
    assert!(matches!(e, BuildError::NoOwner { .. }), "{e}");
    assert!(e.to_string().contains("`M`"), "{e}");
}

#[test]
fn a_stale_warm_slope_does_not_accept_an_unconverged_root() {
    // root at 1, slope −1e-3; the last solve's slope was 1e6 times
    // steeper: its step from 1 + 1e-9 looks converged, the true one not
    let mut f = |p: f64, _: &mut Wires| -1e-3 * (p - 1.0);
    let slope = |_: &Wires| Some(-1e-3);
    let mut w = Wires::default();
    let tol = 1e-12;
    let (p, s) = newton(&mut f, &slope, &mut w, 1.0 + 1e-9, (0.0, 2.0), tol, -1e3).unwrap();
    assert!((p - 1.0).abs() <= tol, "{p}");
    assert!((s + 1e-3).abs() < 1e-9, "{s}");
    // a usable warm slope still converges in one residual when it is right
    let mut calls = 0;
    let mut g = |p: f64, _: &mut Wires| {
        calls += 1;
        -1e-3 * (p - 1.0)
    };
    let (p, _) = newton(&mut g, &slope, &mut w, 1.0 + 1e-13, (0.0, 2.0), tol, -1e-3).unwrap();
    assert!((p - 1.0).abs() <= tol && calls == 1, "{p} {calls}");
}

#[test]
fn the_bend_near_a_small_pressure_drop_takes_few_residuals() {
    // two square-root laws in series, the downstream one far more open:
    // the root p = (k1² p1 + k2² p2)/(k1² + k2²) lies ~2 Pa above p2,
    // where √(p − p2) bends sharply. The start is 40 % too high, the warm
    // slope the one at the root (stale where the solve starts), and there
    // is no analytic slope: secant steps, and from the third trial on
    // inverse quadratic interpolation, which crosses the bend (the secant
    // alone takes 6 residuals)
    let (k1, k2, p1, p2) = (1.0e-8_f64, 1.0e-6_f64, 2.0e4_f64, 0.0_f64);
    let root = (k1 * k1 * p1 + k2 * k2 * p2) / (k1 * k1 + k2 * k2);
    let calls = Cell::new(0);
    let mut f = |p: f64, _: &mut Wires| {
        calls.set(calls.get() + 1);
        k1 * (p1 - p).sqrt() - k2 * (p - p2).sqrt()
    };
    let slope = |_: &Wires| None;
    let warm = -0.5 * k1 / (p1 - root).sqrt() - 0.5 * k2 / (root - p2).sqrt();
    let tol = SERIES_RTOL * 1e5;
    let mut w = Wires::default();
    let (p, _) = newton(&mut f, &slope, &mut w, 1.4 * root, (p2, p1), tol, warm).unwrap();
    assert!((p - root).abs() <= tol, "{p} {root}");
    assert!(calls.get() <= 4, "{} residuals", calls.get());
}

#[test]
fn brent_finds_the_root_of_a_falling_function() {
    let r = hydrocyl_xfactor::brent(|p| 2.0 - p * p, 0.0, 2.0, 1e-14)
        .unwrap()
        .x;
    assert!((r - 2.0_f64.sqrt()).abs() < 1e-13, "{r}");
}
