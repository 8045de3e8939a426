//! The settings a user gives a run by name — the method ([`Solver`]) and the
//! numbers ([`Setting`]) — with their rules stated once, for every front end
//! that takes them: the CLI's flags, the Python package's arguments, the
//! FMU's solver parameters and [`RunOptions`](super::RunOptions) itself.

use hydrocyl_integrators::Method;

/// The integration method, by the names the CLI accepts.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Solver {
    /// Automatic (default): Dormand–Prince 5(4) while the problem is not
    /// stiff, Rosenbrock while it is, switched by the stiffness the run shows
    /// ([`Method::Auto`]; the choice is in
    /// [`Stats::stiff_steps`](hydrocyl_integrators::Stats::stiff_steps) and
    /// [`Stats::switches`](hydrocyl_integrators::Stats::switches)).
    Auto,
    /// Dormand–Prince 5(4) (Simulink's ode45, the thesis's solver).
    Dp45,
    /// Stiff Rosenbrock.
    Rosenbrock,
    /// Fixed-step RK4 (step `RunOptions::rk4_step`).
    Rk4,
    /// Exponential Rosenbrock–Euler ([`Method::Exponential`]): fixed steps
    /// of at most `RunOptions::rk4_step` landing on every output time; a
    /// stiff mode linear over a step (LuGre's bristle) exactly, the output
    /// smooth in the parameters (a fit's finite differences).
    Exponential,
}

impl Solver {
    /// Every method, in the order the names are listed to a user.
    pub const ALL: [Solver; 5] = [
        Solver::Auto,
        Solver::Dp45,
        Solver::Rosenbrock,
        Solver::Rk4,
        Solver::Exponential,
    ];

    /// The integrator crate's method.
    pub fn method(self) -> Method {
        match self {
            Solver::Auto => Method::Auto,
            Solver::Dp45 => Method::DormandPrince45,
            Solver::Rosenbrock => Method::Rosenbrock,
            Solver::Rk4 => Method::Rk4,
            Solver::Exponential => Method::Exponential,
        }
    }
    /// Whether it takes fixed steps of `RunOptions::rk4_step` (at most).
    pub fn fixed_step(self) -> bool {
        matches!(self, Solver::Rk4 | Solver::Exponential)
    }
    /// The CLI name.
    pub fn name(self) -> &'static str {
        match self {
            Solver::Auto => "auto",
            Solver::Dp45 => "dp45",
            Solver::Rosenbrock => "rosenbrock",
            Solver::Rk4 => "rk4",
            Solver::Exponential => "exponential",
        }
    }
    /// Parses a CLI name (`auto`, `dp45`, `rosenbrock`, `rk4`, `exponential`).
    pub fn parse(s: &str) -> Option<Self> {
        Solver::ALL.into_iter().find(|m| m.name() == s)
    }
    /// [`Solver::parse`], or why not: "unknown method `euler` (use auto,
    /// dp45, rosenbrock, rk4 or exponential)".
    pub fn parse_or_why(s: &str) -> Result<Self, String> {
        Solver::parse(s).ok_or_else(|| {
            let names: Vec<&str> = Solver::ALL.iter().map(|m| m.name()).collect();
            let (last, rest) = names.split_last().expect("methods");
            format!("unknown method `{s}` (use {} or {last})", rest.join(", "))
        })
    }
}

impl From<Method> for Solver {
    fn from(m: Method) -> Self {
        match m {
            Method::Auto => Solver::Auto,
            Method::DormandPrince45 => Solver::Dp45,
            Method::Rosenbrock => Solver::Rosenbrock,
            Method::Rk4 => Solver::Rk4,
            Method::Exponential => Solver::Exponential,
        }
    }
}

/// The smallest relative tolerance taken ([`Setting::Rtol`]): below it
/// (about 50 machine epsilons) the error estimates are rounding noise and
/// the step falls to nothing, which the solver would report as a rate out
/// of its physical range.
pub const RTOL_FLOOR: f64 = 1e-14;

/// The rule a relative tolerance in (0, [`RTOL_FLOOR`]) breaks.
const RTOL_BELOW_FLOOR: &str = "below 1e-14 (about 50 machine epsilons), a tolerance double precision cannot meet; use a value in [1e-14, 1), e.g. 1e-6";

/// A number a user sets a run with, and the rule it must meet.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Setting {
    /// The relative tolerance ([`RunOptions::rtol`](super::RunOptions::rtol)).
    Rtol,
    /// The largest step \[s\] ([`RunOptions::h_max`](super::RunOptions::h_max)).
    HMax,
    /// The fixed step \[s\]
    /// ([`RunOptions::rk4_step`](super::RunOptions::rk4_step)).
    Rk4Step,
}

