//! `hydrocyl diagnose`: run a rig against measured records, trace the
//! residual to catalog effects, add the ones that earn their place, and
//! report before and after (human table on stdout, JSON with `--report`,
//! SVG plots with `--plots`). Nothing is written when anything fails.

use std::io::IsTerminal as _;
use std::path::{Path, PathBuf};

use hydrocyl_identify::bench::{self, FrictionBench};
use hydrocyl_identify::catalog::EffectId;
use hydrocyl_identify::data::{write_atomic, ColumnMap, Record};
use hydrocyl_identify::diagnose::{diagnose_bench, DiagnoseOptions, RecordTrace};
use hydrocyl_identify::valve::diagnose_valve_traced;
use hydrocyl_system::rig::valve_rig_from;
use hydrocyl_system::valve_rig::ValveRig;

use crate::error::CliError;

/// Arguments of this subcommand.
#[derive(clap::Args)]
pub struct Args {
    /// Rig: a preset name (valve rig: leaney-moog; friction benches:
    /// tudelft-seal-25, tudelft-seal-257, emps) or a rig JSON file
    /// (kind valve-cylinder or friction-bench).
    #[arg(long)]
    pub rig: String,
    /// Measured record(s) (CSV); repeat for several records of one rig
    /// (e.g. one per pressure level), fitted jointly.
    #[arg(long, required = true, num_args = 1..)]
    pub data: Vec<PathBuf>,
    /// Where to write the JSON report.
    #[arg(long)]
    pub report: Option<PathBuf>,
    /// Folder for SVG plots (measured vs simulated, residual vs regressor).
    #[arg(long)]
    pub plots: Option<PathBuf>,
    /// Least share of the residual an effect must explain to be added.
    #[arg(long, default_value_t = 0.03)]
    pub min_share: f64,
    /// Share at the end of each record held out from the tracing fit.
    #[arg(long, default_value_t = 0.3)]
    pub holdout: f64,
    /// Smoother half-width in samples (default: chosen by GCV).
    #[arg(long)]
    pub window: Option<usize>,
    /// Restrict the effects the loop may add (comma separated catalog ids).
    #[arg(long, value_delimiter = ',')]
    pub effects: Option<Vec<String>>,
    /// Print nothing but errors.
    #[arg(long)]
    pub quiet: bool,
}

/// A rig `diagnose` can run.
enum Rig {
    Bench(FrictionBench),
    Valve(Box<ValveRig>),
}

fn load_rig(spec: &str) -> Result<Rig, CliError> {
    if let Some(r) = bench::preset(spec) {
        return Ok(Rig::Bench(r));
    }
    if let Some(v) = hydrocyl_system::rig::preset(spec) {
        return valve_rig_from(&v)
            .map(|r| Rig::Valve(Box::new(r)))
            .map_err(|e| CliError::Input(format!("--rig {spec}: {e}")));
    }
    let path = Path::new(spec);
    if !path.exists() {
        return Err(CliError::Input(format!(
            "--rig '{spec}': neither a preset ({}, {}) nor an existing rig file",
            bench::PRESETS.join(", "),
            hydrocyl_system::rig::PRESETS
                .iter()
                .map(|p| p.name)
                .collect::<Vec<_>>()
                .join(", ")
        )));
    }
    let text = std::fs::read_to_string(path).map_err(|e| CliError::Io {
        path: spec.to_string(),
        source: e,
    })?;
    let v: serde_json::Value = serde_json::from_str(&text)
        .map_err(|e| CliError::Input(format!("{spec}: not valid JSON: {e}")))?;
    match v.get("kind").and_then(|k| k.as_str()).unwrap_or("") {
        k if k == bench::KIND => FrictionBench::from_json(&text)
            .map(Rig::Bench)
            .map_err(|e| CliError::Input(format!("{spec}: {e}"))),
        k if k == hydrocyl_system::valve_rig::KIND => valve_rig_from(&v)
            .map(|r| Rig::Valve(Box::new(r)))
            .map_err(|e| CliError::Input(format!("{spec}: {e}"))),
        k => Err(CliError::Input(format!(
            "{spec}: rig kind '{k}' cannot be diagnosed (kinds: {}, {})",
            bench::KIND,
            hydrocyl_system::valve_rig::KIND
        ))),
    }
}

