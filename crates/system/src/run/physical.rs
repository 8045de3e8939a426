//! Whether a run's solution is physical: the signs of an integration that
//! blew up (a non-finite value, a chamber pressure far below absolute
//! vacuum), found the same way for every client (the CLI names its remedy,
//! Python raises `SimulationError`).

use super::{Run, Solver};
use crate::netlist::registry::ComponentType;
use crate::rig::ABSOLUTE_VACUUM_GAUGE_PA;

/// The registry's name of the entrained-air parameter (volume fraction at
/// atmospheric pressure) of the component types that model it: the remedy
/// for a chamber of constant-B liquid cavitating, proposed only where the
/// chamber's type has it ([`Cause::Cavitation`]).
pub const AIR_PARAMETER: &str = "air_fraction";

/// Pressures far below absolute vacuum (ten times its depth) or a
/// non-finite value: the solution is not physical \[Pa\].
pub const ABSURD_PRESSURE_PA: f64 = 10.0 * ABSOLUTE_VACUUM_GAUGE_PA;

/// A chamber pressure between this and [`ABSURD_PRESSURE_PA`] from an
/// error-controlled solver is read as the constant-B liquid cavitating
/// (finite, the same with any tolerance); below it, as a blow-up \[Pa\].
pub const LIQUID_TENSION_LIMIT_PA: f64 = -1.0e8;

/// The first sample of a run that is not physical.
#[derive(Clone, Debug, PartialEq)]
pub struct Unphysical {
    /// `<channel> = <value> <unit> at t = <time> s`.
    pub what: String,
    /// The cylinder whose chamber pressure it is, when it is a chamber
    /// pressure (finite, far below vacuum).
    pub chamber_of: Option<String>,
    /// The value itself.
    pub value: f64,
    /// Its sample: [`Run::time`]`[sample]`, [`Run::state`]`(sample)`.
    pub sample: usize,
}

/// What a solution that is not physical says about its cause, for a
/// client to word with its own names for the settings.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Cause {
    /// An error-controlled solver met its tolerance on a finite, moderate
    /// tension: the oil, a liquid of constant bulk modulus, has left its
    /// range in a chamber of `cylinder` (give it entrained air), unless
    /// the run is unstable after all (a smaller tolerance tells).
    Cavitation {
        /// The cylinder whose chamber it is.
        cylinder: String,
        /// The parameter path (`<cylinder>.air_fraction`) that gives the
        /// cylinder's chambers entrained air, when its component type has
        /// one ([`AIR_PARAMETER`]); `None` when it has none (or its type is
        /// not known) and nothing may be proposed to set.
        air: Option<String>,
        /// The cylinder's component type (`generalised_cylinder`), when
        /// known: the one the message says lacks the parameter.
        type_name: Option<&'static str>,
    },
    /// A fixed-step method ([`Solver::fixed_step`]): its step is too long
    /// for the rig.
    StepTooLong,
    /// An error-controlled solver blew up: another method or a smaller
    /// tolerance.
    Unstable,
}

impl Unphysical {
    /// Whether it reads as the liquid's tension rather than a blow-up: a
    /// finite chamber pressure above [`LIQUID_TENSION_LIMIT_PA`].
    pub fn is_tension(&self) -> bool {
        self.chamber_of.is_some() && self.value.is_finite() && self.value > LIQUID_TENSION_LIMIT_PA
    }

    /// Its cause, from a run by `solver`; `type_of` gives a component's
    /// registry type by its instance name (the rig's schematic), so that a
    /// remedy names only a parameter the component has.
    pub fn cause(
        &self,
        solver: Solver,
        type_of: impl Fn(&str) -> Option<&'static ComponentType>,
    ) -> Cause {
        match &self.chamber_of {
            Some(c) if !solver.fixed_step() && self.is_tension() => {
                let ty = type_of(c);
                Cause::Cavitation {
                    cylinder: c.clone(),
                    air: ty
                        .and_then(|t| t.param(AIR_PARAMETER))
                        .map(|p| format!("{c}.{}", p.name)),
                    type_name: ty.map(|t| t.name),
                }
            }
            _ if solver.fixed_step() => Cause::StepTooLong,
            _ => Cause::Unstable,
        }
    }
}

/// The component types with chamber pressure probes (`p1`) that have the
/// entrained-air parameter ([`AIR_PARAMETER`]), in catalog order: where a
/// remedy for a chamber whose type has none can point.
pub fn chamber_types_with_air() -> Vec<&'static str> {
    crate::netlist::registry::types()
        .iter()
        .filter(|t| t.param(AIR_PARAMETER).is_some() && t.probes.iter().any(|(p, _)| *p == "p1"))
        .map(|t| t.name)
        .collect()
}

