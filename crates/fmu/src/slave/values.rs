//! The slave's variables read and set (`fmi2GetReal`, `fmi2SetReal`, the
//! Integer calls, `fmi2SetRealInputDerivatives`) and the rules a
//! parameter's value must meet on its own.

use super::{Phase, Slave, SlaveError};
use crate::variables::{nullable, Role, SolverParam, METHODS};
use hydrocyl_system::netlist::{self, registry};
use hydrocyl_system::rig;
use hydrocyl_system::run::Setting;
use serde_json::Value;

impl Slave {
    /// `fmi2GetReal` of one variable.
    pub fn get_real(&mut self, vr: u32) -> Result<f64, SlaveError> {
        let v = self.var(vr)?;
        match v.role {
            Role::Output(i) => {
                if self.phase == Phase::Instantiated {
                    return Err(format!(
                        "output `{}` is not known before fmi2EnterInitializationMode",
                        v.name
                    ));
                }
                self.ensure_sim()?;
                let s = self.sim.as_ref().ok_or("no circuit")?;
                let mut out = [0.0];
                s.sim
                    .circuit()
                    .read_wires(s.t, s.sim.state(), &s.wires[i..i + 1], &mut out);
                Ok(out[0])
            }
            _ if v.integer => Err(format!("`{}` is an Integer", v.name)),
            _ => Ok(self.values[vr as usize]),
        }
    }

    /// `fmi2GetInteger` of one variable.
    pub fn get_integer(&self, vr: u32) -> Result<i32, SlaveError> {
        let v = self.var(vr)?;
        if !v.integer {
            return Err(format!("`{}` is not an Integer", v.name));
        }
        Ok(self.values[vr as usize] as i32)
    }

    /// `fmi2SetInteger` of one variable (`solver.method`).
    pub fn set_integer(&mut self, vr: u32, value: i32) -> Result<(), SlaveError> {
        let v = self.var(vr)?;
        if !v.integer {
            return Err(format!("`{}` is not an Integer", v.name));
        }
        self.set(vr, value as f64)
    }

    /// `fmi2SetReal` of one variable: the input at any time; a parameter
    /// before the end of initialisation. A parameter's value is checked on
    /// its own here (finite, inside the range its component declares; the
    /// message names the parameter and the rule it breaks); the rules that
    /// relate several parameters are checked once on the whole set, when the
    /// circuit is next assembled (`fmi2ExitInitializationMode`, or an output
    /// read in initialisation mode), so parameters can be set in any order.
    pub fn set_real(&mut self, vr: u32, value: f64) -> Result<(), SlaveError> {
        let v = self.var(vr)?;
        if v.integer {
            return Err(format!("`{}` is an Integer", v.name));
        }
        self.set(vr, value)
    }

    fn set(&mut self, vr: u32, value: f64) -> Result<(), SlaveError> {
        let v = self.var(vr)?.clone();
        let name = &v.name;
        match &v.role {
            Role::Output(_) => return Err(format!("`{name}` is an output: it cannot be set")),
            Role::Input => {
                if !value.is_finite() {
                    return Err(format!("input `{name}` = {value} is not finite"));
                }
                if self.phase == Phase::Failed || self.phase == Phase::Terminated {
                    return Err(format!("setting `{name}` in phase {:?}", self.phase));
                }
                self.values[vr as usize] = value;
                // a new value starts a step without slope until
                // fmi2SetRealInputDerivatives says otherwise
                self.slope = 0.0;
                if let Some(s) = &self.sim {
                    s.input.set(s.t, value, 0.0);
                }
                return Ok(());
            }
            Role::Solver(sp) => {
                self.expect(
                    &[Phase::Instantiated, Phase::Initializing],
                    &format!("setting fixed parameter `{name}`"),
                )?;
                let (ok, rule) = match sp {
                    SolverParam::Method => (
                        value >= 0.0 && value < METHODS.len() as f64 && value.fract() == 0.0,
                        format!(
                            "must be {}",
                            METHODS
                                .iter()
                                .enumerate()
                                .map(|(i, m)| format!("{i} ({})", m.name()))
                                .collect::<Vec<_>>()
                                .join(", ")
                        ),
                    ),
                    SolverParam::Rtol => setting_rule(Setting::Rtol, value),
                    SolverParam::HMax => setting_rule(Setting::HMax, value),
                    SolverParam::Rk4Step => setting_rule(Setting::Rk4Step, value),
                };
                if !ok {
                    return Err(format!(
                        "parameter `{name}` = {} rejected: {rule}",
                        Setting::shown(value)
                    ));
                }
            }
            Role::Parameter(path) => {
                self.expect(
                    &[Phase::Instantiated, Phase::Initializing],
                    &format!("setting fixed parameter `{name}`"),
                )?;
                // NaN: back to "computed by the rig" / "none", for every
                // parameter the rig may leave null
                let text = if value.is_nan() && (v.start.is_nan() || nullable(&self.rig, path)) {
                    "null".to_string()
                } else if value.is_finite() {
                    format!("{value:?}")
                } else {
                    return Err(format!(
                        "parameter `{name}` = {value} rejected: must be finite"
                    ));
                };
                let rejected =
                    |why: String| format!("parameter `{name}` = {value} rejected: {why}");
                if value.is_finite() {
                    own_rule(&self.rig, path, value).map_err(rejected)?;
                }
                let mut r = self.rig.clone();
                rig::apply_set(&mut r, &format!("{path}={text}"))
                    .map_err(|e| rejected(e.to_string()))?;
                self.rig = r;
            }
        }
        self.values[vr as usize] = value;
        self.sim = None;
        Ok(())
    }

