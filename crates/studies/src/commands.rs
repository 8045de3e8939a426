//! The command files of the thesis's experiments, as `hydrocyl simulate`
//! reads them (`fixtures/commands/`, written by `cargo xtask commands`):
//! each study's own command signal ([`chapter3`],
//! [`chapter7`](crate::chapter7), [`chapter8`]) sampled at its output times, with the preset, the `--set`s
//! and the command line that run it, and what the run shows.
//!
//! A command file is a first-order-hold table (the CLI's command CSV): a
//! square wave's step becomes a ramp over one sample interval, which the
//! studies' own [`Signal::Square`] does not have. The runs differ from the
//! studies' by that much (the README's numbers say by how much where it
//! shows).

use crate::chapter7::{Chapter7Test, Load, Shape};
use crate::chapter8::{Drive, Scenario, Wave, G};
use crate::{chapter3, chapter8};
use hydrocyl_system::hybrid::WangHybrid;
use hydrocyl_system::signal::Signal;
use std::fmt::Write as _;

/// The folder the files go to, from the workspace root.
pub const FOLDER: &str = "fixtures/commands";

/// One command file and how to run it.
#[derive(Clone, Debug)]
pub struct CommandFile {
    /// File name (`ch7-square.csv`).
    pub name: String,
    /// The command's unit (`-`: normalised spool demand; `V`: pump drive).
    pub unit: &'static str,
    /// Sample times \[s\].
    pub time: Vec<f64>,
    /// The command at those times.
    pub command: Vec<f64>,
    /// Decimals the times are written with (their grid's).
    pub time_decimals: usize,
    /// The preset it runs on.
    pub rig: &'static str,
    /// `--set PATH=VALUE`s on the preset.
    pub sets: Vec<String>,
    /// `--solver`, where the study's is not the default (auto).
    pub solver: Option<&'static str>,
    /// `--ledger-from` \[s\], for a run whose ledger the study takes after a
    /// warm-up.
    pub ledger_from: Option<f64>,
    /// Thesis section, figure or table.
    pub source: String,
    /// The command.
    pub what: String,
    /// What the run should show, with the number docs/*.md report.
    pub expect: String,
}

impl CommandFile {
    /// The CSV text: `time [s],command [<unit>]`, one row per sample, the
    /// values to the last bit (Rust's shortest round-trip form).
    pub fn csv(&self) -> String {
        let mut s = format!("time [s],command [{}]\n", self.unit);
        for (t, u) in self.time.iter().zip(&self.command) {
            let _ = writeln!(s, "{t:.prec$},{u}", prec = self.time_decimals);
        }
        s
    }

    /// The `hydrocyl simulate` command line, with the output `<stem>.csv`
    /// (and the ledger `<stem>.ledger.json` where the study takes one).
    pub fn command_line(&self) -> String {
        let stem = self.name.trim_end_matches(".csv");
        let mut s = format!(
            "hydrocyl simulate --rig {} --command {FOLDER}/{} --out {stem}.out.csv",
            self.rig, self.name
        );
        if let Some(solver) = self.solver {
            let _ = write!(s, " --solver {solver}");
        }
        for set in &self.sets {
            let _ = write!(s, " --set {set}");
        }
        if let Some(from) = self.ledger_from {
            let _ = write!(s, " --ledger {stem}.ledger.json --ledger-from {from}");
        }
        s
    }
}

/// `signal` sampled at `times`.
fn sampled(signal: &Signal, times: &[f64]) -> Vec<f64> {
    times.iter().map(|&t| signal.value(t)).collect()
}

/// `0, dt, …, n dt`.
fn grid(n: usize, dt: f64) -> Vec<f64> {
    (0..=n).map(|k| k as f64 * dt).collect()
}

/// Every command file, in the README's order.
pub fn all() -> Result<Vec<CommandFile>, String> {
    let mut v = chapter3_files()?;
    v.extend(chapter7_files());
    v.extend(chapter8_files()?);
    Ok(v)
}

