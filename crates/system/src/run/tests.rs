use super::*;
use crate::rig;
use crate::signal::Signal;

/// A 1 kHz square-wave command of `seconds`, open loop.
fn square(seconds: f64) -> (Vec<f64>, Vec<f64>) {
    let n = (seconds * 1e3) as usize;
    let t: Vec<f64> = (0..=n).map(|k| k as f64 * 1e-3).collect();
    let u = t
        .iter()
        .map(|t| {
            if (t / 2.0).rem_euclid(1.0) < 0.5 {
                0.137
            } else {
                -0.198
            }
        })
        .collect();
    (t, u)
}

/// Collects the blocks of a streamed run into one.
fn collect(blocks: &mut Vec<Run>) -> impl FnMut(&Run) -> Result<(), String> + '_ {
    |b: &Run| {
        blocks.push(b.clone());
        Ok(())
    }
}

fn joined(blocks: &[Run]) -> (Vec<f64>, Vec<Vec<f64>>) {
    let t = blocks.iter().flat_map(|b| b.time.iter().copied()).collect();
    let n = blocks[0].channels.len();
    let ch = (0..n)
        .map(|j| {
            blocks
                .iter()
                .flat_map(|b| b.channels[j].values.iter().copied())
                .collect()
        })
        .collect();
    (t, ch)
}

/// A command chunked like a file read a buffer at a time.
struct Chunked {
    t: Vec<f64>,
    u: Vec<f64>,
    at: usize,
    chunk: usize,
}

impl CommandSource for Chunked {
    fn read(&mut self, t: &mut Vec<f64>, u: &mut Vec<f64>) -> Result<bool, String> {
        let end = (self.at + self.chunk).min(self.t.len());
        t.extend_from_slice(&self.t[self.at..end]);
        u.extend_from_slice(&self.u[self.at..end]);
        self.at = end;
        Ok(end < self.t.len())
    }
}

/// A streamed run over many blocks is the one-block run: no restart at
/// a block's start, so the same steps and the same outputs (issue 18:
/// the restarts moved results by up to 7e-3 of a channel's peak).
#[test]
fn streamed_runs_equal_the_whole_run() {
    let value = rig::load("leaney-moog").unwrap();
    let (t, u) = square(30.0);
    let table = Signal::table(t.clone(), u.clone()).unwrap();
    let opts = RunOptions::default();
    let mut c = rig::circuit(&value, table.clone()).unwrap();
    let x0 = c.initial_state();
    let whole = run(&mut c, &x0, &t, &opts).unwrap();

    let mut blocks = Vec::new();
    let mut c = rig::circuit(&value, table).unwrap();
    let total = run_streaming(&mut c, &x0, &t, &opts, 2000, &mut collect(&mut blocks)).unwrap();
    assert!(blocks.len() >= 10, "{} blocks", blocks.len());
    let (ts, ch) = joined(&blocks);
    assert_eq!(ts, whole.time);
    for (a, b) in ch.iter().zip(&whole.channels) {
        assert_eq!(a, &b.values, "channel {}", b.name);
    }
    assert_eq!(total.stats, whole.stats);

    // a command read in chunks into a window, as the CLI streams a file
    let window = StreamedTable::new(8192);
    // the host sets the record's range, as the CLI does from its first
    // pass (a table's corners are judged against it)
    let (lo, hi) = u
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), &v| {
            (l.min(v), h.max(v))
        });
    window.set_range(lo, hi);
    let mut c = rig::circuit(&value, Signal::Streamed(window.clone())).unwrap();
    let mut source = Chunked {
        t: t.clone(),
        u,
        at: 0,
        chunk: 777,
    };
    let mut blocks = Vec::new();
    let total = run_command_stream(
        &mut c,
        &x0,
        &window,
        &mut source,
        t[t.len() - 1],
        &opts,
        2000,
        &mut collect(&mut blocks),
    )
    .unwrap();
    let (ts, ch) = joined(&blocks);
    assert_eq!(ts, whole.time);
    for (a, b) in ch.iter().zip(&whole.channels) {
        let peak = b.values.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        let worst = a
            .iter()
            .zip(&b.values)
            .fold(0.0f64, |m, (x, y)| m.max((x - y).abs()));
        assert!(
            worst <= 1e-12 * peak,
            "channel {}: {worst:e} of {peak:e}",
            b.name
        );
    }
    assert_eq!(total.stats, whole.stats);
    assert!(!window.underrun());
}

