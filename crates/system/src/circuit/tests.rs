//! Tests of the assembler core.
use super::*;
use crate::components::{FixedOrifice, PressureSource, Volume};
use hydrocyl_integrators::{solve, Method, Options};
use hydrocyl_ports::{Area, Density, Pressure};
use hydrocyl_valves::orifice::Orifice;

/// A test component that writes signal `out` algebraically from signal `inp`.
struct Gain {
    name: String,
    inp: String,
    out: String,
    w: (Wire<f64>, Wire<f64>),
}

impl Component for Gain {
    fn name(&self) -> &str {
        &self.name
    }
    fn bind(&mut self, net: &mut Netlist) -> Result<(), BuildError> {
        self.w = (
            net.signal(&self.inp),
            net.own_signal(&self.out, Causality::Algebraic)?,
        );
        Ok(())
    }
    fn evaluate(&self, _t: f64, _x: &[f64], w: &mut Wires) {
        w.set(self.w.1, 2.0 * w.get(self.w.0));
    }
}

fn gain(name: &str, inp: &str, out: &str) -> Box<dyn Component> {
    Box::new(Gain {
        name: name.into(),
        inp: inp.into(),
        out: out.into(),
        w: (Wire::UNBOUND, Wire::UNBOUND),
    })
}

fn orifice() -> Orifice {
    Orifice::new(0.65, Density::new(870.0))
}

#[test]
fn causality_errors_name_components_and_nodes() {
    let two = Circuit::build(vec![
        Box::new(PressureSource::new(
            "supply",
            "P",
            Pressure::from_bar(70.0),
            None,
        )),
        Box::new(Volume::new("line", "P", 1e-4, 7e8, 0.0, None)),
    ])
    .unwrap_err();
    assert!(matches!(two, BuildError::TwoOwners { .. }));
    assert!(
        two.to_string().contains("`P`")
            && two.to_string().contains("supply")
            && two.to_string().contains("line")
    );

    let none = Circuit::build(vec![
        Box::new(PressureSource::new(
            "supply",
            "P",
            Pressure::from_bar(70.0),
            None,
        )),
        Box::new(FixedOrifice::new("o", "P", "A", Area::new(1e-6), orifice())),
    ])
    .unwrap_err();
    assert!(
        none.to_string().contains("`A`") && none.to_string().contains("`o`"),
        "{none}"
    );

    let looped = Circuit::build(vec![gain("g1", "a", "b"), gain("g2", "b", "a")]).unwrap_err();
    assert!(matches!(looped, BuildError::AlgebraicLoop(_)), "{looped}");

    let dup = Circuit::build(vec![gain("g", "a", "b"), gain("g", "b", "c")]).unwrap_err();
    assert!(dup.to_string().contains("two components"), "{dup}");
}

#[test]
fn a_signal_used_as_two_quantities_is_a_build_error() {
    // the spool writes `x` as a position; the gain reads it as a bare f64
    let spool = crate::components::ServoSpool::new(
        "spool",
        "u",
        "x",
        hydrocyl_valves::servovalve::Spool::leaney_moog(),
        0.0,
    );
    let cmd = crate::components::CommandInput::new(
        "cmd",
        "u",
        crate::signal::Signal::Constant { value: 0.0 },
    );
    let e = Circuit::build(vec![Box::new(cmd), Box::new(spool), gain("g", "x", "y")]).unwrap_err();
    assert!(matches!(e, BuildError::UnitMismatch { .. }), "{e}");
    let msg = e.to_string();
    assert!(
        msg.contains("sig:x") && msg.contains("`g`") && msg.contains("m"),
        "{msg}"
    );
}

#[test]
fn algebraic_components_are_ordered_by_dependency() {
    // given in reverse order: g2 reads what g1 writes; g1 reads a stored signal
    let mut c = Circuit::build(vec![
        gain("g2", "b", "c"),
        gain("g1", "a", "b"),
        Box::new(crate::components::CommandInput::new(
            "cmd",
            "a",
            crate::signal::Signal::Constant { value: 1.5 },
        )),
    ])
    .unwrap();
    let w = c.wires_at(0.0, &[]);
    let cw = c.find_wire("sig:c").unwrap();
    assert_eq!(w.get(cw), 6.0);
    c.reset(0.0, &[]);
}

