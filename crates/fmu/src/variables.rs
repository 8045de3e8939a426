//! The FMU's variables, made from a rig: the command input, one output per
//! output channel of the rig's circuit, the solver parameters and one
//! parameter per numeric rig parameter. The model description and the slave
//! both make this table from the same rig, so their value references agree
//! (the GUID checks it: [`crate::model_description`]).

use crate::units::{parameter_unit, unit_name};
use hydrocyl_system::external::ExternalInput;
use hydrocyl_system::rig::{self, RigError};
use hydrocyl_system::run::{RunOptions, Solver};
use hydrocyl_system::signal::Signal;
use hydrocyl_system::{Circuit, Probe};
use serde_json::Value;

/// The name of the input variable of a rig without a named input (and of
/// the circuit's command signal, whose own output channel the input
/// replaces).
pub const INPUT: &str = "command";

/// The name of `rig`'s input variable: the output column that shows the
/// netlist's input ([`Schematic::input_channel`](hydrocyl_system::netlist::Schematic::input_channel))
/// — `command` on an open-loop rig, `reference` on a closed-loop one whose
/// input is the controller's set-point (the controller's output is then the
/// `command` output) — or [`INPUT`].
pub fn input_name(rig: &Value) -> String {
    hydrocyl_system::netlist::schematic(rig)
        .ok()
        .and_then(|s| s.input_channel())
        .unwrap_or_else(|| INPUT.into())
}

/// The unit of `rig`'s input variable: the one in which the rig takes its
/// input ([`Schematic::input_unit`](hydrocyl_system::netlist::Schematic::input_unit):
/// `m` for a closed-loop rig's set-point, `V` for a pump drive's voltage,
/// `m/s` for a friction bench's imposed velocity); `None` for a
/// dimensionless spool demand or where the rig declares none.
pub fn input_unit(rig: &Value) -> Option<&'static str> {
    hydrocyl_system::netlist::schematic(rig)
        .ok()
        .and_then(|s| s.input_unit())
        .and_then(unit_name)
}

/// The solver methods by their `solver.method` number.
pub const METHODS: [Solver; 3] = [Solver::Dp45, Solver::Rosenbrock, Solver::Rk4];

/// A solver setting exposed as a parameter.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SolverParam {
    /// `solver.method`: index into [`METHODS`].
    Method,
    /// `solver.rtol`: relative tolerance.
    Rtol,
    /// `solver.h_max`: largest step \[s\].
    HMax,
    /// `solver.rk4_step`: fixed step of RK4 \[s\].
    Rk4Step,
}

/// What a variable is.
#[derive(Clone, Debug, PartialEq)]
pub enum Role {
    /// The command (causality input).
    Input,
    /// Output channel `i` of [`Variables::outputs`].
    Output(usize),
    /// A solver setting.
    Solver(SolverParam),
    /// A rig parameter by its `--set` path.
    Parameter(String),
}

/// One scalar variable; its value reference is its index in
/// [`Variables::list`].
#[derive(Clone, Debug, PartialEq)]
pub struct Variable {
    /// Name (a rig parameter's path, an output channel's name, ...).
    pub name: String,
    /// What it is.
    pub role: Role,
    /// `Integer` instead of `Real` (only `solver.method`).
    pub integer: bool,
    /// Start value (inputs and parameters); `NaN` for a rig parameter left
    /// `null` (computed by the rig, e.g. a steady initial pressure).
    pub start: f64,
    /// Unit name (see [`crate::units`]).
    pub unit: Option<&'static str>,
    /// One line for the model description.
    pub description: String,
    /// For an output: it changes with the input at the same instant
    /// (direct feedthrough); found by evaluating the circuit.
    pub feedthrough: bool,
}

