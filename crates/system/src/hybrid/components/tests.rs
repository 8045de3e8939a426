//! Tests of the hybrid rig's components: the series return path.
use super::*;
use crate::components::PressureSource;
use crate::series::AlgebraicNode;
use crate::Circuit;
use hydrocyl_valves::pilot_valve::{series_coefficient, PilotFourWay};

/// chamber ══[ pilot valve ]══ T (solved) ══[ needle ]══ tank, pilot fully shifted
fn series(p_chamber: f64) -> Circuit {
    let src = |n: &str, node: &str, p: f64| -> Box<dyn Component> {
        Box::new(PressureSource::new(n, node, Pressure::new(p), None))
    };
    Circuit::build(vec![
        src("l1", "l1", 30.0e5),
        src("l2", "l2", 0.0),
        src("a", "a", 0.0),
        src("b", "b", p_chamber),
        src("tank", "tank", 0.0),
        Box::new(PilotValve::new(
            "pilot",
            PilotFourWay::dddc(),
            PilotNodes {
                pilot_1: "l1",
                pilot_2: "l2",
                a: "a",
                b: "b",
                t: "t",
            },
        )),
        Box::new(NeedleComponent::new(
            "needle",
            NeedleValve::nccc(),
            "t",
            "tank",
        )),
        Box::new(AlgebraicNode::new("t_port", "t", Some("p_t"))),
    ])
    .unwrap()
}

#[test]
fn forward_series_flow_matches_the_series_coefficient() {
    let c = series(5.0e5);
    let w = c.wires_at(0.0, &[]);
    let pt = w.get(c.find_wire("hyd:t:p").unwrap());
    let fw = PilotFourWay::dddc();
    let y = fw.opening(Pressure::new(30.0e5), Pressure::ZERO);
    let (k_fw, k_n) = (fw.return_coefficient(y), NeedleValve::nccc().coefficient());
    // two square-root orifices in series: Q = k √Δp with 1/k² = 1/k1² + 1/k2²
    let q = series_coefficient(k_fw, k_n) * 5.0e5_f64.sqrt();
    let q_needle = NeedleValve::nccc()
        .flow(Pressure::new(pt), Pressure::ZERO)
        .si();
    assert!((q_needle - q).abs() < 1e-10 * q, "{q_needle} {q}");
    // the flows into the T node balance: what reaches the tank left chamber B
    let q_tank = w.get(c.find_wire("hyd:tank:q").unwrap());
    let q_b = -w.get(c.find_wire("hyd:b:q").unwrap());
    assert!((q_tank - q_b).abs() < 1e-12 * q, "{q_tank} {q_b}");
    let d = c.diagnostics();
    let solves = d.iter().find(|(k, _)| k == "t_port.solves").unwrap().1;
    assert!(solves >= 1.0);
}

#[test]
fn reverse_flow_through_the_open_check_balances_at_the_node() {
    let c = series(-0.9e5);
    let w = c.wires_at(0.0, &[]);
    let pt = w.get(c.find_wire("hyd:t:p").unwrap());
    assert!(pt > -0.9e5 && pt < 0.0, "{pt}");
    let n = NeedleValve::nccc();
    let q = n.flow(Pressure::new(pt), Pressure::ZERO).si();
    // the reverse check opened: more backflow than the needle alone would pass
    assert!(q < n.metered_flow(Pressure::new(pt), Pressure::ZERO).si());
    let q_b = w.get(c.find_wire("hyd:b:q").unwrap());
    assert!((q_b + q).abs() < 1e-9 * q.abs(), "{q_b} {q}");
}

#[test]
fn an_algebraic_node_needs_two_resistive_neighbours() {
    let e = Circuit::build(vec![
        Box::new(PressureSource::new("tank", "tank", Pressure::ZERO, None)),
        Box::new(NeedleComponent::new(
            "needle",
            NeedleValve::nccc(),
            "t",
            "tank",
        )),
        Box::new(AlgebraicNode::new("t_port", "t", None)),
    ])
    .unwrap_err();
    assert!(e.to_string().contains("at least two"), "{e}");
}