#[test]
fn volume_filled_through_an_orifice_conserves_mass_and_reaches_supply() {
    // supply → orifice → volume: V/B (p(T) − p(0)) = ∫Q dt, p → Ps
    let (v, b) = (1e-4, 7e8);
    let mut c = Circuit::build(vec![
        Box::new(PressureSource::new(
            "supply",
            "P",
            Pressure::from_bar(70.0),
            Some("ps"),
        )),
        Box::new(FixedOrifice::new("o", "P", "A", Area::new(1e-7), orifice())),
        Box::new(Volume::new("vol", "A", v, b, 0.0, Some("pa"))),
    ])
    .unwrap();
    c.set_ledger(true);
    let x0 = c.initial_state();
    let opts = Options {
        rtol: 1e-9,
        atol: c.atol(1e-9),
        ..Options::default()
    };
    let sol = solve(Method::DormandPrince45, &mut c, 0.0, &x0, 2.0, &opts).unwrap();
    let last = sol.last().unwrap();
    assert!((last[0] - 7e6).abs() < 1e3, "p = {}", last[0]);
    // energy: source = dissipated + storage (volume), each integrated
    let o = c.ledger_offset();
    let src = last[o];
    let diss = last[o + LEDGER_TERMS + 1];
    let stored = last[o + 2 * LEDGER_TERMS + 2];
    assert!(
        (src - diss - stored).abs() < 1e-6 * src,
        "{src} {diss} {stored}"
    );
    // stored = V p²/(2B) for a constant volume
    assert!((stored - v * last[0] * last[0] / (2.0 * b)).abs() < 1e-6 * stored);
}

/// Every entry of the full state vector has a name, whatever is appended
/// (component quadratures, the ledger's terms).
#[test]
fn every_entry_of_the_state_vector_is_named() {
    use hydrocyl_integrators::OdeSystem;
    let v = crate::rig::preset("leaney-moog").unwrap();
    let mut c = crate::rig::circuit(&v, crate::signal::Signal::Constant { value: 0.1 }).unwrap();
    for (quad, ledger) in [(false, false), (true, false), (false, true), (true, true)] {
        c.set_quadratures(quad);
        c.set_ledger(ledger);
        let names = c.state_names();
        assert_eq!(names.len(), c.dim(), "quadratures {quad}, ledger {ledger}");
        if ledger {
            assert_eq!(
                names.last().unwrap(),
                &format!("{}.energy_moved", c.components().last().unwrap().name())
            );
        }
    }
}

/// The hybrid rig's circuit commanded by `signal`, and its initial state.
fn hybrid(signal: crate::signal::Signal) -> (Circuit, Vec<f64>) {
    let c = crate::hybrid::WangHybrid::preset()
        .build(signal)
        .expect("rig");
    let x = c.initial_state();
    (c, x)
}

#[test]
fn a_piecewise_constant_command_leaves_the_circuit_constant_in_time() {
    use crate::signal::Signal;
    let square = Signal::Square {
        amplitude: 0.3,
        period_s: 5.0,
        bias: 0.01,
    };
    let (c, x) = hybrid(square);
    let n = c.dim();
    let (mut a, mut b) = (vec![0.0; n], vec![0.0; n]);
    // between the square's jumps (0, 2.5 s, ...) the promise holds
    for t in [0.1, 1.3, 2.4] {
        assert!(c.constant_in_time(t));
        c.rhs(t, &x, &mut a);
        c.rhs(t + 1e-3, &x, &mut b);
        for (i, (a, b)) in a.iter().zip(&b).enumerate() {
            assert!(
                (a - b).abs() <= 1e-12 * a.abs().max(1.0),
                "state {i}: {a} against {b}"
            );
        }
    }
    let sine = Signal::Sine {
        amplitude: 0.3,
        period_s: 5.0,
        bias: 0.0,
        phase_rad: 0.0,
    };
    let (c, x) = hybrid(sine);
    assert!(!c.constant_in_time(1.3));
    c.rhs(1.3, &x, &mut a);
    c.rhs(1.3 + 1e-3, &x, &mut b);
    assert_ne!(a, b, "the sine's circuit does change with time");
}

#[test]
fn the_table_is_reused_at_the_same_point_until_forgotten() {
    use crate::external::ExternalInput;
    let (input, other) = (ExternalInput::new(), ExternalInput::new());
    input.set(0.0, 0.5, 0.0);
    other.set(0.0, -0.5, 0.0);
    let (c, x) = hybrid(crate::signal::Signal::External(input.clone()));
    let n = c.dim();
    let (mut a, mut b, mut fresh) = (vec![0.0; n], vec![0.0; n], vec![0.0; n]);
    c.rhs(0.0, &x, &mut a);
    // the input changes behind the circuit's back: the same point reads the
    // table as it was (what `Simulation::step_to` forgets before a step)
    input.set(0.0, -0.5, 0.0);
    c.rhs(0.0, &x, &mut b);
    assert_eq!(a, b);
    c.forget_evaluation();
    c.rhs(0.0, &x, &mut b);
    let (d, _) = hybrid(crate::signal::Signal::External(other));
    d.rhs(0.0, &x, &mut fresh);
    assert_ne!(a, b);
    for (i, (b, f)) in b.iter().zip(&fresh).enumerate() {
        assert!(
            (b - f).abs() <= 1e-9 * f.abs().max(1.0),
            "state {i}: {b} against {f}"
        );
    }
}
