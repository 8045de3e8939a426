//! Whether a run's solution is physical, found the same way for every
//! client (the CLI words it with its flags, Python with its arguments):
//! the signs of an integration that blew up (a non-finite value, a chamber
//! pressure below the liquid's tension limit: [`Run::unphysical`], an
//! error), and the known limit of the constant-bulk-modulus liquid, a
//! chamber pulled far below absolute vacuum but not that far
//! ([`Run::deep_cavitation`], a warning: the run is kept).

use super::{Run, Solver};
use crate::netlist::registry::ComponentType;
use crate::rig::ABSOLUTE_VACUUM_GAUGE_PA;

/// The registry's name of the entrained-air parameter (volume fraction at
/// atmospheric pressure) of the component types that model it: the remedy
/// for a chamber of constant-B liquid cavitating, proposed only where the
/// chamber's type has it ([`AirRemedy`]).
pub const AIR_PARAMETER: &str = "air_fraction";

/// A chamber pressure below this (ten times the depth of absolute vacuum)
/// is far outside the constant-B liquid's range: the chamber cavitates
/// ([`Run::deep_cavitation`]) \[Pa\].
pub const ABSURD_PRESSURE_PA: f64 = 10.0 * ABSOLUTE_VACUUM_GAUGE_PA;

/// A chamber pressure between this and [`ABSURD_PRESSURE_PA`] is read as the
/// constant-B liquid cavitating (finite, the same with any method and
/// tolerance); below it, as a blow-up ([`Run::unphysical`]) \[Pa\].
pub const LIQUID_TENSION_LIMIT_PA: f64 = -1.0e8;

/// The first sample of a run that is not physical: a non-finite value in
/// any channel, or a chamber pressure below [`LIQUID_TENSION_LIMIT_PA`].
#[derive(Clone, Debug, PartialEq)]
pub struct Unphysical {
    /// `<channel> = <value> <unit> at t = <time> s`.
    pub what: String,
    /// The cylinder whose chamber pressure it is, when it is a chamber
    /// pressure (finite, below the tension limit).
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
    /// A fixed-step method ([`Solver::fixed_step`]): its step is too long
    /// for the rig.
    StepTooLong,
    /// An error-controlled solver blew up: another method or a smaller
    /// tolerance.
    Unstable,
}

impl Unphysical {
    /// Its cause, from a run by `solver`.
    pub fn cause(&self, solver: Solver) -> Cause {
        if solver.fixed_step() {
            Cause::StepTooLong
        } else {
            Cause::Unstable
        }
    }
}

/// One chamber pressure sample far below vacuum: its channel, its
/// cylinder, the value and the time.
#[derive(Clone, Debug, PartialEq)]
pub struct Tension {
    /// The channel (column) name: `p1`, or whatever a netlist calls it.
    pub channel: String,
    /// The cylinder whose chamber it is.
    pub cylinder: String,
    /// The pressure \[Pa\] (below [`ABSURD_PRESSURE_PA`], finite, above
    /// [`LIQUID_TENSION_LIMIT_PA`]).
    pub value: f64,
    /// Its time \[s\].
    pub time: f64,
}

/// A run whose chambers' constant-B liquid left its range, but which did not
/// blow up: a chamber pressure below [`ABSURD_PRESSURE_PA`] in a run with no
/// non-finite value and none below [`LIQUID_TENSION_LIMIT_PA`]
/// ([`Run::deep_cavitation`]). Not an error: the liquid model's known limit,
/// for a client to warn of. Blocks of one run merge into the run's
/// ([`DeepCavitation::merge`], in any order).
#[derive(Clone, Debug, PartialEq)]
pub struct DeepCavitation {
    /// The earliest sample far below vacuum: from its time on the run is
    /// outside the liquid model's range.
    pub first: Tension,
    /// The lowest chamber pressure of the run.
    pub lowest: Tension,
}

