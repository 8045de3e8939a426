//! `hydrocyl diagnose`: run a rig against measured records, trace the
//! residual to catalog effects, add the ones that earn their place, and
//! report before and after (human table on stdout, JSON with `--report`,
//! SVG plots with `--plots`). Nothing is written when anything fails.

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

use hydrocyl_identify::catalog::EffectId;
use hydrocyl_identify::data::{repeated_record, Record, RecordInput};
use hydrocyl_identify::diagnose::{
    small_sample_warning, DiagnoseError, DiagnoseOptions, DiagnoseRig, RecordTrace,
};

use crate::error::CliError;
use crate::output::Outputs;
use crate::progress::Progress;

/// Arguments of this subcommand.
#[derive(clap::Args)]
pub struct Args {
    /// Rig: a preset name (those diagnose takes: [`presets`]) or a rig JSON
    /// file (a netlist, its `identify` section naming the model, columns and
    /// refits; or an older valve-cylinder or friction-bench file, read as
    /// its netlist).
    #[arg(long)]
    pub rig: String,
    /// Measured record(s) (CSV); repeat for several records of one rig
    /// (e.g. one per pressure level), fitted jointly. A record given twice
    /// (the same file, or the same content under two names) is refused:
    /// its samples would count twice.
    #[arg(long, required = true, num_args = 1..)]
    pub data: Vec<PathBuf>,
    /// Where to write the JSON report.
    #[arg(long)]
    pub report: Option<PathBuf>,
    /// Folder for SVG plots: per record and channel, measured vs simulated
    /// with the residuals (`<record>-<channel>.svg`); for a friction bench
    /// with an effect added, also the residual vs that effect's regressor
    /// (`<record>-residual.svg`). `<record>` is the file's stem; records
    /// whose stems are the same (`a/rec.csv`, `b/rec.csv`; case ignored)
    /// get their position among the --data too (`rec-1`, `rec-2`).
    #[arg(long)]
    pub plots: Option<PathBuf>,
    /// Least share of the residual an effect must explain to be added.
    #[arg(long, default_value_t = 0.03, allow_negative_numbers = true)]
    pub min_share: f64,
    /// Share at the end of each record held out from the tracing fit.
    #[arg(long, default_value_t = 0.3, allow_negative_numbers = true)]
    pub holdout: f64,
    /// Smoother half-width in samples (default: chosen by GCV).
    #[arg(long, allow_negative_numbers = true)]
    pub window: Option<i64>,
    /// Restrict the effects the loop may add (comma separated catalog ids).
    #[arg(long, value_delimiter = ',')]
    pub effects: Option<Vec<String>>,
    /// Print nothing but errors.
    #[arg(long)]
    pub quiet: bool,
    /// Show progress when stderr is not a terminal too (a CI log, a file):
    /// there as plain lines, one every 5 s at most after the first second,
    /// not a redrawn bar (on a terminal a bar shows without this flag).
    #[arg(long)]
    pub progress: bool,
}

/// The rig of `--rig` as `diagnose` runs it: which loop, with which column
/// map, is [`DiagnoseRig::from_value`]'s decision (the one Python's
/// `hydrocyl.diagnose` makes); this reads the preset or file and words the
/// errors for `--rig`.
fn load_rig(spec: &str) -> Result<DiagnoseRig, CliError> {
    let of_value = |v: &serde_json::Value| {
        DiagnoseRig::from_value(v).map_err(|e| CliError::Input(format!("--rig {spec}: {e}")))
    };
    if let Some(v) = hydrocyl_system::rig::preset(spec) {
        return of_value(&v);
    }
    if !Path::new(spec).exists() {
        return Err(CliError::Input(format!(
            "--rig '{spec}': neither a preset ({}; `hydrocyl presets`) nor an existing rig file",
            crate::presets::names()
        )));
    }
    // a friction bench (a netlist whose identification section names the
    // `friction-bench` model, or an older `friction-bench` file)
    if let Some((b, _)) = crate::bench_sim::load(spec, &[])? {
        return Ok(DiagnoseRig::Bench(b));
    }
    // duplicate keys refused, errors with the JSON path and line; an older
    // rig kind (`valve-cylinder`) is read as its netlist
    let v = hydrocyl_system::rig::load(spec).map_err(|e| CliError::Input(e.to_string()))?;
    if v.get("kind").and_then(|k| k.as_str()) == Some(hydrocyl_system::netlist::KIND) {
        // a netlist that does not check (an algebraic loop, a bad
        // parameter) is named as such, with its file and line
        hydrocyl_system::rig::check(&v)
            .map_err(|e| CliError::Input(hydrocyl_system::rig::at_line(e, spec).to_string()))?;
    }
    of_value(&v)
}