/// Runs the subcommand.
pub fn run(args: Args) -> Result<(), CliError> {
    if !(0.0..1.0).contains(&args.min_share) {
        return Err(CliError::Input(format!(
            "--min-share {}: must be in [0, 1)",
            args.min_share
        )));
    }
    if !(0.05..=0.5).contains(&args.holdout) {
        return Err(CliError::Input(format!(
            "--holdout {}: must be in [0.05, 0.5]",
            args.holdout
        )));
    }
    if args.window == Some(0) {
        return Err(CliError::Input("--window 0: must be at least 1".into()));
    }
    let candidates = match &args.effects {
        None => None,
        Some(ids) => Some(
            ids.iter()
                .map(|id| {
                    EffectId::from_id(id.trim())
                        .ok_or_else(|| CliError::Input(format!("--effects: unknown effect '{id}'")))
                })
                .collect::<Result<Vec<_>, _>>()?,
        ),
    };
    let rig = load_rig(&args.rig)?;
    let columns = match &rig {
        Rig::Bench(b) => b.columns.clone(),
        Rig::Valve(_) => ColumnMap::default(),
    };
    let records = args
        .data
        .iter()
        .map(|p| Record::read_mapped(p, &columns))
        .collect::<Result<Vec<_>, _>>()
        .map_err(|e| CliError::Input(e.to_string()))?;
    let opts = DiagnoseOptions {
        min_share: args.min_share,
        holdout: args.holdout,
        half_window: args.window,
        candidates,
        ..DiagnoseOptions::default()
    };
    let reporter = Progress::new(args.quiet);
    let mut progress = |stage: &str, done: usize, total: usize| reporter.update(stage, done, total);
    let (report, traces) = match &rig {
        Rig::Bench(b) => {
            let o = diagnose_bench(b, &records, &opts, &mut progress)
                .map_err(|e| CliError::Input(e.to_string()))?;
            (o.report, o.traces)
        }
        Rig::Valve(v) => {
            if records.len() != 1 {
                return Err(CliError::Input(format!(
                    "--data: the valve rig is diagnosed on one record at a time ({} given)",
                    records.len()
                )));
            }
            let o = diagnose_valve_traced(v, &records[0], &opts, &mut progress)
                .map_err(|e| CliError::Input(e.to_string()))?;
            (o.report, o.traces)
        }
    };
    drop(reporter);
    // Everything computed: now write, plots first, the report last.
    if let Some(dir) = &args.plots {
        write_plots(dir, &traces)?;
    }
    if let Some(path) = &args.report {
        let json = serde_json::to_string_pretty(&report)
            .map_err(|e| CliError::Input(format!("report: {e}")))?;
        write_atomic(path, json.as_bytes()).map_err(|e| CliError::Io {
            path: path.display().to_string(),
            source: e,
        })?;
    }
    if !args.quiet {
        print!("{}", report.human());
        if let Some(dir) = &args.plots {
            println!(
                "plots: {} SVG files in {}",
                plot_count(&traces),
                dir.display()
            );
        }
    }
    Ok(())
}

/// The one place diagnose's progress goes: a bar with the stage, the
/// candidate round, elapsed time and ETA on stderr when it is a terminal,
/// nothing under `--quiet` (the bar is cleared when this is dropped).
struct Progress {
    bar: Option<indicatif::ProgressBar>,
}

impl Progress {
    fn new(quiet: bool) -> Self {
        let bar = (!quiet && std::io::stderr().is_terminal()).then(|| {
            let b = indicatif::ProgressBar::new(1);
            b.set_style(
                indicatif::ProgressStyle::with_template(
                    "{spinner} diagnose [{bar:30}] {pos}/{len} {msg} ({elapsed}, eta {eta})",
                )
                .unwrap_or_else(|_| indicatif::ProgressStyle::default_bar()),
            );
            b
        });
        Self { bar }
    }

    /// Stage `stage`, `done` of `total` steps.
    fn update(&self, stage: &str, done: usize, total: usize) {
        if let Some(b) = &self.bar {
            b.set_length(total as u64);
            b.set_position(done as u64);
            b.set_message(stage.to_string());
        }
    }
}

impl Drop for Progress {
    fn drop(&mut self) {
        if let Some(b) = &self.bar {
            b.finish_and_clear();
        }
    }
}

/// Number of SVG files [`write_plots`] writes for `traces`.
fn plot_count(traces: &[RecordTrace]) -> usize {
    traces.len() + traces.iter().filter(|t| t.regressor.is_some()).count()
}

/// Writes, per record and compared channel, `<stem>-<channel>.svg` (measured,
/// before and after against time, and below it the residuals before and
/// after) and, when an effect with a regressor was added (friction benches),
/// `<stem>-residual.svg` (residual before vs that effect's regressor).
fn write_plots(dir: &Path, traces: &[RecordTrace]) -> Result<(), CliError> {
    std::fs::create_dir_all(dir).map_err(|e| CliError::Io {
        path: dir.display().to_string(),
        source: e,
    })?;
    for (k, tr) in traces.iter().enumerate() {
        let stem = Path::new(&tr.source)
            .file_stem()
            .and_then(|s| s.to_str())
            .map_or_else(|| format!("record{k}"), |s| s.to_string());
        let f = dir.join(format!("{stem}-{}.svg", tr.channel));
        plot_series(&f, tr).map_err(|e| CliError::Input(format!("{}: {e}", f.display())))?;
        if tr.regressor.is_some() {
            let f = dir.join(format!("{stem}-residual.svg"));
            plot_residual(&f, tr).map_err(|e| CliError::Input(format!("{}: {e}", f.display())))?;
        }
    }
    Ok(())
}