/// Section 3.3: the square wave, the underlap sine and the sawtooth on
/// `leaney-moog` ([`chapter3`]).
fn chapter3_files() -> Result<Vec<CommandFile>, String> {
    let e = |e: hydrocyl_system::rig::RigError| e.to_string();
    let square = chapter3::square_wave().map_err(e)?;
    let sine = chapter3::underlap_sine().map_err(e)?;
    let saw = chapter3::sawtooth().map_err(e)?;
    let file = |c: &chapter3::Case, name: &str| CommandFile {
        name: name.into(),
        unit: "-",
        command: sampled(&c.command, &c.times),
        time: c.times.clone(),
        time_decimals: 3,
        rig: "leaney-moog",
        sets: Vec::new(),
        solver: None,
        ledger_from: None,
        source: String::new(),
        what: c.description.clone(),
        expect: String::new(),
    };
    let mut sq = file(&square, "ch3-square.csv");
    sq.source =
        "section 3.3.1, Figs 3-11 and 3-21 (the open-loop bias of section 3.1.3; Table 3-5)".into();
    sq.expect = "plateaus of +90.0 / −90.0 mm/s in `velocity` (docs/models.md section 4, \
                 `ValveRig::open_loop_square`), the piston 90 mm out and back each 2-s period \
                 (`position` from −0.8 to +90.4 mm), no cavitation"
        .into();
    let mut si = file(&sine, "ch3-underlap-sine.csv");
    si.source = "section 3.3.2, Figs 3-22 and 3-23 (Table 3-5)".into();
    // the study's rig: the underlap widened to 20 % of the spool stroke,
    // the spool starting where the piston rests
    si.sets = vec![
        format!("valve.underlap={}", sine.rig.valve.underlap_m),
        format!("spool.initial.position={}", sine.rig.initial.spool),
    ];
    si.expect = "the spool stays inside the widened underlap (`spool` from −0.058 to +0.032 mm, \
                 inside ±0.075 mm), `velocity` from −124.5 to +127.9 mm/s, the piston swinging \
                 81.2 mm in each period and creeping +1.67 mm per period (`position` up to \
                 84.5 mm in the third), far from an end; the underlap must be widened by the \
                 `--set`s (the preset's 4.5 µm is the Moog valve's own; the thesis widens it to \
                 20 % of the stroke for this test, section 3.3.2)"
        .into();
    let mut sw = file(&saw, "ch3-sawtooth.csv");
    sw.source = "section 3.3.3, Figs 3-24 to 3-26 (Table 3-5)".into();
    sw.expect = "the drop at the end of each ramp reverses a piston moving at ~0.3 m/s: chamber 1 \
                 cavitates, p1 down to −14.9 bar with 3 cavitation entries (the summary line; \
                 docs/models.md section 3); `hydrocyl simulate` writes the run and warns that a \
                 chamber pressure fell far below absolute vacuum (from t = 1.505 s: the oil of \
                 constant bulk modulus has left its range), exit code 0"
        .into();
    Ok(vec![sq, si, sw])
}

/// Sections 7.1 and 7.2: the ±50 mm/s square and sine at 0.2 Hz on
/// `wang-hybrid` as shipped, from 60 mm below mid-stroke (the validation's
/// "preset as shipped" runs, docs/hybrid.md items 7 to 9).
fn chapter7_files() -> Vec<CommandFile> {
    let rig = WangHybrid::preset();
    [Shape::Square, Shape::Sine]
        .into_iter()
        .map(|shape| {
            let mut test = Chapter7Test::new(shape, Load::None);
            test.initial_position = -0.06;
            let t_end = test.periods as f64 / test.frequency;
            let n = (t_end / test.sample_interval).round() as usize;
            let time = grid(n, test.sample_interval);
            let (name, source, expect) = match shape {
                Shape::Square => (
                    "ch7-square.csv",
                    "section 7.1, Figs 7-2 to 7-5",
                    "the lowest chamber pressure −2.15 bar with 11 cavitation entries (the \
                     summary line), drift towards extension +0.41 mm in each period after the \
                     first and +2.65 mm over the three (docs/hybrid.md items 7 to 9: −2.15 bar, 11 \
                     entries, +0.41 mm per period; +2.7 mm on a 0.1-ms grid); the friction of eq \
                     7.4 (182 / −133 N), the slower rise retracting and the stall and charging \
                     intervals at the reversals (a few ms) are measured by validate and \
                     `crates/cli/tests/hybrid_square.rs` on 0.1-ms samples of this command",
                ),
                Shape::Sine => (
                    "ch7-sine.csv",
                    "section 7.2, Figs 7-6 to 7-9",
                    "drift towards extension +17.16 mm in the second period (docs/hybrid.md item \
                     7: +17.15 mm per period), no cavitation; a stall of 75–80 ms at each \
                     reversal (item 9)",
                ),
            };
            let command = test.command(&rig);
            CommandFile {
                name: name.into(),
                unit: "V",
                command: sampled(&command, &time),
                time,
                time_decimals: 3,
                rig: "wang-hybrid",
                sets: vec![format!(
                    "cylinder.initial.position={}",
                    test.initial_position
                )],
                solver: None,
                ledger_from: None,
                source: source.into(),
                what: format!(
                    "{} ±50 mm/s at 0.2 Hz with the section-7.1 bias ({}), 15 s",
                    match shape {
                        Shape::Square => "square",
                        Shape::Sine => "sine",
                    },
                    describe(&command)
                ),
                expect: expect.into(),
            }
        })
        .collect()
}