/// A history-free circuit's probes read on a second circuit from the raw
/// states of [`run_streaming_states`] are the whole run's channels, bit for
/// bit; a circuit with a modal component (Karnopp friction's stick/slip) is
/// not history-free and a [`ProbeReader`] refuses it.
#[test]
fn probes_read_on_a_second_circuit_are_the_runs() {
    let value = rig::load("leaney-moog").unwrap();
    let (t, u) = square(5.0);
    let table = Signal::table(t.clone(), u).unwrap();
    let opts = RunOptions::default();
    let mut c = rig::circuit(&value, table.clone()).unwrap();
    assert!(c.history_free());
    let x0 = c.initial_state();
    let whole = run(&mut c, &x0, &t, &opts).unwrap();

    let second = rig::circuit(&value, table.clone()).unwrap();
    let mut reader = ProbeReader::new(second, &x0, t[0], &opts).unwrap();
    let mut blocks = Vec::new();
    let mut c = rig::circuit(&value, table.clone()).unwrap();
    let total = run_streaming_states(&mut c, &x0, &t, &opts, 300, &mut |t, x| {
        let mut b = Run::default();
        reader.read(t, x, &mut b);
        blocks.push(b);
        Ok(())
    })
    .unwrap();
    assert!(blocks.len() >= 10, "{} blocks", blocks.len());
    let (ts, ch) = joined(&blocks);
    assert_eq!(ts, whole.time);
    assert_eq!(ch.len(), whole.channels.len());
    for (j, (a, b)) in ch.iter().zip(&whole.channels).enumerate() {
        assert_eq!(blocks[0].channels[j].name, b.name);
        assert_eq!(a, &b.values, "channel {}", b.name);
    }
    let states: Vec<f64> = blocks.iter().flat_map(|b| b.states.clone()).collect();
    assert_eq!(states, whole.states);
    assert_eq!(total.stats, whole.stats);

    let mut modal = value.clone();
    modal["components"]["friction"] = serde_json::json!({
        "type": "friction_karnopp", "sigma2": 500.0,
        "curve": {"coulomb": 50.0, "stiction": 60.0, "stribeck_velocity": 0.005,
                  "stribeck_exponent": 2.0}
    });
    let c = rig::circuit(&modal, table).unwrap();
    assert!(!c.history_free());
    assert!(ProbeReader::new(c, &x0, t[0], &opts).is_err());
}

/// Runs every preset on the 0.3 s square wave with the default options and
/// calls `f(preset name, rig, command, times, initial state, circuit, run)`
/// on each; returns the command.
fn on_every_preset(
    mut f: impl FnMut(&str, &serde_json::Value, &Signal, &[f64], &[f64], &Circuit, &Run),
) -> Signal {
    let (t, u) = square(0.3);
    let table = Signal::table(t.clone(), u).unwrap();
    for preset in rig::PRESETS {
        let value = (preset.json)();
        let mut c = rig::circuit(&value, table.clone()).unwrap();
        let x0 = c.initial_state();
        let whole = run(&mut c, &x0, &t, &RunOptions::default()).unwrap();
        f(preset.name, &value, &table, &t, &x0, &c, &whole);
    }
    table
}

