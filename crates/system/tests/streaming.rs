//! `Simulation::run_streaming`: one block is `Simulation::run` bit for bit; many blocks (the
//! integrator restarted at each block's first time) agree with `run` to the
//! tolerance and emit every output time once, in order.

use hydrocyl_system::rig;
use hydrocyl_system::run::{Run, RunOptions};
use hydrocyl_system::signal::Signal;
use hydrocyl_system::simulation::Simulation;

fn setup() -> (Simulation, Vec<f64>) {
    let t: Vec<f64> = (0..400).map(|k| k as f64 * 0.005).collect();
    let u: Vec<f64> = t
        .iter()
        .map(|&t| if t % 1.0 < 0.5 { 0.15 } else { -0.2 })
        .collect();
    let v = rig::preset("leaney-moog").unwrap();
    let sim = Simulation::new(&v, Signal::table(t.clone(), u).unwrap()).unwrap();
    (sim, t)
}

fn streamed(block: usize) -> (Vec<f64>, Vec<Vec<f64>>, Run) {
    let (sim, t) = setup();
    let (mut time, mut cols) = (Vec::new(), Vec::<Vec<f64>>::new());
    let total = sim
        .options(RunOptions::default())
        .run_streaming(&t, block, &mut |b: &Run| {
            time.extend_from_slice(&b.time);
            cols.resize(b.channels.len(), Vec::new());
            for (c, ch) in cols.iter_mut().zip(&b.channels) {
                c.extend_from_slice(&ch.values);
            }
            Ok(())
        })
        .unwrap();
    (time, cols, total)
}

#[test]
fn one_block_is_run_and_many_blocks_agree_to_the_tolerance() {
    let (sim, t) = setup();
    let whole = sim.options(RunOptions::default()).run(&t).unwrap();
    let (time, cols, total) = streamed(t.len());
    assert_eq!(time, whole.time);
    for (c, ch) in cols.iter().zip(&whole.channels) {
        assert_eq!(c, &ch.values, "{}", ch.name);
    }
    assert_eq!(total.stats, whole.stats);
    let (time, cols, total) = streamed(37);
    assert_eq!(time, t, "every output time once, in order");
    assert!(total.stats.steps > 0 && total.wall > std::time::Duration::ZERO);
    for (c, ch) in cols.iter().zip(&whole.channels) {
        let scale = ch.values.iter().fold(1e-12f64, |m, v| m.max(v.abs()));
        let err = c
            .iter()
            .zip(&ch.values)
            .fold(0.0f64, |m, (a, b)| m.max((a - b).abs()));
        assert!(err <= 1e-3 * scale, "{}: {err} of {scale}", ch.name);
    }
}