/// A wave's levels, for the README.
fn describe(s: &Signal) -> String {
    match s {
        Signal::Square {
            amplitude, bias, ..
        } => format!(
            "{:.4} extending, {:.4} retracting",
            bias + amplitude,
            bias - amplitude
        ),
        Signal::Sine {
            amplitude, bias, ..
        } => format!("{bias:.4} ± {amplitude:.4}"),
        _ => String::new(),
    }
}

/// hydrocyl's efficiency in docs/energy.md's table for a base scenario
/// (`cargo xtask energy`, Plan::default) \[%\].
fn documented_efficiency(sc: &Scenario) -> Option<f64> {
    let table: [(&str, f64, Wave, f64, f64); 16] = [
        ("valve", 50.0, Wave::Sine, 0.0, 3.66),
        ("valve", 50.0, Wave::Square, 0.0, 4.08),
        ("valve", 100.0, Wave::Sine, 0.0, 4.85),
        ("valve", 100.0, Wave::Square, 0.0, 5.50),
        ("valve", 50.0, Wave::Sine, 20.0, 3.33),
        ("valve", 50.0, Wave::Square, 20.0, 3.84),
        ("valve", 100.0, Wave::Sine, 20.0, 4.09),
        ("valve", 100.0, Wave::Square, 20.0, 4.66),
        ("hybrid", 50.0, Wave::Sine, 0.0, 8.02),
        ("hybrid", 50.0, Wave::Square, 0.0, 7.44),
        ("hybrid", 100.0, Wave::Sine, 0.0, 7.33),
        ("hybrid", 100.0, Wave::Square, 0.0, 5.13),
        ("hybrid", 50.0, Wave::Sine, 20.0, 9.67),
        ("hybrid", 50.0, Wave::Square, 20.0, 7.93),
        ("hybrid", 100.0, Wave::Sine, 20.0, 7.34),
        ("hybrid", 100.0, Wave::Square, 20.0, 6.13),
    ];
    table
        .iter()
        .find(|r| r.0 == sc.system && r.1 == sc.speed_mm_s && r.2 == sc.wave && r.3 == sc.load_kg)
        .map(|r| r.4)
}