/// The cylinder whose chamber pressure probe `<component>.p1` or
/// `<component>.p2` is ([`Channel::probe`](super::Channel::probe): whatever
/// the column is called, `p1` on a preset, `pd1` where a netlist renames it).
pub fn chamber_of(probe: &str) -> Option<&str> {
    probe
        .strip_suffix(".p1")
        .or_else(|| probe.strip_suffix(".p2"))
        .filter(|c| !c.is_empty())
}

impl Run {
    /// The first sample that is not physical (a non-finite value in any
    /// channel, a chamber pressure below [`ABSURD_PRESSURE_PA`]), if any.
    pub fn unphysical(&self) -> Option<Unphysical> {
        self.channels.iter().find_map(|c| {
            let chamber = c.unit == "Pa" && chamber_of(&c.probe).is_some();
            let floor = if chamber {
                ABSURD_PRESSURE_PA
            } else {
                f64::NEG_INFINITY
            };
            // NaN and ±∞ fail the first test; no early exit inside a chunk,
            // so that the test is made on several values at once
            let ok = |v: f64| v.is_finite() & (v >= floor);
            if c.values
                .chunks(16)
                .all(|ch| ch.iter().fold(true, |a, &v| a & ok(v)))
            {
                return None;
            }
            let k = c.values.iter().position(|&v| !ok(v))?;
            let v = c.values[k];
            Some(Unphysical {
                what: format!("{} = {v:e} {} at t = {} s", c.name, c.unit, self.time[k]),
                chamber_of: chamber_of(&c.probe)
                    .filter(|_| chamber && v.is_finite())
                    .map(str::to_string),
                value: v,
                sample: k,
            })
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::run::Channel;

    /// A run of one channel `name` reading probe `probe`.
    fn run_of(name: &str, probe: &str, unit: &'static str, values: Vec<f64>) -> Run {
        Run {
            time: (0..values.len()).map(|k| k as f64 * 0.1).collect(),
            channels: vec![Channel {
                name: name.into(),
                unit,
                probe: probe.into(),
                values,
            }],
            ..Run::default()
        }
    }

    /// A run of one channel named after its probe.
    fn run(probe: &str, unit: &'static str, values: Vec<f64>) -> Run {
        run_of(probe, probe, unit, values)
    }

    #[test]
    fn a_blow_up_a_tension_and_a_good_run_are_told_apart() {
        // within ten times the depth of vacuum: physical enough
        assert_eq!(
            run("cylinder.p1", "Pa", vec![1e5, -5e5, 2e6]).unphysical(),
            None
        );
        // far below vacuum, finite and moderate: the liquid's tension
        let u = run("damper.p2", "Pa", vec![1e5, -4e6])
            .unphysical()
            .unwrap();
        assert_eq!(u.chamber_of.as_deref(), Some("damper"));
        assert!(u.is_tension());
        assert_eq!(u.what, "damper.p2 = -4e6 Pa at t = 0.1 s");
        assert_eq!(
            u.cause(Solver::Auto, |_| None),
            Cause::Cavitation {
                cylinder: "damper".into(),
                air: None,
                type_name: None,
            }
        );
        // the same from a fixed step: the step is too long
        assert_eq!(u.cause(Solver::Exponential, |_| None), Cause::StepTooLong);
        // a renamed column is still the chamber it reads
        let u = run_of("p1", "cylinder.p1", "Pa", vec![-1e9])
            .unphysical()
            .unwrap();
        assert_eq!(u.chamber_of.as_deref(), Some("cylinder"));
        assert!(!u.is_tension());
        // far beyond the tension limit: a blow-up
        assert_eq!(u.cause(Solver::Dp45, |_| None), Cause::Unstable);
        // a non-finite value in any channel; a pressure that is not a
        // chamber's may be as low as it likes
        let u = run("position", "m", vec![0.0, f64::NAN])
            .unphysical()
            .unwrap();
        assert_eq!((u.chamber_of, u.what.contains("NaN")), (None, true));
        assert_eq!(run("ps", "Pa", vec![-1e7]).unphysical(), None);
    }

    #[test]
    fn the_cavitation_remedy_names_air_only_where_the_chambers_type_has_it() {
        use crate::netlist::registry::lookup;
        let u = run("cylinder.p1", "Pa", vec![1e5, -4e6])
            .unphysical()
            .unwrap();
        // the fundamental cylinder models entrained air
        assert_eq!(
            u.cause(Solver::Auto, |_| lookup("cylinder")),
            Cause::Cavitation {
                cylinder: "cylinder".into(),
                air: Some("cylinder.air_fraction".into()),
                type_name: Some("cylinder"),
            }
        );
        assert_eq!(chamber_types_with_air(), ["cylinder"]);
        // the generalised one does not: nothing to set is proposed
        assert_eq!(
            u.cause(Solver::Auto, |_| lookup("generalised_cylinder")),
            Cause::Cavitation {
                cylinder: "cylinder".into(),
                air: None,
                type_name: Some("generalised_cylinder"),
            }
        );
    }
}
