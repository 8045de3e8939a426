//! A netlist's external inputs: the components whose signal comes from
//! outside the circuit (a `--command` record, an FMU input), what each is
//! called and in which unit it is read — found from the schematic, so that
//! the CLI, the FMU and the assembler say it once.

use super::reader::Schematic;
use super::registry::Instance;

/// The component types driven from outside the circuit: a signal source,
/// or an imposed-motion source (a friction bench's drive, whose input is the
/// rod's velocity).
pub const INPUT_TYPES: [&str; 2] = ["command_input", "imposed_motion"];

/// A rating of what the run's input drives ([`Schematic::input_rating`]):
/// a pump's maximum speed, as the command that reaches it.
#[derive(Clone, Debug, PartialEq)]
pub struct InputRating {
    /// The rated component (`pump`).
    pub component: String,
    /// Its steady speed per unit of command, `|K| / displacement`
    /// \[rad·s⁻¹ per V\].
    pub speed_per_command: f64,
    /// Its maximum speed \[rad·s⁻¹\].
    pub max_speed: f64,
    /// The command magnitude that turns it at its maximum speed \[V\].
    pub limit: f64,
}

/// Revolutions per minute in one radian per second.
const RPM_PER_RAD_S: f64 = 60.0 / (2.0 * std::f64::consts::PI);

/// The samples of a command `u` over times `t` beyond `limit` in
/// magnitude, and the largest in magnitude with its time (`(0, NaN)` for
/// no samples): what a command past a valve's stroke or a pump's rating is
/// warned of with.
pub fn samples_beyond(t: &[f64], u: &[f64], limit: f64) -> (usize, (f64, f64)) {
    let outside = u.iter().filter(|x| x.abs() > limit).count();
    let peak = t
        .iter()
        .zip(u)
        .fold((0.0, f64::NAN), |(p, tp), (&tk, &uk)| {
            if uk.abs() > f64::abs(p) {
                (uk, tk)
            } else {
                (p, tp)
            }
        });
    (outside, peak)
}

/// The warning of `outside` samples of a normalised spool demand beyond
/// ±1 (the spool's stroke, where the valve clamps it), the largest in
/// magnitude `peak` = (value, time); `None` when none is. One text for
/// every front end, which says where the command came from before it.
pub fn stroke_warning(outside: usize, peak: (f64, f64)) -> Option<String> {
    (outside > 0).then(|| {
        format!(
            "{outside} command samples outside ±1 (largest {} at t = {} s); the valve clamps them to ±1 (the spool's stroke)",
            peak.0, peak.1
        )
    })
}

impl InputRating {
    /// The steady speed at command `u` \[rad·s⁻¹\].
    pub fn speed(&self, u: f64) -> f64 {
        u.abs() * self.speed_per_command
    }

    /// The warning of `outside` command samples beyond the rating, the
    /// largest in magnitude `peak` = (value, time); `None` when none is.
    /// The pump is not limited to its rating (a motor's maximum speed is a
    /// rating, not a stop): its flow follows the command, and the run goes
    /// on. One text for every front end, which says where the command came
    /// from before it (the CLI its file, Python `command (t, u)`).
    pub fn warning(&self, outside: usize, peak: (f64, f64)) -> Option<String> {
        (outside > 0).then(|| {
            format!(
                "{outside} command samples beyond the maximum speed of `{}` ({:.0} rpm, reached at ±{:.3} V; largest {} V at t = {} s: {:.0} rpm); the pump is not limited to it: its flow follows the command",
                self.component,
                self.max_speed * RPM_PER_RAD_S,
                self.limit,
                peak.0,
                peak.1,
                self.speed(peak.0) * RPM_PER_RAD_S
            )
        })
    }

    /// [`InputRating::warning`] for the command samples `u` at times `t`
    /// ([`samples_beyond`] the rating's limit).
    pub fn check(&self, t: &[f64], u: &[f64]) -> Option<String> {
        let (outside, peak) = samples_beyond(t, u, self.limit);
        self.warning(outside, peak)
    }
}

