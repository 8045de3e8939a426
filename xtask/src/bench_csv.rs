//! `cargo xtask bench --only csv`: CSV reading and writing per row against
//! the previous per-row implementation (the `csv` crate's records with
//! `str::parse`; `format!("{:?}")` per cell), timed interleaved on the issue-19
//! case's output ([`crate::bench_solve::square_case`]).

use crate::bench_solve::square_case;
use hydrocyl_identify::plaincsv::{
    run_columns, write_columns, write_columns_in_parts, write_parts, PlainCsv,
};
use hydrocyl_system::run::Solver;
use hydrocyl_system::signal::Signal;
use std::time::Instant;

/// Rounds of the CSV section's interleaved timing.
const CSV_ROUNDS: usize = 60;

/// The fastest and the median time \[ns\] of one call of each of `fs`,
/// timed **interleaved**: after a warm-up of each, `rounds` rounds in which
/// every variant runs once (the order rotated from round to round), so that
/// a disturbance of the shared machine (another build, a noisy neighbour)
/// falls on every variant alike instead of on one block of one variant's
/// runs. The fastest of a variant is its least disturbed run; the ratios
/// are taken between fastests, the medians printed beside them.
pub(crate) fn interleaved_ns<const N: usize>(
    rounds: usize,
    mut fs: [&mut dyn FnMut() -> usize; N],
) -> [Timing; N] {
    for f in fs.iter_mut() {
        std::hint::black_box(f());
    }
    let mut samples = [(); N].map(|_| Vec::with_capacity(rounds));
    for r in 0..rounds {
        for i in 0..N {
            let k = (i + r) % N;
            let t0 = Instant::now();
            std::hint::black_box(fs[k]());
            samples[k].push(t0.elapsed().as_secs_f64() * 1e9);
        }
    }
    samples.map(|mut v| {
        v.sort_by(f64::total_cmp);
        Timing {
            min: v[0],
            median: v[v.len() / 2],
        }
    })
}

/// One variant's time per call (or, scaled, per row) \[ns\]: its fastest
/// (least disturbed) run and its median run.
#[derive(Clone, Copy)]
pub(crate) struct Timing {
    min: f64,
    median: f64,
}

impl Timing {
    pub(crate) fn per(self, n: f64) -> Timing {
        Timing {
            min: self.min / n,
            median: self.median / n,
        }
    }
    /// "`old`/`self` x (median `...`x)": how many times faster than `old`.
    pub(crate) fn speedup(self, old: Timing) -> String {
        format!(
            "{:.1}x (medians {:.1}x)",
            old.min / self.min,
            old.median / self.median
        )
    }
    /// "fastest ns (median ns)"
    pub(crate) fn show(self) -> String {
        format!("{:.0} ns/row (median {:.0})", self.min, self.median)
    }
}

