//! The diagnose `Model`'s edge cases: a bulk modulus written to volumes
//! declared with different oils, a circuit that holds no pressure above
//! tank.

use hydrocyl_identify::catalog::EffectId;
use hydrocyl_identify::valve::{get, set, Model};
use hydrocyl_system::rig;
use serde_json::Value;

fn preset(name: &str) -> Value {
    rig::preset(name).expect("preset")
}

/// On the hybrid rig the cylinder and both lines are declared with one oil;
/// with `line_1` declared twice as stiff, refitting B keeps that ratio (B is
/// the cylinder's), and setting it back restores every volume exactly.
#[test]
fn bulk_modulus_keeps_each_volumes_declared_ratio() {
    let mut net = preset("wang-hybrid");
    let b_cyl = net["components"]["cylinder"]["bulk_modulus"]
        .as_f64()
        .expect("cylinder B");
    let b_line = net["components"]["line_2"]["bulk_modulus"]
        .as_f64()
        .expect("line_2 B");
    net["components"]["line_1"]["bulk_modulus"] = Value::from(2.0 * b_cyl);
    let mut m = Model::new(&net).expect("model");
    let id = EffectId::BulkModulus;
    assert_eq!(get(&m, id, "B"), Some(b_cyl), "B reads the cylinder's");
    set(&mut m, id, "B", 1.5 * b_cyl);
    let b = |m: &Model, c: &str| m.param(c, "bulk_modulus").expect("B");
    assert_eq!(get(&m, id, "B"), Some(1.5 * b_cyl));
    assert_eq!(b(&m, "cylinder"), 1.5 * b_cyl);
    assert!((b(&m, "line_1") - 3.0 * b_cyl).abs() <= 1e-12 * b_cyl);
    assert!((b(&m, "line_2") - 1.5 * b_cyl * (b_line / b_cyl)).abs() <= 1e-12 * b_cyl);
    set(&mut m, id, "B", b_cyl);
    assert_eq!(b(&m, "cylinder"), b_cyl);
    assert_eq!(b(&m, "line_1"), 2.0 * b_cyl, "the stiffer line restored");
    assert_eq!(b(&m, "line_2"), b_line);
}

/// The valve rig with its supply at tank pressure holds no pressure: the
/// pressure term K (p1 − p2)² v has nothing to be sized at (its typical
/// size was 10 N over a zero Δp) and the supply nothing to droop from —
/// both not applicable, saying why. With the friction's own bound
/// `seal.dp_max` declared, K is sized at that bound instead.
#[test]
fn no_pressure_above_tank_makes_the_pressure_sized_effects_not_applicable() {
    let mut net = preset("leaney-moog");
    net["components"]["supply"]["pressure"] = Value::from(0.0);
    // no steady state to start from without a supply: the chambers start at
    // tank pressure, given (a rig must assemble to be a model)
    net["components"]["cylinder"]["initial"]["p1"] = Value::from(0.0);
    net["components"]["cylinder"]["initial"]["p2"] = Value::from(0.0);
    let m = Model::new(&net).expect("model");
    assert_eq!(m.supply(), 0.0);
    assert_eq!(m.seal_dp(), 0.0);
    for id in [EffectId::PressureViscous, EffectId::SupplyDroop] {
        let why = m.applies(id).expect_err("not applicable");
        assert!(why.contains("no pressure above tank"), "{id:?}: {why}");
        assert_eq!(get(&m, id, id.params()[0].name), None);
    }
    // the effects that do not need a pressure scale still apply
    assert!(m.applies(EffectId::InternalLeakage).is_ok());
    assert!(m.applies(EffectId::AccelerationFriction).is_ok());

    net["components"]["friction"]["seal"] = serde_json::json!({ "dp_max": 4e6 });
    let m = Model::new(&net).expect("model");
    assert_eq!(m.seal_dp(), 4e6);
    assert!(m.applies(EffectId::PressureViscous).is_ok());

    // with the supply back, half of it (below the bound) sizes the term
    net["components"]["supply"]["pressure"] = Value::from(7e6);
    let m = Model::new(&net).expect("model");
    assert_eq!(m.seal_dp(), 3.5e6);
}