impl Setting {
    /// The rule, as a user reads it after the value: "must be in [1e-14, 1),
    /// e.g. 1e-6" (the range [`Setting::check`] enforces). A relative
    /// tolerance in (0, [`RTOL_FLOOR`]) gets a message of its own, which
    /// says why the floor is there.
    pub fn rule(self) -> &'static str {
        match self {
            Setting::Rtol => "must be in [1e-14, 1), e.g. 1e-6",
            Setting::HMax => "must be > 0 [s] (inf: no bound), e.g. 1e-2",
            Setting::Rk4Step => "must be finite and > 0 [s], e.g. 2e-5",
        }
    }
    /// Whether `value` meets the rules ([`Setting::check`]).
    pub fn holds(self, value: f64) -> bool {
        self.check(value).is_ok()
    }
    /// `value`, or the rule it breaks: [`Setting::rule`], or for a relative
    /// tolerance below [`RTOL_FLOOR`] that it asks for more digits than
    /// double precision carries.
    pub fn check(self, value: f64) -> Result<f64, &'static str> {
        let in_range = match self {
            Setting::Rtol => value > 0.0 && value < 1.0,
            Setting::HMax => value > 0.0,
            Setting::Rk4Step => value > 0.0 && value.is_finite(),
        };
        if !in_range {
            Err(self.rule())
        } else if self == Setting::Rtol && value < RTOL_FLOOR {
            Err(RTOL_BELOW_FLOOR)
        } else {
            Ok(value)
        }
    }
    /// `value`, or the message every front end gives, with the setting as
    /// the front end names it: "`--rtol` 0: must be in [1e-14, 1), e.g. 1e-6"
    /// (`name` = `--rtol`; `rtol` in Python and in `RunOptions`), the value
    /// as [`Setting::shown`].
    pub fn check_named(self, name: &str, value: f64) -> Result<f64, String> {
        self.check(value)
            .map_err(|rule| format!("{name} {}: {rule}", Setting::shown(value)))
    }
    /// A setting's value in a message: as Rust writes it (`0`, `-1`, `2e-5`
    /// as `0.00002`), but in exponent form where that would be a long run
    /// of zeros (`1e-300`, not 300 digits).
    pub fn shown(value: f64) -> String {
        let a = value.abs();
        if a != 0.0 && a.is_finite() && !(1e-6..1e16).contains(&a) {
            format!("{value:e}")
        } else {
            format!("{value}")
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_method_parses_by_its_name_and_a_wrong_name_lists_them() {
        for m in Solver::ALL {
            assert_eq!(Solver::parse(m.name()), Some(m));
            assert_eq!(Solver::from(m.method()), m);
        }
        assert_eq!(
            Solver::parse_or_why("euler").unwrap_err(),
            "unknown method `euler` (use auto, dp45, rosenbrock, rk4 or exponential)"
        );
    }

    #[test]
    fn settings_refuse_what_their_rule_refuses() {
        for v in [0.0, 1.0, -1e-6, f64::NAN] {
            assert_eq!(Setting::Rtol.check(v), Err(Setting::Rtol.rule()));
        }
        assert_eq!(Setting::Rtol.check(1e-6), Ok(1e-6));
        // below the floor: its own rule, the value in exponent form
        assert_eq!(Setting::Rtol.check(RTOL_FLOOR), Ok(RTOL_FLOOR));
        for v in [1e-15, 1e-300, f64::MIN_POSITIVE] {
            assert_eq!(Setting::Rtol.check(v), Err(RTOL_BELOW_FLOOR));
            assert!(!Setting::Rtol.holds(v));
        }
        assert!(RTOL_BELOW_FLOOR.starts_with(&format!("below {RTOL_FLOOR:e} ")));
        assert!(RTOL_BELOW_FLOOR.contains(&format!("[{RTOL_FLOOR:e}, 1)")));
        // the rule states the range the check enforces
        assert!(Setting::Rtol
            .rule()
            .contains(&format!("[{RTOL_FLOOR:e}, 1)")));
        assert_eq!(
            Setting::Rtol.check_named("--rtol", 1e-300).unwrap_err(),
            format!("--rtol 1e-300: {RTOL_BELOW_FLOOR}")
        );
        assert_eq!(
            Setting::Rtol.check_named("rtol", 0.0).unwrap_err(),
            "rtol 0: must be in [1e-14, 1), e.g. 1e-6"
        );
        for s in [Setting::HMax, Setting::Rk4Step] {
            for v in [0.0, -1.0, f64::NAN] {
                assert!(s.check(v).is_err(), "{s:?} {v}");
            }
            assert_eq!(s.check(3.0), Ok(3.0));
        }
        // a largest step may be unbounded, a fixed step may not
        assert!(Setting::HMax.check(f64::INFINITY).is_ok());
        assert!(Setting::Rk4Step.check(f64::INFINITY).is_err());
    }
}