/// CSV per row: the plain-CSV path against the previous implementation
/// (the `csv` crate's records with `str::parse`; `format!("{:?}")` per cell,
/// one thread), on one thread (`write_columns`; `PlainCsv::columns_on(_, 1)`)
/// and as the library splits a long table over the cores
/// (`write_columns_in_parts` with `write_parts`; `PlainCsv::columns`, which
/// `hydrocyl` reads with; the CLI formats on one writer thread beside the
/// solve), with the floor of each: the number conversions alone on every
/// cell (no splitting, no columns, no copying, no repeat skipped). The
/// previous and the new implementations of each row are timed interleaved
/// ([`interleaved_ns`], [`CSV_ROUNDS`] rounds): the ratios are between the
/// fastest runs of each, the medians' ratio beside them.
pub(crate) fn csv_per_row() -> Result<(), String> {
    let case = square_case(10.0)?;
    let run = case.run(Solver::Dp45, 1e-5)?;
    let (names, columns) = run_columns(&run);
    let rows = run.time.len() as f64;
    let parts = write_parts(run.time.len(), columns.len());
    let [write_new, write_par, write_old, write_floor] = interleaved_ns(
        CSV_ROUNDS,
        [
            &mut || write_columns(&names, &columns).len(),
            &mut || {
                write_columns_in_parts(&names, &columns, parts)
                    .iter()
                    .map(Vec::len)
                    .sum()
            },
            &mut || {
                let mut s = names.join(",");
                s.push('\n');
                for k in 0..run.time.len() {
                    s.push_str(&format!("{:?}", columns[0][k]));
                    for c in &columns[1..] {
                        s.push_str(&format!(",{:?}", c[k]));
                    }
                    s.push('\n');
                }
                s.len()
            },
            // the floor: zmij alone on the same values
            &mut || {
                let mut buf = zmij::Buffer::new();
                columns
                    .iter()
                    .flat_map(|c| c.iter())
                    .map(|&v| buf.format(v).len())
                    .sum()
            },
        ],
    )
    .map(|t| t.per(rows));
    let text = String::from_utf8(write_columns(&names, &columns)).map_err(|e| e.to_string())?;
    let wanted: Vec<usize> = (0..names.len()).collect();
    let (read_threads, [read_par, read_new, read_old, read_floor]) = read_per_row(&text, &wanted)?;
    let Signal::Table { time_s, value } = &case.command else {
        return Err("not a table".into());
    };
    let cmd = String::from_utf8(write_columns(&["time", "command"], &[time_s, value]))
        .map_err(|e| e.to_string())?;
    let (cmd_threads, [cmd_par, cmd_new, cmd_old, cmd_floor]) = read_per_row(&cmd, &[0, 1])?;
    // the share of the cells whose text is the text above (read: its value
    // is taken, not parsed again)
    let text_repeats = |text: &str| {
        let lines = cells_of(text);
        let same: usize = lines
            .windows(2)
            .map(|w| w[0].iter().zip(&w[1]).filter(|(a, b)| a == b).count())
            .sum();
        100.0 * same as f64 / lines.iter().map(Vec::len).sum::<usize>().max(1) as f64
    };
    println!(
        "CSV per row: fastest of {CSV_ROUNDS} interleaved rounds (median beside); ratios of the fastests against the previous implementation"
    );
    println!(
        "CSV, 1 kHz command file (time, command), read: one thread {} (previous {}, {} faster; fast-float2 alone {:.0}; {:.0} % of the cells repeat the text above), {cmd_threads} threads {} ({}); goal >= 10x",
        cmd_new.show(),
        cmd_old.show(),
        cmd_new.speedup(cmd_old),
        cmd_floor.min,
        text_repeats(&cmd),
        cmd_par.show(),
        cmd_par.speedup(cmd_old),
    );
    // a value equal to the one above it is copied, not formatted again
    let repeats = columns
        .iter()
        .map(|c| {
            c.windows(2)
                .filter(|w| w[0].to_bits() == w[1].to_bits())
                .count()
        })
        .sum::<usize>() as f64
        / (rows * columns.len() as f64);
    println!(
        "CSV, {} columns, write: one thread {} (previous {}, {} faster; zmij alone on every cell {:.0}; {:.0} % of the cells repeat the value above and are copied, not formatted), {parts} threads {} ({}); goal >= 10x",
        names.len(),
        write_new.show(),
        write_old.show(),
        write_new.speedup(write_old),
        write_floor.min,
        100.0 * repeats,
        write_par.show(),
        write_par.speedup(write_old),
    );
    println!(
        "CSV, {} columns, read: one thread {} (previous {}, {} faster; fast-float2 alone on every cell {:.0}; {:.0} % of the cells repeat the text above and take its value, not parsed), {read_threads} threads {} ({}); goal >= 10x",
        names.len(),
        read_new.show(),
        read_old.show(),
        read_new.speedup(read_old),
        read_floor.min,
        text_repeats(&text),
        read_par.show(),
        read_par.speedup(read_old),
    );
    Ok(())
}

/// The cells of each data line of `text` (the header skipped).
fn cells_of(text: &str) -> Vec<Vec<&[u8]>> {
    text.lines()
        .skip(1)
        .map(|l| l.split(',').map(str::as_bytes).collect())
        .collect()
}

/// Reading the `wanted` columns of plain CSV `text`, ns per data line,
/// interleaved: on the threads `PlainCsv` takes (returned beside), on one
/// thread, by the previous per-record reader, and the floor (fast-float2
/// alone on the same cells: no splitting, no columns, no copying).
fn read_per_row(text: &str, wanted: &[usize]) -> Result<(usize, [Timing; 4]), String> {
    let threads = PlainCsv::new(text)
        .map(|p| p.threads(wanted))
        .ok_or("not plain CSV")?;
    let lines = cells_of(text);
    let rows = lines.len() as f64;
    let cells: Vec<&[u8]> = lines.into_iter().flatten().collect();
    let timings = interleaved_ns(
        CSV_ROUNDS,
        [
            &mut || {
                PlainCsv::new(text)
                    .and_then(|p| p.columns(wanted))
                    .map_or(0, |c| c.len())
            },
            &mut || {
                PlainCsv::new(text)
                    .and_then(|p| p.columns_on(wanted, 1))
                    .map_or(0, |c| c.len())
            },
            &mut || {
                let mut rdr = csv_reader(text);
                let mut cols = vec![Vec::new(); wanted.len()];
                for rec in rdr.records().flatten() {
                    for (c, &j) in cols.iter_mut().zip(wanted) {
                        c.push(rec[j].parse::<f64>().unwrap_or(f64::NAN));
                    }
                }
                cols.len()
            },
            &mut || {
                cells
                    .iter()
                    .map(|c| {
                        fast_float2::parse::<f64, _>(c).map_or(0, |v: f64| v.is_finite() as usize)
                    })
                    .sum()
            },
        ],
    )
    .map(|t| t.per(rows));
    Ok((threads, timings))
}

fn csv_reader(text: &str) -> csv::Reader<&[u8]> {
    csv::ReaderBuilder::new()
        .trim(csv::Trim::All)
        .from_reader(text.as_bytes())
}
