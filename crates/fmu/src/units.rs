//! Units of the FMU's variables: the unit of a rig parameter from its path,
//! and the SI base-unit exponents of every unit name used (for the
//! `UnitDefinitions` of the model description).
//!
//! [`parameter_unit`] is the one place that knows which parameter has which
//! unit; once the component registry declares units per parameter it should
//! ask the registry instead.

/// Exponents of the SI base units `(kg, m, s, rad)` of a unit name, as the
/// FMI `BaseUnit` element spells them. `None` for a name hydrocyl does not
/// use (the variable then carries no unit).
pub fn base_units(unit: &str) -> Option<[i32; 4]> {
    Some(match unit {
        "kg" => [1, 0, 0, 0],
        "m" => [0, 1, 0, 0],
        "s" => [0, 0, 1, 0],
        "m/s" => [0, 1, -1, 0],
        "m^2" => [0, 2, 0, 0],
        "m^3" => [0, 3, 0, 0],
        "m^3/s" => [0, 3, -1, 0],
        "kg/m^3" => [1, -3, 0, 0],
        "N" => [1, 1, -2, 0],
        "N/m" => [1, 0, -2, 0],
        "N.s/m" => [1, 0, -1, 0],
        "Pa" => [1, -1, -2, 0],
        "Pa.s/m^3" => [1, -4, -1, 0],
        "m^3/(s.Pa)" => [-1, 4, 1, 0],
        "rad/s" => [0, 0, -1, 1],
        _ => return None,
    })
}

/// The unit of a rig parameter given its `--set` path, `None` when
/// dimensionless or not known. Valve rigs spell the unit in the field name
/// (`area_1_m2`, `pressure_pa`); the hybrid rigs' fields are SI without a
/// suffix, so their last segment names the quantity (`area_1`, `cracking`).
pub fn parameter_unit(path: &str) -> Option<&'static str> {
    let leaf = path.rsplit('.').next().unwrap_or(path);
    const SUFFIXES: &[(&str, &str)] = &[
        ("_m3_per_s_pa", "m^3/(s.Pa)"),
        ("_pa_s_per_m3", "Pa.s/m^3"),
        ("_kg_per_m3", "kg/m^3"),
        ("_m2", "m^2"),
        ("_m3", "m^3"),
        ("_pa", "Pa"),
        ("_kg", "kg"),
        ("_n", "N"),
        ("_s", "s"),
        ("_m", "m"),
    ];
    if let Some((_, u)) = SUFFIXES.iter().find(|(s, _)| leaf.ends_with(s)) {
        return Some(u);
    }
    // `initial.*` of a valve rig and the hybrid rigs' SI fields by name.
    let in_initial = path.starts_with("initial.");
    Some(match leaf {
        "p1" | "p2" if in_initial => "Pa",
        "position" | "spool" if in_initial => "m",
        "velocity" if in_initial => "m/s",
        "initial_position" | "stroke" | "overlap" | "hole_radius" => "m",
        l if l.starts_with("chamber_length") => "m",
        l if l.starts_with("area") => "m^2",
        "pump_line_volume" => "m^3",
        "mass" => "kg",
        "density" => "kg/m^3",
        "bulk_modulus" | "cracking" | "full_open" | "dp_transition" | "tank_pressure"
        | "vapour_pressure" => "Pa",
        "external_force" | "coulomb" | "stiction" => "N",
        "viscous" | "sigma1" => "N.s/m",
        "sigma0" | "spring_rate" => "N/m",
        "stribeck_velocity" | "smoothing_velocity" | "opening_range" => "m/s",
        "natural_frequency" => "rad/s",
        "internal_leakage" | "external_leakage_1" | "external_leakage_2" => "m^3/(s.Pa)",
        _ => return None,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn valve_rig_suffixes_and_hybrid_names() {
        assert_eq!(parameter_unit("cylinder.area_1_m2"), Some("m^2"));
        assert_eq!(parameter_unit("supply.pressure_pa"), Some("Pa"));
        assert_eq!(
            parameter_unit("cylinder.internal_leakage_m3_per_s_pa"),
            Some("m^3/(s.Pa)")
        );
        assert_eq!(parameter_unit("fluid.density_kg_per_m3"), Some("kg/m^3"));
        assert_eq!(parameter_unit("valve.dynamics.time_constant_s"), Some("s"));
        assert_eq!(parameter_unit("initial.p1"), Some("Pa"));
        assert_eq!(parameter_unit("cylinder.area_2"), Some("m^2"));
        assert_eq!(parameter_unit("relief_pilot.cracking"), Some("Pa"));
        assert_eq!(parameter_unit("valve.discharge_coefficient"), None);
    }

    #[test]
    fn every_unit_named_has_base_units() {
        for p in hydrocyl_system::rig::PRESETS {
            for q in hydrocyl_system::rig::parameters(&(p.json)()) {
                if let Some(u) = parameter_unit(&q.path) {
                    assert!(base_units(u).is_some(), "{}: {u}", q.path);
                }
            }
        }
        // a newton is kg·m·s⁻², a pascal a newton per square metre
        let (n, pa) = (base_units("N").unwrap(), base_units("Pa").unwrap());
        assert_eq!([n[0], n[1] - 2, n[2], n[3]], pa);
    }
}