/// The remedy for a chamber of constant-B liquid cavitating: entrained
/// air, where the chamber's component type has it.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct AirRemedy {
    /// The cylinder whose chamber it is.
    pub cylinder: String,
    /// The parameter path (`<cylinder>.air_fraction`) that gives the
    /// cylinder's chambers entrained air, when its component type has one
    /// ([`AIR_PARAMETER`]); `None` when it has none (or its type is not
    /// known) and nothing may be proposed to set.
    pub air: Option<String>,
    /// The cylinder's component type (`generalised_cylinder`), when known:
    /// the one the message says lacks the parameter.
    pub type_name: Option<&'static str>,
}

impl DeepCavitation {
    /// The two of one run (blocks of it, in any order): the earlier first
    /// sample and the lower lowest one.
    pub fn merge(self, other: DeepCavitation) -> DeepCavitation {
        let earlier = |a: Tension, b: Tension| if b.time < a.time { b } else { a };
        let lower = |a: Tension, b: Tension| if b.value < a.value { b } else { a };
        DeepCavitation {
            first: earlier(self.first, other.first),
            lowest: lower(self.lowest, other.lowest),
        }
    }

    /// [`DeepCavitation::merge`] of two that may be absent.
    pub fn merged(a: Option<Self>, b: Option<Self>) -> Option<Self> {
        match (a, b) {
            (Some(a), Some(b)) => Some(a.merge(b)),
            (a, b) => a.or(b),
        }
    }

    /// The facts, for a message: `p1 of `cylinder` fell below -1.01325e6
    /// Pa at t = 1.505 s, lowest -1.4885e6 Pa at t = 1.507 s` (the lowest
    /// chamber named too when it is another).
    pub fn what(&self) -> String {
        let (f, l) = (&self.first, &self.lowest);
        let other = if (&f.channel, &f.cylinder) == (&l.channel, &l.cylinder) {
            String::new()
        } else {
            format!(" {} of `{}`", l.channel, l.cylinder)
        };
        format!(
            "{} of `{}` fell below {ABSURD_PRESSURE_PA:e} Pa at t = {} s, lowest{other} {:.4e} Pa at t = {} s",
            f.channel, f.cylinder, f.time, l.value, l.time
        )
    }

    /// The remedy for the lowest chamber's cylinder; `type_of` gives a
    /// component's registry type by its instance name (the rig's
    /// schematic), so that a remedy names only a parameter the component
    /// has.
    pub fn remedy(&self, type_of: impl Fn(&str) -> Option<&'static ComponentType>) -> AirRemedy {
        let c = &self.lowest.cylinder;
        let ty = type_of(c);
        AirRemedy {
            cylinder: c.clone(),
            air: ty
                .and_then(|t| t.param(AIR_PARAMETER))
                .map(|p| format!("{c}.{}", p.name)),
            type_name: ty.map(|t| t.name),
        }
    }
}

/// How a client names the settings a warning proposes: the CLI its flags,
/// Python its arguments ([`DeepCavitation::warning`]).
#[derive(Clone, Copy, Debug)]
pub struct SettingWords {
    /// How to set the parameter at the path to 0.005, with where to read
    /// more when the client has a place for it (`--set p=0.005,
    /// docs/hybrid.md`).
    pub set: fn(&str) -> String,
    /// The fixed step's setting (`--rk4-step`).
    pub rk4_step: &'static str,
    /// The relative tolerance's setting (`--rtol`).
    pub rtol: &'static str,
    /// The switch to the stiff method (`--solver rosenbrock`).
    pub stiff_solver: &'static str,
    /// The quote a name is set in (`` ` ``).
    pub quote: char,
}

