//! Tests of rig files: loading, kinds, paths and line numbers in errors,
//! `--set`, `--print-rig`.

use super::*;

/// The limit follows the unit the input is read in: a spool demand its
/// stroke, a pump in volts its rating, a set-point none; and the check
/// counts the samples beyond it. A simulation keeps its rig's.
#[test]
fn a_commands_limit_is_the_stroke_the_pumps_rating_or_none() {
    let limit_of = |v: &Value| {
        crate::simulation::Simulation::new(v, Signal::Constant { value: 0.0 })
            .unwrap()
            .command_limit()
            .cloned()
    };
    let limit = |name: &str| limit_of(&preset(name).unwrap());
    assert_eq!(limit("leaney-moog"), Some(CommandLimit::Stroke));
    assert_eq!(limit("leaney-moog-closed-loop"), None);
    let Some(CommandLimit::Rating(r)) = limit("wang-hybrid") else {
        panic!("wang-hybrid: {:?}", limit("wang-hybrid"))
    };
    assert_eq!(r.component, "pump");
    let t = [0.0, 0.1, 0.2, 0.3];
    let stroke = CommandLimit::Stroke
        .check(&t, &[0.0, 1.5, -2.0, 1.0])
        .unwrap();
    assert!(
        stroke.starts_with("2 command samples outside ±1 (largest -2 at t = 0.2 s)"),
        "{stroke}"
    );
    assert_eq!(CommandLimit::Stroke.check(&t, &[0.0, 1.0, -1.0, 0.5]), None);
    let over = [0.0, 0.5, 2.0, 1.0].map(|k| k * r.limit);
    let rating = CommandLimit::Rating(r.clone()).check(&t, &over).unwrap();
    assert!(
        rating.starts_with("1 command samples beyond the maximum speed of `pump`"),
        "{rating}"
    );
    assert_eq!(CommandLimit::Rating(r.clone()).check(&t, &over[..2]), None);
    // the rating is the rig's as set, not the preset's: a pump ten
    // times faster, ten times the command; none without a maximum speed
    let mut faster = preset("wang-hybrid").unwrap();
    apply_set(
        &mut faster,
        &format!("pump.max_speed={}", 10.0 * r.max_speed),
    )
    .unwrap();
    let Some(CommandLimit::Rating(f)) = limit_of(&faster) else {
        panic!("faster: {:?}", limit_of(&faster))
    };
    assert!(
        (f.limit / r.limit - 10.0).abs() < 1e-12,
        "{} {}",
        f.limit,
        r.limit
    );
    let mut unrated = preset("wang-hybrid").unwrap();
    apply_set(&mut unrated, "pump.max_speed=null").unwrap();
    assert_eq!(limit_of(&unrated), None);
    // a circuit assembled by hand has no rig read: no limit
    let c = circuit(
        &preset("leaney-moog").unwrap(),
        Signal::Constant { value: 0.0 },
    )
    .unwrap();
    assert_eq!(
        crate::simulation::Simulation::of_circuit(c).command_limit(),
        None
    );
}

/// An empty or blank rig file is named so, not as JSON that ended early
/// (`EOF while parsing a value at line 1 column 0`).
#[test]
fn an_empty_rig_is_named_empty() {
    for text in ["", " \n\t\n", "\u{feff}"] {
        let e = parse(text, "r.json").unwrap_err().to_string();
        assert!(
            e.contains("r.json") && e.contains("empty, or only blanks"),
            "{e}"
        );
        assert!(!e.contains("EOF"), "{e}");
    }
    let e = parse("{", "r.json").unwrap_err().to_string();
    assert!(e.contains("not valid JSON: EOF"), "{e}");
}

#[test]
fn a_kind_that_is_not_a_string_is_named_so_not_missing() {
    let e = check(&serde_json::json!({"kind": 5}))
        .unwrap_err()
        .to_string();
    assert_eq!(
        e,
        "rig `kind`: must be a string (the rig's kind, e.g. `netlist`), got a number"
    );
    let e = check(&serde_json::json!({"name": "n"}))
        .unwrap_err()
        .to_string();
    assert_eq!(e, "rig `kind`: missing (a rig file names its kind)");
}

#[test]
fn rig_text_reads_as_a_file_does_and_a_byte_order_mark_is_skipped() {
    let text = serde_json::to_string_pretty(&preset("leaney-moog").unwrap()).unwrap();
    let plain = parse(&text, "JSON text").unwrap();
    assert_eq!(
        parse(&format!("\u{feff}{text}"), "JSON text").unwrap(),
        plain
    );
    // a duplicate key is refused with its line, as in a file, in the
    // shape of every other error: the path, then `(line N of source)`
    let twice = text.replacen("\"mass\": 100.0", "\"mass\": 100.0, \"mass\": 5.0", 1);
    let e = parse(&twice, "JSON text").unwrap_err();
    let line = twice
        .lines()
        .position(|l| l.contains("\"mass\": 5.0"))
        .unwrap()
        + 1;
    assert_eq!(
        e.to_string(),
        format!(
            "rig `components.load.mass`: duplicate key (a key may appear once in an object) \
             (line {line} of JSON text)"
        )
    );
    assert_eq!(
        at_line_in(e.clone(), &twice, "JSON text").to_string(),
        e.to_string()
    );
    // a path's line is found in the text
    let mut bad = plain.clone();
    bad["components"]["load"]["mass"] = (-1.0).into();
    let shown = serde_json::to_string_pretty(&bad).unwrap();
    let e = at_line_in(check(&bad).unwrap_err(), &shown, "JSON text").to_string();
    assert!(
        e.contains("components.load.mass") && e.contains("of JSON text)"),
        "{e}"
    );
}

