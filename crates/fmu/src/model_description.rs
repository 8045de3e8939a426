//! `modelDescription.xml` (FMI 2.0 Co-Simulation) from the variable table,
//! and the GUID: a name-based UUID (v5) of this crate's version, the
//! variable list (what fixes the value references) and the text of
//! `resources/rig.json`, from which the library rebuilds the variable table.
//! A library of another version, or of another build that makes other
//! variables of the rig, computes another GUID and refuses the FMU; the
//! digests of the rig's text and of the variable list, in the vendor
//! annotation, tell it which of them differs.

use crate::units::base_units;
use crate::variables::{Role, Variable, Variables};
use std::collections::BTreeSet;
use std::fmt::Write as _;

/// The `modelIdentifier` of an FMU of rig `name`: `hydrocyl_` and the name
/// with every character that is not ASCII alphanumeric turned into `_` (a C
/// identifier; the library inside is `binaries/linux64/<id>.so`).
pub fn model_identifier(name: &str) -> String {
    let s: String = name
        .chars()
        .map(|c| if c.is_ascii_alphanumeric() { c } else { '_' })
        .collect();
    format!("hydrocyl_{s}")
}

/// Escapes text for an XML attribute value.
fn esc(s: &str) -> String {
    let mut o = String::with_capacity(s.len());
    for c in s.chars() {
        match c {
            '&' => o.push_str("&amp;"),
            '<' => o.push_str("&lt;"),
            '>' => o.push_str("&gt;"),
            '"' => o.push_str("&quot;"),
            '\'' => o.push_str("&apos;"),
            c if (c as u32) < 0x20 => o.push(' '),
            c => o.push(c),
        }
    }
    o
}

/// A real in `xs:double` syntax (shortest round-trip form).
fn real(v: f64) -> String {
    if v.is_nan() {
        "NaN".into()
    } else if v.is_infinite() {
        if v > 0.0 { "INF" } else { "-INF" }.into()
    } else {
        format!("{v:?}")
    }
}

/// The causality, variability and type of a variable, as the model
/// description declares them.
fn kind(v: &Variable) -> (&'static str, &'static str, &'static str) {
    let (causality, variability) = match v.role {
        Role::Input => ("input", "continuous"),
        Role::Output(_) => ("output", "continuous"),
        Role::Solver(_) | Role::Parameter(_) => ("parameter", "fixed"),
    };
    (
        causality,
        variability,
        if v.integer { "Integer" } else { "Real" },
    )
}

fn v5(text: &str) -> String {
    format!(
        "{{{}}}",
        uuid::Uuid::new_v5(&uuid::Uuid::NAMESPACE_OID, text.as_bytes())
    )
}

/// What determines the value references: every variable in value-reference
/// order, one line each (`vr name causality variability type`), after this
/// crate's version.
fn variables_text(vars: &Variables) -> String {
    let mut t = format!("hydrocyl-fmu {}\n", env!("CARGO_PKG_VERSION"));
    for (vr, v) in vars.list.iter().enumerate() {
        let (c, va, ty) = kind(v);
        let _ = writeln!(t, "{vr} {} {c} {va} {ty}", v.name);
    }
    t
}

/// The GUID of the FMU whose `resources/rig.json` holds `rig_text` and whose
/// variables, as this build makes them from that rig, are `vars`: a
/// name-based UUID (v5) of this crate's version, the variable list (names,
/// value references, causality, variability, type) and the rig's text. A
/// library that makes another variable list from the same rig (another
/// build: another parameter catalogue) computes another GUID and refuses
/// the FMU, instead of mapping value references to the wrong parameters.
pub fn guid(rig_text: &str, vars: &Variables) -> String {
    v5(&format!("{}\n{rig_text}", variables_text(vars)))
}

/// The digest of the rig's text alone (`rig` of the model description's
/// vendor annotation): an instance whose GUID does not match tells by it
/// whether `resources/rig.json` was edited after the export.
pub fn rig_digest(rig_text: &str) -> String {
    v5(&format!("hydrocyl-fmu rig\n{rig_text}"))
}

/// The digest of the variable list alone (`variables` of the model
/// description's vendor annotation): with the rig unchanged, an instance
/// whose GUID does not match tells by it that the library is another build.
pub fn variables_digest(vars: &Variables) -> String {
    v5(&variables_text(vars))
}