/// The presets `diagnose` takes (a friction bench, or a netlist with a
/// cylinder on a mass): those [`load_rig`] reads, so `--help` lists what
/// works, in `hydrocyl presets`' order.
pub fn presets() -> Vec<&'static str> {
    hydrocyl_system::rig::PRESETS
        .iter()
        .map(|p| p.name)
        .filter(|n| load_rig(n).is_ok())
        .collect()
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
    let window = args
        .window
        .map(|w| {
            hydrocyl_identify::smooth::check_half_window(w)
                .map_err(|why| CliError::Input(format!("--window {w}: {why}")))
        })
        .transpose()?;
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
    // a record given twice would count its samples twice
    distinct_records(&args.data)?;
    let rig = load_rig(&args.rig)?;
    // every output checked (and its temporary created) before any work
    let mut inputs: Vec<(&str, &Path)> =
        args.data.iter().map(|p| ("--data", p.as_path())).collect();
    if Path::new(&args.rig).exists() {
        inputs.push(("--rig", Path::new(&args.rig)));
    }
    let mut outputs = Outputs::new(&inputs);
    let report_out = args
        .report
        .as_ref()
        .map(|p| outputs.file("--report", p))
        .transpose()?;
    if let Some(dir) = &args.plots {
        outputs.check_dir("--plots", dir)?;
    }
    let records = args
        .data
        .iter()
        .map(|p| Record::read_mapped(p, rig.columns()))
        .collect::<Result<Vec<_>, _>>()
        .map_err(|e| CliError::Input(e.to_string()))?;
    // every plot this run can write, named and checked before the fit
    let stems = plot_stems(&args.data);
    if let Some(dir) = &args.plots {
        for (r, stem) in records.iter().zip(&stems) {
            for channel in plot_channels(&rig, r) {
                outputs.check("--plots", &dir.join(plot_name(stem, channel)))?;
            }
        }
    }
    let stem_of: BTreeMap<&str, &str> = records
        .iter()
        .zip(&stems)
        .map(|(r, s)| (r.source.as_str(), s.as_str()))
        .collect();
    // as the run starts (the report's `warnings` carry it after): at its
    // first progress, after the record has been checked against the rig,
    // so that a record refused there gets its one error line alone (a
    // short record with no `command` column was a warning, then the error)
    let warnings: Vec<String> = records.iter().filter_map(small_sample_warning).collect();
    let warned = std::cell::Cell::new(args.quiet);
    let warn = || {
        if !warned.replace(true) {
            for w in &warnings {
                crate::console::note(format_args!("hydrocyl: warning: {w}"));
            }
        }
    };
    let opts = DiagnoseOptions {
        min_share: args.min_share,
        holdout: args.holdout,
        half_window: window,
        candidates,
        ..DiagnoseOptions::default()
    };
    let mut bar = Progress::new("diagnose", 1, args.progress, args.quiet);
    let mut progress = |stage: &str, done: usize, total: usize| {
        warn();
        bar.set(stage, done as u64, total as u64);
    };
    let (report, traces) = rig
        .diagnose(&records, &opts, &mut progress)
        .map_err(|e| match e {
            DiagnoseError::OneRecordAtATime(_) => CliError::Input(format!("--data: {e}")),
            e => CliError::Input(e.to_string()),
        })?;
    warn();
    bar.finish();
    if let Some(wanted) = &args.effects {
        // an effect asked for that the loop neither added nor tried
        let seen = |id: &str| {
            report.effects_added.iter().any(|e| e.id == id)
                || report.effects_rejected.iter().any(|e| e.effect.id == id)
        };
        let untried: Vec<&str> = wanted
            .iter()
            .map(|w| w.trim())
            .filter(|w| !seen(w))
            .collect();
        if untried.len() == wanted.len() {
            // each with the report's reason (already on in the declared rig,
            // no balance for it, ...)
            let why: Vec<String> = untried
                .iter()
                .map(|id| {
                    report
                        .effects_not_applicable
                        .iter()
                        .find(|n| n.id == *id)
                        .map_or_else(|| id.to_string(), |n| format!("{id}: {}", n.why))
                })
                .collect();
            return Err(CliError::Input(format!(
                "--effects {}: cannot be tried on this rig ({} rig; the effects it can try are listed without --effects): {}",
                untried.join(","),
                report.rig_kind,
                why.join("; ")
            )));
        }
    }
    // Everything computed: now write every output together.
    let plots = match &args.plots {
        Some(dir) => render_plots(&traces, &stem_of)?
            .into_iter()
            .map(|(name, svg)| (dir.join(name), svg))
            .collect(),
        None => Vec::new(),
    };
    let made_dir = match &args.plots {
        Some(dir) if !dir.exists() => {
            std::fs::create_dir(dir).map_err(|e| CliError::Io {
                path: dir.display().to_string(),
                source: e,
            })?;
            Some(dir.clone())
        }
        _ => None,
    };
    let written = (|| {
        for (path, svg) in &plots {
            let id = outputs.file("--plots", path)?;
            outputs.write(id, svg.as_bytes())?;
        }
        if let Some(id) = report_out {
            let json = serde_json::to_string_pretty(&report)
                .map_err(|e| CliError::Input(format!("report: {e}")))?;
            outputs.write(id, json.as_bytes())?;
        }
        outputs.commit(false)
    })();
    if written.is_err() {
        if let Some(dir) = made_dir {
            let _ = std::fs::remove_dir_all(dir);
        }
    }
    written?;
    if !args.quiet {
        crate::console::print(&report.human())?;
        if let Some(dir) = &args.plots {
            crate::console::print(&format!(
                "plots: {} SVG files in {}\n",
                plots.len(),
                dir.display()
            ))?;
        }
        crate::console::note(format_args!(
            "hydrocyl: diagnose took {:.2} s in all (reading, fitting, writing)",
            crate::progress::wall()
        ));
    }
    Ok(())
}