/// Section 8.2, Tables 8-2 and 8-3: the base matrix's commands
/// ([`chapter8::run_scenario`]'s waves over its [`chapter8::Plan`]'s
/// default span: one warm-up period and two measured, 2-ms samples). The
/// valve drive's bias depends on the load (the open-loop levels are solved
/// with the load on), so it has a file per load; the pump's does not.
fn chapter8_files() -> Result<Vec<CommandFile>, String> {
    let plan = chapter8::Plan::default();
    let valve = match Drive::wang_valve_c10().map_err(|e| e.to_string())? {
        Drive::Valve(r) => *r,
        Drive::Hybrid(_) => return Err("wang-valve-c10 is not a valve drive".into()),
    };
    let hybrid = WangHybrid::preset();
    let mut v = Vec::new();
    for sc in chapter8::base_matrix() {
        let is_valve = sc.system == "valve";
        if !is_valve && sc.load_kg != 0.0 {
            // the hybrid's command does not depend on the load: the
            // no-load file with the load set
            continue;
        }
        let speed = sc.speed();
        let period = sc.period();
        let (bias, amplitude) = if is_valve {
            let mut r = valve.clone();
            r.load.external_force_n = sc.load_kg * G;
            r.open_loop_square(speed).map_err(|e| e.to_string())?
        } else {
            let (a1, a2) = (hybrid.cylinder.area_1.si(), hybrid.cylinder.area_2.si());
            let k = hybrid.pump.gain;
            (speed * (a1 - a2) / (2.0 * k), speed * (a1 + a2) / (2.0 * k))
        };
        let signal = chapter8::wave_signal(sc.wave, amplitude, period, bias);
        let n_per = (period / plan.sample_s).round().max(1.0) as usize;
        let dt = period / n_per as f64;
        let n = n_per * (plan.warmup_periods + plan.measured_periods);
        let time = grid(n, dt);
        let load = if is_valve {
            format!("-{}kg", sc.load_kg)
        } else {
            String::new()
        };
        let name = format!(
            "ch8-{}-{}mms-{}{load}.csv",
            sc.system,
            sc.speed_mm_s,
            sc.wave.name()
        );
        let loads: Vec<f64> = if is_valve {
            vec![sc.load_kg]
        } else {
            vec![0.0, 20.0]
        };
        let mut expect = String::new();
        for kg in loads {
            let row = Scenario {
                load_kg: kg,
                ..sc.clone()
            };
            let thesis = chapter8::thesis_efficiency(&row.system, row.speed_mm_s, row.wave, kg)
                .map(|e| format!("{:.2} %", 100.0 * e))
                .unwrap_or_else(|| "—".into());
            let ours = documented_efficiency(&row)
                .map(|e| format!("{e:.2} %"))
                .unwrap_or_else(|| "—".into());
            if !expect.is_empty() {
                expect.push_str("; ");
            }
            let _ = write!(
                expect,
                "{kg} kg{}: `efficiency` {ours} in the ledger, as docs/energy.md's table (`cargo xtask energy`; thesis {thesis}), closure below 1e-8",
                if !is_valve && kg > 0.0 {
                    format!(" (add `--set load.external_force={}`)", kg * G)
                } else {
                    String::new()
                }
            );
        }
        let mut sets = vec![format!("cylinder.initial.position={}", sc.start_position())];
        if is_valve && sc.load_kg > 0.0 {
            sets.push(format!("load.external_force={}", sc.load_kg * G));
        }
        v.push(CommandFile {
            name,
            unit: if is_valve { "-" } else { "V" },
            command: sampled(&signal, &time),
            time,
            time_decimals: 3,
            rig: if is_valve { "wang-valve-c10" } else { "wang-hybrid" },
            sets,
            solver: Some(if is_valve { "dp45" } else { "rosenbrock" }),
            ledger_from: Some(period * plan.warmup_periods as f64),
            source: format!(
                "section 8.2, Table {} ({} drive)",
                if is_valve { "8-2" } else { "8-3" },
                if is_valve {
                    "valve-controlled"
                } else {
                    "hybrid pump-controlled"
                }
            ),
            what: format!(
                "{} ±{} mm/s, period {period} s ({}), 3 periods: 1 warm-up, the ledger over the 2 after it",
                sc.wave.name(),
                sc.speed_mm_s,
                describe(&signal)
            ),
            expect,
        });
    }
    Ok(v)
}

/// The folder's README: each file, its thesis source, the command line and
/// what the run shows.
pub fn readme(files: &[CommandFile]) -> String {
    let mut s = String::from(
        "# The thesis's experiments as command files\n\n\
         Written by `cargo xtask commands` from the studies' own signal definitions \
         (`hydrocyl_studies::commands`, from `chapter3`, `chapter7` and `chapter8`); do not edit: \
         the test `crates/cli/tests/commands.rs` checks that these files are what the generator \
         writes and runs each on its preset. Each is a CSV `time [s],command [<unit>]` \
         (`-`: the normalised spool demand of a valve rig; `V`: the hybrid's pump drive voltage), \
         read by `hydrocyl simulate` as a first-order-hold table: a square wave's step is a ramp \
         over one sample interval (1 ms; 2 ms for chapter 8), where the studies step it.\n\n\
         Run from the workspace root (`cargo run --release -p hydrocyl-cli --` for `hydrocyl`). \
         The chapter-8 lines write the energy ledger over the measured periods \
         (`--ledger`, `--ledger-from`: docs/energy.md); its `efficiency` is the tables' figure.\n",
    );
    let mut chapter = "";
    for f in files {
        let ch = &f.name[..3];
        if ch != chapter {
            chapter = ch;
            let title = match ch {
                "ch3" => "Chapter 3: the valve rig (`leaney-moog`)",
                "ch7" => "Chapter 7: the hybrid drive's open-loop tests (`wang-hybrid`)",
                _ => "Chapter 8: the efficiency matrix (`wang-valve-c10`, `wang-hybrid`)",
            };
            let _ = write!(s, "\n## {title}\n");
        }
        let _ = write!(
            s,
            "\n### `{}`\n\n* thesis: {}\n* command: {} ({} samples)\n* preset: `{}`{}\n* run:\n\n  ```sh\n  {}\n  ```\n\n* shows: {}\n",
            f.name,
            f.source,
            f.what,
            f.time.len(),
            f.rig,
            if f.sets.is_empty() {
                " as shipped".to_string()
            } else {
                format!(
                    ", with {}",
                    f.sets
                        .iter()
                        .map(|s| format!("`--set {s}`"))
                        .collect::<Vec<_>>()
                        .join(" ")
                )
            },
            f.command_line(),
            f.expect
        );
    }
    s
}