#[test]
fn parameters_are_set_paths_with_units() {
    let v = preset("leaney-moog").unwrap();
    let ps = parameters(&v);
    let mass = ps.iter().find(|p| p.path == "load.mass").unwrap();
    assert_eq!((mass.value, mass.unit), (Some(100.0), Some("kg")));
    // the steady initial pressure is listed with its computed value
    let p1 = ps.iter().find(|p| p.path == "cylinder.initial.p1").unwrap();
    assert!(p1.value.unwrap() > 1e6);
    // every listed path is settable
    let mut w = v.clone();
    for p in &ps {
        apply_set(&mut w, &format!("{}={}", p.path, p.value.unwrap_or(0.0))).unwrap();
    }
    // an older rig kind lists its numeric leaves
    let old = serde_json::to_value(crate::valve_rig::ValveRig::leaney_moog()).unwrap();
    let leaves = parameters(&old);
    assert!(leaves
        .iter()
        .any(|p| p.path == "load.mass_kg" && p.value == Some(100.0)));
    assert!(leaves
        .iter()
        .any(|p| p.path == "initial.p1" && p.value.is_none()));
}

/// A number as a shell user writes it but JSON does not (`+50`, `.5`,
/// `5.`) is a number, not the string `"+50"` a number cannot be replaced
/// with ("a parameter is a number, got `"+50"`").
#[test]
fn a_set_number_may_be_written_with_a_plus_or_a_bare_point() {
    for (text, want) in [("+50", 50.0), (".5", 0.5), ("5.", 5.0), ("+2.5e1", 25.0)] {
        let mut v = preset("leaney-moog").unwrap();
        apply_set(&mut v, &format!("load.mass={text}")).unwrap();
        let ps = parameters(&v);
        let mass = ps.iter().find(|p| p.path == "load.mass").unwrap();
        assert_eq!(mass.value, Some(want), "{text}");
    }
    let mut v = preset("leaney-moog").unwrap();
    assert!(apply_set(&mut v, "load.mass=+fifty").is_err());
}

#[test]
fn circuit_of_a_preset_has_its_initial_state() {
    for p in PRESETS {
        let c = circuit(&(p.json)(), Signal::Constant { value: 0.0 }).unwrap();
        assert!(
            c.n_states() > 0 && c.initial_state().len() == c.n_states(),
            "{}",
            p.name
        );
    }
}

/// A duplicate key is placed at the repeated key's line, which its path
/// would not find (it names the first): the error carries that line, so
/// placing it again, under any name of the file, leaves it as it is.
#[test]
fn a_duplicate_key_keeps_its_own_line_when_placed_again() {
    let text = "{\n  \"kind\": \"netlist\",\n  \"name\": \"a\",\n  \"name\": \"b\"\n}";
    let e = parse(text, "rig.json").unwrap_err();
    assert!(
        matches!(&e, RigError::InFile { file, line: Some(4), .. } if file == "rig.json"),
        "{e:?}"
    );
    let shown =
        "rig `name`: duplicate key (a key may appear once in an object) (line 4 of rig.json)";
    assert_eq!(e.to_string(), shown);
    for source in ["rig.json", "./rig.json", "JSON text"] {
        assert_eq!(at_line_in(e.clone(), text, source).to_string(), shown);
    }
}

/// An error is placed once: its file named with the line of its path, or
/// alone where the path has none, and not again when placed a second time;
/// a message that merely ends like a placed one is placed all the same.
#[test]
fn an_error_is_placed_once_and_by_its_path_not_its_words() {
    let text = "{\n  \"kind\": \"netlist\",\n  \"name\": \"a\"\n}";
    let e = RigError::Invalid {
        path: "name".into(),
        why: "see the list (item 2 of rig.json)".into(),
    };
    let once = at_line_in(e, text, "rig.json");
    assert_eq!(
        once.to_string(),
        "rig `name`: see the list (item 2 of rig.json) (line 3 of rig.json)"
    );
    assert_eq!(at_line_in(once.clone(), text, "rig.json"), once);
    let e = RigError::OutOfRange {
        path: String::new(),
        value: -1.0,
        why: "must be positive".into(),
    };
    let once = at_line_in(e, text, "rig.json");
    assert_eq!(
        once.to_string(),
        "rig parameter `` = -1: must be positive (in rig.json)"
    );
    assert_eq!(at_line_in(once.clone(), text, "rig.json"), once);
    // an error about the file itself names it as its path already
    let e = parse("{", "rig.json").unwrap_err();
    assert_eq!(at_line_in(e.clone(), "{", "rig.json"), e);
}

/// A retired `hybrid-variant` file is refused at its JSON path `kind`, the
/// file named after the message as every rig error names it.
#[test]
fn a_retired_variant_is_named_at_its_kind_in_the_file() {
    let text = "{\n  \"name\": \"x\",\n  \"kind\": \"hybrid-variant\"\n}";
    let e = parse(text, "old.json").unwrap_err();
    let RigError::InFile { error, file, line } = &e else {
        panic!("{e:?}")
    };
    assert_eq!((file.as_str(), *line), ("old.json", Some(3)));
    assert!(
        matches!(&**error, RigError::Invalid { path, .. } if path == "kind"),
        "{error:?}"
    );
    let shown = e.to_string();
    assert!(
        shown.starts_with("rig `kind`: the `hybrid-variant` kind is retired: ")
            && shown.ends_with("(`--set needle_valve.area=<m^2>`) (line 3 of old.json)"),
        "{shown}"
    );
}