/// All variables of the FMU of one rig.
#[derive(Clone, Debug, PartialEq)]
pub struct Variables {
    /// The variables, value reference = index.
    pub list: Vec<Variable>,
    /// Output channel names and units, in output order.
    pub outputs: Vec<(String, &'static str)>,
}

/// The circuit's output channels in the order of a run's channels
/// (command, position, velocity, p1, p2, then the others in component order, as
/// `hydrocyl_system::simulation::Simulation::run` orders them), without the
/// command (it is the FMU's input, named `input`).
pub fn output_channels(circuit: &Circuit, input: &str) -> Vec<Probe> {
    // a closed-loop rig's `command` (its controller's output) comes first,
    // as in a run
    const ORDER: [&str; 5] = ["command", "position", "velocity", "p1", "p2"];
    let mut out: Vec<Probe> = circuit
        .probes()
        .into_iter()
        .filter(|p| p.name != input)
        .collect();
    out.sort_by_key(|p| {
        ORDER
            .iter()
            .position(|o| *o == p.name)
            .unwrap_or(ORDER.len())
    });
    out
}

/// The circuit of `rig` driven by an external input (whose handle is returned).
pub fn circuit_with_input(rig: &Value) -> Result<(Circuit, ExternalInput), RigError> {
    let input = ExternalInput::new();
    let c = rig::circuit(rig, Signal::External(input.clone()))?;
    Ok((c, input))
}

/// Whether parameter `path` of `rig` may be left to the rig (`null` in a
/// rig file: its default is "computed" or "none", [`Default::Absent`](hydrocyl_system::netlist::registry::Default::Absent)):
/// then `NaN` sets it back to that.
pub fn nullable(rig: &Value, path: &str) -> bool {
    let Some((component, name)) = path.split_once('.') else {
        return false;
    };
    let Some(ty) = rig::component_type(rig, component) else {
        return false;
    };
    let default = match name.strip_prefix("initial.") {
        Some(state) => ty.state(state).map(|s| s.default),
        None => ty.param(name).map(|p| p.default),
    };
    matches!(
        default,
        Some(hydrocyl_system::netlist::registry::Default::Absent)
    )
}

/// Direct feedthrough of each probe: whether it changes with the input
/// alone, at the circuit's initial state.
fn feeds_through(circuit: &Circuit, input: &ExternalInput, probes: &[Probe]) -> Vec<bool> {
    let x0 = circuit.initial_state();
    let wires: Vec<_> = probes.iter().map(|p| p.wire).collect();
    let read = |u: f64| {
        input.set(0.0, u, 0.0);
        let mut row = vec![0.0; wires.len()];
        circuit.read_wires(0.0, &x0, &wires, &mut row);
        row
    };
    let (lo, hi) = (read(-0.5), read(0.5));
    lo.iter().zip(&hi).map(|(a, b)| a != b).collect()
}

impl Variables {
    /// The variables of the FMU of `rig` (checked here).
    pub fn of(rig: &Value) -> Result<Self, RigError> {
        rig::check(rig)?;
        let (circuit, input) = circuit_with_input(rig)?;
        let input_name = input_name(rig);
        let probes = output_channels(&circuit, &input_name);
        let feeds = feeds_through(&circuit, &input, &probes);
        let mut list = vec![Variable {
            name: input_name.clone(),
            role: Role::Input,
            integer: false,
            start: 0.0,
            unit: input_unit(rig),
            description: if input_name == INPUT {
                "the rig's command (normalised spool demand of a valve rig, drive voltage of a pump rig, imposed rod velocity of a friction bench); linear inside a step with fmi2SetRealInputDerivatives".into()
            } else {
                format!("the rig's input `{input_name}` (a closed-loop rig's position set-point [m]); linear inside a step with fmi2SetRealInputDerivatives")
            },
            feedthrough: false,
        }];
        for (i, p) in probes.iter().enumerate() {
            list.push(Variable {
                name: p.name.clone(),
                role: Role::Output(i),
                integer: false,
                start: f64::NAN,
                unit: unit_name(p.unit),
                description: format!("output channel `{}`", p.name),
                feedthrough: feeds[i],
            });
        }
        let d = RunOptions::default();
        let solver = |name: &str, sp, start, unit, description: &str| Variable {
            name: name.into(),
            role: Role::Solver(sp),
            integer: sp == SolverParam::Method,
            start,
            unit,
            description: description.into(),
            feedthrough: false,
        };
        list.push(solver(
            "solver.method",
            SolverParam::Method,
            0.0,
            None,
            "integration method: 0 dp45 (Dormand-Prince 5(4)), 1 rosenbrock (stiff Rodas4), 2 rk4 (fixed step)",
        ));
        let rtol = format!(
            "relative tolerance of the adaptive methods, in [{:e}, 1) (absolute: rtol times each state's scale)",
            hydrocyl_system::run::RTOL_FLOOR
        );
        list.push(solver(
            "solver.rtol",
            SolverParam::Rtol,
            d.rtol,
            None,
            &rtol,
        ));
        list.push(solver(
            "solver.h_max",
            SolverParam::HMax,
            d.h_max,
            Some("s"),
            "largest internal step of the adaptive methods",
        ));
        list.push(solver(
            "solver.rk4_step",
            SolverParam::Rk4Step,
            d.rk4_step,
            Some("s"),
            "fixed internal step of rk4",
        ));
        for p in rig::parameters(rig) {
            list.push(Variable {
                description: match p.value {
                    Some(_) if nullable(rig, &p.path) => format!(
                        "rig parameter `{}`; NaN leaves it to the rig (computed, or none: null in the rig file)",
                        p.path
                    ),
                    Some(_) => format!("rig parameter `{}`", p.path),
                    None => format!(
                        "rig parameter `{}`; NaN (the start) leaves it to the rig (null in the rig file)",
                        p.path
                    ),
                },
                name: p.path.clone(),
                unit: parameter_unit(&p),
                role: Role::Parameter(p.path),
                integer: false,
                start: p.value.unwrap_or(f64::NAN),
                feedthrough: false,
            });
        }
        let mut names: Vec<&str> = list.iter().map(|v| v.name.as_str()).collect();
        names.sort_unstable();
        if let Some(w) = names.windows(2).find(|w| w[0] == w[1]) {
            return Err(RigError::Invalid {
                path: w[0].into(),
                why: "two FMU variables would have this name".into(),
            });
        }
        Ok(Self {
            list,
            outputs: probes.iter().map(|p| (p.name.clone(), p.unit)).collect(),
        })
    }