/// The name of the vendor annotation element holding [`rig_digest`] and
/// [`variables_digest`] (`<Tool name="hydrocyl"><Digests rig=".." variables=".."/>`).
pub const DIGESTS: &str = "Digests";

/// The model description of the FMU of a rig. `model_name` names the rig
/// (its preset name or file stem), `description` says what it is, `guid` is
/// [`guid`] of the rig's text and `vars`; `rig_text` is the text of
/// `resources/rig.json` (its digest goes into the vendor annotation).
pub fn model_description(
    vars: &Variables,
    model_name: &str,
    description: &str,
    rig_text: &str,
) -> String {
    let guid = guid(rig_text, vars);
    let mut x = String::new();
    let w = &mut x;
    let _ = writeln!(w, r#"<?xml version="1.0" encoding="UTF-8"?>"#);
    let _ = writeln!(
        w,
        r#"<fmiModelDescription fmiVersion="2.0" modelName="{}" guid="{guid}" description="{}" generationTool="hydrocyl {}" variableNamingConvention="flat" numberOfEventIndicators="0">"#,
        esc(model_name),
        esc(description),
        env!("CARGO_PKG_VERSION"),
    );
    let _ = writeln!(
        w,
        r#"  <CoSimulation modelIdentifier="{}" needsExecutionTool="false" canHandleVariableCommunicationStepSize="true" canInterpolateInputs="true" maxOutputDerivativeOrder="0" canRunAsynchronuously="false" canBeInstantiatedOnlyOncePerProcess="false" canNotUseMemoryManagementFunctions="true" canGetAndSetFMUstate="true" canSerializeFMUstate="true" providesDirectionalDerivative="false"/>"#,
        model_identifier(model_name)
    );
    let units: BTreeSet<&str> = vars.list.iter().filter_map(|v| v.unit).collect();
    if !units.is_empty() {
        let _ = writeln!(w, "  <UnitDefinitions>");
        for u in &units {
            let _ = write!(w, r#"    <Unit name="{}">"#, esc(u));
            if let Some(e) = base_units(u) {
                let _ = write!(w, "<BaseUnit");
                for (name, k) in ["kg", "m", "s", "A", "rad"].iter().zip(e) {
                    if k != 0 {
                        let _ = write!(w, r#" {name}="{k}""#);
                    }
                }
                let _ = write!(w, "/>");
            }
            let _ = writeln!(w, "</Unit>");
        }
        let _ = writeln!(w, "  </UnitDefinitions>");
    }
    let _ = writeln!(
        w,
        r#"  <DefaultExperiment startTime="0.0" stopTime="1.0" stepSize="0.001"/>"#
    );
    let _ = writeln!(
        w,
        r#"  <VendorAnnotations><Tool name="hydrocyl"><{DIGESTS} rig="{}" variables="{}"/></Tool></VendorAnnotations>"#,
        rig_digest(rig_text),
        variables_digest(vars),
    );
    let _ = writeln!(w, "  <ModelVariables>");
    for (vr, v) in vars.list.iter().enumerate() {
        let (causality, variability, _) = kind(v);
        let initial = match v.role {
            Role::Input => None,
            Role::Output(_) => Some("calculated"),
            Role::Solver(_) | Role::Parameter(_) => Some("exact"),
        };
        let _ = write!(
            w,
            r#"    <ScalarVariable name="{}" valueReference="{vr}" description="{}" causality="{causality}" variability="{variability}""#,
            esc(&v.name),
            esc(&v.description),
        );
        if let Some(i) = initial {
            let _ = write!(w, r#" initial="{i}""#);
        }
        let _ = write!(w, ">");
        let start = match v.role {
            Role::Output(_) => String::new(),
            _ if v.integer => format!(r#" start="{}""#, v.start as i64),
            _ => format!(r#" start="{}""#, real(v.start)),
        };
        if v.integer {
            let _ = write!(w, r#"<Integer{start} min="0" max="2"/>"#);
        } else {
            let unit = v
                .unit
                .map(|u| format!(r#" unit="{}""#, esc(u)))
                .unwrap_or_default();
            let _ = write!(w, "<Real{unit}{start}/>");
        }
        let _ = writeln!(w, "</ScalarVariable>");
    }
    let _ = writeln!(w, "  </ModelVariables>");
    let _ = writeln!(w, "  <ModelStructure>");
    let input_index = 1 + vars
        .list
        .iter()
        .position(|v| v.role == Role::Input)
        .unwrap_or(0);
    let outputs: Vec<(usize, bool)> = vars
        .list
        .iter()
        .enumerate()
        .filter(|(_, v)| matches!(v.role, Role::Output(_)))
        .map(|(i, v)| (i + 1, v.feedthrough))
        .collect();
    let _ = writeln!(w, "    <Outputs>");
    for (i, ft) in &outputs {
        // dependencies: only the input can be a known of a co-simulation
        // output; "" = none (the output is a function of the state)
        let deps = if *ft {
            input_index.to_string()
        } else {
            String::new()
        };
        let kinds = if *ft {
            r#" dependenciesKind="fixed""#
        } else {
            ""
        };
        let _ = writeln!(
            w,
            r#"      <Unknown index="{i}" dependencies="{deps}"{kinds}/>"#
        );
    }
    let _ = writeln!(w, "    </Outputs>");
    // the initial outputs depend on the parameters and the input: no
    // `dependencies` attribute means "on every known"
    let _ = writeln!(w, "    <InitialUnknowns>");
    for (i, _) in &outputs {
        let _ = writeln!(w, r#"      <Unknown index="{i}"/>"#);
    }
    let _ = writeln!(w, "    </InitialUnknowns>");
    let _ = writeln!(w, "  </ModelStructure>");
    let _ = writeln!(w, "</fmiModelDescription>");
    x
}

#[cfg(test)]
mod tests {
    use super::*;
    use hydrocyl_system::rig;

    #[test]
    fn guid_follows_the_rig_and_parameters_carry_start_and_unit() {
        let r = rig::preset("leaney-moog").unwrap();
        let v = Variables::of(&r).unwrap();
        let g = guid(&r.to_string(), &v);
        let xml = model_description(&v, "leaney-moog", "a rig", &r.to_string());
        assert!(xml.contains(&format!(r#"guid="{g}""#)));
        assert_eq!(guid(&r.to_string(), &v), g);
        let mut r2 = r.clone();
        rig::apply_set(&mut r2, "load.mass=50").unwrap();
        assert_ne!(guid(&r2.to_string(), &v), g);
        assert!(xml.contains(&format!(
            r#"<Digests rig="{}" variables="{}"/>"#,
            rig_digest(&r.to_string()),
            variables_digest(&v)
        )));
        assert!(xml.contains(r#"name="load.mass""#));
        assert!(xml.contains(r#"<Real unit="kg" start="100.0"/>"#));
        assert!(xml.contains(r#"<Unit name="Pa"><BaseUnit kg="1" m="-1" s="-2"/></Unit>"#));
    }

    /// A build whose parameter catalogue differs (a parameter missing, so
    /// every value reference after it shifts; a parameter become an input;
    /// an Integer become a Real) computes another GUID for the same rig text.
    #[test]
    fn guid_follows_the_variable_list() {
        let r = rig::preset("wang-hybrid").unwrap();
        let text = r.to_string();
        let v = Variables::of(&r).unwrap();
        let g = guid(&text, &v);
        let at = v
            .list
            .iter()
            .position(|x| matches!(x.role, Role::Parameter(_)))
            .unwrap();
        let mut missing = v.clone();
        missing.list.remove(at);
        let mut renamed = v.clone();
        renamed.list[at].name.push('x');
        let mut input = v.clone();
        input.list[at].role = Role::Input;
        let mut real = v.clone();
        let m = real.list.iter().position(|x| x.integer).unwrap();
        real.list[m].integer = false;
        let mut swapped = v.clone();
        swapped.list.swap(at, at + 1);
        for (what, other) in [
            ("missing", missing),
            ("renamed", renamed),
            ("input", input),
            ("real", real),
            ("swapped", swapped),
        ] {
            assert_ne!(guid(&text, &other), g, "{what}");
            assert_ne!(variables_digest(&other), variables_digest(&v), "{what}");
        }
        // a start value or a description does not move a value reference
        let mut start = v.clone();
        start.list[at].start += 1.0;
        start.list[at].description.push('!');
        assert_eq!(guid(&text, &start), g);
    }

    #[test]
    fn identifier_is_a_c_name() {
        assert_eq!(model_identifier("leaney-moog"), "hydrocyl_leaney_moog");
        assert_eq!(esc(r#"a<"b">&"#), "a&lt;&quot;b&quot;&gt;&amp;");
    }
}
