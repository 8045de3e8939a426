//! `hydrocyl simulate` on a friction-bench rig file (`spec/measured-data.md`:
//! a netlist whose `identify` section names the `friction-bench` model, or an
//! older `friction-bench` file read as that netlist): the drive imposes the motion, so the
//! bench's input is not a command but the motion itself. The `--command` file
//! is a record in the measured-data format (through the rig's column map) with
//! `time`, `position` or `velocity`, and `p1`/`p2` where the bench has
//! pressures; the output adds the predicted load-cell `force`:
//! `time, position, velocity, p1, p2, force` (SI). Velocity and acceleration
//! come from the same smoother `diagnose` uses; the bristle starts from the
//! record's measured force when it has one, else at rest. The bench runs as
//! its netlist through the one run path (`FrictionBench::simulate`:
//! the record's velocity, acceleration and pressures are the netlist's inputs).

use crate::error::CliError;
use hydrocyl_identify::bench::{self, bench_signals, BenchInputs, FrictionBench};
use hydrocyl_identify::data::{Record, Signal};
use std::path::Path;

/// A friction-bench rig file read for the CLI ([`bench::is_bench_rig`]),
/// or `None` for any other `--rig`: the bench (the circuit and the
/// identification section of its netlist after `sets`) and its netlist
/// (what `--print-rig` shows; `--set` takes its `<component>.<parameter>`
/// paths). Errors name the JSON path and line.
pub fn load(
    spec: &str,
    sets: &[String],
) -> Result<Option<(FrictionBench, serde_json::Value)>, CliError> {
    use hydrocyl_system::rig;
    if rig::preset(spec).is_some() {
        return Ok(None);
    }
    // read as every rig file is (a byte-order mark, an older kind)
    let is_bench = rig::load(spec).is_ok_and(|v| bench::is_bench_rig(&v));
    if !is_bench {
        return Ok(None);
    }
    let err = |e: rig::RigError| CliError::Input(e.to_string());
    let mut net = rig::load(spec).map_err(err)?;
    let read = |net: &serde_json::Value| {
        FrictionBench::from_rig(net).map_err(|e| CliError::Input(format!("{spec}: {e}")))
    };
    let as_json = |b: &FrictionBench| serde_json::to_value(b).ok();
    // a value out of range blames the `--set` that gave it, not the file
    let check = |net: &serde_json::Value| {
        rig::check(net).map_err(|e| err(crate::rigfile::at_line_or_set(e, spec, sets)))
    };
    for s in sets {
        let before = as_json(&read(&net)?);
        let old = net.clone();
        rig::apply_set(&mut net, s).map_err(err)?;
        if net == old {
            continue;
        }
        check(&net)?;
        // the bench runs as its standard circuit, read into `FrictionBench`:
        // a set that changes the file but not the bench would be dropped
        if as_json(&read(&net)?) == before {
            return Err(CliError::Input(match switched_off_by(&old, s) {
                Some(why) => format!("--set {s}: {why}"),
                None => format!(
                    "--set {s}: the friction-bench model does not use this parameter (a bench runs as its standard circuit: the drive's mass and load-cell sign, the piston's areas, the friction law; `--print-rig` lists the rest)"
                ),
            }));
        }
    }
    check(&net)?;
    let bench = read(&net)?;
    Ok(Some((bench, net)))
}