    /// Widens the outputs' direct feedthrough (found by [`Variables::of`] at
    /// the rig's own parameter values) to every value of the parameters a
    /// host may set: an output also feeds through when it does with any one
    /// parameter moved across its range (0 to a positive value and back,
    /// halved, doubled, shifted by one; a value the rig refuses is skipped).
    /// A damping that is 0 in the exported rig, and with it the output's
    /// dependence on the input, is then declared (`friction.sigma1` of a
    /// friction bench). A dependency declared that some values do not
    /// have is allowed by FMI; one missing is not.
    pub fn widen_feedthrough(&mut self, rig: &Value) {
        let names: Vec<String> = self.outputs.iter().map(|(n, _)| n.clone()).collect();
        let mut any: Vec<bool> = self
            .list
            .iter()
            .filter(|v| matches!(v.role, Role::Output(_)))
            .map(|v| v.feedthrough)
            .collect();
        for p in rig::parameters(rig) {
            let candidates = match p.value {
                Some(v) if v != 0.0 => vec![2.0 * v, 0.5 * v, v + 1.0, 0.0],
                _ => vec![1.0, 1e-2, 1e2, 1e4],
            };
            for c in candidates {
                let mut r = rig.clone();
                if rig::apply_set(&mut r, &format!("{}={c:?}", p.path)).is_err()
                    || rig::check(&r).is_err()
                {
                    continue;
                }
                let Ok((circuit, input)) = circuit_with_input(&r) else {
                    continue;
                };
                let probes = output_channels(&circuit, &input_name(&r));
                let feeds = feeds_through(&circuit, &input, &probes);
                for (i, name) in names.iter().enumerate() {
                    if let Some(k) = probes.iter().position(|p| &p.name == name) {
                        any[i] |= feeds[k];
                    }
                }
            }
        }
        let mut k = 0;
        for v in self.list.iter_mut() {
            if matches!(v.role, Role::Output(_)) {
                v.feedthrough = any[k];
                k += 1;
            }
        }
    }