    /// `fmi2SetRealInputDerivatives` of order 1: the input's slope over the
    /// next step (the input is linear inside it).
    pub fn set_input_derivative(
        &mut self,
        vr: u32,
        order: i32,
        value: f64,
    ) -> Result<(), SlaveError> {
        let v = self.var(vr)?;
        if v.role != Role::Input {
            return Err(format!("`{}` is not an input", v.name));
        }
        if order != 1 {
            return Err(format!(
                "input derivative of order {order} for `{}`: only order 1 is supported",
                v.name
            ));
        }
        if !value.is_finite() {
            return Err(format!("input derivative of `{}` = {value}", v.name));
        }
        self.slope = value;
        if let Some(s) = &self.sim {
            s.input.set(s.t, self.values[0], value);
        }
        Ok(())
    }
}

/// Whether a solver parameter's `value` meets `setting`'s rules, and the
/// rule it breaks ([`Setting::check`]).
fn setting_rule(setting: Setting, value: f64) -> (bool, String) {
    match setting.check(value) {
        Ok(_) => (true, String::new()),
        Err(rule) => (false, rule.into()),
    }
}

/// The rules a rig parameter's value must meet on its own, whatever the
/// other parameters are: for a netlist, the range its component type
/// declares ([`registry::ParamSpec::range`]) or an initial state's own rule
/// ([`registry::StateSpec::check`]). The rules relating several parameters
/// (a chamber longer than half the stroke, ...) are [`rig::check`]'s.
fn own_rule(rig: &Value, path: &str, value: f64) -> Result<(), String> {
    if rig.get("kind").and_then(Value::as_str) != Some(netlist::KIND) {
        return Ok(());
    }
    let Some((component, name)) = path.split_once('.') else {
        return Ok(());
    };
    let Some(ty) = rig
        .pointer(&format!("/components/{component}/type"))
        .and_then(Value::as_str)
        .and_then(registry::lookup)
    else {
        return Ok(());
    };
    match name.strip_prefix("initial.") {
        Some(state) => ty.state(state).map_or(Ok(()), |s| s.check(value)),
        None => ty.param(name).map_or(Ok(()), |p| p.check(value)),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::slave::tests::vr;

    /// Lengthening the stroke past twice the chamber lengths, then the
    /// chambers: the stroke alone breaks the rig's rule relating it to the
    /// chambers, the whole set does not. The set is checked as a whole at
    /// initialisation, which names the parameters set when it is invalid.
    #[test]
    fn related_parameters_can_be_set_in_any_order() {
        let mut s = Slave::new(rig::preset("leaney-moog").unwrap()).unwrap();
        let start = |s: &Slave, name: &str| s.variables().list[vr(s, name) as usize].start;
        let stroke = 2.0
            * start(&s, "cylinder.chamber_length_1").max(start(&s, "cylinder.chamber_length_2"))
            + start(&s, "cylinder.stroke");
        s.set_real(vr(&s, "cylinder.stroke"), stroke).unwrap();
        s.enter_initialization().unwrap();
        // the stroke alone breaks the chambers' rule: refused at exit, named
        let e = s.exit_initialization().unwrap_err();
        assert!(
            e.contains(&format!("cylinder.stroke = {stroke}"))
                && e.contains("chamber_length_1 must exceed half the stroke"),
            "{e}"
        );
        assert_eq!(s.phase(), Phase::Initializing);
        let e = s.get_real(vr(&s, "position")).unwrap_err();
        assert!(e.contains("cylinder.stroke"), "{e}");
        // the chambers follow: the whole set is valid
        for c in ["cylinder.chamber_length_1", "cylinder.chamber_length_2"] {
            s.set_real(vr(&s, c), 0.6 * stroke).unwrap();
        }
        s.exit_initialization().unwrap();
        s.set_real(vr(&s, "command"), 0.2).unwrap();
        s.do_step(0.0, 1e-2).unwrap();
        assert!(s.get_real(vr(&s, "position")).unwrap() > 0.0);
    }

    /// A value wrong on its own is still refused at once, naming the rule.
    #[test]
    fn a_value_out_of_its_own_range_is_refused_when_set() {
        let mut s = Slave::new(rig::preset("leaney-moog").unwrap()).unwrap();
        let e = s.set_real(vr(&s, "cylinder.stroke"), -0.1).unwrap_err();
        assert!(
            e.contains("cylinder.stroke") && e.contains("-0.1 [m] is out of range: must be > 0"),
            "{e}"
        );
        let e = s.set_real(vr(&s, "cylinder.stroke"), f64::NAN).unwrap_err();
        assert!(e.contains("must be finite"), "{e}");
        let e = s.set_real(vr(&s, "cylinder.initial.p1"), -2e5).unwrap_err();
        assert!(e.contains("below absolute vacuum"), "{e}");
        assert_eq!(s.rig(), &rig::preset("leaney-moog").unwrap());
        // solver parameters: the message is the rule, not the description
        for (name, bad, rule) in [
            ("solver.rtol", 0.0, "must be in [1e-14, 1)"),
            ("solver.rtol", 1e-300, "= 1e-300 rejected: below 1e-14"),
            ("solver.h_max", -1.0, "must be > 0 [s]"),
            (
                "solver.rk4_step",
                f64::INFINITY,
                "must be finite and > 0 [s]",
            ),
        ] {
            let e = s.set_real(vr(&s, name), bad).unwrap_err();
            assert!(e.contains(rule) && !e.contains("tolerance of"), "{e}");
        }
        let e = s.set_integer(vr(&s, "solver.method"), 7).unwrap_err();
        assert!(
            e.contains("must be 0 (dp45), 1 (rosenbrock), 2 (rk4)"),
            "{e}"
        );
        s.enter_initialization().unwrap();
        s.exit_initialization().unwrap();
    }

    /// Every parameter the rig may leave null (an initial pressure computed
    /// from the steady state, an absent end stop) takes NaN as "back to
    /// computed/none", whatever its start value; the others refuse NaN.
    #[test]
    fn nan_is_computed_for_every_nullable_parameter() {
        let mut n_null = 0;
        for preset in ["leaney-moog", "wang-hybrid", "tudelft-seal-25"] {
            let r = rig::preset(preset).unwrap();
            let mut s = Slave::new(r.clone()).unwrap();
            for (i, v) in s.variables().list.clone().iter().enumerate() {
                let Role::Parameter(path) = &v.role else {
                    continue;
                };
                let result = s.set_real(i as u32, f64::NAN);
                if nullable(&r, path) {
                    n_null += 1;
                    assert!(result.is_ok(), "{preset} {path}: {result:?}");
                    assert!(s.get_real(i as u32).unwrap().is_nan());
                } else {
                    let e = result.unwrap_err();
                    assert!(e.contains(path) && e.contains("must be finite"), "{e}");
                }
            }
            // all back to the rig's own choice: a rig that cannot compute
            // one of them (no steady state to start from) says which
            s.enter_initialization().unwrap();
            if let Err(e) = s.exit_initialization() {
                assert!(e.contains("= NaN") && e.contains("give it"), "{e}");
            }
        }
        assert!(n_null > 4, "{n_null}");
        // an initial pressure set, then set back: the computed one again
        let mut s = Slave::new(rig::preset("leaney-moog").unwrap()).unwrap();
        let p1 = vr(&s, "cylinder.initial.p1");
        s.enter_initialization().unwrap();
        let computed = s.get_real(vr(&s, "p1")).unwrap();
        s.set_real(p1, computed + 1e6).unwrap();
        assert_eq!(s.get_real(vr(&s, "p1")).unwrap(), computed + 1e6);
        s.set_real(p1, f64::NAN).unwrap();
        assert_eq!(s.get_real(vr(&s, "p1")).unwrap(), computed);
    }

    #[test]
    fn parameters_are_checked_by_the_rig_and_outputs_follow_them() {
        let mut s = Slave::new(rig::preset("leaney-moog").unwrap()).unwrap();
        let e = s.set_real(vr(&s, "cylinder.area_1"), 0.0).unwrap_err();
        assert!(e.contains("cylinder.area_1"), "{e}");
        // an initial state is a parameter; the output at the start follows it
        s.set_real(vr(&s, "cylinder.initial.p1"), 2e6).unwrap();
        s.enter_initialization().unwrap();
        assert_eq!(s.get_real(vr(&s, "p1")).unwrap(), 2e6);
        s.set_real(vr(&s, "cylinder.initial.p1"), 3e6).unwrap();
        assert_eq!(s.get_real(vr(&s, "p1")).unwrap(), 3e6);
        assert!(s.set_real(vr(&s, "load.mass"), f64::NAN).is_err());
    }
}
