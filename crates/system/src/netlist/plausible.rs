//! Parameters inside their range but far outside what real rigs have: the
//! mark of a unit slip (a bulk modulus of 14000 meant in bar, a bore area
//! of 1963 meant in mm²), which runs and gives physically consistent
//! nonsense. Warned of, not refused: the span is what real rigs have
//! ([`ParamSpec::typical`](super::registry::ParamSpec::typical)), not what
//! the physics allows.

use super::Schematic;

/// One warning per parameter of `s` far outside its type's usual span
/// ([`ParamSpec::implausible`](super::registry::ParamSpec::implausible)),
/// in component order, each naming it by the path `--set` takes: ``rig
/// `cylinder.bulk_modulus`: 14000 [Pa] is far outside the usual 5e7 to 5e9
/// [Pa] of …: a value in bar? (14000 bar = 1.4e9 Pa)``.
pub fn implausible(s: &Schematic) -> Vec<String> {
    s.instances
        .iter()
        .flat_map(|i| {
            i.ty.params.iter().filter_map(|p| {
                let why = p.implausible(*i.params.get(p.name)?)?;
                Some(format!("rig `{}.{}`: {why}", i.name, p.name))
            })
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every preset is plausible; a bulk modulus written in bar and a bore
    /// area in mm² are each named with the unit they were likely meant in,
    /// and a value no slip explains is asked to be checked.
    #[test]
    fn a_unit_slip_is_named_with_the_unit_meant() {
        for p in crate::rig::PRESETS {
            let v = crate::rig::preset(p.name).unwrap();
            if v.get("kind").and_then(serde_json::Value::as_str) != Some(super::super::KIND) {
                continue;
            }
            let w = implausible(&super::super::read(&v).unwrap());
            assert!(w.is_empty(), "{}: {w:?}", p.name);
        }
        let mut v = crate::rig::preset("leaney-moog").unwrap();
        crate::rig::apply_sets(
            &mut v,
            &[
                "cylinder.bulk_modulus=7000".into(),
                "cylinder.area_1=1963".into(),
                "valve.orifice.density=0.87".into(),
            ],
        )
        .unwrap();
        let w = implausible(&super::super::read(&v).unwrap());
        assert_eq!(w.len(), 3, "{w:?}");
        assert!(
            w[0].starts_with(
                "rig `valve.orifice.density`: 0.87 [kg/m^3] is far outside the usual 5e2 to 2e3"
            ),
            "{}",
            w[0]
        );
        assert!(
            w[0].ends_with("a value in g/cm³? (0.87 g/cm³ = 8.7e2 kg/m^3)"),
            "{}",
            w[0]
        );
        assert!(
            w[1].starts_with("rig `cylinder.area_1`: 1963 [m^2]"),
            "{}",
            w[1]
        );
        assert!(
            w[1].ends_with("a value in mm²? (1963 mm² = 1.963e-3 m^2)"),
            "{}",
            w[1]
        );
        assert!(
            w[2].starts_with("rig `cylinder.bulk_modulus`: 7000 [Pa]"),
            "{}",
            w[2]
        );
        assert!(
            w[2].ends_with("a value in bar? (7000 bar = 7e8 Pa)"),
            "{}",
            w[2]
        );
        let mut v = crate::rig::preset("leaney-moog").unwrap();
        crate::rig::apply_sets(&mut v, &["cylinder.bulk_modulus=1e12".into()]).unwrap();
        let w = implausible(&super::super::read(&v).unwrap());
        assert!(
            w[0].ends_with("check its unit: every rig value is SI"),
            "{w:?}"
        );
        // a simulation keeps them from its own reading of the netlist
        let cmd = crate::signal::Signal::Constant { value: 0.0 };
        let sim = crate::simulation::Simulation::new(&v, cmd.clone()).unwrap();
        assert_eq!(sim.implausible(), w);
        let preset = crate::rig::preset("leaney-moog").unwrap();
        let sim = crate::simulation::Simulation::new(&preset, cmd).unwrap();
        assert!(sim.implausible().is_empty());
    }
}
