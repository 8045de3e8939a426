//! Controllers: the position controller that closes the loop of a drive
//! (the command computed from a reference and the measured piston position).

use super::super::registry::{param, ComponentType, Default::*, Instance, Range, Role, StateSpec};
use super::{built, port, MECH, SIG};
use crate::circuit::Component;
use crate::components::{PositionController, PositionLaw};

fn controller(i: &Instance) -> Result<Box<dyn Component>, String> {
    let law = PositionLaw {
        gain: i.get("gain"),
        integral_time: i.get("integral_time"),
        bias: i.get("bias"),
        output_min: i.get("output_min"),
        output_max: i.get("output_max"),
    };
    if law.output_min >= law.output_max {
        return Err(crate::netlist::registry::error_at(
            &format!("components.{}.output_min", i.name),
            &format!(
                "output_min = {} must be below output_max = {}",
                law.output_min, law.output_max
            ),
        ));
    }
    let integral = i.initial("integral").unwrap_or(0.0);
    // named at its own path, so that a `--set` that gave it is blamed
    // rather than the file's line
    let at = format!("components.{}.initial.integral", i.name);
    if !integral.is_finite() {
        return Err(crate::netlist::registry::error_at(
            &at,
            &format!("initial.integral = {integral} must be finite"),
        ));
    }
    if integral != 0.0 && (law.integral_time <= 0.0 || law.integral_time.is_nan()) {
        return Err(crate::netlist::registry::error_at(
            &at,
            &format!("initial.integral = {integral} needs a PI controller (integral_time > 0)"),
        ));
    }
    built(
        PositionController::new(
            &i.name,
            i.node("reference"),
            i.node("rod"),
            i.node("command"),
            law,
        )
        .with_integral(integral),
    )
}

/// The component types of this family.
pub const TYPES: &[ComponentType] = &[ComponentType {
    name: "position_controller",
    summary: "position controller, P or PI: u = clip(Kp (r − x + ∫(r − x) dt / Ti) + u0, lo, hi), the integral held while clipped",
    ports: &[
        port("reference", SIG, Role::Reads, false, "position set-point r [m]"),
        port("rod", MECH, Role::Reads, false, "the body whose position x it controls"),
        port("command", SIG, Role::Owns, false, "the command u it writes, in the unit of what reads it (a spool's demand [-], a pump's volts [V])"),
    ],
    params: &[
        param("gain", "1/m", Required, Range::ANY, "proportional gain Kp"),
        param(
            "integral_time",
            "s",
            Value(0.0),
            Range::NON_NEGATIVE,
            "integral time Ti; 0 = a P controller",
        ),
        param("bias", "-", Value(0.0), Range::ANY, "output offset u0 (added before the limits)"),
        param("output_min", "-", Value(-1.0), Range::ANY, "lower output limit"),
        param("output_max", "-", Value(1.0), Range::ANY, "upper output limit"),
    ],
    states: &[StateSpec {
        name: "integral",
        unit: "m s",
        default: Value(0.0),
        doc: "initial integral of the error ∫(r − x) dt (PI only; a restart carries it on)",
    }],
    build: controller,
    hints: None,
    probes: &[("command", "-")],
}];

#[cfg(test)]
mod tests {
    use crate::run::RunOptions;
    use crate::signal::Signal;
    use crate::valve_rig::ValveRig;

    fn closed_loop() -> ValveRig {
        let v: serde_json::Value = serde_json::from_str(crate::valve_netlist::CLOSED_LOOP).unwrap();
        ValveRig::from_netlist(&v).unwrap()
    }

    /// A P-controlled drive is an integrator behind a gain: away from the
    /// fast spool and chamber dynamics the piston follows the quasi-static
    /// law `ẋ = V(Kp (r − x))`, V the drive's own steady velocity at a
    /// command, and settles where the spool sits at the drive's
    /// zero-velocity position `x_s0`: `x_∞ = r − x_s0 / (x_max Kp)` (the
    /// asymmetric cylinder needs a spool offset to hold p1 A1 = p2 A2 at
    /// rest). Both are checked against the whole circuit.
    #[test]
    fn a_p_controlled_drive_follows_its_quasi_static_law_and_settles_in_closed_form() {
        let rig = closed_loop();
        let c = rig.controller.expect("the preset is closed loop");
        let xm = rig.valve.stroke_m;
        let r = 0.004; // 4 mm: a command of 0.04 at the start
        let xs0 = rig.spool_for_velocity(0.0).unwrap();
        let x_inf = r - xs0 / (xm * c.gain_per_m);
        // the quasi-static law, integrated by RK4 at 1 ms
        let v = |x: f64| {
            let u = (c.gain_per_m * (r - x)).clamp(c.output_min, c.output_max);
            rig.steady_velocity(u * xm).unwrap()
        };
        let h = 1e-3;
        let mut quasi = vec![0.0_f64];
        for _ in 0..1000 {
            let x = *quasi.last().unwrap();
            let k1 = v(x);
            let k2 = v(x + 0.5 * h * k1);
            let k3 = v(x + 0.5 * h * k2);
            let k4 = v(x + h * k3);
            quasi.push(x + h / 6.0 * (k1 + 2.0 * k2 + 2.0 * k3 + k4));
        }
        let t: Vec<f64> = (0..=400).map(|k| k as f64 * 0.01).collect();
        let run = rig
            .simulate(
                Signal::Constant { value: r },
                &t,
                &RunOptions {
                    rtol: 1e-8,
                    ..RunOptions::dp45()
                },
            )
            .unwrap();
        let x = run.channel("position").unwrap();
        let u = run.channel("command").unwrap();
        let last = *x.last().unwrap();
        assert!(
            (last - x_inf).abs() < 1e-3 * r,
            "settles at {last} m, closed form {x_inf} m"
        );
        assert!((u.last().unwrap() - c.gain_per_m * (r - last)).abs() < 1e-12);
        // the approach within 6 % of the step (the spool lag τ = 4 ms and the
        // chambers, which start at the rest pressures of a centred spool,
        // make up the rest: at most 5.2 % here, at 60 ms)
        for k in (3..=100).map(|k| 10 * k) {
            let (got, expect) = (x[k / 10], quasi[k]);
            assert!(
                (got - expect).abs() < 0.06 * r,
                "x({} s) = {got} m, quasi-static {expect} m",
                k as f64 * h
            );
        }
    }
}