impl DeepCavitation {
    /// The warning of a run whose chamber fell far below vacuum without
    /// blowing up, in one line and the client's `words`: the chamber, its
    /// lowest pressure and when, from when on the constant-B liquid is out
    /// of its range, the remedy ([`DeepCavitation::remedy`]: a parameter it
    /// proposes to set is one the component's type has, `type_of`), and
    /// how to tell whether the solver is to blame instead (`solver`; the
    /// fixed step `rk4_step` \[s\] when it has one).
    pub fn warning(
        &self,
        type_of: impl Fn(&str) -> Option<&'static ComponentType>,
        solver: Solver,
        rk4_step: f64,
        words: &SettingWords,
    ) -> String {
        let q = words.quote;
        let AirRemedy {
            cylinder,
            air,
            type_name,
        } = self.remedy(type_of);
        let remedy = match air {
            Some(p) => format!("give it entrained air ({})", (words.set)(&p)),
            None => format!(
                "{q}{cylinder}{q}{} has no entrained-air parameter, so its chambers cannot be given air here (the component types that have {q}{AIR_PARAMETER}{q}: {})",
                type_name
                    .map(|t| format!(" ({} {q}{t}{q})", crate::netlist::a_or_an(t)))
                    .unwrap_or_default(),
                chamber_types_with_air().join(", ")
            ),
        };
        let check = if solver.fixed_step() {
            format!(
                "; a smaller {} than {rk4_step} tells whether the {} step is to blame instead",
                words.rk4_step,
                solver.name()
            )
        } else {
            format!(
                "; if the {} run is unstable instead, a smaller {}{} tells",
                solver.name(),
                words.rtol,
                if matches!(solver, Solver::Rosenbrock) {
                    String::new()
                } else {
                    format!(" or {}", words.stiff_solver)
                }
            )
        };
        format!(
            "a chamber pressure fell far below absolute vacuum ({}): the oil, a liquid of constant bulk modulus, has left its range from then on (the chamber cavitates); {remedy}{check}",
            self.what()
        )
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
    /// Whether the run is physical, the one rule for every client: `Err`
    /// with the earliest sample that is not ([`Run::unphysical`]: a
    /// non-finite value in any channel, a chamber pressure below
    /// [`LIQUID_TENSION_LIMIT_PA`], anywhere in the run), else whether its
    /// constant-B liquid left its range ([`Run::deep_cavitation`]: a chamber
    /// pressure below [`ABSURD_PRESSURE_PA`]). One pass over the channels.
    pub fn physical(&self) -> Result<Option<DeepCavitation>, Unphysical> {
        // the earliest bad sample: (sample, channel)
        let mut bad: Option<(usize, usize)> = None;
        let mut deep: Option<DeepCavitation> = None;
        for (i, c) in self.channels.iter().enumerate() {
            let cylinder = chamber_of(&c.probe).filter(|_| c.unit == "Pa");
            let floor = if cylinder.is_some() {
                LIQUID_TENSION_LIMIT_PA
            } else {
                f64::NEG_INFINITY
            };
            // NaN and ±∞ fail the first test; no early exit inside a chunk,
            // so that the test is made on several values at once
            let ok = |v: f64| v.is_finite() & (v >= floor);
            if !c
                .values
                .chunks(16)
                .all(|ch| ch.iter().fold(true, |a, &v| a & ok(v)))
            {
                if let Some(k) = c.values.iter().position(|&v| !ok(v)) {
                    if bad.is_none_or(|(b, _)| k < b) {
                        bad = Some((k, i));
                    }
                }
            }
            let Some(cylinder) = cylinder else {
                continue;
            };
            if bad.is_some()
                || c.values.iter().copied().fold(f64::INFINITY, f64::min) >= ABSURD_PRESSURE_PA
            {
                continue;
            }
            let tension = |k: usize| Tension {
                channel: c.name.clone(),
                cylinder: cylinder.to_string(),
                value: c.values[k],
                time: self.time[k],
            };
            let Some(first) = c.values.iter().position(|&v| v < ABSURD_PRESSURE_PA) else {
                continue;
            };
            let lowest =
                (first..c.values.len())
                    .fold(first, |m, k| if c.values[k] < c.values[m] { k } else { m });
            let d = DeepCavitation {
                first: tension(first),
                lowest: tension(lowest),
            };
            deep = DeepCavitation::merged(deep, Some(d));
        }
        match bad {
            Some((k, i)) => {
                let c = &self.channels[i];
                let v = c.values[k];
                Err(Unphysical {
                    what: format!("{} = {v:e} {} at t = {} s", c.name, c.unit, self.time[k]),
                    chamber_of: chamber_of(&c.probe)
                        .filter(|_| c.unit == "Pa" && v.is_finite())
                        .map(str::to_string),
                    value: v,
                    sample: k,
                })
            }
            None => Ok(deep),
        }
    }

    /// The earliest sample that is not physical — a non-finite value in any
    /// channel, a chamber pressure below [`LIQUID_TENSION_LIMIT_PA`] (a
    /// blow-up) — if any: an error ([`Run::physical`]).
    pub fn unphysical(&self) -> Option<Unphysical> {
        self.physical().err()
    }

    /// Where a run that is physical ([`Run::unphysical`] is `None`) has a
    /// chamber pressure below [`ABSURD_PRESSURE_PA`]: the constant-B liquid
    /// has left its range (the chamber cavitates) from its first such sample
    /// on. A warning, not an error ([`Run::physical`]); `None` for a run that
    /// is not physical.
    pub fn deep_cavitation(&self) -> Option<DeepCavitation> {
        self.physical().ok().flatten()
    }

    /// Number of cavitation entries of all chambers (0 = none).
    pub fn cavitation_entries(&self) -> usize {
        self.cavitation_by_chamber().iter().map(|(_, k)| k).sum()
    }

    /// The chambers that cavitated and how often, by their diagnostics'
    /// names (`cylinder_1.cavitation_entries_2`, `line_1.cavitation_entries`),
    /// in component order; empty when none did.
    pub fn cavitation_by_chamber(&self) -> Vec<(&str, usize)> {
        self.diagnostics
            .iter()
            .filter(|(n, v)| n.contains("cavitation_entries") && *v > 0.0)
            .map(|(n, v)| (n.as_str(), *v as usize))
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::run::Channel;

    /// A channel `name` reading probe `probe`.
    fn channel(name: &str, probe: &str, unit: &'static str, values: Vec<f64>) -> Channel {
        Channel {
            name: name.into(),
            unit,
            probe: probe.into(),
            values,
        }
    }

    /// A run of `channels`, sampled every 0.1 s.
    fn run_with(channels: Vec<Channel>) -> Run {
        let n = channels.first().map_or(0, |c| c.values.len());
        Run {
            time: (0..n).map(|k| k as f64 * 0.1).collect(),
            channels,
            ..Run::default()
        }
    }

    /// A run of one channel named after its probe.
    fn run(probe: &str, unit: &'static str, values: Vec<f64>) -> Run {
        run_with(vec![channel(probe, probe, unit, values)])
    }

    #[test]
    fn a_blow_up_a_deep_cavitation_and_a_good_run_are_told_apart() {
        // within ten times the depth of vacuum: physical, no warning
        let r = run("cylinder.p1", "Pa", vec![1e5, -5e5, 2e6]);
        assert_eq!(r.physical(), Ok(None));
        // far below vacuum, finite and above the tension limit: the
        // liquid's known limit, a warning, not an error
        let r = run("damper.p2", "Pa", vec![1e5, -4e6, -2e6, -9e6, 1e5]);
        assert_eq!(r.unphysical(), None);
        let d = r.deep_cavitation().unwrap();
        assert_eq!(
            (d.first.time, d.first.value, d.lowest.time, d.lowest.value),
            (0.1, -4e6, 0.30000000000000004, -9e6)
        );
        assert_eq!(d.lowest.cylinder, "damper");
        assert_eq!(
            d.what(),
            "damper.p2 of `damper` fell below -1.01325e6 Pa at t = 0.1 s, lowest -9.0000e6 Pa at t = 0.30000000000000004 s"
        );
        // below the tension limit: a blow-up, whatever the solver
        let r = run_with(vec![channel("p1", "cylinder.p1", "Pa", vec![-1e9])]);
        let u = r.unphysical().unwrap();
        assert_eq!(u.chamber_of.as_deref(), Some("cylinder"));
        assert_eq!(r.deep_cavitation(), None);
        assert_eq!(u.cause(Solver::Dp45), Cause::Unstable);
        assert_eq!(u.cause(Solver::Rk4), Cause::StepTooLong);
        // a non-finite value in any channel; a pressure that is not a
        // chamber's may be as low as it likes
        let u = run("position", "m", vec![0.0, f64::NAN])
            .unphysical()
            .unwrap();
        assert_eq!((u.chamber_of, u.what.contains("NaN")), (None, true));
        assert_eq!(run("ps", "Pa", vec![-1e9]).physical(), Ok(None));
    }

    #[test]
    fn a_run_that_passes_through_tension_and_then_blows_up_is_an_error() {
        // moderate tension first (in the pressure channel listed first),
        // a NaN later in another: the whole run is checked, the NaN found
        let r = run_with(vec![
            channel("p1", "cylinder.p1", "Pa", vec![1e5, -4e6, -8e7, -5e7]),
            channel("position", "cylinder.x", "m", vec![0.0, 0.1, 0.2, f64::NAN]),
        ]);
        let u = r.unphysical().unwrap();
        assert_eq!((u.sample, u.value.is_nan()), (3, true));
        assert_eq!(r.deep_cavitation(), None);
        // the earliest bad sample of all the channels is the one named
        let r = run_with(vec![
            channel("position", "cylinder.x", "m", vec![0.0, 0.1, f64::INFINITY]),
            channel("p1", "cylinder.p1", "Pa", vec![1e5, -2e8, -5e7]),
        ]);
        assert_eq!(r.unphysical().unwrap().sample, 1);
    }

    #[test]
    fn the_blocks_of_a_run_merge_into_the_runs_deep_cavitation() {
        let whole = run_with(vec![
            channel(
                "p1",
                "cylinder.p1",
                "Pa",
                vec![1e5, -2e6, -3e6, 1e5, 1e5, 1e5],
            ),
            channel(
                "p2",
                "cylinder.p2",
                "Pa",
                vec![1e5, 1e5, 1e5, 1e5, -7e6, 1e5],
            ),
        ]);
        let d = whole.deep_cavitation().unwrap();
        assert_eq!((d.first.channel.as_str(), d.first.time), ("p1", 0.1));
        assert_eq!((d.lowest.channel.as_str(), d.lowest.value), ("p2", -7e6));
        assert_eq!(
            d.what(),
            "p1 of `cylinder` fell below -1.01325e6 Pa at t = 0.1 s, lowest p2 of `cylinder` -7.0000e6 Pa at t = 0.4 s"
        );
        // the same from two blocks, merged in either order
        let block = |range: std::ops::Range<usize>| Run {
            time: whole.time[range.clone()].to_vec(),
            channels: whole
                .channels
                .iter()
                .map(|c| Channel {
                    values: c.values[range.clone()].to_vec(),
                    ..c.clone()
                })
                .collect(),
            ..Run::default()
        };
        let (a, b) = (block(0..3).deep_cavitation(), block(3..6).deep_cavitation());
        assert_eq!(
            DeepCavitation::merged(a.clone(), b.clone()),
            Some(d.clone())
        );
        assert_eq!(DeepCavitation::merged(b, a), Some(d));
    }

    #[test]
    fn the_cavitation_remedy_names_air_only_where_the_chambers_type_has_it() {
        use crate::netlist::registry::lookup;
        let d = run("cylinder.p1", "Pa", vec![1e5, -4e6])
            .deep_cavitation()
            .unwrap();
        // the fundamental cylinder models entrained air
        assert_eq!(
            d.remedy(|_| lookup("cylinder")),
            AirRemedy {
                cylinder: "cylinder".into(),
                air: Some("cylinder.air_fraction".into()),
                type_name: Some("cylinder"),
            }
        );
        assert_eq!(chamber_types_with_air(), ["cylinder"]);
        // the generalised one does not: nothing to set is proposed
        assert_eq!(
            d.remedy(|_| lookup("generalised_cylinder")),
            AirRemedy {
                cylinder: "cylinder".into(),
                air: None,
                type_name: Some("generalised_cylinder"),
            }
        );
        // nor where the type is not known
        assert_eq!(d.remedy(|_| None).air, None);
    }
}