    /// The variable with value reference `vr`.
    pub fn get(&self, vr: u32) -> Option<&Variable> {
        self.list.get(vr as usize)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn outputs_are_the_channels_of_a_run_and_parameters_are_the_rigs() {
        for preset in rig::PRESETS {
            let rig = (preset.json)();
            let v = Variables::of(&rig).unwrap();
            assert_eq!(v.list[0].role, Role::Input);
            // the outputs are the run's channels without the command, same order
            let run = rig::simulate(
                &rig,
                Signal::Constant { value: 0.1 },
                &[0.0, 0.01],
                &RunOptions::default(),
            )
            .unwrap();
            let names: Vec<&str> = run
                .channels
                .iter()
                .map(|c| c.name.as_str())
                .filter(|n| *n != input_name(&rig))
                .collect();
            let ours: Vec<&str> = v.outputs.iter().map(|(n, _)| n.as_str()).collect();
            assert_eq!(ours, names, "{}", preset.name);
            let n_par = v
                .list
                .iter()
                .filter(|x| matches!(x.role, Role::Parameter(_)))
                .count();
            assert_eq!(n_par, rig::parameters(&rig).len(), "{}", preset.name);
        }
        // the input carries the unit the rig takes it in; a spool demand has none
        for (preset, name, unit) in [
            ("leaney-moog", "command", None),
            ("leaney-moog-closed-loop", "reference", Some("m")),
            ("wang-hybrid", "command", Some("V")),
            ("emps", "command", Some("m/s")),
            ("tudelft-seal-25", "command", Some("m/s")),
        ] {
            let v = Variables::of(&rig::preset(preset).unwrap()).unwrap();
            assert_eq!(
                (v.list[0].name.as_str(), v.list[0].unit),
                (name, unit),
                "{preset}"
            );
        }
        // the spool lags the command: nothing feeds through
        let v = Variables::of(&rig::preset("leaney-moog").unwrap()).unwrap();
        assert!(v.list.iter().all(|x| !x.feedthrough));
    }

    fn feedthrough(v: &Variables, name: &str) -> bool {
        v.list.iter().find(|x| x.name == name).unwrap().feedthrough
    }

    /// The friction bench's forces do not feed through at its exported
    /// σ1 = σ2 = 0; with σ1 > 0 they do, and the widened analysis declares
    /// it for the exported rig. What feeds through at the rig's own values
    /// stays declared.
    #[test]
    fn feedthrough_that_a_parameter_creates_is_declared() {
        let r = rig::preset("tudelft-seal-25").unwrap();
        let exported = Variables::of(&r).unwrap();
        let mut with_sigma1 = r.clone();
        rig::apply_set(&mut with_sigma1, "friction.sigma1=100").unwrap();
        let damped = Variables::of(&with_sigma1).unwrap();
        let mut widened = exported.clone();
        widened.widen_feedthrough(&r);
        let mut created = 0;
        for (name, _) in &exported.outputs {
            let (at, then) = (feedthrough(&exported, name), feedthrough(&damped, name));
            created += usize::from(then && !at);
            assert!(
                feedthrough(&widened, name) || !(at || then),
                "{name}: exported {at}, with sigma1 {then}"
            );
        }
        assert!(created > 0, "sigma1 creates a feedthrough");
        // a rig whose every output lags the input keeps none
        let lm = rig::preset("leaney-moog").unwrap();
        let mut v = Variables::of(&lm).unwrap();
        v.widen_feedthrough(&lm);
        assert!(v.list.iter().all(|x| !x.feedthrough));
    }
}
