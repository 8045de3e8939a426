//! Units of the FMU's variables: the unit of a rig parameter (the component
//! registry's, where the rig is a netlist), and the SI base-unit exponents
//! of every unit name used (for the `UnitDefinitions` of the model
//! description).

use hydrocyl_system::rig::Parameter;

/// Exponents of the SI base units `(kg, m, s, A, rad)` of a unit name, as
/// the FMI `BaseUnit` element spells them. `None` for a name whose
/// exponents are not integers (`m^3/(s Pa^0.5)`, an orifice's flow
/// coefficient) or that hydrocyl does not use: the unit is then declared
/// without a `BaseUnit`.
pub fn base_units(unit: &str) -> Option<[i32; 5]> {
    Some(match unit {
        "kg" => [1, 0, 0, 0, 0],
        "m" => [0, 1, 0, 0, 0],
        "s" => [0, 0, 1, 0, 0],
        "m/s" => [0, 1, -1, 0, 0],
        "m^2" => [0, 2, 0, 0, 0],
        "m^3" => [0, 3, 0, 0, 0],
        "m^3/s" => [0, 3, -1, 0, 0],
        "kg/m^3" => [1, -3, 0, 0, 0],
        "N" => [1, 1, -2, 0, 0],
        "N/m" => [1, 0, -2, 0, 0],
        "1/m" => [0, -1, 0, 0, 0],
        "m s" => [0, 1, 1, 0, 0],
        "N s/m" => [1, 0, -1, 0, 0],
        "N^2 s/m^4" => [2, -2, -3, 0, 0],
        "Pa" => [1, -1, -2, 0, 0],
        "Pa/m" => [1, -2, -2, 0, 0],
        "Pa s/m^3" => [1, -4, -1, 0, 0],
        "m^3/(s Pa)" => [-1, 4, 1, 0, 0],
        "m^3 s/N" => [-1, 2, 3, 0, 0],
        "V" => [1, 2, -3, -1, 0],
        "m^3/(s V)" => [-1, 1, 2, 1, 0],
        "rad/s" => [0, 0, -1, 0, 1],
        "m^3/rad" => [0, 3, 0, 0, -1],
        _ => return None,
    })
}

/// A unit as the FMU names it: `None` for a dimensionless `-` or an empty
/// name.
pub fn unit_name(unit: &'static str) -> Option<&'static str> {
    (!unit.is_empty() && unit != "-").then_some(unit)
}

/// The unit of a rig parameter: the one the rig declares (a netlist's
/// component registry), else, for the older rig kinds, from its path —
/// valve rigs spell the unit in the field name (`area_1_m2`, `pressure_pa`).
/// `None` when dimensionless or not known.
pub fn parameter_unit(p: &Parameter) -> Option<&'static str> {
    if let Some(u) = p.unit {
        return unit_name(u);
    }
    let leaf = p.path.rsplit('.').next().unwrap_or(&p.path);
    const SUFFIXES: &[(&str, &str)] = &[
        ("_m3_per_s_pa", "m^3/(s Pa)"),
        ("_pa_s_per_m3", "Pa s/m^3"),
        ("_kg_per_m3", "kg/m^3"),
        ("_m2", "m^2"),
        ("_m3", "m^3"),
        ("_pa", "Pa"),
        ("_kg", "kg"),
        ("_n", "N"),
        ("_s", "s"),
        ("_m", "m"),
    ];
    SUFFIXES
        .iter()
        .find(|(s, _)| leaf.ends_with(s))
        .map(|(_, u)| *u)
}

#[cfg(test)]
mod tests {
    use super::*;
    use hydrocyl_system::rig;

    fn param(path: &str, unit: Option<&'static str>) -> Parameter {
        Parameter {
            path: path.into(),
            value: None,
            unit,
            doc: None,
        }
    }

    #[test]
    fn declared_units_first_then_suffixes() {
        assert_eq!(parameter_unit(&param("load.mass", Some("kg"))), Some("kg"));
        assert_eq!(parameter_unit(&param("valve.orifice.cd", Some("-"))), None);
        assert_eq!(
            parameter_unit(&param("cylinder.area_1_m2", None)),
            Some("m^2")
        );
        assert_eq!(
            parameter_unit(&param("cylinder.internal_leakage_m3_per_s_pa", None)),
            Some("m^3/(s Pa)")
        );
        assert_eq!(
            parameter_unit(&param("valve.discharge_coefficient", None)),
            None
        );
    }

    #[test]
    fn preset_units_have_base_units_where_the_exponents_are_integers() {
        for p in rig::PRESETS {
            for q in rig::parameters(&(p.json)()) {
                if let Some(u) = parameter_unit(&q) {
                    assert!(
                        base_units(u).is_some() || u.contains("^0.5"),
                        "{}: {u}",
                        q.path
                    );
                }
            }
        }
        // a newton is kg·m·s⁻², a pascal a newton per square metre
        let (n, pa) = (base_units("N").unwrap(), base_units("Pa").unwrap());
        assert_eq!([n[0], n[1] - 2, n[2], n[3], n[4]], pa);
    }
}