fn bounds(series: &[&[f64]]) -> (f64, f64) {
    let lo = series
        .iter()
        .flat_map(|s| s.iter())
        .copied()
        .fold(f64::INFINITY, f64::min);
    let hi = series
        .iter()
        .flat_map(|s| s.iter())
        .copied()
        .fold(f64::NEG_INFINITY, f64::max);
    let pad = 0.05 * (hi - lo).max(1e-12);
    (lo - pad, hi + pad)
}

/// SI unit of a compared channel, for axis labels.
fn unit(channel: &str) -> &'static str {
    match channel {
        "force" => "N",
        "position" => "m",
        "velocity" => "m/s",
        "p1" | "p2" | "ps" => "Pa",
        _ => "SI",
    }
}

/// One time-series panel: `lines` (name, values, colour) against `t`.
fn time_panel(
    area: &plotters::drawing::DrawingArea<
        plotters::prelude::SVGBackend<'_>,
        plotters::coord::Shift,
    >,
    caption: &str,
    y_desc: &str,
    t: &[f64],
    lines: &[(&str, &[f64], plotters::style::RGBColor)],
) -> Result<(), Box<dyn std::error::Error>> {
    use plotters::prelude::*;
    let t0 = t[0];
    let t1 = *t.last().unwrap_or(&t0);
    let ys: Vec<&[f64]> = lines.iter().map(|l| l.1).collect();
    let (lo, hi) = bounds(&ys);
    let mut ch = ChartBuilder::on(area)
        .caption(caption, ("sans-serif", 15))
        .margin(10)
        .x_label_area_size(35)
        .y_label_area_size(70)
        .build_cartesian_2d(t0..t1, lo..hi)?;
    ch.configure_mesh()
        .x_desc("time [s]")
        .y_desc(y_desc)
        .draw()?;
    for &(name, y, colour) in lines {
        ch.draw_series(LineSeries::new(
            t.iter().copied().zip(y.iter().copied()),
            colour,
        ))?
        .label(name)
        .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 15, y)], colour));
    }
    ch.configure_series_labels()
        .border_style(BLACK)
        .background_style(WHITE)
        .draw()?;
    Ok(())
}

fn plot_series(path: &Path, tr: &RecordTrace) -> Result<(), Box<dyn std::error::Error>> {
    use plotters::prelude::*;
    let root = SVGBackend::new(path, (1000, 650)).into_drawing_area();
    root.fill(&WHITE)?;
    let (upper, lower) = root.split_vertically(420);
    let u = unit(&tr.channel);
    time_panel(
        &upper,
        &format!("{}: {} measured vs simulated", tr.source, tr.channel),
        &format!("{} [{u}]", tr.channel),
        &tr.t,
        &[
            ("measured", &tr.measured, BLACK),
            ("before", &tr.before, RED),
            ("after", &tr.after, BLUE),
        ],
    )?;
    let resid =
        |sim: &[f64]| -> Vec<f64> { tr.measured.iter().zip(sim).map(|(m, s)| m - s).collect() };
    let (rb, ra) = (resid(&tr.before), resid(&tr.after));
    time_panel(
        &lower,
        "residual = measured − simulated",
        &format!("residual [{u}]"),
        &tr.t,
        &[("before", &rb, RED), ("after", &ra, BLUE)],
    )?;
    root.present()?;
    Ok(())
}

fn plot_residual(path: &Path, tr: &RecordTrace) -> Result<(), Box<dyn std::error::Error>> {
    use plotters::prelude::*;
    let Some((name, phi)) = &tr.regressor else {
        return Ok(());
    };
    let resid: Vec<f64> = tr
        .measured
        .iter()
        .zip(&tr.before)
        .map(|(m, b)| m - b)
        .collect();
    let root = SVGBackend::new(path, (700, 500)).into_drawing_area();
    root.fill(&WHITE)?;
    let (xlo, xhi) = bounds(&[phi]);
    let (ylo, yhi) = bounds(&[&resid]);
    let mut ch = ChartBuilder::on(&root)
        .caption(
            format!("{}: residual before vs {name} regressor", tr.source),
            ("sans-serif", 15),
        )
        .margin(10)
        .x_label_area_size(35)
        .y_label_area_size(60)
        .build_cartesian_2d(xlo..xhi, ylo..yhi)?;
    ch.configure_mesh()
        .x_desc(format!("{name} regressor [SI]"))
        .y_desc("residual before [SI]")
        .draw()?;
    let step = (phi.len() / 1500).max(1);
    ch.draw_series(
        phi.iter()
            .zip(&resid)
            .step_by(step)
            .map(|(x, y)| Circle::new((*x, *y), 1, BLUE.filled())),
    )?;
    root.present()?;
    Ok(())
}