/// Refuses a record given twice (exit 2, naming both arguments): the same
/// file (the same path once resolved through links, or the same file
/// under two names: a hard link), or two files with the same bytes (a
/// copy), as [`repeated_record`] finds them. Fitted jointly, its samples
/// would count twice and every ± interval would be √2 too narrow.
fn distinct_records(paths: &[PathBuf]) -> Result<(), CliError> {
    let inputs: Vec<RecordInput<'_>> = paths.iter().map(|p| RecordInput::File(p)).collect();
    match repeated_record(&inputs) {
        None => Ok(()),
        Some(r) => Err(CliError::Input(r.message(
            &format!("--data {}", paths[r.first].display()),
            &format!("--data {}", paths[r.second].display()),
            "arguments",
        ))),
    }
}

/// The name each record's plots start with, distinct for distinct records
/// (ASCII case ignored, for file systems that ignore it): the file's stem
/// (`record<k>` for one that is not UTF-8); records sharing a stem get
/// their position `k` (from 1) among the `--data` appended, `<stem>-<k>`,
/// repeated in the rare case that is still another record's name. A plot
/// name is `<stem>-<channel>.svg` and no channel holds a `-`, so distinct
/// stems give distinct plot names.
fn plot_stems(paths: &[PathBuf]) -> Vec<String> {
    let base: Vec<String> = paths
        .iter()
        .enumerate()
        .map(|(k, p)| {
            p.file_stem()
                .and_then(|s| s.to_str())
                .map_or_else(|| format!("record{}", k + 1), str::to_string)
        })
        .collect();
    let key = |s: &str| s.to_ascii_lowercase();
    let shared = |s: &str| base.iter().filter(|b| key(b) == key(s)).count() > 1;
    let mut taken: BTreeSet<String> = base.iter().filter(|b| !shared(b)).map(|b| key(b)).collect();
    base.iter()
        .enumerate()
        .map(|(k, b)| {
            if !shared(b) {
                return b.clone();
            }
            let mut name = format!("{b}-{}", k + 1);
            while !taken.insert(key(&name)) {
                name = format!("{name}-{}", k + 1);
            }
            name
        })
        .collect()
}