/// Why a `--set` of a friction law's parameter (`friction.stribeck_velocity`)
/// left the bench unchanged where the parameter belongs to an effect that is
/// off in `net` (the netlist before the set): the bench reads an effect as
/// on only where its first parameter (`stiction`, `sigma0`) is given off
/// its default ([`FrictionBench::from_rig`]), so the others are unused until
/// it is. `None` for any other parameter.
fn switched_off_by(net: &serde_json::Value, set: &str) -> Option<String> {
    use hydrocyl_identify::bench::BENCH_EFFECTS;
    use hydrocyl_system::netlist::identify::{bench_law_params, bench_law_stiction_is_coulomb};
    use hydrocyl_system::netlist::registry::{self, Default};
    let path = set.split_once('=')?.0.trim();
    let path = path.strip_prefix("components.").unwrap_or(path);
    let (comp, param) = path.split_once('.')?;
    let ty = net.get("components")?.get(comp)?.get("type")?.as_str()?;
    let law = |catalog: String| bench_law_params(ty, &catalog, true).unwrap_or_default();
    BENCH_EFFECTS.iter().find_map(|&id| {
        let (first, rest) = id.params().split_first()?;
        rest.iter()
            .any(|q| law(format!("{}.{}", id.id(), q.name)).contains(&param))
            .then_some(())?;
        let on = law(format!("{}.{}", id.id(), first.name));
        let on = on.first()?;
        let spec = registry::lookup(ty)?.param(on)?;
        let unit = if spec.unit.is_empty() || spec.unit == "-" {
            String::new()
        } else {
            format!(", in {}", spec.unit)
        };
        let given = match spec.default {
            Default::Value(d) => format!("set off its default {d}"),
            _ => "set".to_string(),
        };
        let coulomb = if bench_law_stiction_is_coulomb(ty) && on.contains("stiction") {
            " and differs from the Coulomb level"
        } else {
            ""
        };
        Some(format!(
            "the friction-bench model uses `{comp}.{param}` only where `{comp}.{on}` is {given}{coulomb} (the `{}` effect is off without it, as in this file): set it too (--set {comp}.{on}=VALUE{unit})",
            id.id()
        ))
    })
}

/// `true` when `simulate` runs the rig `spec` on a record's motion
/// ([`load`], [`simulate`]): a friction-bench rig file whose netlist takes
/// the record's acceleration or pressures as inputs of their own
/// (`command_input` components: an older `friction-bench` file, the
/// netlists of `fixtures/measured/`). A bench preset's netlist (`emps`,
/// `tudelft-seal-25`), whose one input is the drive's velocity, is
/// simulated on a command as the preset is, by name, as a file or printed
/// by `--print-rig`; `diagnose` reads each of them as the same bench.
pub fn runs_on_motion(spec: &str) -> bool {
    use hydrocyl_system::rig;
    rig::preset(spec).is_none()
        && rig::load(spec).is_ok_and(|v| {
            bench::is_bench_rig(&v)
                && v.get("components")
                    .and_then(|c| c.as_object())
                    .is_some_and(|c| {
                        c.values().any(|i| {
                            i.get("type").and_then(|t| t.as_str()) == Some("command_input")
                        })
                    })
        })
}

/// Simulates `bench` on the motion in `input`; returns the output CSV text.
pub fn simulate(bench: &FrictionBench, input: &Path) -> Result<String, CliError> {
    let mut rec =
        Record::read_mapped(input, &bench.columns).map_err(|e| CliError::Input(e.to_string()))?;
    if rec.get(Signal::Position).is_none() && rec.get(Signal::Velocity).is_none() {
        return Err(CliError::Input(format!(
            "{}: a friction bench is driven by its motion: the file needs a `position` or `velocity` column",
            input.display()
        )));
    }
    let measured_force = rec.get(Signal::Force).is_some();
    if !measured_force {
        rec.signals.insert(Signal::Force, vec![0.0; rec.len()]);
    }
    let (s, _) = bench_signals(&rec, None, bench.steady_state)
        .map_err(|e| CliError::Input(e.to_string()))?;
    let inputs = BenchInputs::of(&s).map_err(CliError::Input)?;
    let force = if measured_force {
        bench.simulate(&s, &inputs)
    } else {
        bench.simulate_from_rest(&s, &inputs)
    }
    .map_err(|e| CliError::Input(format!("{}: {e}", input.display())))?;
    if let Some(i) = force.iter().position(|f| !f.is_finite()) {
        return Err(CliError::Input(format!(
            "{}: the bench model gave a non-finite force at row {} (t = {} s)",
            input.display(),
            i + 2,
            s.t[i]
        )));
    }
    let mut out = String::from("time,position,velocity,p1,p2,force\n");
    for (i, f) in force.iter().enumerate() {
        out.push_str(&format!(
            "{:.9e},{:.9e},{:.9e},{:.9e},{:.9e},{f:.9e}\n",
            s.t[i], s.x[i], s.v[i], s.p1[i], s.p2[i]
        ));
    }
    Ok(out)
}
