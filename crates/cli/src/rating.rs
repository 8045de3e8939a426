//! A rig's rating against its command: a pump driven by the run's input
//! has a maximum speed (`displacement` and `max_speed`, Table 4-2 on the
//! hybrid presets; [`hydrocyl_system::netlist::Schematic::input_rating`]).
//! A command whose steady flow turns the pump faster is warned of once, with
//! the count and the largest, as a valve command beyond its stroke is. It is
//! not limited: a motor's maximum speed is a rating, not a stop (the spool's
//! stroke is one, and the valve clamps there); the identified model's flow
//! follows the command past it. Either is the rig's [`CommandLimit`]
//! (from its one reading, [`crate::rigfile::Checked::command_limit`]),
//! warned of here after the command file's name.

use hydrocyl_system::rig::CommandLimit;
use hydrocyl_system::signal::Signal;
use std::path::Path;

/// The samples of a command table beyond `limit` in magnitude, and the
/// largest in magnitude with its time (`(0, NaN)` for no samples).
pub fn beyond(signal: &Signal, limit: f64) -> (usize, (f64, f64)) {
    let Signal::Table { time_s, value } = signal else {
        return (0, (0.0, f64::NAN));
    };
    crate::command::beyond(time_s, value, limit)
}

/// The warning of `outside` command samples of `file` beyond the rig's
/// command limit (a pump's rating, or the spool's stroke, where the valve
/// clamps the command to ±1), the largest in magnitude `peak` = (value,
/// time); `None` when none is. The text is the library's
/// ([`CommandLimit::warning`], which Python warns with too), after the
/// file's name.
pub fn warning(
    file: &Path,
    limit: &CommandLimit,
    outside: usize,
    peak: (f64, f64),
) -> Option<String> {
    limit
        .warning(outside, peak)
        .map(|w| format!("hydrocyl: warning: {}: {w}", file.display()))
}

/// Prints [`warning`], if any, on standard error.
pub fn warn(file: &Path, limit: &CommandLimit, outside: usize, peak: (f64, f64)) {
    if let Some(w) = warning(file, limit, outside, peak) {
        crate::console::note(format_args!("{w}"));
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use hydrocyl_system::netlist::InputRating;

    /// Revolutions per minute in one radian per second.
    const RPM_PER_RAD_S: f64 = 60.0 / (2.0 * std::f64::consts::PI);

    /// Table 4-2's pump: 2.05 cc/rev, 8000 rpm, at 1.07e-5 m^3/(s V): 25.5 V.
    fn wang() -> InputRating {
        let d = 2.05e-6 / (2.0 * std::f64::consts::PI);
        let w = 8000.0 / RPM_PER_RAD_S;
        InputRating {
            component: "pump".into(),
            speed_per_command: 1.07e-5 / d,
            max_speed: w,
            limit: w * d / 1.07e-5,
        }
    }

    #[test]
    fn a_command_past_the_rating_is_counted_and_its_largest_named() {
        let r = wang();
        assert!((r.limit - 25.545).abs() < 1e-3, "{}", r.limit);
        let s = Signal::table(vec![0.0, 0.5, 1.0], vec![0.0, 50.0, -30.0]).unwrap();
        let (n, peak) = beyond(&s, r.limit);
        assert_eq!((n, peak), (2, (50.0, 0.5)));
        let limit = CommandLimit::Rating(r);
        let w = warning(Path::new("bigv.csv"), &limit, n, peak).unwrap();
        for part in [
            "bigv.csv: 2 command samples",
            "8000 rpm",
            "25.545 V",
            "50 V at t = 0.5 s",
            "15659 rpm",
            "not limited",
        ] {
            assert!(w.contains(part), "{part}: {w}");
        }
        assert_eq!(warning(Path::new("c.csv"), &limit, 0, (10.0, 0.1)), None);
        // a spool demand: the stroke's text, after the file's name too
        let w = warning(Path::new("u.csv"), &CommandLimit::Stroke, 1, (1.5, 0.2)).unwrap();
        assert!(
            w.starts_with(
                "hydrocyl: warning: u.csv: 1 command samples outside ±1 (largest 1.5 at t = 0.2 s)"
            ),
            "{w}"
        );
    }
}
