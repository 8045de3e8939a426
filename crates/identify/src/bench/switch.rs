//! Which catalog effect a friction law's parameter belongs to, and the rule
//! by which a bench reads that effect as switched on
//! ([`FrictionBench::from_netlist`]): said once, here, for the reader and
//! for whoever explains why a parameter changed nothing (the CLI's `--set`
//! of `friction.stribeck_velocity` on a law without `stiction`).

use super::{FrictionBench, BENCH_EFFECTS};
use crate::catalog::EffectId;
use hydrocyl_system::netlist::identify::{bench_law_params, bench_law_stiction_is_coulomb};
use hydrocyl_system::netlist::registry::{self, Default};

/// How a catalog effect of a friction law of one netlist type is switched
/// on: the effect is on where the law's parameter [`EffectSwitch::on`] (the
/// law parameter of the effect's first catalog parameter: `stiction` for
/// `stribeck`, `sigma0` for `lugre_dynamics`) is given off its default
/// ([`EffectSwitch::is_on`]); its other parameters are unused until then.
#[derive(Clone, Debug, PartialEq)]
pub struct EffectSwitch {
    /// The effect.
    pub effect: EffectId,
    /// The law's parameter that switches it on (its first, for a law with
    /// one set per direction: `extending.curve.stiction`).
    pub on: &'static str,
    /// That parameter's unit (`N`; empty or `-` for none).
    pub unit: &'static str,
    /// That parameter's default: the effect is on where the parameter is
    /// given and differs from it. `None`: a parameter without a default
    /// value, on wherever given — an optional one (`friction_bench`'s
    /// `stiction`: absent, no hump) or a required one (the Coulomb + viscous
    /// law's `viscous`, LuGre's σ0 and σ2), so that a netlist printed with
    /// every default written out (`--print-rig`) declares what the file
    /// declared.
    pub default: Option<f64>,
    /// The effect is on only where [`EffectSwitch::on`] also differs from
    /// the law's Coulomb level: the Stribeck hump of a law whose stiction
    /// level is its Coulomb level where it has no hump (`friction_lugre`).
    pub not_at_coulomb: bool,
}

impl EffectSwitch {
    /// `true` when a law whose [`EffectSwitch::on`] parameter is `given`
    /// (`None`: not in the netlist) and whose Coulomb level is `coulomb`
    /// \[N\] has the effect on.
    pub fn is_on(&self, given: Option<f64>, coulomb: f64) -> bool {
        given.is_some_and(|x| Some(x) != self.default && !(self.not_at_coulomb && x == coulomb))
    }

    /// The law parameters of the effect's catalog parameters, in catalog
    /// order (each the first of its set for a law with one set per
    /// direction): the first is [`EffectSwitch::on`].
    pub fn params(&self, ty: &str) -> Vec<&'static str> {
        law_params(ty, self.effect).unwrap_or_default()
    }
}

/// The first law parameter of each of effect `id`'s catalog parameters on
/// a law of type `ty`, or `None` where the law lacks one of them.
fn law_params(ty: &str, id: EffectId) -> Option<Vec<&'static str>> {
    id.params()
        .iter()
        .map(|q| {
            bench_law_params(ty, &format!("{}.{}", id.id(), q.name), true)?
                .first()
                .copied()
        })
        .collect()
}

impl FrictionBench {
    /// The switches of the effects ([`BENCH_EFFECTS`] order) that a
    /// friction law of netlist type `ty` has (every catalog parameter of
    /// the effect is one of the law's): the rule by which
    /// [`FrictionBench::from_netlist`] reads each as on. Empty for a type
    /// with no friction-bench view.
    pub fn effect_switches(ty: &str) -> Vec<EffectSwitch> {
        let Some(spec) = registry::lookup(ty) else {
            return Vec::new();
        };
        BENCH_EFFECTS
            .iter()
            .filter_map(|&effect| {
                let on = *law_params(ty, effect)?.first()?;
                let p = spec.param(on)?;
                Some(EffectSwitch {
                    effect,
                    on,
                    unit: p.unit,
                    default: match p.default {
                        Default::Value(d) => Some(d),
                        _ => None,
                    },
                    not_at_coulomb: bench_law_stiction_is_coulomb(ty)
                        && effect == EffectId::Stribeck,
                })
            })
            .collect()
    }

    /// The switch of the effect that parameter `param` of a friction law
    /// of netlist type `ty` belongs to (`stribeck_velocity` →
    /// `stribeck`, switched by `stiction`; the switch's own parameter
    /// too), or `None` for a parameter of no effect (the Coulomb level, the
    /// smoothing velocity) or a type with no friction-bench view. Either
    /// set of a law with one set per direction names the effect.
    pub fn effect_switch_of(ty: &str, param: &str) -> Option<EffectSwitch> {
        Self::effect_switches(ty).into_iter().find(|s| {
            s.effect.params().iter().any(|q| {
                bench_law_params(ty, &format!("{}.{}", s.effect.id(), q.name), true)
                    .unwrap_or_default()
                    .contains(&param)
            })
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The rule, on each law type: `friction_bench` switches the hump by
    /// `stiction` (on wherever given) and LuGre's bristle by `sigma0` (off
    /// at its default 0); LuGre's hump
    /// is off where its stiction level is its Coulomb level; a parameter of
    /// no effect has no switch.
    #[test]
    fn each_parameter_names_its_effect_and_switch() {
        let s = FrictionBench::effect_switch_of("friction_bench", "stribeck_velocity").unwrap();
        assert_eq!(
            (s.effect, s.on, s.unit),
            (EffectId::Stribeck, "stiction", "N")
        );
        assert_eq!(s.default, None);
        assert!(!s.not_at_coulomb);
        assert!(!s.is_on(None, 5.0));
        assert!(s.is_on(Some(5.0), 5.0) && s.is_on(Some(7.0), 5.0));
        assert_eq!(
            s.params("friction_bench"),
            ["stiction", "stribeck_velocity", "stribeck_exponent"]
        );
        let s = FrictionBench::effect_switch_of("friction_bench", "sigma1").unwrap();
        assert_eq!((s.effect, s.on), (EffectId::LugreDynamics, "sigma0"));
        assert_eq!(s.default, Some(0.0));
        assert!(!s.is_on(None, 5.0) && !s.is_on(Some(0.0), 5.0) && s.is_on(Some(1e5), 5.0));
        assert_eq!(
            FrictionBench::effect_switch_of("friction_bench", "stiction").map(|s| s.effect),
            Some(EffectId::Stribeck)
        );
        assert_eq!(
            FrictionBench::effect_switch_of("friction_bench", "coulomb"),
            None
        );
        assert_eq!(
            FrictionBench::effect_switch_of("friction_bench", "smoothing_velocity"),
            None
        );
        let s =
            FrictionBench::effect_switch_of("friction_lugre", "retracting.curve.stribeck_velocity")
                .unwrap();
        assert_eq!(
            (s.effect, s.on),
            (EffectId::Stribeck, "extending.curve.stiction")
        );
        assert!(s.not_at_coulomb);
        assert!(!s.is_on(Some(5.0), 5.0) && s.is_on(Some(7.0), 5.0));
        assert!(FrictionBench::effect_switches("mass").is_empty());
    }
}