impl Schematic {
    /// The input components ([`INPUT_TYPES`]), in component order.
    pub fn inputs(&self) -> impl Iterator<Item = &Instance> {
        self.instances
            .iter()
            .filter(|i| INPUT_TYPES.contains(&i.ty.name))
    }

    /// The output column that shows the run's input, when the netlist has
    /// one input and it publishes its value: the column of the probe
    /// `<input>.command` (`command` on an open-loop rig, `reference` on a
    /// closed-loop one, whose controller's output is then `command`).
    pub fn input_channel(&self) -> Option<String> {
        let mut inputs = self.inputs();
        let (input, None) = (inputs.next()?, inputs.next()) else {
            return None;
        };
        if !input.ty.probes.iter().any(|(p, _)| *p == "command") {
            return None;
        }
        let probe = format!("{}.command", input.name);
        if self.outputs.is_empty() {
            return Some(probe);
        }
        self.outputs
            .iter()
            .find(|(_, p)| *p == probe)
            .map(|(col, _)| col.clone())
    }

    /// The unit in which the input is taken: for a signal source, from the
    /// declaration of the port reading it (`… [V]` for a pump drive, `… [m]`
    /// for a position controller's set-point, `… [-]` for a spool demand);
    /// for an imposed-motion drive, the rod's velocity it imposes (its
    /// `velocity` probe's unit, `m/s`). `None` when the netlist has not
    /// exactly one input, nothing reads it on a signal node, or the reading
    /// port names no unit.
    pub fn input_unit(&self) -> Option<&'static str> {
        let mut inputs = self.inputs();
        let (input, None) = (inputs.next()?, inputs.next()) else {
            return None;
        };
        if input.ty.name == "imposed_motion" {
            return input
                .ty
                .probes
                .iter()
                .find(|(p, _)| *p == "velocity")
                .map(|(_, u)| *u);
        }
        self.unit_read_at(input, "out")
    }

    /// Whether the run's one input is a position set-point: a `reference`
    /// port (a position controller's) reads it. A closed-loop rig's record
    /// then drives it from its `reference` column.
    pub fn input_is_set_point(&self) -> bool {
        let mut inputs = self.inputs();
        let (Some(input), None) = (inputs.next(), inputs.next()) else {
            return false;
        };
        let Some((_, ports)) = input.nodes.get("out").and_then(|n| self.nodes.get(n)) else {
            return false;
        };
        ports
            .iter()
            .filter_map(|p| p.split_once('.'))
            .any(|(c, port)| c != input.name && port == "reference")
    }

    /// The unit in which the other components on the signal node at
    /// `port` of `inst` read it: the first reading port whose declaration
    /// ends in a unit (`command [V]`). `None` when the port is not
    /// connected or no reader names a unit.
    pub fn unit_read_at(&self, inst: &Instance, port: &str) -> Option<&'static str> {
        let (_, ports) = self.nodes.get(inst.nodes.get(port)?)?;
        ports
            .iter()
            .filter_map(|p| p.split_once('.'))
            .filter(|(c, _)| *c != inst.name)
            .filter_map(|(c, port)| self.instance(c)?.ty.ports.iter().find(|q| q.name == port))
            .find_map(|q| q.unit())
    }

    /// The rating the run's input is checked against, when the input drives
    /// a pump directly (its `command` port on the input's node) and the
    /// pump has a rating (`displacement` and `max_speed`): the command
    /// magnitude at which the pump's steady flow `K u` turns it at its
    /// maximum speed. `None` otherwise (no rating is known, or the pump
    /// is driven by a controller whose output has its own limits).
    pub fn input_rating(&self) -> Option<InputRating> {
        let mut inputs = self.inputs();
        let (input, None) = (inputs.next()?, inputs.next()) else {
            return None;
        };
        let node = input.nodes.get("out")?;
        self.instances
            .iter()
            .filter(|i| i.ty.name == "pump_identified" && i.nodes.get("command") == Some(node))
            .find_map(|i| {
                let (d, w) = (i.opt("displacement")?, i.opt("max_speed")?);
                let per_volt = i.get("gain").abs() / d;
                Some(InputRating {
                    component: i.name.clone(),
                    speed_per_command: per_volt,
                    max_speed: w,
                    limit: w / per_volt,
                })
            })
    }

    /// The units of the `command` probes of the components that compute a
    /// command inside the circuit (a position controller owning its
    /// `command` port): the unit its readers take it in (`V` for a pump,
    /// `-` for a spool), as `(component, unit)`.
    pub fn command_units(&self) -> Vec<(&str, &'static str)> {
        self.instances
            .iter()
            .filter(|i| !INPUT_TYPES.contains(&i.ty.name))
            .filter(|i| i.ty.probes.iter().any(|(p, _)| *p == "command"))
            .filter(|i| {
                i.ty.port("command")
                    .is_some_and(|p| p.role == super::registry::Role::Owns)
            })
            .filter_map(|i| Some((i.name.as_str(), self.unit_read_at(i, "command")?)))
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use crate::rig;

    fn schematic(name: &str) -> super::Schematic {
        crate::netlist::schematic(&rig::preset(name).unwrap()).unwrap()
    }

    #[test]
    fn each_preset_names_its_input_and_unit() {
        let s = schematic("leaney-moog-closed-loop");
        assert_eq!(s.input_channel().as_deref(), Some("reference"));
        assert_eq!(s.input_unit(), Some("m"));
        assert!(s.input_is_set_point());
        let s = schematic("wang-hybrid");
        assert_eq!(s.input_channel().as_deref(), Some("command"));
        assert_eq!(s.input_unit(), Some("V"));
        assert!(!s.input_is_set_point());
        let s = schematic("leaney-moog");
        assert_eq!(s.input_channel().as_deref(), Some("command"));
        assert_eq!(s.input_unit(), Some("-"));
        // the command straight onto the valve's spool: a position [m], read
        // from the `command` column, not a controller's set-point
        let mut v = rig::preset("leaney-moog").unwrap();
        v["components"].as_object_mut().unwrap().remove("spool");
        v.as_object_mut().unwrap().remove("outputs");
        v["connections"] = serde_json::json!([
            ["command.out", "valve.spool"],
            ["supply.port", "valve.P"],
            ["tank.port", "valve.T"],
            ["valve.A", "cylinder.A", "friction.A"],
            ["valve.B", "cylinder.B", "friction.B"],
            ["cylinder.rod", "load.rod", "friction.rod"]
        ]);
        let s = crate::netlist::schematic(&v).unwrap();
        assert_eq!(s.input_unit(), Some("m"));
        assert!(!s.input_is_set_point());
        // the friction benches' drive takes the rod's velocity, shown as
        // the `command` column every rig writes (the drive's `command` probe)
        for bench in ["emps", "tudelft-seal-25"] {
            let s = schematic(bench);
            assert_eq!(s.inputs().count(), 1);
            assert_eq!(
                (s.input_channel().as_deref(), s.input_unit()),
                (Some("command"), Some("m/s"))
            );
        }
    }

    /// Every rig file's `command` output is in the unit of what it drives:
    /// a valve's normalised spool demand [-], a pump's drive voltage [V]
    /// (the closed-loop hybrid's controller output too: ±10 V), a
    /// bench drive's imposed velocity [m/s]; a closed loop's `reference`
    /// is the position set-point [m].
    #[test]
    fn every_rig_files_command_is_in_the_unit_of_what_it_drives() {
        let dir = std::path::Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/../../fixtures/rigs"));
        let expected = |name: &str| -> (&str, Option<&str>) {
            match name {
                "leaney-moog-closed-loop" => ("-", Some("m")),
                "wang-hybrid-closed-loop" => ("V", Some("m")),
                n if n.starts_with("leaney-moog") || n == "wang-valve-c10" => ("-", None),
                n if n.starts_with("wang-hybrid") => ("V", None),
                "tudelft-seal-25" | "tudelft-seal-257" | "emps" => ("m/s", None),
                other => panic!("a rig file the test does not know: {other}"),
            }
        };
        let mut seen = 0;
        for entry in std::fs::read_dir(dir).unwrap() {
            let path = entry.unwrap().path();
            if path.extension().and_then(|e| e.to_str()) != Some("json") {
                continue;
            }
            let name = path.file_stem().unwrap().to_str().unwrap().to_string();
            let v = rig::parse(&std::fs::read_to_string(&path).unwrap(), &name).unwrap();
            let c = rig::circuit(&v, crate::signal::Signal::Constant { value: 0.0 }).unwrap();
            let units: Vec<(String, &str)> =
                c.probes().into_iter().map(|p| (p.name, p.unit)).collect();
            let unit = |col: &str| units.iter().find(|(n, _)| n == col).map(|(_, u)| *u);
            let (command, reference) = expected(&name);
            // a bench's input is its drive's velocity, shown as `command`
            // or under the drive's own column
            if command == "m/s" {
                let s = crate::netlist::schematic(&v).unwrap();
                assert_eq!(s.input_unit(), Some("m/s"), "{name}");
            } else {
                assert_eq!(unit("command"), Some(command), "{name}: command");
            }
            assert_eq!(unit("reference"), reference, "{name}: reference");
            seen += 1;
        }
        assert!(seen >= 13, "{seen} rig files");
    }

    /// Two inputs, each driving its own first-order spool: each spool
    /// follows its own signal, `x(t) = u x_max (1 − e^(−t/τ))`; a missing,
    /// unknown or one-for-all signal is refused by name.
    #[test]
    fn several_inputs_each_drive_their_component() {
        use crate::netlist::{assemble, assemble_inputs, schematic};
        use crate::signal::Signal;
        use crate::simulation::Simulation;
        let spool = serde_json::json!({
            "type": "servo_spool_first_order", "stroke": 1e-3, "time_constant": 0.01
        });
        let v = serde_json::json!({
            "kind": "netlist", "name": "two",
            "components": {
                "a": { "type": "command_input" }, "b": { "type": "command_input" },
                "spool_a": spool, "spool_b": spool
            },
            "connections": [
                ["a.out", "spool_a.command"], ["b.out", "spool_b.command"],
                ["spool_a.spool", "x_a"], ["spool_b.spool", "x_b"]
            ]
        });
        let s = schematic(&v).unwrap();
        assert_eq!(s.inputs().count(), 2);
        assert_eq!((s.input_channel(), s.input_unit()), (None, None));
        let drive = vec![
            ("a".to_string(), Signal::Constant { value: 0.5 }),
            ("b".to_string(), Signal::Constant { value: -0.25 }),
        ];
        let t: Vec<f64> = (0..=50).map(|k| k as f64 * 1e-3).collect();
        let mut sim = Simulation::of_circuit(assemble_inputs(&s, &drive).unwrap());
        let run = sim.run(&t).unwrap();
        for (name, u) in [("spool_a.spool", 0.5), ("spool_b.spool", -0.25)] {
            let x = run.channel(name).unwrap();
            for (k, &tk) in t.iter().enumerate() {
                let exact = u * 1e-3 * (1.0 - (-tk / 0.01).exp());
                assert!(
                    (x[k] - exact).abs() < 1e-6 * 1e-3,
                    "{name} at {tk}: {} vs {exact}",
                    x[k]
                );
            }
        }
        let e = assemble_inputs(&s, &drive[..1]).unwrap_err().to_string();
        assert!(
            e.contains("components.b") && e.contains("no command"),
            "{e}"
        );
        let mut extra = drive.clone();
        extra.push(("spool_a".into(), Signal::Constant { value: 0.0 }));
        let e = assemble_inputs(&s, &extra).unwrap_err().to_string();
        assert!(e.contains("inputs.spool_a") && e.contains("a, b"), "{e}");
        let e = assemble(&s, Signal::Constant { value: 0.0 })
            .unwrap_err()
            .to_string();
        assert!(e.contains("several inputs"), "{e}");
    }
}
