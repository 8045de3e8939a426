//! Parts of the valve-rig report: why an effect is not tried, and the
//! measured and simulated series behind `--plots`.

use super::*;

/// Why effect `id` is not tried on this rig.
pub(super) fn not_applicable_why(id: EffectId, rig: &Model, opts: &DiagnoseOptions) -> String {
    if opts.candidates.as_ref().is_some_and(|c| !c.contains(&id)) {
        return "left out by --effects".into();
    }
    match rig.applies(id) {
        Err(why) => why,
        Ok(()) if id != EffectId::BulkModulus && is_on(rig, id) => {
            let values: Vec<String> = id
                .params()
                .iter()
                .filter_map(|q| get(rig, id, q.name).map(|v| format!("{} = {v:.4e}", q.name)))
                .collect();
            format!(
                "already on in the declared rig ({}; {}): the loop adds only effects that are off",
                values.join(", "),
                rig.paths_of(id).join(", ")
            )
        }
        Ok(()) => "its parameters cannot be read on this rig".into(),
    }
}

/// Measured, before and after series of every compared channel, from the
/// runs the report's NRMSEs were computed on (empty where a run failed).
pub(super) fn traces(
    rec: &Record,
    p: &Prepared,
    before: &[Vec<f64>],
    after: &[Vec<f64>],
) -> Vec<RecordTrace> {
    let velocity = p
        .meas
        .iter()
        .find(|(ch, _)| *ch == Signal::Velocity)
        .map_or_else(Vec::new, |(_, v)| v.clone());
    p.meas
        .iter()
        .zip(before.iter().zip(after))
        .map(|((ch, m), (b, a))| RecordTrace {
            source: rec.source.clone(),
            t: p.t.to_vec(),
            velocity: velocity.clone(),
            channel: ch.name().to_string(),
            measured: m.clone(),
            before: b.clone(),
            after: a.clone(),
            regressor: None,
        })
        .collect()
}
