//! The measured piston's travel against the declared model's on the same
//! command: a command in another unit or scale than the rig takes.

use super::{bulk, DataProblem, RigFacts};
use crate::data::{DataError, Record, Signal};
use crate::smooth::noise_sigma;

/// The measured travel this many times the declared model's on the same
/// command (either way) contradicts the command's unit or scale (the gain
/// check's factor, [`super::GAIN_FACTOR`]: a wrong supply, a leak or a
/// friction level the loop can find move the travel by far less).
const TRAVEL_FACTOR: f64 = super::GAIN_FACTOR;

/// After the declared model's first run on the record's command: the
/// piston's travel (the range between the 0.5th and 99.5th percentiles of
/// the position) measured and simulated, as an error naming the command
/// column when one is more than 20 times the other. A
/// valve rig's normalised demand given to a pump rig that takes volts moves
/// the simulated piston 2.2 mm where the record's moves 81 mm (it was
/// diagnosed, the residual resembling "a Coulomb level four times
/// declared"); the header `command` without a unit does not say. Whatever
/// drives the model then is not the record's input, so the loop would fit
/// noise: a refusal, as for a constant command. This needs no steady gain
/// of the rig ([`RigFacts::velocity_gain`] is the valve circuit's only), so
/// it holds for any netlist rig. Skipped for a closed-loop record (the
/// controller makes both follow the reference) and where the position
/// already has a data problem (its scale is then unknown).
pub fn travel_error(
    rec: &Record,
    simulated: &[f64],
    f: &RigFacts,
    problems: &[DataProblem],
) -> Result<(), DataError> {
    if rec.get(Signal::Reference).is_some()
        || problems
            .iter()
            .any(|p| p.channel == Signal::Position.name())
    {
        return Ok(());
    }
    let (Some(x), Some(_)) = (rec.get(Signal::Position), rec.get(Signal::Command)) else {
        return Ok(());
    };
    if x.len() < 50 || simulated.len() < 50 {
        return Ok(());
    }
    let span = |y: &[f64]| {
        let (lo, hi) = bulk(y);
        hi - lo
    };
    let (meas, sim) = (span(x), span(simulated));
    let sigma = noise_sigma(&rec.time, x);
    let moves = |d| super::input::is_motion(d, sigma, f.stroke);
    let ratio = if moves(meas) && meas > TRAVEL_FACTOR * sim {
        meas / sim.max(f64::MIN_POSITIVE)
    } else if moves(sim) && sim > TRAVEL_FACTOR * meas {
        meas / sim
    } else {
        return Ok(());
    };
    let times = if (1e-3..1e4).contains(&ratio) {
        format!("{ratio:.3}")
    } else {
        format!("{ratio:.3e}")
    };
    let column = match rec.units.get(&Signal::Command) {
        Some(u) => format!("command [{u}]"),
        None => "command".to_string(),
    };
    let unit = match f.command_unit {
        Some("V") => "a drive voltage in V",
        Some("-") => "a normalised spool demand (-1 to 1)",
        _ => "in the rig's unit",
    };
    Err(DataError::UnitContradictsRig {
        file: rec.source.clone(),
        column,
        reason: format!(
            "on this command the declared rig moves the piston over {} m, the record's over {} m ({times} times as far): the command is not in the unit or scale the rig takes ({unit}; a valve's normalised demand given to a pump rig?), or the position's unit or the rig is not this record's: check the command column and the rig",
            super::num(sim),
            super::num(meas)
        ),
    })
}

#[cfg(test)]
mod tests {
    use super::travel_error;
    use crate::data::{DataError, Signal};
    use crate::data_checks::tests::{facts, moving, rec};

    /// The tests' piston travels 64 mm; a model that moves it 2 mm on
    /// the same command (a command 30 times too small for the rig) is an
    /// error naming the command column.
    #[test]
    fn a_travel_far_off_the_models_is_an_error() {
        let (u, x) = moving(2000);
        let sim: Vec<f64> = x.iter().map(|v| v / 30.0).collect();
        let r = rec(&[(Signal::Command, u), (Signal::Position, x)]);
        match travel_error(&r, &sim, &facts(), &[]) {
            Err(e @ DataError::UnitContradictsRig { .. }) => {
                let s = e.to_string();
                assert!(s.starts_with("test: row 1, column 'command'"), "{s}");
            }
            other => panic!("{other:?}"),
        }
        // the other way: the model moves 30 times as far as the record
        let (u, x) = moving(2000);
        let sim = x.clone();
        let small: Vec<f64> = x.iter().map(|v| v / 30.0).collect();
        let r = rec(&[(Signal::Command, u), (Signal::Position, small)]);
        assert!(travel_error(&r, &sim, &facts(), &[]).is_err());
    }

    /// A model that travels 3 times less or more than the record (a wrong
    /// supply, a leak) is not an error; nor is a record at rest that the
    /// model holds at rest.
    #[test]
    fn a_travel_near_the_models_is_not_an_error() {
        let (u, x) = moving(2000);
        for k in [3.0, 1.0 / 3.0] {
            let sim: Vec<f64> = x.iter().map(|v| v * k).collect();
            let r = rec(&[(Signal::Command, u.clone()), (Signal::Position, x.clone())]);
            assert_eq!(travel_error(&r, &sim, &facts(), &[]), Ok(()));
        }
        let e = crate::smooth::gaussian_noise(2000, 4);
        let still: Vec<f64> = e.iter().map(|v| 2e-5 * v).collect();
        let r = rec(&[(Signal::Command, u), (Signal::Position, still.clone())]);
        assert_eq!(travel_error(&r, &still, &facts(), &[]), Ok(()));
    }
}