/// The channels a record's plots can be of: a friction bench's `friction`
/// and `residual`; on a circuit rig every signal the record has (those the
/// model compares are among them).
fn plot_channels(rig: &DiagnoseRig, rec: &Record) -> Vec<&'static str> {
    match rig {
        DiagnoseRig::Bench(_) => vec!["friction", "residual"],
        DiagnoseRig::Net(..) => hydrocyl_identify::data::Signal::ALL
            .into_iter()
            .filter(|&s| s != hydrocyl_identify::data::Signal::Time && rec.get(s).is_some())
            .map(|s| s.name())
            .collect(),
    }
}

/// The file name of a record's plot of `channel`.
fn plot_name(stem: &str, channel: &str) -> String {
    format!("{stem}-{channel}.svg")
}

/// The SVG files for `traces` as `(file name, text)`: per record and
/// compared channel `<stem>-<channel>.svg` (measured, before and after
/// against time, and below it the residuals before and after) and, when an
/// effect with a regressor was added (friction benches),
/// `<stem>-residual.svg` (residual before vs that effect's regressor);
/// `stem_of` maps a record's source to its stem ([`plot_stems`]).
fn render_plots(
    traces: &[RecordTrace],
    stem_of: &BTreeMap<&str, &str>,
) -> Result<Vec<(String, String)>, CliError> {
    let mut out = Vec::new();
    for (k, tr) in traces.iter().enumerate() {
        let stem = stem_of
            .get(tr.source.as_str())
            .map_or_else(|| format!("record{}", k + 1), |s| s.to_string());
        let name = plot_name(&stem, &tr.channel);
        let mut svg = String::new();
        plot_series(&mut svg, &tr.source, tr)
            .map_err(|e| CliError::Input(format!("{name}: {e}")))?;
        out.push((name, svg));
        if tr.regressor.is_some() {
            let name = plot_name(&stem, "residual");
            let mut svg = String::new();
            plot_residual(&mut svg, &tr.source, tr)
                .map_err(|e| CliError::Input(format!("{name}: {e}")))?;
            out.push((name, svg));
        }
    }
    Ok(out)
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

/// Unit of a compared channel on the plots and the factor from SI to it
/// (pressures in bar).
fn unit(channel: &str) -> (&'static str, f64) {
    match channel {
        "force" => ("N", 1.0),
        "position" => ("m", 1.0),
        "velocity" => ("m/s", 1.0),
        "p1" | "p2" | "ps" => ("bar", 1e-5),
        _ => ("SI", 1.0),
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
    // head room above the data for the legend, so it hides none of it
    let hi = hi + 0.25 * (hi - lo);
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
        .position(SeriesLabelPosition::UpperRight)
        .border_style(BLACK)
        .background_style(WHITE)
        .draw()?;
    Ok(())
}

fn plot_series(
    svg: &mut String,
    title: &str,
    tr: &RecordTrace,
) -> Result<(), Box<dyn std::error::Error>> {
    use plotters::prelude::*;
    let root = SVGBackend::with_string(svg, (1000, 650)).into_drawing_area();
    root.fill(&WHITE)?;
    let (upper, lower) = root.split_vertically(420);
    let (u, f) = unit(&tr.channel);
    let scaled = |v: &[f64]| -> Vec<f64> { v.iter().map(|x| x * f).collect() };
    time_panel(
        &upper,
        &format!("{title}: {} measured vs simulated", tr.channel),
        &format!("{} [{u}]", tr.channel),
        &tr.t,
        &[
            ("measured", &scaled(&tr.measured), BLACK),
            ("before", &scaled(&tr.before), RED),
            ("after", &scaled(&tr.after), BLUE),
        ],
    )?;
    let resid = |sim: &[f64]| -> Vec<f64> {
        tr.measured
            .iter()
            .zip(sim)
            .map(|(m, s)| (m - s) * f)
            .collect()
    };
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

fn plot_residual(
    svg: &mut String,
    title: &str,
    tr: &RecordTrace,
) -> Result<(), Box<dyn std::error::Error>> {
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
    let root = SVGBackend::with_string(svg, (700, 500)).into_drawing_area();
    root.fill(&WHITE)?;
    let (xlo, xhi) = bounds(&[phi]);
    let (ylo, yhi) = bounds(&[&resid]);
    let mut ch = ChartBuilder::on(&root)
        .caption(
            format!("{title}: residual before vs {name} regressor"),
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

#[cfg(test)]
mod tests {
    use super::*;

    fn stems(paths: &[&str]) -> Vec<String> {
        let p: Vec<PathBuf> = paths.iter().map(PathBuf::from).collect();
        plot_stems(&p)
    }

    /// Distinct stems stay as they are; records sharing a stem (tester
    /// t38d D15: `a/rec.csv`, `b/rec.csv`) get their position, case
    /// ignored, and a name so made that is another record's stem is made
    /// again: no two records share a plot name.
    #[test]
    fn records_sharing_a_file_stem_get_distinct_plot_names() {
        assert_eq!(stems(&["x/a.csv", "y/b.csv"]), ["a", "b"]);
        assert_eq!(
            stems(&["coll/a/rec.csv", "coll/b/rec.csv"]),
            ["rec-1", "rec-2"]
        );
        assert_eq!(
            stems(&["a/Rec.csv", "b/rec.csv", "c.csv"]),
            ["Rec-1", "rec-2", "c"]
        );
        let s = stems(&["a/rec.csv", "b/rec.csv", "rec-1.csv"]);
        assert_eq!(s, ["rec-1-1", "rec-2", "rec-1"]);
        let lower: BTreeSet<String> = s.iter().map(|x| x.to_ascii_lowercase()).collect();
        assert_eq!(lower.len(), s.len());
    }

    /// The same file under two spellings or through a link, and a copy, are
    /// refused naming both arguments; two different files pass.
    #[cfg(unix)]
    #[test]
    fn a_record_given_twice_is_refused() {
        let dir = tempfile::tempdir().unwrap();
        let d = dir.path();
        std::fs::write(d.join("a.csv"), "time,force\n0,1\n").unwrap();
        std::fs::write(d.join("b.csv"), "time,force\n0,2\n").unwrap();
        std::fs::write(d.join("copy.csv"), "time,force\n0,1\n").unwrap();
        std::os::unix::fs::symlink(d.join("a.csv"), d.join("link.csv")).unwrap();
        let e = |names: &[&str]| {
            let p: Vec<PathBuf> = names.iter().map(|n| d.join(n)).collect();
            distinct_records(&p).err().map(|e| e.to_string())
        };
        assert_eq!(e(&["a.csv", "b.csv"]), None);
        let m = e(&["b.csv", "a.csv", "link.csv"]).unwrap();
        assert!(
            m.contains("link.csv (arguments 2 and 3): the same file"),
            "{m}"
        );
        let m = e(&["a.csv", "copy.csv"]).unwrap();
        assert!(m.contains("(arguments 1 and 2): the same content"), "{m}");
    }
}