#[test]
fn stored_channels_read_alone_are_the_full_runs_on_every_preset() {
    // Every preset: the channels whose wires a component publishes from its
    // state, read alone (without evaluating the circuit), equal the full
    // run's, bit for bit; the valve rig's compared channels are such.
    let opts = RunOptions::default();
    let table = on_every_preset(|preset, value, table, t, x0, c, whole| {
        let stored: Vec<String> = c
            .probes()
            .into_iter()
            .filter(|p| c.publisher_of(p.wire).is_some())
            .map(|p| p.name)
            .collect();
        if preset == "leaney-moog" {
            for n in ["position", "velocity", "p1", "p2"] {
                assert!(stored.iter().any(|s| s == n), "{n} is not stored");
            }
        }
        let alone = RunOptions {
            only_channels: Some(stored.clone()),
            ..opts.clone()
        };
        let mut c = rig::circuit(value, table.clone()).unwrap();
        let part = run(&mut c, x0, t, &alone).unwrap();
        assert_eq!(part.channels.len(), stored.len(), "{preset}");
        for ch in &part.channels {
            assert_eq!(
                Some(&ch.values),
                whole.channel(&ch.name).map(|v| v.to_vec()).as_ref(),
                "{preset}: {}",
                ch.name
            );
        }
    });
    let (t, _) = square(0.3);
    let value = rig::load("leaney-moog").unwrap();
    let mut c = rig::circuit(&value, table).unwrap();
    let x0 = c.initial_state();
    let wrong = RunOptions {
        only_channels: Some(vec!["position".into(), "p3".into()]),
        ..opts
    };
    let e = run(&mut c, &x0, &t, &wrong).unwrap_err().to_string();
    assert!(e.contains("channel `p3`") && e.contains("p1"), "{e}");
}

#[test]
fn each_channel_read_from_what_it_depends_on_is_the_full_runs_on_every_preset() {
    // Every preset: each channel read alone (its wire set by what it depends
    // on, `Circuit::partial_for`, not by the whole circuit)
    // equals the full run's, bit for bit; debug builds also compare every
    // such row with a full evaluation as it is read.
    let table = on_every_preset(|preset, value, table, t, x0, c, whole| {
        for probe in c.probes() {
            let alone = RunOptions {
                only_channels: Some(vec![probe.name.clone()]),
                ..RunOptions::default()
            };
            let mut c = rig::circuit(value, table.clone()).unwrap();
            let part = run(&mut c, x0, t, &alone).unwrap();
            assert_eq!(
                Some(part.channels[0].values.as_slice()),
                whole.channel(&probe.name),
                "{preset}: {}",
                probe.name
            );
        }
    });
    // the valve rig's channels (the friction force and the load pressure
    // among them): the friction and the cylinder are evaluated, not the
    // valve's orifices (its supply pressure, undrooped, is the supply's)
    let c = rig::circuit(&rig::load("leaney-moog").unwrap(), table).unwrap();
    let wires: Vec<_> = c.probes().into_iter().map(|p| p.wire).collect();
    let names: Vec<&str> = c.components().map(|k| k.name()).collect();
    let evaluated: Vec<&str> = c
        .partial_for(&wires)
        .expect("less than the whole evaluation")
        .steps()
        .iter()
        .map(|s| match *s {
            crate::series::Step::Evaluate(i) => names[i],
            crate::series::Step::Solve(_) => "an algebraic node",
        })
        .collect();
    assert!(
        evaluated.contains(&"friction")
            && evaluated.contains(&"cylinder")
            && !evaluated.contains(&"valve"),
        "{evaluated:?}"
    );
}

#[test]
fn min_chamber_pressure_reads_every_cylinders_chambers_and_nothing_else() {
    let channel = |probe: &str, values: Vec<f64>| Channel {
        name: format!("column of {probe}"),
        unit: "Pa",
        probe: probe.into(),
        values,
    };
    let mut r = Run {
        time: vec![0.0, 1.0],
        channels: vec![
            channel("cylinder_1.p1", vec![3e5, 2e5]),
            channel("cylinder_2.p2", vec![1e5, -4e4]),
            channel("line_1.p", vec![-9e5, -9e5]),
        ],
        ..Run::default()
    };
    assert_eq!(r.min_chamber_pressure(), -4e4);
    r.channels.push(channel("cylinder.p1", vec![-5e4, 0.0]));
    assert_eq!(r.min_chamber_pressure(), -5e4);
    r.channels.clear();
    assert_eq!(r.min_chamber_pressure(), f64::INFINITY);
}
